// image_io.cpp: reading height fields and writing results: OpenImageIO for EXR and other
// images; georeferenced rasters and GeoTIFF outputs are handed to gdal_io.cpp.
#include "hfvis/image_io.hpp"

#include <OpenImageIO/imageio.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>
#include <new>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include "gdal_io.hpp"
#include "hfvis/errors.hpp"

namespace hfvis {
namespace {

namespace fs = std::filesystem;

std::string joinNames(const std::vector<std::string>& names) {
  std::string joined;
  for (std::size_t i = 0; i < names.size(); ++i) {
    if (i > 0) joined += ", ";
    joined += "'" + names[i] + "'";
  }
  return joined;
}

// OpenImageIO's error strings sometimes end in a newline; a reason reads better without it.
std::string trimmed(std::string text) {
  while (!text.empty() && (text.back() == '\n' || text.back() == ' ')) text.pop_back();
  return text;
}

std::string withDetail(const std::string& reason, const std::string& detail) {
  const std::string d = trimmed(detail);
  return d.empty() ? reason : reason + " (" + d + ")";
}

// ---------------------------------------------------------------------------------------------
// Reading pixels.

int selectChannel(const std::string& path, const OIIO::ImageSpec& spec, const std::string& choice) {
  const std::vector<std::string>& names = spec.channelnames;
  const std::string available = std::to_string(spec.nchannels) + " channels: " + joinNames(names);
  if (choice.empty()) {
    if (spec.nchannels == 1) return 0;
    throw IoError(path,
                  "image has " + available + "; choose one by name or zero-based index (hfvis --channel)");
  }
  for (int c = 0; c < spec.nchannels && c < static_cast<int>(names.size()); ++c) {
    if (names[c] == choice) return c;
  }
  if (choice.size() <= 9 &&
      std::all_of(choice.begin(), choice.end(), [](char ch) { return ch >= '0' && ch <= '9'; })) {
    const int index = std::stoi(choice);
    if (index < spec.nchannels) return index;
  }
  throw IoError(path, "no channel '" + choice + "' (image has " + available + ")");
}

template <typename T>
void convertIntegers(const std::vector<unsigned char>& raw, double rescale, std::vector<float>* out) {
  const T* values = reinterpret_cast<const T*>(raw.data());
  for (std::size_t i = 0; i < out->size(); ++i) {
    const double v = static_cast<double>(values[i]);
    (*out)[i] = static_cast<float>(rescale == 1.0 ? v : std::round(v * rescale));
  }
}

// Reads channel `ch` of subimage 0 as type `as` (T: float, or bytes for other types) in
// blocks of rows, the buffer growing with the rows read: a header that claims more pixels
// than the file holds fails at its first missing rows, not after allocating the whole claim.
// Tiled files are read whole (OpenImageIO reads them a tile row at a time internally).
template <typename T>
std::vector<T> readRows(const std::string& path, OIIO::ImageInput& in, int ch, OIIO::TypeDesc as) {
  const OIIO::ImageSpec& spec = in.spec();
  const std::size_t row_values = static_cast<std::size_t>(spec.width) * as.size() / sizeof(T);
  const auto fail = [&] {
    throw IoError(path,
                  withDetail("cannot read pixel data; the file is truncated or corrupt", in.geterror()));
  };
  std::vector<T> values;
  if (spec.tile_width > 0) {
    values.resize(row_values * static_cast<std::size_t>(spec.height));
    if (!in.read_image(0, 0, ch, ch + 1, as, values.data())) fail();
    return values;
  }
  const int block = static_cast<int>(std::clamp<std::size_t>(
      (std::size_t(16) << 20) / (row_values * sizeof(T)), 1, static_cast<std::size_t>(spec.height)));
  for (int y = 0; y < spec.height; y += block) {
    const int y_end = std::min(spec.height, y + block);
    values.resize(row_values * static_cast<std::size_t>(y_end));
    if (!in.read_scanlines(0, 0, spec.y + y, spec.y + y_end, 0, ch, ch + 1, as,
                           values.data() + row_values * static_cast<std::size_t>(y)))
      fail();
  }
  return values;
}

// Reads channel `ch` of subimage 0 as the stored values (integers are not normalised).
std::vector<float> readChannel(const std::string& path, OIIO::ImageInput& in, int ch) {
  const OIIO::ImageSpec& spec = in.spec();
  const OIIO::TypeDesc type = spec.channelformat(ch);
  switch (type.basetype) {
    case OIIO::TypeDesc::HALF:
    case OIIO::TypeDesc::FLOAT:
    case OIIO::TypeDesc::DOUBLE:
      return readRows<float>(path, in, ch, OIIO::TypeDesc::FLOAT);
    case OIIO::TypeDesc::UINT8:
    case OIIO::TypeDesc::INT8:
    case OIIO::TypeDesc::UINT16:
    case OIIO::TypeDesc::INT16:
    case OIIO::TypeDesc::UINT32:
    case OIIO::TypeDesc::INT32:
    case OIIO::TypeDesc::UINT64:
    case OIIO::TypeDesc::INT64:
      break;
    default:
      throw IoError(path, "unsupported pixel type '" + std::string(type.c_str()) + "'");
  }
  // Integers: read in their own type, since OpenImageIO's conversion to float would
  // normalise them to [0, 1]. Files with fewer bits than the type (a 12-bit TIFF) are
  // delivered scaled up to the type's full range; scale them back to the stored values.
  const std::vector<unsigned char> raw = readRows<unsigned char>(
      path, in, ch, OIIO::TypeDesc(static_cast<OIIO::TypeDesc::BASETYPE>(type.basetype)));
  std::vector<float> heights(raw.size() / type.size());
  double rescale = 1.0;
  const int bits = spec.get_int_attribute("oiio:BitsPerSample", 0);
  const int type_bits = static_cast<int>(8 * type.size());
  if (bits > 0 && bits < type_bits && bits < 64 && type_bits < 64 && !type.is_signed()) {
    rescale = (std::ldexp(1.0, bits) - 1.0) / (std::ldexp(1.0, type_bits) - 1.0);
  }
  switch (type.basetype) {
    case OIIO::TypeDesc::UINT8:
      convertIntegers<std::uint8_t>(raw, rescale, &heights);
      break;
    case OIIO::TypeDesc::INT8:
      convertIntegers<std::int8_t>(raw, rescale, &heights);
      break;
    case OIIO::TypeDesc::UINT16:
      convertIntegers<std::uint16_t>(raw, rescale, &heights);
      break;
    case OIIO::TypeDesc::INT16:
      convertIntegers<std::int16_t>(raw, rescale, &heights);
      break;
    case OIIO::TypeDesc::UINT32:
      convertIntegers<std::uint32_t>(raw, rescale, &heights);
      break;
    case OIIO::TypeDesc::INT32:
      convertIntegers<std::int32_t>(raw, rescale, &heights);
      break;
    case OIIO::TypeDesc::UINT64:
      convertIntegers<std::uint64_t>(raw, rescale, &heights);
      break;
    default:
      convertIntegers<std::int64_t>(raw, rescale, &heights);
      break;
  }
  return heights;
}

// ---------------------------------------------------------------------------------------------
// Atomic writing: everything goes to a temporary file beside the target, which is renamed
// into place only after a successful close. The temporary keeps the target's extension so
// the same writer (OpenImageIO's, by extension, or the GeoTIFF one) takes it.

std::string temporaryPathFor(const std::string& path) {
  static std::atomic<unsigned> counter{0};
  const fs::path target(path);
  const std::string name = "." + target.stem().string() + ".tmp" + std::to_string(::getpid()) + "_" +
                           std::to_string(counter.fetch_add(1)) + target.extension().string();
  return (target.parent_path() / name).string();
}

class TemporaryFile {
 public:
  explicit TemporaryFile(std::string path) : path_(std::move(path)) {}
  ~TemporaryFile() {
    if (!committed_) {
      std::error_code ignored;
      fs::remove(path_, ignored);
    }
  }
  TemporaryFile(const TemporaryFile&) = delete;
  TemporaryFile& operator=(const TemporaryFile&) = delete;
  const std::string& path() const { return path_; }
  void commitTo(const std::string& target) {
    if (std::rename(path_.c_str(), target.c_str()) != 0) {
      throw IoError(target, "cannot rename the finished temporary file '" + path_ + "' into place (" +
                                std::strerror(errno) + ")");
    }
    committed_ = true;
  }

 private:
  std::string path_;
  bool committed_ = false;
};

// The checks every writer makes before it creates anything, and the temporary file beside
// `path` that it writes.
TemporaryFile temporaryBeside(const std::string& path) {
  requireImageWriter(path);
  const fs::path target(path);
  if (target.filename().empty()) throw IoError(path, "not a file name");
  const fs::path dir = target.parent_path().empty() ? fs::path(".") : target.parent_path();
  std::error_code ec;
  if (!fs::is_directory(dir, ec)) {
    throw IoError(path, "directory '" + dir.string() + "' does not exist");
  }
  return TemporaryFile(temporaryPathFor(path));
}

// Writes `spec.height` rows produced by `fill_rows(y_begin, y_end, buffer)` (interleaved pixels
// of `spec.format`, at most `rows_per_chunk` rows at a time) to `path` atomically.
template <typename Pixel, typename FillRows>
void writeAtomically(const std::string& path, const OIIO::ImageSpec& spec, FillRows fill_rows) {
  TemporaryFile temporary = temporaryBeside(path);
  std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(temporary.path());
  if (!out) throw IoError(path, withDetail("no image writer for this file", OIIO::geterror()));
  if (!out->open(temporary.path(), spec)) {
    throw IoError(path, withDetail("cannot write the image", out->geterror()));
  }
  // Rows go out in chunks so a large many-channel image never needs a second full copy.
  const std::size_t row_values = static_cast<std::size_t>(spec.width) * spec.nchannels;
  const int rows_per_chunk =
      static_cast<int>(std::clamp<std::size_t>((std::size_t(1) << 22) / row_values, 1, 256));
  std::vector<Pixel> buffer(row_values * static_cast<std::size_t>(std::min(rows_per_chunk, spec.height)));
  const OIIO::TypeDesc format = spec.format;
  for (int y = 0; y < spec.height; y += rows_per_chunk) {
    const int y_end = std::min(spec.height, y + rows_per_chunk);
    fill_rows(y, y_end, buffer.data());
    if (!out->write_scanlines(y, y_end, 0, format, buffer.data())) {
      const std::string error = out->geterror();
      out->close();
      throw IoError(path, withDetail("cannot write the image", error));
    }
  }
  if (!out->close()) {
    throw IoError(path, withDetail("cannot finish writing the image", out->geterror()));
  }
  out.reset();
  temporary.commitTo(path);
}

}  // namespace

// Cell size stored by hfvis itself (data/make_data.py and hfvis outputs write the string
// attributes "hfvis:cell_size_x" and "hfvis:cell_size_y"); both must parse as positive.
static std::optional<std::pair<double, double>> hfvisCellSize(const OIIO::ImageSpec& spec) {
  return detail::storedCellSize(spec.get_string_attribute("hfvis:cell_size_x").c_str(),
                                spec.get_string_attribute("hfvis:cell_size_y").c_str());
}

namespace {

// Opens an image for reading, with the checks every reader shares: the file exists, is not
// empty, and holds a 2D, non-deep image with pixels.
constexpr std::uint64_t kDefaultMaxImageBytes = std::uint64_t(64) << 30;

std::unique_ptr<OIIO::ImageInput> openImage(const std::string& path, std::uint64_t max_image_bytes = 0) {
  std::error_code ec;
  const fs::file_status status = fs::status(path, ec);
  if (!fs::exists(status)) throw IoError(path, "no such file");
  if (fs::is_directory(status)) throw IoError(path, "is a directory, not an image file");
  if (fs::is_regular_file(status) && fs::file_size(path, ec) == 0 && !ec) {
    throw IoError(path, "file is empty (0 bytes)");
  }

  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path);
  if (!in) throw IoError(path, withDetail("cannot read as an image", OIIO::geterror()));
  const OIIO::ImageSpec& spec = in->spec();
  if (spec.width <= 0 || spec.height <= 0 || spec.nchannels <= 0) {
    throw IoError(path, "image is empty (" + std::to_string(spec.width) + " x " +
                            std::to_string(spec.height) + " pixels, " + std::to_string(spec.nchannels) +
                            " channels)");
  }
  // The kernels index pixels with 32-bit integers (computeHorizons refuses larger fields), so
  // a larger image is refused before any of it is read.
  if (static_cast<std::uint64_t>(spec.width) * static_cast<std::uint64_t>(spec.height) >=
      (std::uint64_t(1) << 31)) {
    throw IoError(path, "image is " + std::to_string(spec.width) + " x " + std::to_string(spec.height) +
                            " pixels; hfvis reads fields below 2^31 pixels (split it into tiles)");
  }
  // What the header claims, before the readers allocate for it (a damaged or hostile header
  // can claim terabytes in a few bytes).
  // A TIFF's strips may claim more rows than the image has; OpenImageIO buffers a whole strip.
  const std::uint64_t limit = max_image_bytes ? max_image_bytes : kDefaultMaxImageBytes;
  const std::uint64_t rows =
      std::max<std::uint64_t>(spec.height, std::max(0, spec.get_int_attribute("tiff:RowsPerStrip", 0)));
  const std::uint64_t scanline = static_cast<std::uint64_t>(spec.width) * spec.pixel_bytes(true);
  if (scanline / std::max<std::uint64_t>(spec.width, 1) != spec.pixel_bytes(true) ||
      scanline * rows / rows != scanline || scanline * rows > limit) {
    throw IoError(path, "image claims " + std::to_string(spec.width) + " x " + std::to_string(spec.height) +
                            " pixels of " + std::to_string(spec.nchannels) + " channels, more than the " +
                            std::to_string(limit >> 20) + " MiB read at most");
  }
  if (spec.depth > 1) throw IoError(path, "volume images (depth > 1) are not supported");
  if (spec.deep) throw IoError(path, "deep images are not supported");
  return in;
}

}  // namespace

HeightField readHeightField(const std::string& path, const HeightFieldReadOptions& options) {
  if (detail::isGdalRaster(path)) return detail::readGdalHeightField(path, options);
  std::unique_ptr<OIIO::ImageInput> in = openImage(path, options.max_image_bytes);
  const OIIO::ImageSpec& spec = in->spec();
  const int channel = selectChannel(path, spec, options.channel);

  HeightField field;
  field.width = spec.width;
  field.height = spec.height;
  try {
    field.heights = readChannel(path, *in, channel);
  } catch (const std::bad_alloc&) {
    throw IoError(path, "image is too large to hold in memory (" + std::to_string(spec.width) + " x " +
                            std::to_string(spec.height) + " pixels)");
  }
  const auto stored_cell_size = hfvisCellSize(spec);
  in->close();

  if (options.cell_size_x > 0.0 || options.cell_size_y > 0.0) {
    // One given size applies to both axes.
    field.cell_size_x = options.cell_size_x > 0.0 ? options.cell_size_x : options.cell_size_y;
    field.cell_size_y = options.cell_size_y > 0.0 ? options.cell_size_y : options.cell_size_x;
  } else if (stored_cell_size) {
    field.cell_size_x = stored_cell_size->first;
    field.cell_size_y = stored_cell_size->second;
  }
  field.z_scale = options.z_scale;
  return field;
}

ImageChannels readImage(const std::string& path) {
  if (detail::isGdalRaster(path)) return detail::readGdalImage(path);
  std::unique_ptr<OIIO::ImageInput> in = openImage(path);
  const OIIO::ImageSpec& spec = in->spec();
  ImageChannels image;
  image.width = spec.width;
  image.height = spec.height;
  try {
    for (int c = 0; c < spec.nchannels; ++c) {
      const bool named = c < static_cast<int>(spec.channelnames.size()) && !spec.channelnames[c].empty();
      image.names.push_back(named ? spec.channelnames[c] : "channel" + std::to_string(c));
      image.planes.push_back(readChannel(path, *in, c));
    }
  } catch (const std::bad_alloc&) {
    throw IoError(path, "image is too large to hold in memory (" + std::to_string(spec.width) + " x " +
                            std::to_string(spec.height) + " pixels, " + std::to_string(spec.nchannels) +
                            " channels)");
  }
  in->close();
  return image;
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
  if (OIIO::ImageOutput::create(path)) return;
  OIIO::geterror();  // clear OpenImageIO's message: this one says what to do instead
  const std::string extension = fs::path(path).extension().string();
  throw IoError(path,
                "no image writer for the extension '" + extension + "' (write .exr, or .tif for a GeoTIFF)");
}

void writeImage(const std::string& path, const ImageChannels& image) {
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
  if (const auto& transform = image.georeference.geotransform) {
    if (!std::all_of(transform->begin(), transform->end(), [](double t) { return std::isfinite(t); }))
      throw InvalidArgument("the geotransform to write to '" + path + "' is not finite");
  }

  if (writesGeoTiff(path)) {
    TemporaryFile temporary = temporaryBeside(path);
    detail::writeGeoTiff(temporary.path(), path, image);
    temporary.commitTo(path);
    return;
  }

  const int channels = static_cast<int>(image.planes.size());
  OIIO::ImageSpec spec(image.width, image.height, channels, OIIO::TypeDesc::FLOAT);
  spec.channelnames = image.names;
  spec.alpha_channel = -1;  // every channel is data; none may be treated as alpha
  spec.z_channel = -1;
  for (const auto& [name, value] : image.attributes) spec.attribute(name, value);

  writeAtomically<float>(path, spec, [&](int y_begin, int y_end, float* rows) {
    for (int y = y_begin; y < y_end; ++y) {
      for (int x = 0; x < image.width; ++x) {
        const std::size_t src = static_cast<std::size_t>(y) * image.width + x;
        float* pixel = rows + (static_cast<std::size_t>(y - y_begin) * image.width + x) * channels;
        for (int c = 0; c < channels; ++c) pixel[c] = image.planes[c][src];
      }
    }
  });
}

void writePreviewPng(const std::string& path, int width, int height, const std::vector<float>& plane,
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

  OIIO::ImageSpec spec(width, height, 1, OIIO::TypeDesc::UINT8);
  spec.channelnames = {"Y"};
  writeAtomically<std::uint8_t>(path, spec, [&](int y_begin, int y_end, std::uint8_t* rows) {
    const std::size_t begin = static_cast<std::size_t>(y_begin) * width;
    const std::size_t end = static_cast<std::size_t>(y_end) * width;
    for (std::size_t i = begin; i < end; ++i) rows[i - begin] = grey(plane[i]);
  });
}

std::pair<float, float> quantileRange(const std::vector<float>& plane, double lo_q, double hi_q) {
  std::vector<float> finite;
  for (float v : plane)
    if (std::isfinite(v)) finite.push_back(v);
  if (finite.empty()) return {0.0f, 0.0f};
  auto at = [&](double q) {
    const std::size_t rank = static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * (finite.size() - 1) + 0.5);
    std::nth_element(finite.begin(), finite.begin() + rank, finite.end());
    return finite[rank];
  };
  const float lo = at(lo_q), hi = at(hi_q);
  return {lo, hi};
}

void writeToneMappedPng(const std::string& path, int width, int height, const std::vector<std::vector<float>>& planes,
                        double exposure) {
  const std::size_t count = static_cast<std::size_t>(width) * static_cast<std::size_t>(height);
  if (width <= 0 || height <= 0 || (planes.size() != 1 && planes.size() != 3))
    throw InvalidArgument("preview '" + path + "' needs one or three planes of a non-empty image");
  for (const auto& plane : planes)
    if (plane.size() != count)
      throw InvalidArgument("preview '" + path + "' has a plane of " + std::to_string(plane.size()) + " values for " +
                            std::to_string(count) + " pixels");
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
  OIIO::ImageSpec spec(width, height, channels, OIIO::TypeDesc::UINT8);
  spec.channelnames = rgb ? std::vector<std::string>{"R", "G", "B"} : std::vector<std::string>{"Y"};
  writeAtomically<std::uint8_t>(path, spec, [&](int y_begin, int y_end, std::uint8_t* rows) {
    const std::size_t begin = static_cast<std::size_t>(y_begin) * width;
    const std::size_t end = static_cast<std::size_t>(y_end) * width;
    for (std::size_t i = begin; i < end; ++i) {
      for (int c = 0; c < channels; ++c) {
        const double v = planes[c][i] * scale;
        rows[(i - begin) * channels + c] = std::isfinite(v) ? encode(filmic(std::max(0.0, v))) : 0;
      }
    }
  });
}

std::vector<std::string> directionChannelNames(const std::string& prefix, int count) {
  if (count < 0)
    throw InvalidArgument("direction count must not be negative (got " + std::to_string(count) + ")");
  const int digits = static_cast<int>(std::to_string(std::max(count - 1, 0)).size());
  const int width = std::max(3, digits);
  std::vector<std::string> names;
  names.reserve(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) {
    const std::string index = std::to_string(k);
    names.push_back(prefix + std::string(static_cast<std::size_t>(width) - index.size(), '0') + index);
  }
  return names;
}

}  // namespace hfvis
