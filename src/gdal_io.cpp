// gdal_io.cpp: reading georeferenced rasters through GDAL (see gdal_io.hpp).
#include "gdal_io.hpp"

#include <gdal.h>
#include <ogr_srs_api.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <limits>
#include <memory>
#include <mutex>

#include "hfvis/errors.hpp"

namespace hfvis::detail {
namespace {

constexpr std::uint64_t kDefaultMaxImageBytes = std::uint64_t(64) << 30;

void registerOnce() {
  static std::once_flag once;
  std::call_once(once, [] {
    GDALAllRegister();
    CPLSetErrorHandler(CPLQuietErrorHandler);  // errors are reported through IoError
  });
}

std::string lastError() {
  const char* message = CPLGetLastErrorMsg();
  return message && *message ? message : "GDAL cannot read it";
}

struct DatasetCloser {
  void operator()(void* dataset) const { GDALClose(dataset); }
};

}  // namespace

// Ground metres per degree on the WGS84 ellipsoid at geodetic latitude `lat_deg`:
// along a meridian (radius of curvature M) and along a parallel (N cos(lat)).
void metresPerDegree(double lat_deg, double* along_meridian, double* along_parallel) {
  const double a = 6378137.0;
  const double f = 1.0 / 298.257223563;
  const double e2 = f * (2.0 - f);
  const double lat = lat_deg * M_PI / 180.0;
  const double s = std::sin(lat);
  const double w = 1.0 - e2 * s * s;
  const double m = a * (1.0 - e2) / (w * std::sqrt(w));
  const double n = a / std::sqrt(w);
  *along_meridian = m * M_PI / 180.0;
  *along_parallel = n * std::cos(lat) * M_PI / 180.0;
}

bool isGdalRaster(const std::string& path) {
  std::string extension = std::filesystem::path(path).extension().string();
  std::transform(extension.begin(), extension.end(), extension.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  for (const char* gdal : {".tif", ".tiff", ".hgt", ".asc", ".vrt", ".img", ".bil", ".dem", ".grd", ".adf"})
    if (extension == gdal) return true;
  return false;
}

HeightField readGdalHeightField(const std::string& path, const HeightFieldReadOptions& options) {
  registerOnce();
  if (!std::filesystem::exists(path)) throw IoError(path, "no such file");
  std::unique_ptr<void, DatasetCloser> dataset(GDALOpen(path.c_str(), GA_ReadOnly));
  if (!dataset) throw IoError(path, lastError());
  const int width = GDALGetRasterXSize(dataset.get()), height = GDALGetRasterYSize(dataset.get());
  const int bands = GDALGetRasterCount(dataset.get());
  if (width <= 0 || height <= 0 || bands <= 0) throw IoError(path, "the raster has no pixels");
  // The band: the only one, an index, or a description.
  int band_index = 0;
  if (options.channel.empty()) {
    if (bands != 1)
      throw IoError(path, "the raster has " + std::to_string(bands) + " bands: choose one with --channel");
  } else if (std::all_of(options.channel.begin(), options.channel.end(), ::isdigit)) {
    band_index = std::stoi(options.channel);
    if (band_index >= bands) throw IoError(path, "no band " + options.channel);
  } else {
    band_index = -1;
    for (int b = 0; b < bands; ++b)
      if (options.channel == GDALGetDescription(GDALGetRasterBand(dataset.get(), b + 1))) band_index = b;
    if (band_index < 0) throw IoError(path, "no band named '" + options.channel + "'");
  }
  const std::uint64_t limit = options.max_image_bytes ? options.max_image_bytes : kDefaultMaxImageBytes;
  if (std::uint64_t(width) * std::uint64_t(height) * sizeof(float) > limit)
    throw IoError(path, "raster of " + std::to_string(width) + " x " + std::to_string(height) +
                            " pixels is more than the " + std::to_string(limit >> 20) + " MiB read at most");
  GDALRasterBandH band = GDALGetRasterBand(dataset.get(), band_index + 1);
  HeightField field;
  field.width = width;
  field.height = height;
  field.heights.resize(std::size_t(width) * height);
  if (GDALRasterIO(band, GF_Read, 0, 0, width, height, field.heights.data(), width, height, GDT_Float32, 0, 0) !=
      CE_None)
    throw IoError(path, lastError());
  int has_nodata = 0;
  const double nodata = GDALGetRasterNoDataValue(band, &has_nodata);
  if (has_nodata) {
    const float value = static_cast<float>(nodata);
    for (float& h : field.heights)
      if (h == value || (std::isnan(nodata) && std::isnan(h))) h = std::numeric_limits<float>::quiet_NaN();
  }
  // Cell sizes: given, else from the geotransform (north-up or south-up only).
  double gt[6];
  if (options.cell_size_x > 0.0 || options.cell_size_y > 0.0) {
    field.cell_size_x = options.cell_size_x > 0.0 ? options.cell_size_x : options.cell_size_y;
    field.cell_size_y = options.cell_size_y > 0.0 ? options.cell_size_y : options.cell_size_x;
  } else if (GDALGetGeoTransform(dataset.get(), gt) != CE_None) {
    // No geotransform: a geographic raster's spacing in metres cannot be known.
    OGRSpatialReferenceH srs = GDALGetSpatialRef(dataset.get());
    if (srs && OSRIsGeographic(srs))
      throw IoError(path, "a geographic raster without a geotransform (no tiepoint) has no cell size in "
                          "metres; give one with --cell-size");
  } else {
    if (gt[2] != 0.0 || gt[4] != 0.0)
      throw IoError(path, "rotated or sheared geotransforms are not supported (terms " + std::to_string(gt[2]) +
                              ", " + std::to_string(gt[4]) + "); warp the raster north-up first (gdalwarp)");
    field.cell_size_x = std::fabs(gt[1]);
    field.cell_size_y = std::fabs(gt[5]);
    OGRSpatialReferenceH srs = GDALGetSpatialRef(dataset.get());
    if (srs && OSRIsGeographic(srs)) {
      const double lat = gt[3] + gt[5] * 0.5 * height;
      double per_deg_y, per_deg_x;
      metresPerDegree(lat, &per_deg_y, &per_deg_x);
      field.cell_size_x *= per_deg_x;
      field.cell_size_y *= per_deg_y;
    }
  }
  field.z_scale = options.z_scale;
  return field;
}

}  // namespace hfvis::detail
