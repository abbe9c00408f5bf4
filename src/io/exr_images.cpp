// exr_images.cpp: EXR files through OpenEXR's C++ library (exr_images.hpp): reading one part's
// channels as float32 in blocks of rows, after the checks a hostile header needs, and writing
// float32 outputs through a file whose every write is checked.
#include "io/exr_images.hpp"

#include <Iex.h>
#include <ImfChannelList.h>
#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfIO.h>
#include <ImfInputPart.h>
#include <ImfIntAttribute.h>
#include <ImfMultiPartInputFile.h>
#include <ImfOutputFile.h>
#include <ImfPartType.h>
#include <ImfStringAttribute.h>
#include <ImfThreading.h>
#include <ImfTileDescriptionAttribute.h>
#include <fcntl.h>
#include <strings.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <map>
#include <memory>
#include <mutex>
#include <new>
#include <string>
#include <thread>
#include <tuple>
#include <utility>
#include <vector>

#include "core/number_text.hpp"
#include "hfvis/errors.hpp"
#include "io/image_reading.hpp"
#include "io/output_files.hpp"

namespace hfvis::detail {
namespace {

// ---------------------------------------------------------------------------------------------
// Headers.

// OpenEXR reads a header attribute into a buffer of the size the header claims (a string
// attribute is even filled first) before it finds the file ending: 2 GiB for a few bytes. So the
// headers are walked here first, and an attribute that claims more bytes than the file has after
// it is refused. Anything else amiss is left for OpenEXR to report.
void requireAttributesWithinFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary | std::ios::ate);
  const std::streamoff size = in.tellg();
  unsigned char head[8] = {};
  if (size < 8 || !in.seekg(0) || !in.read(reinterpret_cast<char*>(head), 8)) return;
  const bool multipart = (head[5] & 0x10) != 0;  // the version field's bit 12
  // A name: up to 255 bytes and its terminating zero.
  const auto name = [&](std::string* text) {
    text->clear();
    for (int c = in.get(); in; c = in.get()) {
      if (c == 0) return true;
      if (text->size() == 255) return false;
      text->push_back(static_cast<char>(c));
    }
    return false;
  };
  std::string attribute, type;
  for (bool first_of_header = true;;) {
    if (!name(&attribute)) return;
    if (attribute.empty()) {
      // The end of a header; in a multi-part file, an empty header ends the list.
      if (!multipart || first_of_header) return;
      first_of_header = true;
      continue;
    }
    first_of_header = false;
    unsigned char bytes[4];
    if (!name(&type) || !in.read(reinterpret_cast<char*>(bytes), 4)) return;
    const std::int32_t claimed =
        static_cast<std::int32_t>(bytes[0] | bytes[1] << 8 | bytes[2] << 16 | std::uint32_t(bytes[3]) << 24);
    const std::streamoff left = size - in.tellg();
    if (claimed < 0) return;
    if (claimed > left) {
      throw IoError(path, "cannot read as an image (the header's attribute '" + attribute + "' claims " +
                              std::to_string(claimed) + " bytes; " + std::to_string(left) +
                              " follow it in the file)");
    }
    in.seekg(claimed, std::ios::cur);
  }
}

// The channels in the order OpenImageIO 2.4 gave them (its exrinput.cpp, query_channels), which
// readImage has always reported and environment maps and tests rely on: grouped by layer (the
// name up to its last '.'; layers sorted), within a layer the reserved names first, in this
// order and any case: R, Red, G, Green, B, Blue, Y, real, imag, A, Alpha, AR, RA, AG, GA, AB,
// BA, Z, Depth, Zback (in a layer with X and Y or Z, positions or normals: R, Red, G, Green, B,
// Blue, X, Y, Z, real, imag, A, ...), then the others sorted by name.
std::vector<std::string> channelOrder(const Imf::ChannelList& list) {
  static const std::vector<const char*> kReserved = {"R",    "Red",  "G",  "Green", "B",     "Blue", "Y",
                                                     "real", "imag", "A",  "Alpha", "AR",    "RA",   "AG",
                                                     "GA",   "AB",   "BA", "Z",     "Depth", "Zback"};
  static const std::vector<const char*> kReservedXyz = {"R",  "Red", "G",    "Green", "B",  "Blue",  "X",
                                                        "Y",  "Z",   "real", "imag",  "A",  "Alpha", "AR",
                                                        "RA", "AG",  "GA",   "AB",    "BA", "Depth", "Zback"};
  struct Channel {
    std::string layer, suffix;
    std::size_t rank;
  };
  std::vector<Channel> channels;
  struct Layer {
    bool x = false, y_or_z = false;
  };
  std::map<std::string, Layer> layers;
  for (auto it = list.begin(); it != list.end(); ++it) {
    const std::string name = it.name();
    const std::size_t dot = name.rfind('.');
    Channel c{dot == std::string::npos ? "" : name.substr(0, dot + 1),
              dot == std::string::npos ? name : name.substr(dot + 1), 0};
    Layer& layer = layers[c.layer];
    layer.x = layer.x || ::strcasecmp(c.suffix.c_str(), "X") == 0;
    layer.y_or_z =
        layer.y_or_z || ::strcasecmp(c.suffix.c_str(), "Y") == 0 || ::strcasecmp(c.suffix.c_str(), "Z") == 0;
    channels.push_back(std::move(c));
  }
  for (Channel& c : channels) {
    const Layer& layer = layers[c.layer];
    const std::vector<const char*>& reserved = layer.x && layer.y_or_z ? kReservedXyz : kReserved;
    c.rank = reserved.size();
    for (std::size_t i = 0; i < reserved.size() && c.rank == reserved.size(); ++i)
      if (::strcasecmp(c.suffix.c_str(), reserved[i]) == 0) c.rank = i;
  }
  std::sort(channels.begin(), channels.end(), [](const Channel& a, const Channel& b) {
    return std::tie(a.layer, a.rank, a.suffix) < std::tie(b.layer, b.rank, b.suffix);
  });
  std::vector<std::string> names;
  for (const Channel& c : channels) names.push_back(c.layer + c.suffix);
  return names;
}

std::uint64_t bytesOf(Imf::PixelType type) { return type == Imf::HALF ? 2 : 4; }

// The rows of a scanline file's chunk: what OpenEXR decompresses, and buffers, at once.
int chunkRows(Imf::Compression compression) {
  switch (compression) {
    case Imf::NO_COMPRESSION:
    case Imf::RLE_COMPRESSION:
    case Imf::ZIPS_COMPRESSION:
      return 1;
    case Imf::ZIP_COMPRESSION:
    case Imf::PXR24_COMPRESSION:
      return 16;
    case Imf::PIZ_COMPRESSION:
    case Imf::B44_COMPRESSION:
    case Imf::B44A_COMPRESSION:
    case Imf::DWAA_COMPRESSION:
      return 32;
    default:  // DWAB
      return 256;
  }
}

// OpenEXR's threads for a file whose chunks (of every channel) hold `chunk_bytes`: it keeps two
// chunk buffers per thread, and its compressors as much again, so large chunks get fewer threads,
// and a file of one chunk none (the calling thread does the work). OpenEXR's shared pool is
// started for the first file that takes threads, unless the program started one.
int threadsFor(std::uint64_t chunk_bytes, int chunks) {
  const std::uint64_t cores = std::max(1u, std::thread::hardware_concurrency());
  const std::uint64_t threads =
      std::min(cores, (std::uint64_t(256) << 20) / std::max<std::uint64_t>(4 * chunk_bytes, 1));
  if (chunks <= 1 || threads < 2) return 0;
  static std::once_flag pool;
  std::call_once(pool, [&] {
    if (Imf::globalThreadCount() == 0) Imf::setGlobalThreadCount(static_cast<int>(cores));
  });
  return static_cast<int>(threads);
}

// ---------------------------------------------------------------------------------------------
// Reading.

std::unique_ptr<Imf::MultiPartInputFile> openExr(const std::string& path) {
  requireAttributesWithinFile(path);
  try {
    // No threads: one chunk buffer (a header may claim chunks of gigabytes; see readExr).
    return std::make_unique<Imf::MultiPartInputFile>(path.c_str(), 0);
  } catch (const std::bad_alloc&) {
    throw IoError(path, "cannot read as an image (its header does not fit in memory)");
  } catch (const std::exception& e) {
    throw IoError(path, withDetail("cannot read as an image", e.what()));
  }
}

// Reads rows of `part` into `planes`, one per channel of `names`, in blocks: the planes grow
// with the rows read, so a header that claims more pixels than the file holds fails at its first
// missing rows, not after allocating the whole claim. A block holds about 16 MiB of the planes'
// rows (one row at least), whole chunks or tile rows where it holds one, so that no chunk is
// decompressed twice.
void readPlanes(Imf::InputPart& part, const Imath::Box2i& window, int chunk_rows,
                const std::vector<std::string>& names, std::vector<std::vector<float>>* planes) {
  const std::size_t width = static_cast<std::size_t>(window.max.x - window.min.x) + 1;
  const int height = window.max.y - window.min.y + 1;
  const std::size_t row_bytes = width * sizeof(float) * names.size();
  int block = static_cast<int>(std::clamp<std::size_t>((std::size_t(16) << 20) / row_bytes, 1, height));
  if (block >= chunk_rows) block -= block % chunk_rows;
  planes->assign(names.size(), {});
  for (int y = 0; y < height; y += block) {
    const int y_end = std::min(height, y + block);
    Imf::FrameBuffer frame;
    for (std::size_t c = 0; c < names.size(); ++c) {
      std::vector<float>& plane = (*planes)[c];
      plane.resize(width * static_cast<std::size_t>(y_end));
      frame.insert(names[c], Imf::Slice::Make(Imf::FLOAT, plane.data() + width * static_cast<std::size_t>(y),
                                              Imath::V2i(window.min.x, window.min.y + y),
                                              static_cast<std::int64_t>(width), y_end - y, sizeof(float),
                                              width * sizeof(float)));
    }
    part.setFrameBuffer(frame);
    part.readPixels(window.min.y + y, window.min.y + y_end - 1);
  }
}

// ---------------------------------------------------------------------------------------------
// Writing.

// The file an EXR is written to, through a descriptor whose every write, flush and close is
// checked: a failed write stops OpenEXR with an exception, and its number is kept for the
// message (OpenEXR's own file reports a full disk in words of its own, or, for the offset table
// written as the file closes, not at all).
class CheckedExrFile final : public Imf::OStream {
 public:
  explicit CheckedExrFile(const std::string& file) : Imf::OStream(file.c_str()) {
    fd_ = ::open(file.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0666);
    if (fd_ < 0) error_ = errno;
  }
  ~CheckedExrFile() override {
    if (fd_ >= 0) ::close(fd_);
  }

  void write(const char c[], int n) override {
    std::size_t done = 0;
    while (done < static_cast<std::size_t>(n) && error_ == 0) {
      const ssize_t w =
          ::pwrite(fd_, c + done, static_cast<std::size_t>(n) - done, static_cast<off_t>(position_ + done));
      if (w < 0 && errno == EINTR) continue;
      if (w <= 0) error_ = w < 0 ? errno : ENOSPC;
      if (w > 0) done += static_cast<std::size_t>(w);
    }
    if (error_ != 0) throw Iex::IoExc(writeFailure(error_));
    position_ += done;
  }
  std::uint64_t tellp() override { return position_; }
  void seekp(std::uint64_t position) override { position_ = position; }

  // Flushes the file to the disk (a delayed write error, NFS or a quota, shows here) and closes
  // it; the first failure's error number, 0 for none.
  int finish() {
    if (fd_ >= 0) {
      if (::fsync(fd_) != 0 && error_ == 0) error_ = errno;
      if (::close(fd_) != 0 && error_ == 0) error_ = errno;
      fd_ = -1;
    }
    return error_;
  }
  int failure() const { return error_; }

 private:
  int fd_ = -1;
  int error_ = 0;
  std::uint64_t position_ = 0;
};

// The part of a multi-part file to read: the first, where it holds the channel named `channel`
// (or none is named: as before, and a stereo file's R is its first view's), else the one other
// part that holds it (an index counts in the first part). Throws IoError when the first lacks it
// and several others hold it, or none does (listing every part's channels).
int partToRead(const std::string& path, const Imf::MultiPartInputFile& file, const std::string* channel) {
  const int parts = file.parts();
  if (parts <= 1 || !channel || channel->empty() || file.header(0).channels().findChannel(*channel)) return 0;
  std::vector<int> holding;
  for (int p = 1; p < parts; ++p)
    if (file.header(p).channels().findChannel(*channel)) holding.push_back(p);
  if (holding.size() == 1) return holding.front();
  const auto partName = [&](int p) {
    return "part " + std::to_string(p) + (file.header(p).hasName() ? " '" + file.header(p).name() + "'" : "");
  };
  if (holding.size() > 1)
    throw IoError(path, "channel '" + *channel + "' is not in part 0 but in " + partName(holding[0]) +
                            " and in " + partName(holding[1]) +
                            "; hfvis reads one part (split the file: exrmultipart -separate)");
  // None by name: an index, or a name part 0 lacks too (its error then lists every part).
  const std::vector<std::string> first = channelOrder(file.header(0).channels());
  const bool index = channel->size() <= 9 && std::all_of(channel->begin(), channel->end(),
                                                         [](char ch) { return ch >= '0' && ch <= '9'; });
  if (index && std::stoul(*channel) < first.size()) return 0;
  std::string listed;
  for (int p = 0; p < parts; ++p) {
    listed += (p > 0 ? "; " : "") + partName(p) + ":";
    for (const std::string& name : channelOrder(file.header(p).channels())) listed += " '" + name + "'";
  }
  throw IoError(path, "no channel '" + *channel + "' (the file has " + std::to_string(parts) +
                          " parts: " + listed + ")");
}

}  // namespace

bool isExrFile(const std::string& path) {
  unsigned char magic[4] = {};
  std::ifstream in(path, std::ios::binary);
  return in.read(reinterpret_cast<char*>(magic), 4) && magic[0] == 0x76 && magic[1] == 0x2f &&
         magic[2] == 0x31 && magic[3] == 0x01;
}

namespace {

// The fewest significant digits that read back as the same float.
std::string shortestFloat(float value) {
  char text[32];
  for (int digits = 6; digits < 9; ++digits) {
    std::snprintf(text, sizeof(text), "%.*g", digits, double(value));
    if (std::strtof(text, nullptr) == value) return text;
  }
  std::snprintf(text, sizeof(text), "%.9g", double(value));
  return text;
}

}  // namespace

ImageChannels readExr(const std::string& path, std::uint64_t max_image_bytes, const std::string* channel,
                      double* rounding) {
  const std::unique_ptr<Imf::MultiPartInputFile> file = openExr(path);
  const int part_index = partToRead(path, *file, channel);
  const Imf::Header& header = file->header(part_index);
  const Imath::Box2i window = header.dataWindow();
  const std::int64_t width = std::int64_t(window.max.x) - window.min.x + 1;
  const std::int64_t height = std::int64_t(window.max.y) - window.min.y + 1;
  const std::vector<std::string> names = channelOrder(header.channels());
  std::uint64_t pixel_bytes = 0;
  for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
    if (it.channel().xSampling != 1 || it.channel().ySampling != 1)
      throw IoError(path, "cannot read as an image (channel '" + std::string(it.name()) +
                              "' is subsampled, " + std::to_string(it.channel().xSampling) + " x " +
                              std::to_string(it.channel().ySampling) +
                              "; hfvis reads channels of every pixel)");
    pixel_bytes += bytesOf(it.channel().type);
  }
  const int channels = static_cast<int>(names.size());
  requirePixelCount(path, width, height, channels);
  // What OpenEXR buffers at once: a chunk of rows, or a row of tiles, each as wide as the image
  // or a tile, if wider.
  const bool tiled = header.hasTileDescription() && Imf::isTiled(header.type());
  const Imf::TileDescription tile = tiled ? header.tileDescription() : Imf::TileDescription(0, 0);
  const int chunk_rows = tiled ? static_cast<int>(std::clamp<unsigned>(tile.ySize, 1, 1u << 30))
                               : chunkRows(header.compression());
  const std::uint64_t columns = std::max<std::uint64_t>(width, tile.xSize);
  requireClaimWithin(path, max_image_bytes, static_cast<int>(width), static_cast<int>(height), channels,
                     columns * pixel_bytes, std::max<std::uint64_t>(height, tiled ? tile.ySize : chunk_rows));
  if (Imf::isDeepData(header.type())) throw IoError(path, "deep images are not supported");

  ImageChannels image;
  image.width = static_cast<int>(width);
  image.height = static_cast<int>(height);
  image.names = channel ? std::vector<std::string>{names[chooseChannel(path, names, *channel)]} : names;
  try {
    std::unique_ptr<Imf::InputPart> part;
    try {
      part = std::make_unique<Imf::InputPart>(*file, part_index);
    } catch (const Iex::BaseExc& e) {
      throw IoError(path, withDetail("cannot read as an image", e.what()));
    }
    readPlanes(*part, window, chunk_rows, image.names, &image.planes);
    for (const std::string& name : image.names)
      image.integers = image.integers || header.channels().findChannel(name)->type == Imf::UINT;
  } catch (const Error&) {
    throw;
  } catch (const std::bad_alloc&) {
    throw IoError(path, "image is too large to hold in memory (" + std::to_string(width) + " x " +
                            std::to_string(height) + " pixels" +
                            (channel ? std::string() : ", " + std::to_string(channels) + " channels") + ")");
  } catch (const std::exception& e) {
    throw IoError(path, withDetail("cannot read pixel data; the file is truncated or corrupt", e.what()));
  }
  // A UINT channel: float32 holds its integers exactly only up to 2^24, beyond by up to half its
  // spacing at the largest (the reader of heights asks requireHeightsKeptInFloat32 whether that
  // is too much, as the GDAL reader asks of the rounding it measures).
  if (rounding) *rounding = 0.0;
  if (rounding && channel && header.channels().findChannel(image.names.front())->type == Imf::UINT) {
    const std::vector<float>& plane = image.planes.front();
    const auto high = std::max_element(plane.begin(), plane.end());
    if (high != plane.end() && double(*high) > double(1 << 24))
      *rounding = 0.5 * (double(std::nextafter(*high, INFINITY)) - double(*high));
  }
  // Where the data window is not the display window, a note of both (readColourImage refuses such
  // an environment map or light image, which map over their whole extent: the data window alone
  // was taken as the whole sphere, twice as bright).
  const Imath::Box2i display = header.displayWindow();
  if (display != window) {
    const auto box = [](const Imath::Box2i& b) {
      return "(" + std::to_string(b.min.x) + ", " + std::to_string(b.min.y) + ") .. (" +
             std::to_string(b.max.x) + ", " + std::to_string(b.max.y) + ")";
    };
    image.attributes.emplace_back(
        "exr:windows", "data window " + box(window) + " is not its display window " + box(display));
  }
  // The cell size as hfvis writes it (a string), or as other tools write a number (oiiotool
  // --attrib writes 3 as an int): a number was passed over and the cell size taken as 1.
  for (const char* name : {"hfvis:cell_size_x", "hfvis:cell_size_y"}) {
    const auto found = header.find(name);
    if (found == header.end()) continue;
    const Imf::Attribute* any = &found.attribute();
    std::string text;
    if (const auto* s = dynamic_cast<const Imf::StringAttribute*>(any))
      text = s->value();
    else if (const auto* i = dynamic_cast<const Imf::IntAttribute*>(any))
      text = std::to_string(i->value());
    else if (const auto* f = dynamic_cast<const Imf::FloatAttribute*>(any))
      text = shortestFloat(f->value());  // (0.1f as 0.1, not its double 0.100000001490116)
    else if (const auto* d = dynamic_cast<const Imf::DoubleAttribute*>(any))
      text = detail::exactNumber(d->value());
    else
      throw IoError(path, std::string("the attribute ") + name + " is of type " + any->typeName() +
                              ": a cell size is a number or a string holding one");
    if (!text.empty()) image.attributes.emplace_back(name, text);
  }
  return image;
}

void writeExr(const std::string& file, const std::string& path, const ImageChannels& image) {
  Imf::Header header(image.width, image.height);
  header.compression() = Imf::ZIP_COMPRESSION;
  Imf::FrameBuffer frame;
  const std::size_t row_bytes = static_cast<std::size_t>(image.width) * sizeof(float);
  try {
    for (std::size_t c = 0; c < image.names.size(); ++c) {
      header.channels().insert(image.names[c], Imf::Channel(Imf::FLOAT));
      frame.insert(
          image.names[c],
          Imf::Slice(Imf::FLOAT, const_cast<char*>(reinterpret_cast<const char*>(image.planes[c].data())),
                     sizeof(float), row_bytes));
    }
    for (const auto& [name, value] : image.attributes) header.insert(name, Imf::StringAttribute(value));
  } catch (const std::exception& e) {
    throw IoError(path, withDetail("cannot write the image", e.what()));
  }
  CheckedExrFile out(file);
  if (out.failure()) throw IoError(path, "cannot create the file: " + writeFailure(out.failure()));
  // The system's reason for a failed write, where there is one, over OpenEXR's own words.
  const auto fail = [&](const std::string& what, const std::string& detail) {
    if (out.failure()) throw IoError(path, what + ": " + writeFailure(out.failure()));
    throw IoError(path, withDetail(what, detail));
  };
  try {
    const int chunks = (image.height + 15) / 16;
    Imf::OutputFile exr(out, header, threadsFor(row_bytes * image.names.size() * 16, chunks));
    exr.setFrameBuffer(frame);
    exr.writePixels(image.height);
    // The destructor writes the offset table; a failure there shows in out.failure().
  } catch (const std::exception& e) {
    fail("cannot write the image", e.what());
  }
  if (out.failure()) fail("cannot finish writing the image", "");
  if (const int error = out.finish())
    throw IoError(path, "cannot finish writing the image: " + writeFailure(error));
}

}  // namespace hfvis::detail
