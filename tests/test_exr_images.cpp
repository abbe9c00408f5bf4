// test_exr_images.cpp: EXR inputs and outputs through OpenEXR (src/io/exr_images.cpp): files written
// here with OpenEXR's own API (half, float and unsigned channels, tiles and mipmaps, a data window
// away from the origin, several parts, deep and subsampled images) read back as the OpenImageIO
// path read them, channel order included; hostile headers refused quickly without allocating
// what they claim; outputs as OpenImageIO wrote them (float32, ZIP, string attributes).
#include <ImfChannelList.h>
#include <ImfDeepFrameBuffer.h>
#include <ImfDeepScanLineOutputFile.h>
#include <ImfDoubleAttribute.h>
#include <ImfFloatAttribute.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfIntAttribute.h>
#include <ImfMultiPartOutputFile.h>
#include <ImfOutputFile.h>
#include <ImfOutputPart.h>
#include <ImfPartType.h>
#include <ImfStringAttribute.h>
#include <ImfTiledOutputFile.h>
#include <ImfVecAttribute.h>
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <memory>
#include <string>
#include <vector>

#include "hfvis/environment_map.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/image_io.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

namespace fs = std::filesystem;

class ImageIoExrTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::freshTestDirectory("exr_images");
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  fs::path dir_;
};

// Expects `call` to throw IoError naming `path` whose message holds `part`.
template <typename Call>
void expectIoError(const std::string& path, Call call, const std::string& part) {
  try {
    call();
    ADD_FAILURE() << "no IoError for " << path;
  } catch (const IoError& e) {
    EXPECT_EQ(e.path(), path);
    EXPECT_NE(std::string(e.what()).find(part), std::string::npos) << e.what();
  }
}

// Distinct values per channel and pixel: channel c, pixel i holds c * 1000 + i.
float valueOf(std::size_t c, std::size_t i) { return static_cast<float>(c * 1000 + i); }

// A scanline EXR of `names` (all `type`), each channel filled by valueOf in the order given,
// over `window` (display window the same).
void writeScanlineExr(const std::string& file, const std::vector<std::string>& names, Imf::PixelType type,
                      const Imath::Box2i& window, Imf::Compression compression = Imf::ZIP_COMPRESSION) {
  Imf::Header header(window, window);
  header.compression() = compression;
  const int width = window.max.x - window.min.x + 1, height = window.max.y - window.min.y + 1;
  const std::size_t n = static_cast<std::size_t>(width) * height;
  std::vector<std::vector<float>> floats(names.size(), std::vector<float>(n));
  std::vector<std::vector<half>> halves(names.size(), std::vector<half>(n));
  std::vector<std::vector<unsigned>> uints(names.size(), std::vector<unsigned>(n));
  Imf::FrameBuffer frame;
  for (std::size_t c = 0; c < names.size(); ++c) {
    header.channels().insert(names[c], Imf::Channel(type));
    for (std::size_t i = 0; i < n; ++i) {
      floats[c][i] = valueOf(c, i);
      halves[c][i] = half(valueOf(c, i));
      uints[c][i] = static_cast<unsigned>(valueOf(c, i));
    }
    char* base = type == Imf::FLOAT  ? reinterpret_cast<char*>(floats[c].data())
                 : type == Imf::HALF ? reinterpret_cast<char*>(halves[c].data())
                                     : reinterpret_cast<char*>(uints[c].data());
    const std::size_t size = type == Imf::HALF ? 2 : 4;
    frame.insert(names[c], Imf::Slice::Make(type, base, window.min, width, height, size, size * width));
  }
  Imf::OutputFile out(file.c_str(), header);
  out.setFrameBuffer(frame);
  out.writePixels(height);
}

Imath::Box2i windowOf(int width, int height, int x0 = 0, int y0 = 0) {
  return Imath::Box2i(Imath::V2i(x0, y0), Imath::V2i(x0 + width - 1, y0 + height - 1));
}

std::vector<std::string> oiioChannelNames(const std::string& file) {
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(file);
  if (!in) {
    ADD_FAILURE() << OIIO::geterror();
    return {};
  }
  return in->spec().channelnames;
}

TEST_F(ImageIoExrTest, ChannelsComeInTheOrderOpenImageIoGaveThem) {
  // In the file (sorted by name): A B G R Y Z albedo diffuse.G diffuse.R normal.X normal.Y
  // normal.Z zeta; as OpenImageIO gave them: layers apart, colours, Y and alpha first, X Y Z of
  // a position or normal layer in that order.
  const std::vector<std::string> names = {"Z",         "A",        "B",        "G",        "R",
                                          "albedo",    "normal.X", "normal.Y", "normal.Z", "diffuse.R",
                                          "diffuse.G", "zeta",     "Y"};
  const std::string file = path("layers.exr");
  writeScanlineExr(file, names, Imf::FLOAT, windowOf(3, 2));
  const ImageChannels image = readImage(file);
  const std::vector<std::string> expected = {"R",        "G",        "B",       "Y",         "A",
                                             "Z",        "albedo",   "zeta",    "diffuse.R", "diffuse.G",
                                             "normal.X", "normal.Y", "normal.Z"};
  EXPECT_EQ(image.names, expected);
  EXPECT_EQ(image.names, oiioChannelNames(file));
  ASSERT_EQ(image.planes.size(), names.size());
  for (std::size_t c = 0; c < image.names.size(); ++c) {
    const std::size_t written = std::find(names.begin(), names.end(), image.names[c]) - names.begin();
    for (std::size_t i = 0; i < 6; ++i) EXPECT_EQ(image.planes[c][i], valueOf(written, i)) << image.names[c];
  }
  // A channel by index counts in that order.
  HeightFieldReadOptions options;
  options.channel = "3";
  EXPECT_EQ(readHeightField(file, options).heights, image.planes[3]);
}

TEST_F(ImageIoExrTest, HalfAndUnsignedChannelsReadAsTheirValues) {
  const std::string halves = path("half.exr"), uints = path("uint.exr");
  writeScanlineExr(halves, {"Y"}, Imf::HALF, windowOf(5, 3));
  writeScanlineExr(uints, {"U", "V"}, Imf::UINT, windowOf(5, 3));
  const HeightField field = readHeightField(halves);
  for (std::size_t i = 0; i < 15; ++i) EXPECT_EQ(field.heights[i], valueOf(0, i));  // exact in half
  const ImageChannels image = readImage(uints);
  ASSERT_EQ(image.names, (std::vector<std::string>{"U", "V"}));
  for (std::size_t i = 0; i < 15; ++i) EXPECT_EQ(image.planes[1][i], valueOf(1, i));  // not normalised
}

TEST_F(ImageIoExrTest, TiledMipmappedFileReadsItsFullResolution) {
  const int width = 37, height = 23;
  const Imath::Box2i window = windowOf(width, height, -5, 9);  // the data window anywhere
  Imf::Header header(window, window);
  header.setTileDescription(Imf::TileDescription(8, 4, Imf::MIPMAP_LEVELS));
  header.channels().insert("height", Imf::Channel(Imf::FLOAT));
  const std::string file = path("tiled.exr");
  std::vector<float> heights(static_cast<std::size_t>(width) * height);
  for (std::size_t i = 0; i < heights.size(); ++i) heights[i] = valueOf(0, i) - 500.0f;
  {
    Imf::TiledOutputFile out(file.c_str(), header);
    for (int level = 0; level < out.numLevels(); ++level) {
      const int w = out.levelWidth(level), h = out.levelHeight(level);
      std::vector<float> pixels(static_cast<std::size_t>(w) * h);
      for (int y = 0; y < h; ++y)
        for (int x = 0; x < w; ++x)
          pixels[static_cast<std::size_t>(y) * w + x] =
              level == 0 ? heights[static_cast<std::size_t>(y) * w + x] : -1.0f;
      Imf::FrameBuffer frame;
      frame.insert("height", Imf::Slice::Make(Imf::FLOAT, pixels.data(), window.min, w, h));
      out.setFrameBuffer(frame);
      out.writeTiles(0, out.numXTiles(level) - 1, 0, out.numYTiles(level) - 1, level);
    }
  }
  const HeightField field = readHeightField(file);
  EXPECT_EQ(field.width, width);
  EXPECT_EQ(field.height, height);
  EXPECT_EQ(field.heights, heights);
}

TEST_F(ImageIoExrTest, DataWindowAwayFromTheOriginIsTheImage) {
  const std::string file = path("window.exr");
  const Imath::Box2i window = windowOf(6, 40, 1000, -300);  // three ZIP chunks of 16 rows
  Imf::Header header(windowOf(4, 4), window);               // a display window elsewhere
  header.channels().insert("Y", Imf::Channel(Imf::FLOAT));
  std::vector<float> pixels(6 * 40);
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = valueOf(0, i);
  {
    Imf::OutputFile out(file.c_str(), header);
    Imf::FrameBuffer frame;
    frame.insert("Y", Imf::Slice::Make(Imf::FLOAT, pixels.data(), window.min, 6, 40));
    out.setFrameBuffer(frame);
    out.writePixels(40);
  }
  const HeightField field = readHeightField(file);
  EXPECT_EQ(field.width, 6);
  EXPECT_EQ(field.height, 40);
  EXPECT_EQ(field.heights, pixels);
}

// The cell size as hfvis writes it (strings) or as other tools write it (oiiotool --attrib writes
// 3 as an int): numbers were passed over and the cell size taken as 1, without a word. An
// attribute of another type is refused, naming it.
TEST_F(ImageIoExrTest, CellSizeAttributesAreReadAsStringsOrNumbers) {
  const auto write = [&](const std::string& name, const std::function<void(Imf::Header&)>& attributes) {
    const std::string file = path(name);
    Imf::Header header(4, 3);
    header.channels().insert("Y", Imf::Channel(Imf::FLOAT));
    attributes(header);
    std::vector<float> pixels(12, 1.0f);
    Imf::OutputFile out(file.c_str(), header);
    Imf::FrameBuffer frame;
    frame.insert("Y", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(pixels.data()), sizeof(float),
                                 4 * sizeof(float)));
    out.setFrameBuffer(frame);
    out.writePixels(3);
    return file;
  };
  const HeightField ints = readHeightField(write("ints.exr", [](Imf::Header& h) {
    h.insert("hfvis:cell_size_x", Imf::IntAttribute(3));
    h.insert("hfvis:cell_size_y", Imf::IntAttribute(2));
  }));
  EXPECT_EQ(ints.cell_size_x, 3.0);
  EXPECT_EQ(ints.cell_size_y, 2.0);
  const HeightField floats = readHeightField(write("floats.exr", [](Imf::Header& h) {
    h.insert("hfvis:cell_size_x", Imf::FloatAttribute(0.1f));
    h.insert("hfvis:cell_size_y", Imf::DoubleAttribute(0.25));
  }));
  EXPECT_EQ(floats.cell_size_x, 0.1);  // (the float's shortest text, not its double's)
  EXPECT_EQ(floats.cell_size_y, 0.25);
  const HeightField mixed = readHeightField(write("mixed.exr", [](Imf::Header& h) {
    h.insert("hfvis:cell_size_x", Imf::StringAttribute("1.5"));
    h.insert("hfvis:cell_size_y", Imf::IntAttribute(4));
  }));
  EXPECT_EQ(mixed.cell_size_x, 1.5);
  EXPECT_EQ(mixed.cell_size_y, 4.0);
  const std::string vector = write("vector.exr", [](Imf::Header& h) {
    h.insert("hfvis:cell_size_x", Imf::V2fAttribute(Imath::V2f(1.0f, 2.0f)));
    h.insert("hfvis:cell_size_y", Imf::IntAttribute(4));
  });
  try {
    readHeightField(vector);
    ADD_FAILURE() << "a vector cell size was taken";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("hfvis:cell_size_x is of type v2f"), std::string::npos) << e.what();
  }
  // One axis's alone is named as missing (it was named as '', "not a cell size").
  const std::string alone =
      write("alone.exr", [](Imf::Header& h) { h.insert("hfvis:cell_size_x", Imf::IntAttribute(3)); });
  try {
    readHeightField(alone);
    ADD_FAILURE() << "one axis's cell size was taken";
  } catch (const IoError& e) {
    EXPECT_NE(std::string(e.what()).find("hfvis:cell_size_y is missing or empty beside hfvis:cell_size_x"),
              std::string::npos)
        << e.what();
  }
}

// An environment map covers the sphere with its whole extent: one whose data window is not its
// display window is refused (its data window alone was taken as the sphere: twice the light of the
// same map written whole). Heights still read their data window wherever it lies.
TEST_F(ImageIoExrTest, AnEnvironmentMapWithADataWindowInsideItsDisplayIsRefused) {
  const auto write = [&](const std::string& name, const Imath::Box2i& data) {
    const std::string file = path(name);
    Imf::Header header(windowOf(8, 4), data);
    header.channels().insert("Y", Imf::Channel(Imf::FLOAT));
    const int width = data.max.x - data.min.x + 1, height = data.max.y - data.min.y + 1;
    std::vector<float> pixels(std::size_t(width) * height, 1.0f);
    Imf::OutputFile out(file.c_str(), header);
    Imf::FrameBuffer frame;
    frame.insert("Y", Imf::Slice::Make(Imf::FLOAT, pixels.data(), data.min, width, height));
    out.setFrameBuffer(frame);
    out.writePixels(height);
    return file;
  };
  const std::string inside = write("inside.exr", windowOf(4, 2, 2, 0));
  try {
    readEnvironmentMap(inside);
    ADD_FAILURE() << "an environment map of part of its display window was taken";
  } catch (const IoError& e) {
    EXPECT_NE(
        std::string(e.what()).find("data window (2, 0) .. (5, 1) is not its display window (0, 0) .. (7, 3)"),
        std::string::npos)
        << e.what();
  }
  EXPECT_EQ(readHeightField(inside).width, 4);
  const EnvironmentMap whole = readEnvironmentMap(write("whole.exr", windowOf(8, 4)));
  EXPECT_EQ(whole.width, 8);
  EXPECT_EQ(whole.height, 4);
}

TEST_F(ImageIoExrTest, MultiPartFileReadsItsFirstPartOrTheOneHoldingTheChannel) {
  const std::string file = path("parts.exr");
  std::vector<Imf::Header> headers(2, Imf::Header(3, 2));
  headers[0].setName("first");
  headers[0].channels().insert("Y", Imf::Channel(Imf::FLOAT));
  headers[1] = Imf::Header(windowOf(3, 2), windowOf(5, 5));  // parts share their display window
  headers[1].setName("second");
  headers[1].channels().insert("R", Imf::Channel(Imf::FLOAT));
  headers[1].channels().insert("G", Imf::Channel(Imf::FLOAT));
  for (Imf::Header& h : headers) h.setType(Imf::SCANLINEIMAGE);
  headers[0].insert("hfvis:cell_size_x", Imf::StringAttribute("2.5"));
  headers[0].insert("hfvis:cell_size_y", Imf::StringAttribute("4"));
  {
    Imf::MultiPartOutputFile out(file.c_str(), headers.data(), 2);
    std::vector<float> first = {1, 2, 3, 4, 5, 6}, second(25, 9.0f);
    Imf::OutputPart part0(out, 0), part1(out, 1);
    Imf::FrameBuffer frame0, frame1;
    frame0.insert("Y", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(first.data()), 4, 12));
    for (const char* name : {"R", "G"})
      frame1.insert(name, Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(second.data()), 4, 20));
    part0.setFrameBuffer(frame0);
    part0.writePixels(2);
    part1.setFrameBuffer(frame1);
    part1.writePixels(5);
  }
  const HeightField field = readHeightField(file);
  EXPECT_EQ(field.width, 3);
  EXPECT_EQ(field.heights, (std::vector<float>{1, 2, 3, 4, 5, 6}));
  EXPECT_EQ(field.cell_size_x, 2.5);
  EXPECT_EQ(field.cell_size_y, 4.0);
  // A channel of another part is read from that part, by its name (an index counts in the first).
  HeightFieldReadOptions options;
  options.channel = "G";
  const HeightField second = readHeightField(file, options);
  EXPECT_EQ(second.width, 5);
  EXPECT_EQ(second.heights, std::vector<float>(25, 9.0f));
  options.channel = "0";
  EXPECT_EQ(readHeightField(file, options).heights, field.heights);
  // A channel no part holds: the error lists every part's channels.
  options.channel = "Z";
  try {
    readHeightField(file, options);
    ADD_FAILURE() << "a channel no part holds was read";
  } catch (const IoError& error) {
    EXPECT_NE(error.reason().find("part 1 'second': 'R' 'G'"), std::string::npos) << error.what();
  }
}

// UINT heights beyond 2^24 that float32 rounds by more than a thousandth of their range are
// refused, as the GDAL reader refuses such a band (near 4.29e9 a wall of 100 came out flat, exit
// 0); the same heights from 0 are read exactly.
TEST_F(ImageIoExrTest, UintHeightsFloat32CannotHoldAreRefused) {
  const std::string file = path("uint.exr");
  for (const std::uint32_t base : {4294900000u, 0u}) {
    SCOPED_TRACE(base);
    std::vector<std::uint32_t> values(16, base);
    for (int i = 4; i < 8; ++i) values[i] = base + 100;
    {
      Imf::Header header(4, 4);
      header.channels().insert("Y", Imf::Channel(Imf::UINT));
      Imf::OutputFile out(file.c_str(), header);
      Imf::FrameBuffer frame;
      frame.insert("Y", Imf::Slice(Imf::UINT, reinterpret_cast<char*>(values.data()), 4, 16));
      out.setFrameBuffer(frame);
      out.writePixels(4);
    }
    if (base == 0) {
      EXPECT_EQ(readHeightField(file).heights[5], 100.0f);
      continue;
    }
    try {
      readHeightField(file);
      ADD_FAILURE() << "heights near 4.29e9 were read";
    } catch (const IoError& error) {
      EXPECT_NE(error.reason().find("rounds them by up to"), std::string::npos) << error.what();
    }
  }
}

TEST_F(ImageIoExrTest, AChannelInTwoLaterPartsIsRefused) {
  // A depth part first, then two views with Y each: Y is read from neither (which one?), Z from
  // the first part.
  const std::string file = path("views.exr");
  std::vector<Imf::Header> headers(3, Imf::Header(2, 2));
  const char* names[] = {"depth", "left", "right"};
  const char* channels[] = {"Z", "Y", "Y"};
  for (int p = 0; p < 3; ++p) {
    headers[p].setName(names[p]);
    headers[p].channels().insert(channels[p], Imf::Channel(Imf::FLOAT));
    headers[p].setType(Imf::SCANLINEIMAGE);
  }
  {
    Imf::MultiPartOutputFile out(file.c_str(), headers.data(), 3);
    std::vector<float> values = {1, 2, 3, 4};
    for (int p = 0; p < 3; ++p) {
      Imf::OutputPart part(out, p);
      Imf::FrameBuffer frame;
      frame.insert(channels[p], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(values.data()), 4, 8));
      part.setFrameBuffer(frame);
      part.writePixels(2);
    }
  }
  HeightFieldReadOptions options;
  options.channel = "Y";
  try {
    readHeightField(file, options);
    ADD_FAILURE() << "a channel two later parts hold was read from one of them";
  } catch (const IoError& error) {
    EXPECT_NE(error.reason().find("in part 1 'left' and in part 2 'right'"), std::string::npos)
        << error.what();
  }
  options.channel = "Z";
  EXPECT_EQ(readHeightField(file, options).heights, (std::vector<float>{1, 2, 3, 4}));
}

TEST_F(ImageIoExrTest, ExrUnderAnotherExtensionIsReadByItsContent) {
  const std::string file = path("field.png");
  writeScanlineExr(file, {"Y"}, Imf::FLOAT, windowOf(4, 2));
  EXPECT_EQ(readHeightField(file).heights, (std::vector<float>{0, 1, 2, 3, 4, 5, 6, 7}));
}

TEST_F(ImageIoExrTest, DeepAndSubsampledImagesAreRefused) {
  const std::string deep = path("deep.exr");
  {
    Imf::Header header(2, 2);
    header.setType(Imf::DEEPSCANLINE);
    header.compression() = Imf::ZIPS_COMPRESSION;
    header.channels().insert("Z", Imf::Channel(Imf::FLOAT));
    Imf::DeepScanLineOutputFile out(deep.c_str(), header);
    std::vector<unsigned> counts(4, 1);
    std::vector<float> depth = {1, 2, 3, 4};
    std::vector<float*> samples = {&depth[0], &depth[1], &depth[2], &depth[3]};
    Imf::DeepFrameBuffer frame;
    frame.insertSampleCountSlice(Imf::Slice(Imf::UINT, reinterpret_cast<char*>(counts.data()), 4, 8));
    frame.insert("Z", Imf::DeepSlice(Imf::FLOAT, reinterpret_cast<char*>(samples.data()), sizeof(float*),
                                     2 * sizeof(float*), sizeof(float)));
    out.setFrameBuffer(frame);
    out.writePixels(2);
  }
  expectIoError(
      deep, [&] { readHeightField(deep); }, "deep images are not supported");

  const std::string subsampled = path("subsampled.exr");
  {
    Imf::Header header(4, 4);
    header.channels().insert("Y", Imf::Channel(Imf::FLOAT));
    header.channels().insert("C", Imf::Channel(Imf::FLOAT, 2, 2));
    std::vector<float> y(16, 1.0f), c(4, 2.0f);
    Imf::FrameBuffer frame;
    frame.insert("Y", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(y.data()), 4, 16));
    frame.insert("C", Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(c.data()), 4, 8, 2, 2));
    Imf::OutputFile out(subsampled.c_str(), header);
    out.setFrameBuffer(frame);
    out.writePixels(4);
  }
  expectIoError(
      subsampled, [&] { readImage(subsampled); }, "subsampled");
}

// The bytes of `file`.
std::string bytesOf(const std::string& file) {
  std::ifstream in(file, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

void writeBytes(const std::string& file, const std::string& bytes) {
  std::ofstream(file, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

// The peak resident memory of this process since the last resetPeakMemory(), in bytes (0 where
// /proc cannot tell).
void resetPeakMemory() { std::ofstream("/proc/self/clear_refs") << "5"; }
std::uint64_t peakMemory() {
  std::ifstream status("/proc/self/status");
  for (std::string line; std::getline(status, line);)
    if (line.rfind("VmHWM:", 0) == 0) return std::stoull(line.substr(6)) << 10;
  return 0;
}

TEST_F(ImageIoExrTest, HostileHeadersAreRefusedQuicklyWithoutTheirClaims) {
  // fuzz/regressions/environment/oom-wide-zip-exr less its first byte (the fuzzer's choice of
  // extension): 421 bytes claiming 15990792 x 4 float pixels in one ZIP chunk of 16 rows, which
  // once took 16 GB through OpenImageIO. Its screenWindowWidth (a float) claims 1296891908
  // bytes, past the end of the file: refused from the header (OpenEXR 3.1 reads a float's four
  // bytes whatever the size says; later versions refuse the size too).
  const std::string fuzzed = path("fuzzed.exr"), wide = path("wide.exr");
  std::string bytes =
      bytesOf(std::string(HFVIS_DATA_DIR) + "/../fuzz/regressions/environment/oom-wide-zip-exr").substr(1);
  ASSERT_EQ(bytes.size(), 421u);
  writeBytes(fuzzed, bytes);
  expectIoError(
      fuzzed, [&] { readEnvironmentMap(fuzzed); }, "attribute 'screenWindowWidth' claims 1296891908 bytes");
  // With that size mended to 4, the header passes; OpenEXR reserves its buffers for a chunk
  // (untouched), the reader one 64 MB row of the plane, and the missing data stops it.
  const std::string width_key = std::string("screenWindowWidth") + '\0' + "float" + '\0';
  const std::size_t width_at = bytes.find(width_key);
  ASSERT_NE(width_at, std::string::npos);
  bytes.replace(width_at + width_key.size(), 4, std::string("\x04\0\0\0", 4));
  writeBytes(wide, bytes);
  resetPeakMemory();
  const std::uint64_t before = peakMemory();
  const auto start = std::chrono::steady_clock::now();
  expectIoError(
      wide, [&] { readEnvironmentMap(wide); }, "truncated or corrupt");
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
  if (before > 0) {
    EXPECT_LT(peakMemory() - before, std::uint64_t(256) << 20);
  }
  // With the height-field fuzzer's 64 MiB limit it is refused from the header alone.
  HeightFieldReadOptions small;
  small.max_image_bytes = std::uint64_t(64) << 20;
  expectIoError(
      wide, [&] { readHeightField(wide, small); }, "image claims 15990792 x 4 pixels of 1 channels");

  // An attribute claiming 2 GiB in a small file (OpenEXR would fill a 2 GiB string first).
  const std::string good = path("good.exr"), claims = path("claims.exr");
  ImageChannels image;
  image.width = image.height = 2;
  image.names = {"Y"};
  image.planes = {{1, 2, 3, 4}};
  image.attributes = {{"hfvis:note", "abc"}};
  writeImage(good, image);
  bytes = bytesOf(good);
  const std::string key = std::string("hfvis:note") + '\0' + "string" + '\0';
  const std::size_t at = bytes.find(key);
  ASSERT_NE(at, std::string::npos);
  const std::uint32_t size = 0x7fffff00u;
  std::memcpy(&bytes[at + key.size()], &size, 4);  // little-endian, as the file
  writeBytes(claims, bytes);
  resetPeakMemory();
  const std::uint64_t before_claims = peakMemory();
  expectIoError(
      claims, [&] { readHeightField(claims); }, "attribute 'hfvis:note' claims 2147483392 bytes");
  if (before_claims > 0) {
    EXPECT_LT(peakMemory() - before_claims, std::uint64_t(64) << 20);
  }

  // 2^31 pixels or more, from the header alone (a file of a few kilobytes).
  const std::string huge = path("huge.exr");
  {
    Imf::Header header(65536, 32768);
    header.channels().insert("Y", Imf::Channel(Imf::HALF));
    Imf::OutputFile out(huge.c_str(), header);  // no pixels written
  }
  expectIoError(
      huge, [&] { readHeightField(huge); }, "below 2^31 pixels");
}

TEST_F(ImageIoExrTest, OutputsAreFloatZipWithStringAttributes) {
  // Several chunks of rows and channels (OpenEXR's threads, where there are cores for them).
  const int width = 257, height = 255;
  ImageChannels image;
  image.width = width;
  image.height = height;
  image.names = {"slope", "aspect", "h000", "curvature"};
  for (std::size_t c = 0; c < image.names.size(); ++c) {
    image.planes.emplace_back(static_cast<std::size_t>(width) * height);
    for (std::size_t i = 0; i < image.planes[c].size(); ++i) image.planes[c][i] = valueOf(c, i) * 0.5f;
  }
  image.attributes = {{"hfvis:cell_size_x", "30"}, {"hfvis:cell_size_y", "20"}, {"hfvis:units", "metres"}};
  const std::string file = path("out.exr");
  writeImage(file, image);

  Imf::InputFile in(file.c_str());
  const Imf::Header& header = in.header();
  EXPECT_EQ(header.compression(), Imf::ZIP_COMPRESSION);
  EXPECT_EQ(header.dataWindow(), windowOf(width, height));
  EXPECT_EQ(header.displayWindow(), windowOf(width, height));
  std::vector<std::string> stored;
  for (auto it = header.channels().begin(); it != header.channels().end(); ++it) {
    stored.push_back(it.name());
    EXPECT_EQ(it.channel().type, Imf::FLOAT) << it.name();
  }
  // EXR sorts them by name (and so does readImage, none being R, G, B, A, ...).
  EXPECT_EQ(stored, (std::vector<std::string>{"aspect", "curvature", "h000", "slope"}));
  for (const auto& [name, value] : image.attributes) {
    const auto* attribute = header.findTypedAttribute<Imf::StringAttribute>(name);
    ASSERT_NE(attribute, nullptr) << name;
    EXPECT_EQ(attribute->value(), value);
  }
  const ImageChannels back = readImage(file);
  ASSERT_EQ(back.names, stored);
  for (std::size_t c = 0; c < back.names.size(); ++c) {
    const std::size_t written =
        std::find(image.names.begin(), image.names.end(), back.names[c]) - image.names.begin();
    EXPECT_EQ(back.planes[c], image.planes[written]) << back.names[c];
  }
  EXPECT_TRUE(back.attributes.empty());  // readImage keeps none; readHeightField reads the cell size
  HeightFieldReadOptions options;
  options.channel = "h000";
  EXPECT_EQ(readHeightField(file, options).cell_size_x, 30.0);
  EXPECT_EQ(readHeightField(file, options).cell_size_y, 20.0);
}

}  // namespace
}  // namespace hfvis
