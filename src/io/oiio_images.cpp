// oiio_images.cpp: PNG, TIFF bytes under another extension and the other images neither GDAL nor
// OpenEXR (exr_images.cpp) takes, through OpenImageIO (oiio_images.hpp): reading channels as
// stored values, and writing 8-bit previews.
#include "io/oiio_images.hpp"

#include <OpenImageIO/filesystem.h>
#include <OpenImageIO/imageio.h>
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdint>
#include <memory>
#include <new>
#include <string>
#include <vector>

#include "hfvis/errors.hpp"
#include "io/image_reading.hpp"
#include "io/output_files.hpp"

namespace hfvis::detail {
namespace {

// ---------------------------------------------------------------------------------------------
// Reading pixels.

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
// Rows are read in the file's own format and converted here: OpenImageIO's converting
// read_scanlines buffers at least 256 rows of every channel whatever it is asked for (it took
// 16 GB for a 422-byte EXR claiming 16 million columns, when EXRs came this way); a block here
// holds about 16 MiB of rows of every channel (what a reader may buffer for a channel subset),
// one row at least.
// Tiled files are read whole (OpenImageIO reads them a tile row at a time internally).
template <typename T>
std::vector<T> readRows(const std::string& path, OIIO::ImageInput& in, int ch, OIIO::TypeDesc as) {
  const OIIO::ImageSpec& spec = in.spec();
  const std::size_t width = static_cast<std::size_t>(spec.width);
  const std::size_t row_values = width * as.size() / sizeof(T);
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
  const OIIO::TypeDesc native = spec.channelformat(ch);
  const std::size_t widest_row =
      std::max({spec.scanline_bytes(true), width * native.size(), row_values * sizeof(T)});
  const int block = static_cast<int>(std::clamp<std::size_t>((std::size_t(16) << 20) / std::max<std::size_t>(widest_row, 1),
                                                             1, static_cast<std::size_t>(spec.height)));
  std::vector<unsigned char> rows;  // one block in the file's format, where it differs from `as`
  for (int y = 0; y < spec.height; y += block) {
    const int y_end = std::min(spec.height, y + block);
    const std::size_t n = width * static_cast<std::size_t>(y_end - y);
    values.resize(row_values * static_cast<std::size_t>(y_end));
    void* out = values.data() + row_values * static_cast<std::size_t>(y);
    if (native == as) {
      if (!in.read_native_scanlines(0, 0, spec.y + y, spec.y + y_end, 0, ch, ch + 1, out)) fail();
      continue;
    }
    rows.resize(n * native.size());
    if (!in.read_native_scanlines(0, 0, spec.y + y, spec.y + y_end, 0, ch, ch + 1, rows.data()) ||
        !OIIO::convert_pixel_values(native, rows.data(), as, out, static_cast<int>(n)))
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
// Reading and writing.

// Opens an image for reading, with the checks every reader shares (image_reading.hpp): a 2D,
// non-deep image with pixels, below 2^31 of them, whose header claims no more than the limit.
std::unique_ptr<OIIO::ImageInput> openImage(const std::string& path, std::uint64_t max_image_bytes) {
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path);
  if (!in) throw IoError(path, withDetail("cannot read as an image", OIIO::geterror()));
  const OIIO::ImageSpec& spec = in->spec();
  requirePixelCount(path, spec.width, spec.height, spec.nchannels);
  // A TIFF's strips and a tiled file's tiles may claim more rows than the image has;
  // OpenImageIO buffers a whole strip or row of tiles.
  const std::uint64_t rows = std::max<std::uint64_t>(
      {static_cast<std::uint64_t>(spec.height),
       static_cast<std::uint64_t>(std::max(0, spec.get_int_attribute("tiff:RowsPerStrip", 0))),
       static_cast<std::uint64_t>(std::max(0, spec.tile_height))});
  requireClaimWithin(path, max_image_bytes, spec.width, spec.height, spec.nchannels,
                     static_cast<std::uint64_t>(spec.width) * spec.pixel_bytes(true), rows);
  if (spec.depth > 1) throw IoError(path, "volume images (depth > 1) are not supported");
  if (spec.deep) throw IoError(path, "deep images are not supported");
  return in;
}

ImageChannels read(const std::string& path, std::uint64_t max_image_bytes, const std::string* channel) {
  std::unique_ptr<OIIO::ImageInput> in = openImage(path, max_image_bytes);
  const OIIO::ImageSpec& spec = in->spec();
  ImageChannels image;
  image.width = spec.width;
  image.height = spec.height;
  try {
    if (channel) {
      std::vector<std::string> names = spec.channelnames;
      names.resize(static_cast<std::size_t>(spec.nchannels));
      const int c = chooseChannel(path, names, *channel);
      image.names.push_back(names[c]);
      image.planes.push_back(readChannel(path, *in, c));
      image.integers = !spec.channelformat(c).is_floating_point();
    } else {
      for (int c = 0; c < spec.nchannels; ++c) {
        const bool named = c < static_cast<int>(spec.channelnames.size()) && !spec.channelnames[c].empty();
        image.names.push_back(named ? spec.channelnames[c] : "channel" + std::to_string(c));
        image.planes.push_back(readChannel(path, *in, c));
        image.integers = image.integers || !spec.channelformat(c).is_floating_point();
      }
    }
  } catch (const std::bad_alloc&) {
    throw IoError(path, "image is too large to hold in memory (" + std::to_string(spec.width) + " x " +
                            std::to_string(spec.height) + " pixels" +
                            (channel ? std::string() : ", " + std::to_string(spec.nchannels) + " channels") +
                            ")");
  }
  // A string as hfvis writes it, or a number as other tools write it (a number was passed over:
  // a cell size of 1); anything else (an array) reaches storedCellSize as text and is refused there.
  for (const char* name : {"hfvis:cell_size_x", "hfvis:cell_size_y"}) {
    const OIIO::ParamValue* value = spec.find_attribute(name);
    if (!value) continue;
    const std::string text = value->type() == OIIO::TypeDesc::STRING
                                 ? std::string(spec.get_string_attribute(name))
                                 : std::string(value->get_string());
    if (!text.empty()) image.attributes.emplace_back(name, text);
  }
  in->close();
  return image;
}

bool canWrite(const std::string& path) {
  if (OIIO::ImageOutput::create(path)) return true;
  OIIO::geterror();  // clear OpenImageIO's message: the caller says what to do instead
  return false;
}

// The file an image is written to, through a descriptor whose every write, flush and close is
// checked: OpenImageIO's own files drop the errors of a buffered write (a small PNG on a full
// disk came out empty with no error), and a writer may ignore a short write.
class CheckedFile final : public OIIO::Filesystem::IOProxy {
 public:
  explicit CheckedFile(const std::string& file) : IOProxy(file, Write) {
    fd_ = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd_ < 0) error_ = errno;
  }
  ~CheckedFile() override { close(); }
  CheckedFile(const CheckedFile&) = delete;
  CheckedFile& operator=(const CheckedFile&) = delete;

  const char* proxytype() const override { return "hfvis-checked-file"; }
  bool opened() const override { return fd_ >= 0; }
  size_t write(const void* buf, size_t size) override {
    const size_t written = pwrite(buf, size, m_pos);
    m_pos += static_cast<int64_t>(written);
    return written;
  }
  size_t pwrite(const void* buf, size_t size, int64_t offset) override {
    const char* bytes = static_cast<const char*>(buf);
    size_t done = 0;
    while (done < size && fd_ >= 0 && error_ == 0) {
      const ssize_t n = ::pwrite(fd_, bytes + done, size - done, offset + static_cast<int64_t>(done));
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) {
        error_ = n < 0 ? errno : ENOSPC;
        break;
      }
      done += static_cast<size_t>(n);
    }
    return done;
  }
  size_t size() const override {
    struct stat status {};
    return fd_ >= 0 && ::fstat(fd_, &status) == 0 ? static_cast<size_t>(status.st_size) : 0;
  }
  // Flushed to the disk before it is closed: a delayed write error (NFS, a quota) shows here.
  void close() override {
    if (fd_ < 0) return;
    if (::fsync(fd_) != 0 && error_ == 0) error_ = errno;
    if (::close(fd_) != 0 && error_ == 0) error_ = errno;
    fd_ = -1;
    m_mode = Closed;
  }
  // The first failure's error number, 0 for none.
  int failure() const { return error_; }

 private:
  int fd_ = -1;
  int error_ = 0;
};

void write(const std::string& file, const std::string& path, int width, int height,
           const std::vector<std::string>& names,
           const std::function<void(int, int, std::uint8_t*)>& fill_rows) {
  const int channels = static_cast<int>(names.size());
  OIIO::ImageSpec spec(width, height, channels, OIIO::TypeDesc::UINT8);
  spec.channelnames = names;
  spec.alpha_channel = -1;  // every channel is data; none may be treated as alpha
  spec.z_channel = -1;
  std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(file);
  if (!out) throw IoError(path, withDetail("no image writer for this file", OIIO::geterror()));
  if (!out->supports("ioproxy"))
    throw IoError(path, "this OpenImageIO cannot write the format through a checked file");
  CheckedFile checked(file);
  if (checked.failure()) throw IoError(path, "cannot create the file: " + writeFailure(checked.failure()));
  // The system's reason for a failed write, where there is one, over the writer's own words.
  const auto fail = [&](const std::string& what, const std::string& detail) {
    if (checked.failure()) throw IoError(path, what + ": " + writeFailure(checked.failure()));
    throw IoError(path, withDetail(what, detail));
  };
  if (!out->set_ioproxy(&checked) || !out->open(file, spec)) fail("cannot write the image", out->geterror());
  // Rows go out in chunks so a large many-channel image never needs a second full copy.
  const std::size_t row_values = static_cast<std::size_t>(width) * channels;
  const int rows_per_chunk =
      static_cast<int>(std::clamp<std::size_t>((std::size_t(1) << 22) / row_values, 1, 256));
  std::vector<std::uint8_t> buffer(row_values * static_cast<std::size_t>(std::min(rows_per_chunk, height)));
  for (int y = 0; y < height; y += rows_per_chunk) {
    const int y_end = std::min(height, y + rows_per_chunk);
    fill_rows(y, y_end, buffer.data());
    if (!out->write_scanlines(y, y_end, 0, spec.format, buffer.data())) {
      const std::string error = out->geterror();
      out->close();
      fail("cannot write the image", error);
    }
  }
  if (!out->close()) fail("cannot finish writing the image", out->geterror());
  checked.close();
  if (checked.failure()) fail("cannot finish writing the image", "");
}

}  // namespace

const OiioImages& oiioImages() {
  static const OiioImages table{read, canWrite, write};
  return table;
}

}  // namespace hfvis::detail

extern "C" __attribute__((visibility("default"))) const hfvis::detail::OiioImages* hfvis_oiio_images() {
  return &hfvis::detail::oiioImages();
}
