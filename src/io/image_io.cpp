// image_io.cpp: reading height fields and writing results: georeferenced rasters and GeoTIFF
// outputs are handed to gdal_io.cpp, EXR inputs (by their magic number) and .exr outputs to
// OpenEXR (exr_images.hpp), PNG previews and the other images to OpenImageIO (oiio_images.hpp).
#include "hfvis/image_io.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "hfvis/errors.hpp"
#include "io/exr_images.hpp"
#include "io/gdal_io.hpp"
#include "io/oiio_images.hpp"
#include "io/output_files.hpp"

namespace hfvis {
namespace {

namespace fs = std::filesystem;

// Reads an image GDAL does not take: an EXR (by its magic number, whatever its name) through
// OpenEXR, anything else through OpenImageIO.
// `rounding`: see readExr (0 for the others, whose channels float32 holds).
ImageChannels readOtherImage(const std::string& path, std::uint64_t max_image_bytes,
                             const std::string* channel, double* rounding = nullptr) {
  detail::requireInputFile(path);
  if (rounding) *rounding = 0.0;
  if (detail::isExrFile(path)) return detail::readExr(path, max_image_bytes, channel, rounding);
  return detail::oiioImages().read(path, max_image_bytes, channel);
}

std::string attributeOf(const ImageChannels& image, const std::string& name) {
  for (const auto& [key, value] : image.attributes)
    if (key == name) return value;
  return "";
}

}  // namespace

HeightField readHeightField(const std::string& path, const HeightFieldReadOptions& options) {
  if (detail::isGdalHeightField(path)) return detail::readGdalHeightField(path, options);
  double rounding = 0.0;
  ImageChannels image = readOtherImage(path, options.max_image_bytes, &options.channel, &rounding);
  HeightField field;
  field.width = image.width;
  field.height = image.height;
  field.heights = std::move(image.planes.front());
  if (options.cell_size_x > 0.0 || options.cell_size_y > 0.0) {
    // One given size applies to both axes.
    field.cell_size_x = options.cell_size_x > 0.0 ? options.cell_size_x : options.cell_size_y;
    field.cell_size_y = options.cell_size_y > 0.0 ? options.cell_size_y : options.cell_size_x;
  } else if (const auto stored_cell_size =
                 // Cell size stored by hfvis itself (data/make_data.py and hfvis outputs write the
                 // string attributes "hfvis:cell_size_x" and "hfvis:cell_size_y").
             detail::storedCellSize(path, attributeOf(image, "hfvis:cell_size_x").c_str(),
                                    attributeOf(image, "hfvis:cell_size_y").c_str())) {
    field.cell_size_x = stored_cell_size->first;
    field.cell_size_y = stored_cell_size->second;
  }
  if (rounding > 0.0) {
    const auto [low, high] = std::minmax_element(field.heights.begin(), field.heights.end());
    try {
      requireHeightsKeptInFloat32(rounding, *low, *high, std::min(field.cell_size_x, field.cell_size_y));
    } catch (const InvalidArgument& error) {
      throw IoError(path, error.what());
    }
  }
  field.z_scale = options.z_scale;
  return field;
}

std::vector<std::string> filesRead(const std::string& path) {
  return detail::isGdalHeightField(path) ? detail::gdalFilesRead(path) : std::vector<std::string>{path};
}

ImageChannels readImage(const std::string& path) {
  if (detail::isGdalRaster(path)) return detail::readGdalImage(path);
  ImageChannels image = readOtherImage(path, 0, nullptr);
  image.attributes.clear();
  return image;
}

ImageChannels readColourImage(const std::string& path, const std::string& what) {
  ImageChannels image = detail::isGdalRaster(path) ? readImage(path) : readOtherImage(path, 0, nullptr);
  if (const std::string windows = attributeOf(image, "exr:windows"); !windows.empty())
    throw IoError(path, what + " covers its whole extent, but the EXR's " + windows +
                            ": write it with the two windows the same");
  image.attributes.clear();
  const auto find = [&](const char* name) {
    for (std::size_t i = 0; i < image.names.size(); ++i)
      if (image.names[i] == name) return static_cast<int>(i);
    return -1;
  };
  const int r = find("R"), g = find("G"), b = find("B");
  const bool rgb = r >= 0 && g >= 0 && b >= 0;
  const std::size_t others = image.names.size() - (rgb ? 3 : 0) - (rgb && find("A") >= 0 ? 1 : 0);
  ImageChannels out;
  out.width = image.width;
  out.height = image.height;
  out.integers = image.integers;
  if (rgb && others == 0) {
    out.names = {"R", "G", "B"};
    for (const int i : {r, g, b}) out.planes.push_back(std::move(image.planes[i]));
  } else if (image.names.size() == 1) {
    out.names = {"Y"};
    out.planes.push_back(std::move(image.planes[0]));
  } else {
    std::string names;
    for (const std::string& n : image.names) names += (names.empty() ? "" : ", ") + n;
    throw IoError(path, what + " needs one channel or R, G, B (and A, ignored); it has " +
                            (names.empty() ? std::string("none") : names));
  }
  return out;
}

bool writesGeoTiff(const std::string& path) {
  const std::string extension = detail::lowercaseExtension(path);
  return extension == ".tif" || extension == ".tiff";
}

void requireImageWriter(const std::string& path) {
  if (writesGeoTiff(path)) {
    if (detail::hasGeoTiffWriter()) return;
    throw IoError(path, "this GDAL has no GTiff driver to write a GeoTIFF (write .exr)");
  }
  // Data are float32: an 8-bit format (PNG, JPEG, ...) would clip and round them silently.
  if (detail::lowercaseExtension(path) == ".exr") return;
  const std::string extension = fs::path(path).extension().string();
  throw IoError(path, "no image writer for the extension '" + extension +
                          "' (write .exr, or .tif for a GeoTIFF: outputs hold float32 data; 8-bit "
                          "images only through --preview)");
}

namespace {

// The 8-bit previews: PNG, or what else OpenImageIO writes by extension.
void requirePreviewWriter(const std::string& path) {
  if (detail::oiioImages().can_write(path)) return;
  throw IoError(path, "no image writer for the extension '" + fs::path(path).extension().string() +
                          "' (a preview is a .png)");
}

void requireConsistent(const std::string& path, const ImageChannels& image) {
  if (image.width <= 0 || image.height <= 0) {
    throw InvalidArgument("image to write to '" + path + "' is empty (" + std::to_string(image.width) +
                          " x " + std::to_string(image.height) + " pixels)");
  }
  if (image.planes.empty() || image.names.size() != image.planes.size()) {
    throw InvalidArgument("image to write to '" + path + "' has " + std::to_string(image.planes.size()) +
                          " planes and " + std::to_string(image.names.size()) + " channel names");
  }
  const std::size_t count = static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height);
  std::set<std::string> seen;
  for (std::size_t c = 0; c < image.planes.size(); ++c) {
    if (image.planes[c].size() != count) {
      throw InvalidArgument("channel '" + image.names[c] + "' to write to '" + path + "' holds " +
                            std::to_string(image.planes[c].size()) + " values for " +
                            std::to_string(image.width) + " x " + std::to_string(image.height) + " pixels");
    }
    if (image.names[c].empty() || !seen.insert(image.names[c]).second) {
      throw InvalidArgument("channel names to write to '" + path + "' must be non-empty and unique (got '" +
                            image.names[c] + "')");
    }
  }
  if (std::isinf(image.nodata)) {
    throw InvalidArgument("the nodata value to write to '" + path + "' must be finite or NaN (got " +
                          std::to_string(image.nodata) + ")");
  }
  // A data value equal to the nodata value would be read back as nodata.
  if (writesGeoTiff(path) && !std::isnan(image.nodata)) {
    for (std::size_t c = 0; c < image.planes.size(); ++c) {
      const auto at = std::find(image.planes[c].begin(), image.planes[c].end(), image.nodata);
      if (at == image.planes[c].end()) continue;
      const std::size_t i = static_cast<std::size_t>(at - image.planes[c].begin());
      char value[32];
      std::snprintf(value, sizeof(value), "%.9g", image.nodata);
      throw InvalidArgument("the nodata value " + std::string(value) + " is also a data value of '" + path +
                            "' (channel " + image.names[c] + ", column " + std::to_string(i % image.width) +
                            ", row " + std::to_string(i / image.width) +
                            "): a reader would take it for nodata; choose a value the data never hold, "
                            "such as -9999, or nan");
    }
  }
  if (const auto& transform = image.georeference.geotransform) {
    if (!std::all_of(transform->begin(), transform->end(), [](double t) { return std::isfinite(t); }))
      throw InvalidArgument("the geotransform to write to '" + path + "' is not finite");
  }
}

void writeImageFile(const std::string& file, const std::string& path, const ImageChannels& image) {
  if (writesGeoTiff(path)) {
    detail::writeGeoTiff(file, path, image);
    detail::syncFile(file, path);
    return;
  }
  detail::writeExr(file, path, image);  // requireImageWriter let only .exr through
}

}  // namespace

void OutputFiles::image(const std::string& path, const ImageChannels& image) {
  requireConsistent(path, image);
  requireImageWriter(path);
  stage(
      path, [&](const std::string& file) { writeImageFile(file, path, image); }, writesGeoTiff(path));
}

void OutputFiles::text(const std::string& path, const std::string& text) {
  stage(path,
        [&](const std::string& file) { detail::writeFileChecked(file, path, text.data(), text.size()); });
}

void writeImage(const std::string& path, const ImageChannels& image) {
  OutputFiles files;
  files.image(path, image);
  files.commit();
}

void OutputFiles::previewPng(const std::string& path, int width, int height, const std::vector<float>& plane,
                             float lo, float hi) {
  if (width <= 0 || height <= 0) {
    throw InvalidArgument("preview '" + path + "' is empty (" + std::to_string(width) + " x " +
                          std::to_string(height) + " pixels)");
  }
  const std::size_t count = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (plane.size() != count) {
    throw InvalidArgument("preview '" + path + "' has " + std::to_string(plane.size()) + " values for " +
                          std::to_string(width) + " x " + std::to_string(height) + " pixels");
  }
  if (!std::isfinite(lo) || !std::isfinite(hi)) {
    throw InvalidArgument("preview '" + path + "' range must be finite (got " + std::to_string(lo) + ", " +
                          std::to_string(hi) + ")");
  }
  bool any_finite = true;
  if (lo == hi) {
    any_finite = false;
    for (float v : plane) {
      if (!std::isfinite(v)) continue;
      lo = any_finite ? std::min(lo, v) : v;
      hi = any_finite ? std::max(hi, v) : v;
      any_finite = true;
    }
  }
  // A constant plane has no range to map: draw it mid-grey (black when nothing is finite).
  const bool flat = lo == hi;
  const double scale = flat ? 0.0 : 255.0 / (static_cast<double>(hi) - lo);
  auto grey = [&](float v) -> std::uint8_t {
    if (std::isnan(v)) return 0;
    if (flat) return any_finite ? 128 : 0;
    const double g = std::round((static_cast<double>(v) - lo) * scale);
    return static_cast<std::uint8_t>(std::clamp(g, 0.0, 255.0));
  };

  requirePreviewWriter(path);
  stage(path, [&](const std::string& file) {
    detail::oiioImages().write(file, path, width, height, {"Y"},
                               [&](int y_begin, int y_end, std::uint8_t* rows) {
                                 const std::size_t begin = static_cast<std::size_t>(y_begin) * width;
                                 const std::size_t end = static_cast<std::size_t>(y_end) * width;
                                 for (std::size_t i = begin; i < end; ++i) rows[i - begin] = grey(plane[i]);
                               });
  });
}

void OutputFiles::toneMappedPng(const std::string& path, int width, int height,
                                const std::vector<std::vector<float>>& planes, double exposure) {
  const std::size_t count = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (width <= 0 || height <= 0 || (planes.size() != 1 && planes.size() != 3))
    throw InvalidArgument("preview '" + path + "' needs one or three planes of a non-empty image");
  for (const auto& plane : planes)
    if (plane.size() != count)
      throw InvalidArgument("preview '" + path + "' has a plane of " + std::to_string(plane.size()) +
                            " values for " + std::to_string(count) + " pixels");
  const bool rgb = planes.size() == 3;
  auto luminance = [&](std::size_t i) {
    return rgb ? 0.2126 * planes[0][i] + 0.7152 * planes[1][i] + 0.0722 * planes[2][i] : double(planes[0][i]);
  };
  double log_sum = 0.0;
  std::size_t finite = 0;
  for (std::size_t i = 0; i < count; ++i) {
    const double l = luminance(i);
    if (!std::isfinite(l)) continue;
    log_sum += std::log(1e-6 + std::max(0.0, l));
    ++finite;
  }
  const double key = finite ? std::exp(log_sum / finite) : 1.0;
  const double scale = 0.3 / std::max(key, 1e-6) * std::exp2(exposure);
  // Narkowicz's (2015) fit of the ACES filmic curve: a toe that keeps shadows' contrast and a
  // shoulder for the highlights.
  auto filmic = [](double x) { return x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14); };
  auto encode = [](double v) -> std::uint8_t {  // sRGB transfer curve
    v = std::clamp(v, 0.0, 1.0);
    const double s = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
    return static_cast<std::uint8_t>(std::lround(255.0 * s));
  };
  const int channels = rgb ? 3 : 1;
  const std::vector<std::string> names =
      rgb ? std::vector<std::string>{"R", "G", "B"} : std::vector<std::string>{"Y"};
  requirePreviewWriter(path);
  stage(path, [&](const std::string& file) {
    detail::oiioImages().write(
        file, path, width, height, names, [&](int y_begin, int y_end, std::uint8_t* rows) {
          const std::size_t begin = static_cast<std::size_t>(y_begin) * width;
          const std::size_t end = static_cast<std::size_t>(y_end) * width;
          for (std::size_t i = begin; i < end; ++i) {
            for (int c = 0; c < channels; ++c) {
              const double v = planes[c][i] * scale;
              rows[(i - begin) * channels + c] = std::isfinite(v) ? encode(filmic(std::max(0.0, v))) : 0;
            }
          }
        });
  });
}

}  // namespace hfvis
