// geotiff_support.hpp: GeoTIFFs made and read back with GDAL's C API itself, independently of
// hfvis's reader and writer, for the image IO and CLI tests.
#pragma once

#include <cpl_string.h>
#include <gdal.h>
#include <gtest/gtest.h>
#include <ogr_srs_api.h>

#include <array>
#include <map>
#include <optional>
#include <string>
#include <vector>

namespace hfvis::testing {

// 500 km east, 4100 km north in UTM zone 33N, 30 m cells, row 0 north (negative y pixel size).
inline constexpr std::array<double, 6> kUtmGeotransform = {500000.0, 30.0, 0.0, 4100000.0, 0.0, -30.0};

inline void registerGdal() {
  static const bool registered = [] {
    GDALAllRegister();
    return true;
  }();
  (void)registered;
}

// The WKT of a CRS GDAL knows by `user_input` ("EPSG:32633").
inline std::string crsWkt(const std::string& user_input) {
  registerGdal();
  OGRSpatialReferenceH srs = OSRNewSpatialReference(nullptr);
  EXPECT_EQ(OSRSetFromUserInput(srs, user_input.c_str()), OGRERR_NONE) << user_input;
  char* wkt = nullptr;
  OSRExportToWkt(srs, &wkt);
  const std::string text = wkt ? wkt : "";
  CPLFree(wkt);
  OSRDestroySpatialReference(srs);
  return text;
}

// Whether two WKT strings name the same CRS (OSRIsSame).
inline bool sameCrs(const std::string& a, const std::string& b) {
  registerGdal();
  OGRSpatialReferenceH sa = OSRNewSpatialReference(nullptr), sb = OSRNewSpatialReference(nullptr);
  const bool same = OSRSetFromUserInput(sa, a.c_str()) == OGRERR_NONE &&
                    OSRSetFromUserInput(sb, b.c_str()) == OGRERR_NONE && OSRIsSame(sa, sb);
  OSRDestroySpatialReference(sa);
  OSRDestroySpatialReference(sb);
  return same;
}

// Writes a one-band float32 GeoTIFF (uncompressed, in strips: not how hfvis writes) with the
// geotransform, CRS (user input as for crsWkt; "" = none) and nodata value given.
inline void writeGdalGeoTiff(const std::string& path, int width, int height, const std::vector<float>& values,
                             const std::array<double, 6>& geotransform, const std::string& crs,
                             std::optional<double> nodata) {
  registerGdal();
  GDALDatasetH dataset =
      GDALCreate(GDALGetDriverByName("GTiff"), path.c_str(), width, height, 1, GDT_Float32, nullptr);
  ASSERT_NE(dataset, nullptr) << CPLGetLastErrorMsg();
  std::array<double, 6> transform = geotransform;
  EXPECT_EQ(GDALSetGeoTransform(dataset, transform.data()), CE_None);
  if (!crs.empty()) {
    EXPECT_EQ(GDALSetProjection(dataset, crsWkt(crs).c_str()), CE_None);
  }
  GDALRasterBandH band = GDALGetRasterBand(dataset, 1);
  if (nodata) {
    EXPECT_EQ(GDALSetRasterNoDataValue(band, *nodata), CE_None);
  }
  std::vector<float> pixels = values;
  EXPECT_EQ(
      GDALRasterIO(band, GF_Write, 0, 0, width, height, pixels.data(), width, height, GDT_Float32, 0, 0),
      CE_None);
  GDALClose(dataset);
}

// A GeoTIFF as GDAL reads it.
struct GdalRaster {
  int width = 0;
  int height = 0;
  std::vector<std::string> descriptions;  // per band
  std::vector<std::vector<float>> bands;  // raw values, nodata cells as stored
  std::vector<std::optional<double>> nodata;
  std::vector<std::array<int, 2>> block_sizes;
  std::optional<std::array<double, 6>> geotransform;
  std::string crs_wkt;
  std::map<std::string, std::string> metadata;         // default domain
  std::map<std::string, std::string> image_structure;  // COMPRESSION, PREDICTOR, INTERLEAVE, ...
  std::string driver;
};

inline std::map<std::string, std::string> metadataOf(GDALDatasetH dataset, const char* domain) {
  std::map<std::string, std::string> items;
  for (char** item = GDALGetMetadata(dataset, domain); item && *item; ++item) {
    char* name = nullptr;
    const char* value = CPLParseNameValue(*item, &name);
    if (name && value) items[name] = value;
    CPLFree(name);
  }
  return items;
}

inline GdalRaster readGdalRaster(const std::string& path) {
  registerGdal();
  GdalRaster raster;
  GDALDatasetH dataset = GDALOpen(path.c_str(), GA_ReadOnly);
  if (!dataset) {
    ADD_FAILURE() << "GDAL cannot open " << path << ": " << CPLGetLastErrorMsg();
    return raster;
  }
  raster.driver = GDALGetDriverShortName(GDALGetDatasetDriver(dataset));
  raster.width = GDALGetRasterXSize(dataset);
  raster.height = GDALGetRasterYSize(dataset);
  for (int b = 1; b <= GDALGetRasterCount(dataset); ++b) {
    GDALRasterBandH band = GDALGetRasterBand(dataset, b);
    raster.descriptions.push_back(GDALGetDescription(band));
    std::vector<float> values(static_cast<std::size_t>(raster.width) * raster.height);
    EXPECT_EQ(GDALRasterIO(band, GF_Read, 0, 0, raster.width, raster.height, values.data(), raster.width,
                           raster.height, GDT_Float32, 0, 0),
              CE_None);
    raster.bands.push_back(values);
    int has_nodata = 0;
    const double nodata = GDALGetRasterNoDataValue(band, &has_nodata);
    raster.nodata.push_back(has_nodata ? std::optional<double>(nodata) : std::nullopt);
    int bx = 0, by = 0;
    GDALGetBlockSize(band, &bx, &by);
    raster.block_sizes.push_back({bx, by});
  }
  std::array<double, 6> transform;
  if (GDALGetGeoTransform(dataset, transform.data()) == CE_None) raster.geotransform = transform;
  if (const char* wkt = GDALGetProjectionRef(dataset)) raster.crs_wkt = wkt;
  raster.metadata = metadataOf(dataset, nullptr);
  raster.image_structure = metadataOf(dataset, "IMAGE_STRUCTURE");
  GDALClose(dataset);
  return raster;
}

}  // namespace hfvis::testing
