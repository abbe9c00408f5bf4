// test_image_io.cpp: reading height fields (formats, pixel types, channels, GeoTIFF spacing,
// bad files) and writing results (channel order round trip, atomic replace, previews, GeoTIFF
// outputs checked with GDAL itself).
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include "geotiff_support.hpp"
#include "hfvis/environment_map.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/image_io.hpp"
#include "image_outputs.hpp"
#include "io/gdal_io.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

using testing::crsWkt;
using testing::GdalRaster;
using testing::kUtmGeotransform;
using testing::readGdalRaster;
using testing::sameCrs;

namespace fs = std::filesystem;

// One preview written on its own, as OutputFiles stages and commits it.
void writePreviewPng(const std::string& path, int width, int height, const std::vector<float>& plane,
                     float lo = 0.0f, float hi = 0.0f) {
  OutputFiles files;
  files.previewPng(path, width, height, plane, lo, hi);
  files.commit();
}
constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// A fresh, empty directory per test, so tests can run in parallel and leftovers are visible.
class ImageIoTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::freshTestDirectory("image_io");
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::vector<std::string> filesInDir() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }
  fs::path dir_;
};

// Writes interleaved `data` of type `type` with OpenImageIO itself (independent of the code under
// test), stored as `file_type` (default: `type`).
void writeWithOiio(const std::string& path, int width, int height, int channels, OIIO::TypeDesc type,
                   const void* data, const std::vector<std::string>& names = {},
                   OIIO::TypeDesc file_type = OIIO::TypeDesc::UNKNOWN) {
  OIIO::ImageSpec spec(width, height, channels, file_type == OIIO::TypeDesc::UNKNOWN ? type : file_type);
  if (!names.empty()) spec.channelnames = names;
  std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(path);
  ASSERT_TRUE(out) << OIIO::geterror();
  ASSERT_TRUE(out->open(path, spec)) << out->geterror();
  ASSERT_TRUE(out->write_image(type, data)) << out->geterror();
  ASSERT_TRUE(out->close()) << out->geterror();
}

// Fixed test data with negative values and a NaN: 7 x 13.
std::vector<float> oddField(int width, int height) {
  std::vector<float> values(static_cast<std::size_t>(width) * height);
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c)
      values[static_cast<std::size_t>(r) * width + c] = 0.25f * c - 1.5f * r + 3.0f;
  }
  values[5] = kNaN;
  values[17] = -1234.5f;
  return values;
}

void expectSameHeights(const std::vector<float>& expected, const std::vector<float>& actual) {
  ASSERT_EQ(expected.size(), actual.size());
  for (std::size_t i = 0; i < expected.size(); ++i) {
    if (std::isnan(expected[i])) {
      EXPECT_TRUE(std::isnan(actual[i])) << "at " << i;
    } else {
      EXPECT_EQ(expected[i], actual[i]) << "at " << i;
    }
  }
}

// Expects `call` to throw IoError whose path is `path` and whose message names it.
template <typename Call>
void expectIoError(const std::string& path, Call call, const std::string& message_part = "") {
  try {
    call();
    ADD_FAILURE() << "no IoError for " << path;
  } catch (const IoError& e) {
    EXPECT_EQ(e.path(), path);
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos) << e.what();
    EXPECT_FALSE(e.reason().empty());
    if (!message_part.empty()) {
      EXPECT_NE(std::string(e.what()).find(message_part), std::string::npos) << e.what();
    }
  }
}

// A minimal uncompressed single-strip float32 GeoTIFF written byte by byte, so that the tags
// are exactly the ones a test names (GDAL reads it, as every .tif). The tags follow the GeoTIFF
// 1.1 specification (ModelPixelScale 33550, ModelTiepoint 33922, ModelTransformation 34264,
// GeoKeyDirectory 34735).
struct GeoTiffSpec {
  int width = 4;
  int height = 2;
  bool big_endian = false;
  std::vector<double> pixel_scale;  // empty = no tag
  std::vector<double> tiepoint;
  std::vector<double> transform;
  std::vector<std::uint16_t> geo_keys;  // full GeoKeyDirectory contents; empty = no tag
};

class TiffBytes {
 public:
  explicit TiffBytes(bool big_endian) : big_(big_endian) {}
  void put(std::uint64_t v, int size) {
    for (int i = 0; i < size; ++i)
      bytes.push_back(static_cast<std::uint8_t>(v >> (8 * (big_ ? size - 1 - i : i))));
  }
  void putDouble(double d) {
    std::uint64_t raw;
    std::memcpy(&raw, &d, sizeof raw);
    put(raw, 8);
  }
  void putFloat(float f) {
    std::uint32_t raw;
    std::memcpy(&raw, &f, sizeof raw);
    put(raw, 4);
  }
  void setAt(std::size_t at, std::uint64_t v, int size) {
    for (int i = 0; i < size; ++i)
      bytes[at + i] = static_cast<std::uint8_t>(v >> (8 * (big_ ? size - 1 - i : i)));
  }
  std::vector<std::uint8_t> bytes;

 private:
  bool big_;
};

std::vector<float> writeGeoTiff(const std::string& path, const GeoTiffSpec& g) {
  TiffBytes t(g.big_endian);
  t.put(g.big_endian ? 0x4D4D : 0x4949, 2);
  t.put(42, 2);
  t.put(0, 4);  // IFD offset, set below
  std::vector<float> pixels(static_cast<std::size_t>(g.width) * g.height);
  for (std::size_t i = 0; i < pixels.size(); ++i) pixels[i] = 10.0f * static_cast<float>(i) - 5.0f;
  const std::size_t pixel_offset = t.bytes.size();
  for (float p : pixels) t.putFloat(p);
  // Out-of-line values first, then the IFD.
  auto doubles = [&](const std::vector<double>& v) {
    const std::size_t at = t.bytes.size();
    for (double d : v) t.putDouble(d);
    return at;
  };
  const std::size_t scale_at = doubles(g.pixel_scale);
  const std::size_t tie_at = doubles(g.tiepoint);
  const std::size_t transform_at = doubles(g.transform);
  const std::size_t keys_at = t.bytes.size();
  for (std::uint16_t k : g.geo_keys) t.put(k, 2);

  struct Entry {
    std::uint16_t tag, type;
    std::uint32_t count, value;  // value: inline SHORT/LONG or an offset
  };
  std::vector<Entry> entries = {
      {256, 4, 1, static_cast<std::uint32_t>(g.width)},
      {257, 4, 1, static_cast<std::uint32_t>(g.height)},
      {258, 3, 1, 32},  // BitsPerSample
      {259, 3, 1, 1},   // no compression
      {262, 3, 1, 1},   // BlackIsZero
      {273, 4, 1, static_cast<std::uint32_t>(pixel_offset)},
      {277, 3, 1, 1},  // SamplesPerPixel
      {278, 4, 1, static_cast<std::uint32_t>(g.height)},
      {279, 4, 1, static_cast<std::uint32_t>(pixels.size() * 4)},
      {284, 3, 1, 1},  // contiguous
      {339, 3, 1, 3},  // IEEE float
  };
  auto add = [&](std::uint16_t tag, std::uint16_t type, std::size_t count, std::size_t at) {
    if (count > 0)
      entries.push_back({tag, type, static_cast<std::uint32_t>(count), static_cast<std::uint32_t>(at)});
  };
  add(33550, 12, g.pixel_scale.size(), scale_at);
  add(33922, 12, g.tiepoint.size(), tie_at);
  add(34264, 12, g.transform.size(), transform_at);
  add(34735, 3, g.geo_keys.size(), keys_at);

  const std::size_t ifd = t.bytes.size();
  t.setAt(4, ifd, 4);
  t.put(entries.size(), 2);
  for (const Entry& e : entries) {
    t.put(e.tag, 2);
    t.put(e.type, 2);
    t.put(e.count, 4);
    if (e.type == 3 && e.count == 1) {
      t.put(e.value, 2);  // a SHORT sits in the first two bytes of the value field
      t.put(0, 2);
    } else {
      t.put(e.value, 4);
    }
  }
  t.put(0, 4);  // no next IFD
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(t.bytes.data()), static_cast<std::streamsize>(t.bytes.size()));
  return pixels;
}

// GeoKeyDirectory with the given (key, value) pairs, all inline SHORTs.
std::vector<std::uint16_t> geoKeys(const std::vector<std::pair<std::uint16_t, std::uint16_t>>& keys) {
  std::vector<std::uint16_t> dir = {1, 1, 0, static_cast<std::uint16_t>(keys.size())};
  for (const auto& [key, value] : keys) dir.insert(dir.end(), {key, 0, 1, value});
  return dir;
}

// ---------------------------------------------------------------------------------------------
// Formats and pixel types.

TEST_F(ImageIoTest, FloatExrSingleChannelRoundTripKeepsNaNAndNegatives) {
  const int w = 7, h = 13;
  const std::vector<float> values = oddField(w, h);
  writeWithOiio(path("field.exr"), w, h, 1, OIIO::TypeDesc::FLOAT, values.data());

  const HeightField field = readHeightField(path("field.exr"));
  EXPECT_EQ(field.width, w);
  EXPECT_EQ(field.height, h);
  expectSameHeights(values, field.heights);
  EXPECT_EQ(field.at(3, 4), 0.25f * 3 - 1.5f * 4 + 3.0f);  // row-major, row 0 first
  EXPECT_EQ(field.cell_size_x, 1.0);
  EXPECT_EQ(field.cell_size_y, 1.0);
  EXPECT_EQ(field.z_scale, 1.0);
  EXPECT_EQ(field.nodataCount(), 1u);
}

TEST_F(ImageIoTest, HalfExrReadsAsFloat) {
  const std::vector<float> values = {-2.5f, 0.0f, 1.0f, 1024.0f, 0.125f, kNaN};  // exact in half
  writeWithOiio(path("half.exr"), 3, 2, 1, OIIO::TypeDesc::FLOAT, values.data(), {}, OIIO::TypeDesc::HALF);
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(path("half.exr"));
  ASSERT_TRUE(in);
  EXPECT_EQ(in->spec().format, OIIO::TypeDesc::HALF);
  in->close();
  expectSameHeights(values, readHeightField(path("half.exr")).heights);
}

TEST_F(ImageIoTest, MultiChannelExrNeedsAChannelChoice) {
  const int w = 5, h = 3;
  std::vector<float> rgb(static_cast<std::size_t>(w) * h * 3);
  for (std::size_t i = 0; i < rgb.size(); ++i)
    rgb[i] = static_cast<float>(i % 3) * 100.0f + static_cast<float>(i / 3);
  const std::string file = path("rgb.exr");
  writeWithOiio(file, w, h, 3, OIIO::TypeDesc::FLOAT, rgb.data(), {"R", "G", "B"});

  try {
    readHeightField(file);
    ADD_FAILURE() << "a 3-channel image was read without a channel choice";
  } catch (const IoError& e) {
    const std::string message = e.what();
    EXPECT_EQ(e.path(), file);
    EXPECT_NE(message.find("channels"), std::string::npos) << message;
    for (const char* name : {"'R'", "'G'", "'B'"})
      EXPECT_NE(message.find(name), std::string::npos) << message;
    EXPECT_NE(message.find("choose"), std::string::npos) << message;
  }

  HeightFieldReadOptions by_name;
  by_name.channel = "G";
  const HeightField green = readHeightField(file, by_name);
  HeightFieldReadOptions by_index;
  by_index.channel = "2";
  const HeightField blue = readHeightField(file, by_index);
  for (int i = 0; i < w * h; ++i) {
    EXPECT_EQ(green.heights[i], 100.0f + i);
    EXPECT_EQ(blue.heights[i], 200.0f + i);
  }

  HeightFieldReadOptions unknown;
  unknown.channel = "height";
  expectIoError(
      file, [&] { readHeightField(file, unknown); }, "'height'");
  unknown.channel = "3";  // one past the last index
  expectIoError(
      file, [&] { readHeightField(file, unknown); }, "'R'");
}

TEST_F(ImageIoTest, Png16BitReadsStoredIntegers) {
  const std::vector<std::uint16_t> values = {0,     1,     2,     255,   256,   1000,
                                             32767, 32768, 65534, 65535, 12345, 54321};
  writeWithOiio(path("dem.png"), 4, 3, 1, OIIO::TypeDesc::UINT16, values.data());
  const HeightField field = readHeightField(path("dem.png"));
  ASSERT_EQ(field.heights.size(), values.size());
  for (std::size_t i = 0; i < values.size(); ++i)
    EXPECT_EQ(field.heights[i], static_cast<float>(values[i])) << i;
}

TEST_F(ImageIoTest, Png8BitReadsStoredIntegers) {
  const std::vector<std::uint8_t> values = {0, 1, 127, 128, 254, 255};
  writeWithOiio(path("dem8.png"), 2, 3, 1, OIIO::TypeDesc::UINT8, values.data());
  const HeightField field = readHeightField(path("dem8.png"));
  for (std::size_t i = 0; i < values.size(); ++i)
    EXPECT_EQ(field.heights[i], static_cast<float>(values[i])) << i;
}

// Radiance is linear floats: an 8- or 16-bit environment is refused (its 0 .. 255 were taken as
// radiance, 256 times the float image's, exit 0); readImage flags integer pixels (the exit
// radiance of `bounce` is refused by them), float ones stay unflagged; a light image's colours
// (the output in their units) may be integers.
TEST_F(ImageIoTest, IntegerImagesAreNoRadiance) {
  const std::vector<std::uint8_t> grey(8 * 4 * 3, 128);
  writeWithOiio(path("env8.png"), 8, 4, 3, OIIO::TypeDesc::UINT8, grey.data());
  const std::vector<std::uint16_t> grey16(8 * 4 * 3, 32768);
  writeWithOiio(path("env16.png"), 8, 4, 3, OIIO::TypeDesc::UINT16, grey16.data());
  const std::vector<float> half(8 * 4 * 3, 0.5f);
  writeWithOiio(path("env.tif"), 8, 4, 3, OIIO::TypeDesc::FLOAT, half.data());
  for (const char* name : {"env8.png", "env16.png"}) {
    expectIoError(
        path(name), [&] { readEnvironmentMap(path(name)); }, "holds integers");
    EXPECT_TRUE(readColourImage(path(name), "--light-image").integers) << name;
    EXPECT_TRUE(readImage(path(name)).integers) << name;
  }
  EXPECT_FALSE(readImage(path("env.tif")).integers);
  EXPECT_EQ(readEnvironmentMap(path("env.tif")).radiance.front(), 0.5f);
}

TEST_F(ImageIoTest, Int16TiffKeepsNegativeValues) {
  const std::vector<std::int16_t> values = {-32768, -1000, -1, 0, 1, 32767};
  writeWithOiio(path("bathy.tif"), 3, 2, 1, OIIO::TypeDesc::INT16, values.data());
  const HeightField field = readHeightField(path("bathy.tif"));
  for (std::size_t i = 0; i < values.size(); ++i)
    EXPECT_EQ(field.heights[i], static_cast<float>(values[i])) << i;
  EXPECT_EQ(field.cell_size_x, 1.0);  // a plain TIFF has no spacing
}

TEST_F(ImageIoTest, Uint32TiffReadsStoredIntegers) {
  const std::vector<std::uint32_t> values = {0, 123456, 4000000000u, 65536};  // all exact in float
  writeWithOiio(path("u32.tif"), 2, 2, 1, OIIO::TypeDesc::UINT32, values.data());
  const HeightField field = readHeightField(path("u32.tif"));
  for (std::size_t i = 0; i < values.size(); ++i)
    EXPECT_EQ(field.heights[i], static_cast<float>(values[i])) << i;
}

TEST_F(ImageIoTest, TwelveBitTiffReadsStoredIntegers) {
  // OpenImageIO delivers a 12-bit TIFF scaled to the full uint16 range; the reader undoes that.
  const std::string file = path("dem12.tif");
  OIIO::ImageSpec spec(4, 1, 1, OIIO::TypeDesc::UINT16);
  spec.attribute("oiio:BitsPerSample", 12);
  const std::vector<std::uint16_t> full_range = {0, 65535, 1600, 32768};  // 12-bit values 0, 4095, 100, 2048
  std::unique_ptr<OIIO::ImageOutput> out = OIIO::ImageOutput::create(file);
  ASSERT_TRUE(out && out->open(file, spec));
  ASSERT_TRUE(out->write_image(OIIO::TypeDesc::UINT16, full_range.data()));
  ASSERT_TRUE(out->close());
  const HeightField field = readHeightField(file);
  EXPECT_EQ(field.heights, (std::vector<float>{0.0f, 4095.0f, 100.0f, 2048.0f}));
}

TEST_F(ImageIoTest, FloatTiffRoundTrip) {
  const int w = 7, h = 13;
  const std::vector<float> values = oddField(w, h);
  writeWithOiio(path("field.tif"), w, h, 1, OIIO::TypeDesc::FLOAT, values.data());
  expectSameHeights(values, readHeightField(path("field.tif")).heights);
}

TEST(ImageIoData, BundledExrFieldsRead) {
  // Every height field shipped in data/ must read without options, and the environment map as one.
  int count = 0;
  for (const auto& entry : fs::directory_iterator(HFVIS_DATA_DIR)) {
    if (entry.path().extension() != ".exr") continue;
    if (entry.path().filename() == "clear_sky.exr") {
      const EnvironmentMap sky = readEnvironmentMap(entry.path().string());
      EXPECT_EQ(sky.channels, 3);
      EXPECT_EQ(sky.width, 2 * sky.height);
      continue;
    }
    const HeightField field = readHeightField(entry.path().string());
    EXPECT_GT(field.width, 0) << entry.path();
    EXPECT_GT(field.height, 0) << entry.path();
    EXPECT_LT(field.nodataCount(), field.pixelCount()) << entry.path();
    ++count;
  }
  EXPECT_GE(count, 6) << "data/ should hold the four synthetic fields and two DEMs";
}

TEST(ImageIoData, CellSizeStoredByHfvisIsUsedUnlessOverridden) {
  const std::string dem = std::string(HFVIS_DATA_DIR) + "/jacksboro_fault_dem.exr";
  const HeightField field = readHeightField(dem);
  EXPECT_DOUBLE_EQ(field.cell_size_x, 74.573);
  EXPECT_DOUBLE_EQ(field.cell_size_y, 92.475);
  HeightFieldReadOptions options;
  options.cell_size_x = 30.0;
  const HeightField overridden = readHeightField(dem, options);
  EXPECT_DOUBLE_EQ(overridden.cell_size_x, 30.0);
  EXPECT_DOUBLE_EQ(overridden.cell_size_y, 30.0);
}

// ---------------------------------------------------------------------------------------------
// Cell size and z-scale.

TEST_F(ImageIoTest, ExplicitCellSizeAndZScale) {
  const std::vector<float> values = {1, 2, 3, 4};
  writeWithOiio(path("f.exr"), 2, 2, 1, OIIO::TypeDesc::FLOAT, values.data());
  HeightFieldReadOptions options;
  options.cell_size_x = 2.5;
  options.z_scale = 3.0;
  HeightField field = readHeightField(path("f.exr"), options);
  EXPECT_EQ(field.cell_size_x, 2.5);
  EXPECT_EQ(field.cell_size_y, 2.5);  // only x given: both axes
  EXPECT_EQ(field.z_scale, 3.0);
  options.cell_size_y = 4.0;
  field = readHeightField(path("f.exr"), options);
  EXPECT_EQ(field.cell_size_x, 2.5);
  EXPECT_EQ(field.cell_size_y, 4.0);
}

TEST_F(ImageIoTest, GeoTiffProjectedPixelScale) {
  GeoTiffSpec g;
  g.pixel_scale = {30.0, 25.0, 0.0};
  g.tiepoint = {0, 0, 0, 500000.0, 4100000.0, 0};
  g.geo_keys = geoKeys({{1024, 1}, {1025, 1}, {3072, 32633}});  // projected, PixelIsArea, UTM 33N
  const std::vector<float> pixels = writeGeoTiff(path("utm.tif"), g);
  HeightField field = readHeightField(path("utm.tif"));
  EXPECT_EQ(field.heights, pixels);
  EXPECT_EQ(field.cell_size_x, 30.0);
  EXPECT_EQ(field.cell_size_y, 25.0);

  HeightFieldReadOptions options;  // explicit sizes win over the file's
  options.cell_size_x = 7.0;
  field = readHeightField(path("utm.tif"), options);
  EXPECT_EQ(field.cell_size_x, 7.0);
  EXPECT_EQ(field.cell_size_y, 7.0);
}

TEST_F(ImageIoTest, GeoTiffBigEndianAndTransformationMatrix) {
  GeoTiffSpec g;
  g.big_endian = true;
  g.transform = {10, 0, 0, 300000, 0, -12, 0, 5000000, 0, 0, 1, 0, 0, 0, 0, 1};
  g.geo_keys = geoKeys({{1024, 1}});
  const std::vector<float> pixels = writeGeoTiff(path("mm.tif"), g);
  const HeightField field = readHeightField(path("mm.tif"));
  EXPECT_EQ(field.heights, pixels);
  EXPECT_EQ(field.cell_size_x, 10.0);
  EXPECT_EQ(field.cell_size_y, 12.0);
}

TEST_F(ImageIoTest, GeoTiffGeographicDegreesBecomeMetres) {
  // 1 arc-second cells, 2 rows, PixelIsArea, top edge 1" north of 45 N: centre latitude 45.
  // WGS84 at 45 degrees: 111132.954 m per degree of latitude, 78846.835 m per degree of longitude.
  GeoTiffSpec g;
  const double arcsec = 1.0 / 3600.0;
  g.pixel_scale = {arcsec, arcsec, 0.0};
  g.tiepoint = {0, 0, 0, 7.0, 45.0 + arcsec, 0};
  g.geo_keys = geoKeys({{1024, 2}, {1025, 1}, {2048, 4326}});
  writeGeoTiff(path("wgs84.tif"), g);
  const HeightField field = readHeightField(path("wgs84.tif"));
  EXPECT_NEAR(field.cell_size_x, 78846.835 * arcsec, 1e-3);
  EXPECT_NEAR(field.cell_size_y, 111132.954 * arcsec, 1e-3);
}

// A tall latitude / longitude grid (1 degree cells, rows centred on 65 .. 55 N) gets each row's
// own spacing on the WGS84 ellipsoid: along columns from about 47.2 km at 65 N to 64.0 km at
// 55 N (55.80 km at 60 N), along rows about 111.4 km; the field's cell size is the centre latitude's (row 5's).
TEST_F(ImageIoTest, GeoTiffGeographicRowsGetTheirOwnSpacing) {
  GeoTiffSpec g;
  g.width = 3;
  g.height = 11;
  g.pixel_scale = {1.0, 1.0, 0.0};
  g.tiepoint = {0, 0, 0, 10.0, 65.5, 0};
  g.geo_keys = geoKeys({{1024, 2}, {1025, 1}, {2048, 4326}});
  writeGeoTiff(path("tall.tif"), g);
  const HeightField field = readHeightField(path("tall.tif"));
  ASSERT_EQ(field.row_cell_size_x.size(), 11u);
  ASSERT_EQ(field.row_cell_size_y.size(), 11u);
  EXPECT_NEAR(field.row_cell_size_x[5], 55800.00, 0.05);  // 60 N
  EXPECT_NEAR(field.row_cell_size_y[5], 111412.3, 0.5);
  EXPECT_EQ(field.cell_size_x, field.row_cell_size_x[5]);
  EXPECT_EQ(field.cell_size_y, field.row_cell_size_y[5]);
  for (int r = 0; r < 11; ++r) {
    double along_meridian = 0.0, along_parallel = 0.0;
    detail::metresPerDegree(65.0 - r, &along_meridian, &along_parallel);
    EXPECT_DOUBLE_EQ(field.row_cell_size_x[r], along_parallel) << r;
    EXPECT_DOUBLE_EQ(field.row_cell_size_y[r], along_meridian) << r;
    if (r > 0) {
      EXPECT_GT(field.row_cell_size_x[r], field.row_cell_size_x[r - 1]);
    }
  }
  // A projected raster, or a cell size given, has none.
  HeightFieldReadOptions given;
  given.cell_size_x = 30.0;
  EXPECT_TRUE(readHeightField(path("tall.tif"), given).row_cell_size_x.empty());
}

TEST_F(ImageIoTest, GeoTiffGeographicMatchesJacksboroDataNotes) {
  // data/jacksboro_fault_dem.txt: 3 arc-second cells, 403 x 344, top edge 36.732917 N,
  // cell size 74.573 x 92.475 m (WGS84 at the centre latitude 36.58958).
  GeoTiffSpec g;
  g.width = 403;
  g.height = 344;
  const double step = 0.0008333333333333334;
  g.pixel_scale = {step, step, 0.0};
  g.tiepoint = {0, 0, 0, -84.41375, 36.73291666666667, 0};
  g.geo_keys = geoKeys({{1024, 2}, {2048, 4326}});
  writeGeoTiff(path("jacksboro.tif"), g);
  const HeightField field = readHeightField(path("jacksboro.tif"));
  EXPECT_NEAR(field.cell_size_x, 74.573, 1e-3);
  EXPECT_NEAR(field.cell_size_y, 92.475, 1e-3);
}

TEST_F(ImageIoTest, GeoTiffGeographicWithoutTiepointIsAnError) {
  GeoTiffSpec g;
  g.pixel_scale = {0.001, 0.001, 0.0};
  g.geo_keys = geoKeys({{1024, 2}});
  writeGeoTiff(path("notie.tif"), g);
  expectIoError(
      path("notie.tif"), [&] { readHeightField(path("notie.tif")); }, "cell size");
  HeightFieldReadOptions options;  // an explicit cell size needs no tags
  options.cell_size_x = 20.0;
  EXPECT_EQ(readHeightField(path("notie.tif"), options).cell_size_y, 20.0);
}

TEST_F(ImageIoTest, TiffBytesUnderAnotherExtensionAreAGeoTiff) {
  // Known by their first bytes, read by GDAL with their tags (through OpenImageIO, which reads no
  // GeoTIFF tags, they had cells of 1 and no CRS).
  GeoTiffSpec g;
  g.pixel_scale = {30.0, 25.0, 0.0};
  g.tiepoint = {0, 0, 0, 500000.0, 4100000.0, 0};
  g.geo_keys = geoKeys({{1024, 1}, {1025, 1}, {3072, 32633}});
  const std::vector<float> pixels = writeGeoTiff(path("utm.hdr"), g);
  const HeightField field = readHeightField(path("utm.hdr"));
  EXPECT_EQ(field.heights, pixels);
  EXPECT_EQ(field.cell_size_x, 30.0);
  EXPECT_EQ(field.cell_size_y, 25.0);
  EXPECT_FALSE(field.georeference.empty());
}

TEST_F(ImageIoTest, GeoTiffInputFillsTheGeoreference) {
  const std::vector<float> heights = {1, 2, 3, -9999, 5, 6};
  const std::string file = path("dem.tif");
  testing::writeGdalGeoTiff(file, 3, 2, heights, kUtmGeotransform, "EPSG:32633", -9999.0);
  const HeightField field = readHeightField(file);
  ASSERT_TRUE(field.georeference.geotransform);
  EXPECT_EQ(*field.georeference.geotransform, kUtmGeotransform);
  EXPECT_TRUE(sameCrs(field.georeference.crs_wkt, crsWkt("EPSG:32633"))) << field.georeference.crs_wkt;
  EXPECT_EQ(field.cell_size_x, 30.0);
  EXPECT_EQ(field.cell_size_y, 30.0);
  EXPECT_TRUE(std::isnan(field.heights[3]));
  EXPECT_EQ(field.heights[4], 5.0f);
  // TIFF bytes under another name (.gtif, .cog, none) are the same GeoTIFF: through OpenImageIO
  // they lost the nodata (-9999 became a pit), the cells and the CRS, exit 0 (a probe's find).
  for (const char* name : {"dem.gtif", "dem.cog", "dem"}) {
    fs::copy_file(file, path(name));
    const HeightField same = readHeightField(path(name));
    EXPECT_EQ(same.georeference.geotransform, field.georeference.geotransform) << name;
    EXPECT_EQ(same.cell_size_x, 30.0) << name;
    EXPECT_TRUE(std::isnan(same.heights[3])) << name;
    EXPECT_EQ(filesRead(path(name)), std::vector<std::string>{path(name)}) << name;
  }
  // Images OpenImageIO reads have none, as a field filled in memory.
  writeWithOiio(path("f.exr"), 3, 2, 1, OIIO::TypeDesc::FLOAT, heights.data());
  EXPECT_TRUE(readHeightField(path("f.exr")).georeference.empty());
  EXPECT_TRUE(HeightField{}.georeference.empty());
}

// ---------------------------------------------------------------------------------------------
// Bad input.

TEST_F(ImageIoTest, MissingFileIsAnIoError) {
  expectIoError(
      path("missing.exr"), [&] { readHeightField(path("missing.exr")); }, "no such file");
}

TEST_F(ImageIoTest, GarbageBytesAreAnIoError) {
  std::ofstream(path("garbage.exr"), std::ios::binary) << "this is not an image, only some text bytes";
  expectIoError(path("garbage.exr"), [&] { readHeightField(path("garbage.exr")); });
  const char tiff_garbage[] = "II*\0garbage after a TIFF magic number";
  std::ofstream(path("garbage.tif"), std::ios::binary).write(tiff_garbage, sizeof tiff_garbage - 1);
  expectIoError(path("garbage.tif"), [&] { readHeightField(path("garbage.tif")); });
}

TEST_F(ImageIoTest, TruncatedExrIsAnIoError) {
  const int w = 64, h = 64;
  std::vector<float> values(static_cast<std::size_t>(w) * h);
  for (std::size_t i = 0; i < values.size(); ++i)
    values[i] = std::sin(0.37f * static_cast<float>(i)) * 100.0f;
  const std::string file = path("cut.exr");
  writeWithOiio(file, w, h, 1, OIIO::TypeDesc::FLOAT, values.data());
  ASSERT_NO_THROW(readHeightField(file));
  fs::resize_file(file, fs::file_size(file) / 2);
  expectIoError(
      file, [&] { readHeightField(file); }, "truncated");
}

TEST_F(ImageIoTest, ZeroByteFileIsAnIoError) {
  std::ofstream(path("empty.exr")).close();
  expectIoError(
      path("empty.exr"), [&] { readHeightField(path("empty.exr")); }, "empty");
}

TEST_F(ImageIoTest, DirectoryIsAnIoError) {
  fs::create_directories(path("folder.exr"));
  expectIoError(
      path("folder.exr"), [&] { readHeightField(path("folder.exr")); }, "directory");
}

// ---------------------------------------------------------------------------------------------
// Writing.

// The CLI's channel names (cli/image_outputs.hpp), which the image tests write with.
using cli::directionChannelNames;

TEST(DirectionChannelNames, ZeroPaddedInDirectionOrder) {
  EXPECT_EQ(directionChannelNames("h", 1), (std::vector<std::string>{"h000"}));
  EXPECT_TRUE(directionChannelNames("h", 0).empty());
  const std::vector<std::string> k64 = directionChannelNames("h", 64);
  ASSERT_EQ(k64.size(), 64u);
  EXPECT_EQ(k64.front(), "h000");
  EXPECT_EQ(k64.back(), "h063");
  EXPECT_EQ(directionChannelNames("h", 1000).back(), "h999");
  const std::vector<std::string> k1001 = directionChannelNames("h", 1001);
  EXPECT_EQ(k1001.front(), "h0000");
  EXPECT_EQ(k1001.back(), "h1000");
  EXPECT_TRUE(std::is_sorted(k1001.begin(), k1001.end()));
  EXPECT_EQ(directionChannelNames("dir_", 3)[2], "dir_002");
  EXPECT_THROW(directionChannelNames("h", -1), InvalidArgument);
}

// K planes where plane k holds k * 1000 + pixel index: any channel reordering shows.
ImageChannels horizonImage(int width, int height, int k) {
  ImageChannels image;
  image.width = width;
  image.height = height;
  image.names = directionChannelNames("h", k);
  for (int d = 0; d < k; ++d) {
    std::vector<float> plane(static_cast<std::size_t>(width) * height);
    for (std::size_t i = 0; i < plane.size(); ++i)
      plane[i] = static_cast<float>(d) * 1000.0f + static_cast<float>(i);
    image.planes.push_back(plane);
  }
  return image;
}

TEST_F(ImageIoTest, HorizonExrChannelsRoundTripInDirectionOrder) {
  const int w = 7, h = 13, k = 12;
  ImageChannels image = horizonImage(w, h, k);
  image.planes[3][4] = kNaN;
  image.planes[5][0] = -1.25f;
  image.attributes = {{"hfvis:directions", "12"}, {"hfvis:convention", "phi_k = 2 pi k / K"}};
  const std::string file = path("horizon.exr");
  writeImage(file, image);

  // The file stores the channels sorted by name, which is the direction order.
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(file);
  ASSERT_TRUE(in) << OIIO::geterror();
  EXPECT_EQ(in->spec().channelnames, image.names);
  EXPECT_EQ(in->spec().format, OIIO::TypeDesc::FLOAT);
  EXPECT_EQ(in->spec().get_string_attribute("hfvis:directions"), "12");
  EXPECT_EQ(in->spec().get_string_attribute("hfvis:convention"), "phi_k = 2 pi k / K");
  in->close();

  for (int d = 0; d < k; ++d) {
    HeightFieldReadOptions options;
    options.channel = image.names[d];
    const HeightField plane = readHeightField(file, options);
    EXPECT_EQ(plane.width, w);
    EXPECT_EQ(plane.height, h);
    expectSameHeights(image.planes[d], plane.heights);
  }
  EXPECT_EQ(filesInDir(), (std::vector<std::string>{"horizon.exr"}));
}

TEST_F(ImageIoTest, ThousandDirectionExrKeepsDirectionOrder) {
  const int k = 1001;  // names h0000 .. h1000
  const ImageChannels image = horizonImage(2, 1, k);
  const std::string file = path("many.exr");
  writeImage(file, image);

  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(file);
  ASSERT_TRUE(in) << OIIO::geterror();
  ASSERT_EQ(in->spec().nchannels, k);
  EXPECT_EQ(in->spec().channelnames, image.names);
  std::vector<float> all(static_cast<std::size_t>(2) * k);
  ASSERT_TRUE(in->read_image(0, 0, 0, k, OIIO::TypeDesc::FLOAT, all.data()));
  for (int d = 0; d < k; ++d) {
    EXPECT_EQ(all[d], image.planes[d][0]) << image.names[d];
    EXPECT_EQ(all[k + d], image.planes[d][1]) << image.names[d];
  }
  in->close();
  for (int d : {0, 9, 10, 99, 100, 999, 1000}) {
    HeightFieldReadOptions options;
    options.channel = image.names[d];
    EXPECT_EQ(readHeightField(file, options).heights, image.planes[d]) << image.names[d];
  }
}

TEST_F(ImageIoTest, WriteImageValidatesArguments) {
  ImageChannels image = horizonImage(3, 2, 2);
  image.names.pop_back();
  EXPECT_THROW(writeImage(path("a.exr"), image), InvalidArgument);
  image = horizonImage(3, 2, 2);
  image.planes[1].pop_back();
  EXPECT_THROW(writeImage(path("a.exr"), image), InvalidArgument);
  image = horizonImage(3, 2, 2);
  image.width = 0;
  EXPECT_THROW(writeImage(path("a.exr"), image), InvalidArgument);
  image = horizonImage(3, 2, 2);
  image.names[1] = image.names[0];
  EXPECT_THROW(writeImage(path("a.exr"), image), InvalidArgument);
  EXPECT_TRUE(filesInDir().empty());
}

TEST_F(ImageIoTest, WriteImageFailureLeavesNoFileBehind) {
  const ImageChannels image = horizonImage(3, 2, 2);
  const std::string nowhere = path("no_such_dir/out.exr");
  expectIoError(nowhere, [&] { writeImage(nowhere, image); });
  EXPECT_TRUE(filesInDir().empty());

  // A failure after the temporary file exists (PNG cannot hold 12 channels) removes it and
  // keeps the existing output untouched.
  const std::string png = path("out.png");
  writePreviewPng(png, 3, 2, image.planes[0]);
  const auto before = fs::file_size(png);
  expectIoError(png, [&] { writeImage(png, horizonImage(3, 2, 12)); });
  EXPECT_EQ(filesInDir(), (std::vector<std::string>{"out.png"}));
  EXPECT_EQ(fs::file_size(png), before);

  expectIoError(path("out.unknown_ext"), [&] { writeImage(path("out.unknown_ext"), image); });
  EXPECT_EQ(filesInDir(), (std::vector<std::string>{"out.png"}));
}

TEST_F(ImageIoTest, WriteImageReplacesAnExistingFile) {
  const std::string file = path("result.exr");
  writeImage(file, horizonImage(5, 4, 3));
  ImageChannels second = horizonImage(2, 3, 1);
  second.planes[0] = {-1, -2, -3, -4, -5, -6};
  writeImage(file, second);
  HeightFieldReadOptions options;
  options.channel = "h000";
  const HeightField field = readHeightField(file);  // one channel now: no choice needed
  EXPECT_EQ(field.width, 2);
  EXPECT_EQ(field.height, 3);
  EXPECT_EQ(field.heights, second.planes[0]);
  EXPECT_EQ(readHeightField(file, options).heights, second.planes[0]);
  EXPECT_EQ(filesInDir(), (std::vector<std::string>{"result.exr"}));
}

// ---------------------------------------------------------------------------------------------
// GeoTIFF outputs, read back with GDAL itself and with hfvis.

TEST(ImageWriters, GeoTiffNamesGoThroughGdal) {
  for (const char* name : {"a.tif", "a.tiff", "dir.x/A.TIF", "a.TiFf"}) {
    EXPECT_TRUE(writesGeoTiff(name)) << name;
    EXPECT_NO_THROW(requireImageWriter(name)) << name;
  }
  for (const char* name : {"a.exr", "a.tif.exr", "tif", "a.tifx", "a.png"})
    EXPECT_FALSE(writesGeoTiff(name)) << name;
}

TEST_F(ImageIoTest, GeoTiffOfWholeNumbersSkipsTheFloatingPointPredictor) {
  // Visible 0 / 1 and counts (NaN at nodata) compress better and faster without it; one
  // fractional value anywhere brings it back.
  ImageChannels image;
  image.width = 9;
  image.height = 4;
  image.names = {"visible", "count"};
  image.planes = {std::vector<float>(36, 1.0f), std::vector<float>(36, 7.0f)};
  image.planes[0][3] = 0.0f;
  image.planes[1][5] = kNaN;
  const std::string whole = path("whole.tif"), fractional = path("fractional.tif");
  writeImage(whole, image);
  image.planes[1][8] = 2.5f;
  writeImage(fractional, image);
  const GdalRaster a = readGdalRaster(whole), b = readGdalRaster(fractional);
  EXPECT_EQ(a.image_structure.at("COMPRESSION"), "DEFLATE");
  EXPECT_EQ(a.image_structure.count("PREDICTOR"), 0u);  // none
  EXPECT_EQ(b.image_structure.at("PREDICTOR"), "3");
  ASSERT_EQ(a.bands.size(), 2u);
  EXPECT_EQ(a.bands[0][3], 0.0f);
  EXPECT_EQ(a.bands[0][4], 1.0f);
  EXPECT_TRUE(std::isnan(a.bands[1][5]));
  EXPECT_EQ(b.bands[1][8], 2.5f);
}

TEST_F(ImageIoTest, GeoTiffOutputKeepsBandsGeoreferenceAndNodata) {
  ImageChannels image = horizonImage(7, 5, 3);
  image.planes[0][4] = kNaN;
  image.planes[2][0] = kNaN;
  image.planes[1][6] = -1.25f;
  image.attributes = {{"hfvis:directions", "3"}, {"hfvis:units", "radians: up = positive"}};
  image.georeference.geotransform = kUtmGeotransform;
  image.georeference.crs_wkt = crsWkt("EPSG:32633");
  image.nodata = -9999.0f;
  const std::string file = path("h.tif");
  writeImage(file, image);
  EXPECT_EQ(filesInDir(), (std::vector<std::string>{"h.tif"}));  // no temporary, no .aux.xml

  const GdalRaster raster = readGdalRaster(file);
  EXPECT_EQ(raster.driver, "GTiff");
  ASSERT_EQ(raster.width, 7);
  ASSERT_EQ(raster.height, 5);
  EXPECT_EQ(raster.descriptions, image.names);
  ASSERT_EQ(raster.bands.size(), 3u);
  for (std::size_t b = 0; b < 3; ++b) {
    SCOPED_TRACE(image.names[b]);
    ASSERT_TRUE(raster.nodata[b]);
    EXPECT_EQ(*raster.nodata[b], -9999.0);
    EXPECT_EQ(raster.block_sizes[b], (std::array<int, 2>{256, 256}));  // tiled
    for (std::size_t i = 0; i < raster.bands[b].size(); ++i) {
      const float expected = std::isnan(image.planes[b][i]) ? -9999.0f : image.planes[b][i];
      EXPECT_EQ(raster.bands[b][i], expected) << "at " << i;
    }
  }
  ASSERT_TRUE(raster.geotransform);
  EXPECT_EQ(*raster.geotransform, kUtmGeotransform);
  EXPECT_TRUE(sameCrs(raster.crs_wkt, image.georeference.crs_wkt)) << raster.crs_wkt;
  EXPECT_EQ(raster.image_structure.at("COMPRESSION"), "DEFLATE");
  EXPECT_EQ(raster.image_structure.at("PREDICTOR"), "3");
  EXPECT_EQ(raster.image_structure.at("INTERLEAVE"), "BAND");
  EXPECT_EQ(raster.metadata.at("hfvis_directions"), "3");
  EXPECT_EQ(raster.metadata.at("hfvis_units"), "radians: up = positive");

  // Back through hfvis: the bands by description or index, nodata as NaN, the georeference.
  const ImageChannels back = readImage(file);
  EXPECT_EQ(back.names, image.names);
  ASSERT_EQ(back.planes.size(), 3u);
  for (std::size_t b = 0; b < 3; ++b) expectSameHeights(image.planes[b], back.planes[b]);
  const auto has = [&](const std::string& name, const std::string& value) {
    return std::find(back.attributes.begin(), back.attributes.end(), std::make_pair(name, value)) !=
           back.attributes.end();
  };
  EXPECT_TRUE(has("hfvis:directions", "3"));
  EXPECT_TRUE(has("hfvis:units", "radians: up = positive"));
  ASSERT_TRUE(back.georeference.geotransform);
  EXPECT_EQ(*back.georeference.geotransform, kUtmGeotransform);
  EXPECT_TRUE(sameCrs(back.georeference.crs_wkt, image.georeference.crs_wkt));

  HeightFieldReadOptions by_name;
  by_name.channel = "h002";
  const HeightField h2 = readHeightField(file, by_name);
  expectSameHeights(image.planes[2], h2.heights);
  EXPECT_EQ(h2.cell_size_x, 30.0);
  EXPECT_EQ(h2.cell_size_y, 30.0);
  HeightFieldReadOptions by_index;
  by_index.channel = "1";
  expectSameHeights(image.planes[1], readHeightField(file, by_index).heights);
  expectIoError(
      file, [&] { readHeightField(file); }, "3 bands");
  HeightFieldReadOptions unknown;
  unknown.channel = "h003";
  expectIoError(
      file, [&] { readHeightField(file, unknown); }, "'h003'");
}

TEST_F(ImageIoTest, GeoTiffOutputWithoutGeoreferenceKeepsNaNAndTheCellSize) {
  ImageChannels image = horizonImage(4, 3, 1);
  image.planes[0][2] = kNaN;
  image.attributes = {{"hfvis:cell_size_x", "2.5"}, {"hfvis:cell_size_y", "4"}};
  const std::string file = path("plain.TIFF");
  writeImage(file, image);
  const GdalRaster raster = readGdalRaster(file);
  EXPECT_FALSE(raster.geotransform);
  EXPECT_TRUE(raster.crs_wkt.empty()) << raster.crs_wkt;
  ASSERT_TRUE(raster.nodata[0]);
  EXPECT_TRUE(std::isnan(*raster.nodata[0]));
  EXPECT_TRUE(std::isnan(raster.bands[0][2]));
  EXPECT_EQ(raster.bands[0][3], image.planes[0][3]);
  const HeightField field = readHeightField(file);  // one band: no choice needed
  EXPECT_TRUE(field.georeference.empty());
  EXPECT_EQ(field.cell_size_x, 2.5);
  EXPECT_EQ(field.cell_size_y, 4.0);
  expectSameHeights(image.planes[0], field.heights);
}

TEST_F(ImageIoTest, GeoTiffWriteFailureLeavesTheOldFileAndNothingElse) {
  const std::string file = path("r.tif");
  writeImage(file, horizonImage(5, 4, 2));
  const std::vector<std::string> before_files = filesInDir();
  std::ifstream before_stream(file, std::ios::binary);
  const std::string before((std::istreambuf_iterator<char>(before_stream)), std::istreambuf_iterator<char>());

  ImageChannels unwritable = horizonImage(5, 4, 3);
  unwritable.georeference.crs_wkt = "not a coordinate reference system";  // fails once the file exists
  expectIoError(
      file, [&] { writeImage(file, unwritable); }, "CRS");
  ImageChannels infinite = horizonImage(5, 4, 3);
  infinite.nodata = std::numeric_limits<float>::infinity();
  EXPECT_THROW(writeImage(file, infinite), InvalidArgument);
  ImageChannels bad_transform = horizonImage(5, 4, 3);
  bad_transform.georeference.geotransform = {0.0, std::nan(""), 0.0, 0.0, 0.0, -1.0};
  EXPECT_THROW(writeImage(file, bad_transform), InvalidArgument);
  expectIoError(
      path("none/r.tif"), [&] { writeImage(path("none/r.tif"), unwritable); }, "does not exist");
  // Under a file rather than a directory: said so (it was "does not exist").
  const std::string under_file = file + "/r.tif";
  expectIoError(
      under_file, [&] { writeImage(under_file, horizonImage(5, 4, 3)); }, "is a file, not a directory");

  EXPECT_EQ(filesInDir(), before_files);
  std::ifstream after_stream(file, std::ios::binary);
  const std::string after((std::istreambuf_iterator<char>(after_stream)), std::istreambuf_iterator<char>());
  EXPECT_EQ(after, before);
}

std::vector<std::uint8_t> readPng8(const std::string& file, int* width, int* height) {
  std::unique_ptr<OIIO::ImageInput> in = OIIO::ImageInput::open(file);
  EXPECT_TRUE(in) << OIIO::geterror();
  if (!in) return {};
  EXPECT_EQ(std::string(in->format_name()), "png");
  EXPECT_EQ(in->spec().format, OIIO::TypeDesc::UINT8);
  EXPECT_EQ(in->spec().nchannels, 1);
  *width = in->spec().width;
  *height = in->spec().height;
  std::vector<std::uint8_t> pixels(static_cast<std::size_t>(*width) * *height);
  EXPECT_TRUE(in->read_image(0, 0, 0, 1, OIIO::TypeDesc::UINT8, pixels.data()));
  return pixels;
}

TEST_F(ImageIoTest, PreviewPngMapsRangeToGrey) {
  const std::vector<float> plane = {
      -1.0f, 0.0f, 0.5f, 1.0f, 2.0f, kNaN, 0.25f, std::numeric_limits<float>::infinity(), 0.75f};
  int w = 0, h = 0;
  writePreviewPng(path("explicit.png"), 3, 3, plane, 0.0f, 1.0f);
  EXPECT_EQ(readPng8(path("explicit.png"), &w, &h),
            (std::vector<std::uint8_t>{0, 0, 128, 255, 255, 0, 64, 255, 191}));
  EXPECT_EQ(w, 3);
  EXPECT_EQ(h, 3);

  // lo == hi: the finite min (-1) and max (2) of the plane.
  writePreviewPng(path("auto.png"), 3, 3, plane);
  EXPECT_EQ(readPng8(path("auto.png"), &w, &h),
            (std::vector<std::uint8_t>{0, 85, 128, 170, 255, 0, 106, 255, 149}));
  EXPECT_EQ(filesInDir(), (std::vector<std::string>{"auto.png", "explicit.png"}));
}

TEST_F(ImageIoTest, PreviewPngOfFlatOrEmptyPlane) {
  int w = 0, h = 0;
  writePreviewPng(path("flat.png"), 2, 1, {5.0f, 5.0f});
  EXPECT_EQ(readPng8(path("flat.png"), &w, &h), (std::vector<std::uint8_t>{128, 128}));
  writePreviewPng(path("nan.png"), 1, 2, {kNaN, kNaN});
  EXPECT_EQ(readPng8(path("nan.png"), &w, &h), (std::vector<std::uint8_t>{0, 0}));
  EXPECT_THROW(writePreviewPng(path("bad.png"), 2, 2, {1.0f}), InvalidArgument);
  EXPECT_THROW(writePreviewPng(path("bad.png"), 0, 0, {}), InvalidArgument);
  expectIoError(path("none/p.png"), [&] { writePreviewPng(path("none/p.png"), 2, 1, {0.0f, 1.0f}); });
}

}  // namespace
}  // namespace hfvis

namespace hfvis {
namespace {

// A one-band GeoTIFF of GDAL type `type` holding `values` (written as float64, GDAL converting),
// with a scale and offset, a nodata value and a per-dataset mask (0: no data) where given.
void writeTypedGeoTiff(const std::string& path, int width, int height, GDALDataType type,
                       const std::vector<double>& values,
                       std::optional<std::pair<double, double>> scale_offset, std::optional<double> nodata,
                       const std::vector<unsigned char>& mask = {}) {
  testing::registerGdal();
  GDALDatasetH dataset =
      GDALCreate(GDALGetDriverByName("GTiff"), path.c_str(), width, height, 1, type, nullptr);
  ASSERT_NE(dataset, nullptr) << CPLGetLastErrorMsg();
  GDALRasterBandH band = GDALGetRasterBand(dataset, 1);
  if (scale_offset) {
    EXPECT_EQ(GDALSetRasterScale(band, scale_offset->first), CE_None);
    EXPECT_EQ(GDALSetRasterOffset(band, scale_offset->second), CE_None);
  }
  if (nodata) {
    EXPECT_EQ(GDALSetRasterNoDataValue(band, *nodata), CE_None);
  }
  std::vector<double> pixels = values;
  EXPECT_EQ(
      GDALRasterIO(band, GF_Write, 0, 0, width, height, pixels.data(), width, height, GDT_Float64, 0, 0),
      CE_None);
  if (!mask.empty()) {
    ASSERT_EQ(GDALCreateDatasetMaskBand(dataset, GMF_PER_DATASET), CE_None);
    std::vector<unsigned char> bytes = mask;
    EXPECT_EQ(GDALRasterIO(GDALGetMaskBand(band), GF_Write, 0, 0, width, height, bytes.data(), width, height,
                           GDT_Byte, 0, 0),
              CE_None);
  }
  GDALClose(dataset);
}

// A band's scale and offset map its stored values to heights (an int16 DEM of decimetres), its
// nodata value stays nodata whatever they are, and a per-dataset mask's 0 is nodata too; a float64
// value beyond float32's range is refused, not made infinite (which would pass for nodata); a
// float32 nodata value that float64 does not hold (0.1) still matches. All were read as stored.
TEST(GdalRasters, ScaleOffsetMaskAndRangeAreTheBands) {
  const std::string dir = std::string(HFVIS_TEST_TMP_DIR);
  const std::string scaled = dir + "/scaled.tif", masked = dir + "/masked.tif", wide = dir + "/wide.tif",
                    tenth = dir + "/tenth.tif";
  writeTypedGeoTiff(scaled, 3, 2, GDT_Int16, {10, 20, -32768, 40, 50, 60}, std::pair{0.1, 5.0}, -32768.0);
  const HeightField s = readHeightField(scaled);
  EXPECT_FLOAT_EQ(s.heights[0], 6.0f);
  EXPECT_FLOAT_EQ(s.heights[1], 7.0f);
  EXPECT_TRUE(std::isnan(s.heights[2]));
  EXPECT_FLOAT_EQ(s.heights[5], 11.0f);
  writeTypedGeoTiff(masked, 3, 2, GDT_Float32, {1, 2, 3, 4, 5, 6}, std::nullopt, std::nullopt,
                    {255, 0, 255, 255, 255, 0});
  const HeightField m = readHeightField(masked);
  EXPECT_EQ(m.heights[0], 1.0f);
  EXPECT_TRUE(std::isnan(m.heights[1]));
  EXPECT_EQ(m.heights[4], 5.0f);
  EXPECT_TRUE(std::isnan(m.heights[5]));
  EXPECT_EQ(m.nodataCount(), 2u);
  writeTypedGeoTiff(wide, 2, 2, GDT_Float64, {1, 2, 1e39, 4}, std::nullopt, std::nullopt);
  try {
    readHeightField(wide);
    ADD_FAILURE() << "a value beyond float32 was read";
  } catch (const IoError& error) {
    EXPECT_NE(std::string(error.what()).find("column 0, row 1"), std::string::npos) << error.what();
  }
  writeTypedGeoTiff(tenth, 2, 1, GDT_Float32, {0.1, 2}, std::nullopt, 0.1);
  const HeightField t = readHeightField(tenth);
  EXPECT_TRUE(std::isnan(t.heights[0]));
  EXPECT_EQ(t.heights[1], 2.0f);
}

// A signed-byte band is read as signed: GDAL before 3.7 stores Int8 as a Byte band marked
// PIXELTYPE=SIGNEDBYTE and hands its values over as 0 .. 255 (-55 was read as 201, exit 0), its
// nodata -128 among them.
TEST(GdalRasters, SignedByteBandsAreSigned) {
  testing::registerGdal();
  const std::string path = std::string(HFVIS_TEST_TMP_DIR) + "/signed_byte.tif";
  const std::vector<double> values = {-55.0, 29.0, -128.0, 127.0, -1.0, 0.0};
#if GDAL_VERSION_NUM >= 3070000
  GDALDatasetH dataset = GDALCreate(GDALGetDriverByName("GTiff"), path.c_str(), 3, 2, 1, GDT_Int8, nullptr);
  ASSERT_NE(dataset, nullptr) << CPLGetLastErrorMsg();
  std::vector<double> pixels = values;
  EXPECT_EQ(GDALRasterIO(GDALGetRasterBand(dataset, 1), GF_Write, 0, 0, 3, 2, pixels.data(), 3, 2,
                         GDT_Float64, 0, 0),
            CE_None);
#else
  const char* const options[] = {"PIXELTYPE=SIGNEDBYTE", nullptr};
  GDALDatasetH dataset =
      GDALCreate(GDALGetDriverByName("GTiff"), path.c_str(), 3, 2, 1, GDT_Byte, const_cast<char**>(options));
  ASSERT_NE(dataset, nullptr) << CPLGetLastErrorMsg();
  std::vector<unsigned char> bytes;
  for (double v : values) bytes.push_back(static_cast<unsigned char>(static_cast<signed char>(v)));
  EXPECT_EQ(
      GDALRasterIO(GDALGetRasterBand(dataset, 1), GF_Write, 0, 0, 3, 2, bytes.data(), 3, 2, GDT_Byte, 0, 0),
      CE_None);
#endif
  EXPECT_EQ(GDALSetRasterNoDataValue(GDALGetRasterBand(dataset, 1), -128.0), CE_None);
  GDALClose(dataset);
  const HeightField field = readHeightField(path);
  EXPECT_EQ(field.heights[0], -55.0f);
  EXPECT_EQ(field.heights[1], 29.0f);
  EXPECT_TRUE(std::isnan(field.heights[2]));
  EXPECT_EQ(field.heights[3], 127.0f);
  EXPECT_EQ(field.heights[4], -1.0f);
  EXPECT_EQ(field.heights[5], 0.0f);
}

// A raster georeferenced by ground control points alone has no grid of known spacing: refused
// (GDAL answers the identity geotransform; the run went on with cells of 1 and wrote outputs
// without the CRS, exit 0), with --cell-size too.
TEST(GdalRasters, GroundControlPointsWithoutAGeotransformAreRefused) {
  testing::registerGdal();
  const std::string path = std::string(HFVIS_TEST_TMP_DIR) + "/gcps.tif";
  GDALDatasetH dataset =
      GDALCreate(GDALGetDriverByName("GTiff"), path.c_str(), 4, 4, 1, GDT_Float32, nullptr);
  ASSERT_NE(dataset, nullptr) << CPLGetLastErrorMsg();
  std::vector<float> heights(16, 1.0f);
  EXPECT_EQ(GDALRasterIO(GDALGetRasterBand(dataset, 1), GF_Write, 0, 0, 4, 4, heights.data(), 4, 4,
                         GDT_Float32, 0, 0),
            CE_None);
  OGRSpatialReferenceH utm = OSRNewSpatialReference(nullptr);
  ASSERT_EQ(OSRImportFromEPSG(utm, 32633), OGRERR_NONE);
  GDAL_GCP gcps[3];
  GDALInitGCPs(3, gcps);
  const double points[3][4] = {{0, 0, 500000, 4000040}, {4, 0, 500040, 4000040}, {0, 4, 500000, 4000000}};
  for (int i = 0; i < 3; ++i) {
    gcps[i].dfGCPPixel = points[i][0], gcps[i].dfGCPLine = points[i][1];
    gcps[i].dfGCPX = points[i][2], gcps[i].dfGCPY = points[i][3];
  }
  EXPECT_EQ(GDALSetGCPs2(dataset, 3, gcps, utm), CE_None);
  GDALDeinitGCPs(3, gcps);
  OSRDestroySpatialReference(utm);
  GDALClose(dataset);
  for (const double cell : {0.0, 10.0}) {
    HeightFieldReadOptions options;
    options.cell_size_x = cell;
    try {
      readHeightField(path, options);
      ADD_FAILURE() << "read with cells of " << cell;
    } catch (const IoError& error) {
      EXPECT_NE(error.reason().find("ground control points"), std::string::npos) << error.what();
    }
  }
}

// An image's alpha band is a channel, not a mask over its colours: an RGBA GeoTIFF's R, G and B
// keep their values where its alpha is 0 (a light image, an environment map, an albedo).
TEST(GdalRasters, AnImagesAlphaMasksNothing) {
  testing::registerGdal();
  const std::string path = std::string(HFVIS_TEST_TMP_DIR) + "/rgba.tif";
  char** create = CSLSetNameValue(nullptr, "ALPHA", "YES");
  GDALDatasetH dataset = GDALCreate(GDALGetDriverByName("GTiff"), path.c_str(), 2, 1, 4, GDT_Byte, create);
  CSLDestroy(create);
  ASSERT_NE(dataset, nullptr) << CPLGetLastErrorMsg();
  for (int b = 1; b <= 4; ++b) {
    std::vector<unsigned char> values = {static_cast<unsigned char>(10 * b),
                                         static_cast<unsigned char>(b == 4 ? 0 : 200)};
    EXPECT_EQ(GDALRasterIO(GDALGetRasterBand(dataset, b), GF_Write, 0, 0, 2, 1, values.data(), 2, 1, GDT_Byte,
                           0, 0),
              CE_None);
  }
  ASSERT_NE(GDALGetMaskFlags(GDALGetRasterBand(dataset, 1)) & GMF_ALPHA, 0);  // (what the case is about)
  GDALClose(dataset);
  const ImageChannels colour = readColourImage(path, "a light image");
  ASSERT_EQ(colour.names, (std::vector<std::string>{"R", "G", "B"}));
  for (int c = 0; c < 3; ++c) EXPECT_EQ(colour.planes[c][0], 10.0f * (c + 1)) << c;  // where alpha is 40
  for (int c = 0; c < 3; ++c) EXPECT_EQ(colour.planes[c][1], 200.0f) << c;           // where alpha is 0
}

// A georeferenced raster GDAL reads and OpenImageIO does not (ESRI ASCII grid): its nodata
// value becomes NaN and its cell size the field's.
TEST(GdalRasters, AsciiGridWithNodataAndCellSize) {
  const std::string path = std::string(HFVIS_TEST_TMP_DIR) + "/grid.asc";
  {
    std::ofstream out(path);
    out << "ncols 3\nnrows 2\nxllcorner 500000\nyllcorner 4000000\ncellsize 30\nNODATA_value -9999\n"
        << "1 2 3\n4 -9999 6\n";
  }
  const HeightField field = readHeightField(path);
  ASSERT_EQ(field.width, 3);
  ASSERT_EQ(field.height, 2);
  EXPECT_EQ(field.heights[0], 1.0f);
  EXPECT_EQ(field.heights[5], 6.0f);
  EXPECT_TRUE(std::isnan(field.heights[4]));
  EXPECT_DOUBLE_EQ(field.cell_size_x, 30.0);
  EXPECT_DOUBLE_EQ(field.cell_size_y, 30.0);
  // A corner GDAL reads as infinite or NaN is refused, naming the input (the run went on: "x":
  // null in a region's JSON, inf in its CSV).
  for (const char* corner : {"1e309", "nan"}) {
    {
      std::ofstream out(path);
      out << "ncols 3\nnrows 2\nxllcorner " << corner << "\nyllcorner 4000000\ncellsize 30\n1 2 3\n4 5 6\n";
    }
    try {
      readHeightField(path);
      ADD_FAILURE() << "a geotransform with " << corner << " was taken";
    } catch (const IoError& e) {
      EXPECT_NE(std::string(e.what()).find("the geotransform is not finite"), std::string::npos) << e.what();
    }
  }
}

// A TIFF of a few bytes claiming side x side float32 pixels in one DEFLATE strip that holds 64.
void writeClaimingTiff(const std::string& path, std::uint32_t side) {
  std::string data;
  {
    // zlib's stream of 64 zero bytes (what Python's zlib.compress(bytes(64)) gives)
    const unsigned char deflated[] = {0x78, 0x9c, 0x63, 0x60, 0xa0, 0x0c, 0x00, 0x00, 0x00, 0x40, 0x00, 0x01};
    data.assign(reinterpret_cast<const char*>(deflated), sizeof deflated);
  }
  const std::uint32_t ifd = 8 + static_cast<std::uint32_t>(data.size());
  std::string out = std::string("II") + '\x2a' + '\0';
  const auto u16 = [&](std::uint16_t v) { out.append(reinterpret_cast<const char*>(&v), 2); };
  const auto u32 = [&](std::uint32_t v) { out.append(reinterpret_cast<const char*>(&v), 4); };
  u32(ifd);
  out += data;
  const std::uint32_t tags[][3] = {
      {256, 4, side}, {257, 4, side}, {258, 3, 32},
      {259, 3, 8},    {262, 3, 1},    {273, 4, 8},
      {277, 3, 1},    {278, 4, side}, {279, 4, static_cast<std::uint32_t>(data.size())},
      {284, 3, 1},    {339, 3, 3}};
  u16(static_cast<std::uint16_t>(std::size(tags)));
  for (const auto& tag : tags) {
    u16(static_cast<std::uint16_t>(tag[0]));
    u16(static_cast<std::uint16_t>(tag[1]));
    u32(1);
    if (tag[1] == 3) {
      u16(static_cast<std::uint16_t>(tag[2]));
      u16(0);
    } else {
      u32(tag[2]);
    }
  }
  u32(0);
  std::ofstream(path, std::ios::binary) << out;
}

// A header claiming far more pixels than the file holds fails at its first missing rows, having
// allocated about one read's worth beside what GDAL itself takes for the strip: the whole claim was
// allocated first, twice over (float32 values and float64 reads), 6 GB for 158 bytes of TIFF
// claiming 20000^2. Measured in a child process: the growth of its peak resident memory.
TEST(GdalRasters, AClaimedSizeIsNotAllocatedBeforeTheRowsAreRead) {
  const std::string path = std::string(HFVIS_TEST_TMP_DIR) + "/claim.tif";
  constexpr std::uint32_t kSide = 6000;  // 144 MB of float32, 288 MB as float64
  writeClaimingTiff(path, kSide);
  const pid_t child = ::fork();
  if (child == 0) {
    ::alarm(120);  // (a hang ends the child, and fails the test, instead of holding the suite)
    rusage before{}, after{};
    ::getrusage(RUSAGE_SELF, &before);
    int status = 3;
    try {
      readHeightField(path);
      status = 2;  // read: the file did not claim what it lacks
    } catch (const IoError&) {
      ::getrusage(RUSAGE_SELF, &after);
      const long grown_kb = after.ru_maxrss - before.ru_maxrss;
      // GDAL's strip (144 MB) and a read's worth; the claim read whole took 576 MB
      status = grown_kb < 300L * 1024 ? 0 : 1;
    } catch (...) {
    }
    ::_exit(status);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 0) << "1: the claim was allocated; 2: the file was read; 3: another error";
}

// A complex band is refused (GDAL gave its real part alone), and so are heights that float32 rounds
// by more than a thousandth of their range and a hundredth of a cell (UInt32 heights near 4e9 with
// walls of 50 came out flat, exit 0). Heights near 4000 in float64 over a range of 0.1 are not.
TEST(GdalRasters, ComplexBandsAndHeightsFloat32CannotHoldAreRefused) {
  testing::registerGdal();
  const std::string path = std::string(HFVIS_TEST_TMP_DIR) + "/typed.tif";
  const auto write = [&](GDALDataType type, const std::vector<double>& values) {
    GDALDatasetH dataset = GDALCreate(GDALGetDriverByName("GTiff"), path.c_str(), 4, 2, 1, type, nullptr);
    ASSERT_NE(dataset, nullptr) << CPLGetLastErrorMsg();
    std::vector<double> pixels = values;
    if (GDALDataTypeIsComplex(type)) {  // (real, imaginary) pairs
      pixels.clear();
      for (double v : values) pixels.push_back(v), pixels.push_back(v / 2);
    }
    EXPECT_EQ(GDALRasterIO(GDALGetRasterBand(dataset, 1), GF_Write, 0, 0, 4, 2, pixels.data(), 4, 2,
                           GDALDataTypeIsComplex(type) ? GDT_CFloat64 : GDT_Float64, 0, 0),
              CE_None);
    GDALClose(dataset);
  };
  const auto refusal = [&]() -> std::string {
    try {
      readHeightField(path);
    } catch (const IoError& error) {
      return error.reason();
    }
    return "(read)";
  };
  write(GDT_CFloat32, {1, 2, 3, 4, 5, 6, 7, 8});
  EXPECT_NE(refusal().find("complex numbers (CFloat32)"), std::string::npos) << refusal();
  write(GDT_UInt32, {4e9, 4e9, 4e9 + 50, 4e9 + 50, 4e9, 4e9, 4e9, 4e9});
  EXPECT_NE(refusal().find("rounds them by up to"), std::string::npos) << refusal();
  write(GDT_Float64, {4000.0, 4000.1, 4000.05, 4000.02, 4000.0, 4000.03, 4000.07, 4000.01});
  EXPECT_EQ(refusal(), "(read)");
  EXPECT_FLOAT_EQ(readHeightField(path).heights[1], 4000.1f);
  // The same on cells of 0.1 (a flat roof in a LiDAR DSM): a float32 file rounds as much.
  {
    GDALDatasetH dataset = GDALOpen(path.c_str(), GA_Update);
    std::array<double, 6> geotransform = {500000.0, 0.1, 0.0, 4100000.0, 0.0, -0.1};
    ASSERT_EQ(GDALSetGeoTransform(dataset, geotransform.data()), CE_None);
    GDALClose(dataset);
  }
  EXPECT_EQ(refusal(), "(read)");
  // Heights near 1e6 on those cells round by 0.06: over a hundredth of a cell, and of the range.
  write(GDT_Float64, {1e6, 1e6 + 0.1, 1e6 + 0.05, 1e6 + 0.02, 1e6, 1e6 + 0.03, 1e6 + 0.07, 1e6 + 0.01});
  {
    GDALDatasetH dataset = GDALOpen(path.c_str(), GA_Update);
    std::array<double, 6> geotransform = {500000.0, 0.1, 0.0, 4100000.0, 0.0, -0.1};
    ASSERT_EQ(GDALSetGeoTransform(dataset, geotransform.data()), CE_None);
    GDALClose(dataset);
  }
  EXPECT_NE(refusal().find("a hundredth of a cell"), std::string::npos) << refusal();
}

// A geographic raster's degrees become metres on the Earth: one in radians, or on Mars, got cells
// of the wrong size without a word; both are refused (--cell-size still reads them), EPSG:4326 is
// read.
TEST(GdalRasters, GeographicCrssNotInDegreesOnTheEarthAreRefused) {
  const std::string tif = std::string(HFVIS_TEST_TMP_DIR) + "/geographic.tif";
  const std::string vrt = std::string(HFVIS_TEST_TMP_DIR) + "/geographic.vrt";
  testing::writeGdalGeoTiff(tif, 4, 4, std::vector<float>(16, 1.0f), {0.0, 0.001, 0.0, 0.5, 0.0, -0.001},
                            "EPSG:4326", std::nullopt);
  EXPECT_NEAR(readHeightField(tif).cell_size_y, 110.6, 0.5);  // (0.001 degree of latitude)
  // (a VRT keeps the CRS as written; GDAL reads a GeoTIFF's WGS84 datum back as EPSG:4326)
  const std::string radians =
      "GEOGCS[\"radians\",DATUM[\"WGS_1984\",SPHEROID[\"WGS 84\",6378137,298.257223563]],"
      "PRIMEM[\"Greenwich\",0],UNIT[\"radian\",1]]";
  const std::string mars =
      "GEOGCS[\"Mars 2000\",DATUM[\"D_Mars_2000\",SPHEROID[\"Mars_2000_IAU_IAG\",3396190,169.894447223612]],"
      "PRIMEM[\"Reference_Meridian\",0],UNIT[\"degree\",0.0174532925199433]]";
  for (const auto& [crs, words] :
       {std::pair<std::string, std::string>{radians, "not degrees"}, {mars, "not the Earth"}}) {
    SCOPED_TRACE(words);
    std::ofstream(vrt) << "<VRTDataset rasterXSize=\"4\" rasterYSize=\"4\"><SRS>" << crs
                       << "</SRS><GeoTransform>0, 1e-5, 0, 0.5, 0, -1e-5</GeoTransform>"
                          "<VRTRasterBand dataType=\"Float32\" band=\"1\"><SimpleSource><SourceFilename "
                          "relativeToVRT=\"1\">geographic.tif</SourceFilename><SourceBand>1</SourceBand>"
                          "</SimpleSource></VRTRasterBand></VRTDataset>\n";
    try {
      readHeightField(vrt);
      ADD_FAILURE() << "read with cell sizes";
    } catch (const IoError& error) {
      EXPECT_NE(error.reason().find(words), std::string::npos) << error.what();
    }
    HeightFieldReadOptions given;
    given.cell_size_x = 2.0;
    EXPECT_EQ(readHeightField(vrt, given).cell_size_y, 2.0);
  }
}

// GDAL's ASCII grid readers take a value that is not a number as 0 (or as its leading digits), and
// read the values in order whatever the lines: such a grid, or one whose values are too few or too
// many for its header, is refused, in ESRI's format and in GRASS's.
TEST(GdalRasters, AsciiGridValuesThatAreNotNumbersAreRefused) {
  const std::string path = std::string(HFVIS_TEST_TMP_DIR) + "/words.asc";
  const std::string esri = "ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value -9999\n";
  const std::string grass = "north: 2\nsouth: 0\neast: 3\nwest: 0\nrows: 2\ncols: 3\n";
  for (const std::string& header : {esri, grass}) {
    // (a number's prefix among them: the check takes plain decimals without strtod, and asks
    // strtod of the rest)
    for (const std::string bad : {"abc", "1,5", "2x", "1e", "1e+", "-", ".", "+.e1", "1.5.2", "--1", "0x"}) {
      SCOPED_TRACE(header.substr(0, 6) + bad);
      { std::ofstream(path) << header << "1 2 3\n4 " << bad << " 6\n"; }
      try {
        readHeightField(path);
        ADD_FAILURE() << "read '" << bad << "' as a height";
      } catch (const IoError& error) {
        EXPECT_NE(error.reason().find("line 8: '" + bad + "' is not a number"), std::string::npos)
            << error.what();
      }
    }
    // The same grid with numbers in every form strtod takes is read.
    { std::ofstream(path) << header << "1 2e0 +3\n-4.5 .5 6.\n"; }
    const HeightField field = readHeightField(path);
    EXPECT_EQ(field.heights[3], -4.5f);
    EXPECT_EQ(field.heights[4], 0.5f);
    EXPECT_EQ(field.heights[5], 6.0f);
    { std::ofstream(path) << header << "1E+1 -2.5e-1 0x1p2\n  4\t5\r\n6\n"; }  // (hex: strtod's form)
    const HeightField more = readHeightField(path);
    EXPECT_EQ(more.heights[0], 10.0f);
    EXPECT_EQ(more.heights[1], -0.25f);
    EXPECT_EQ(more.heights[5], 6.0f);
    // A value short, or one too many (GDAL read them in order: 0 for the missing last one, or
    // every later row shifted).
    for (const std::string& values : {std::string("1 2 3\n4 5\n"), std::string("1 2 3 9\n4 5 6\n")}) {
      { std::ofstream(path) << header << values; }
      try {
        readHeightField(path);
        ADD_FAILURE() << "read " << values;
      } catch (const IoError& error) {
        EXPECT_NE(error.reason().find("values where its header says 3 columns of 2 rows"), std::string::npos)
            << error.what();
      }
    }
  }
  // GRASS's null token (and its keys written without a space) is read as nodata.
  { std::ofstream(path) << "north:2\nsouth:0\neast:3\nwest:0\nrows:2\ncols:3\nnull: *\n1 * 3\n4 5 6\n"; }
  const HeightField grass_field = readHeightField(path);
  EXPECT_TRUE(std::isnan(grass_field.heights[1]));
  EXPECT_EQ(grass_field.heights[5], 6.0f);
  // The header's values are numbers too: GDAL read `NODATA_value abc` as 0 (every height 0 a
  // hole) and `xllcorner abc` as 0, and a cell size of 0 placed every pixel at one point.
  const std::vector<std::pair<std::string, std::string>> headers = {
      {"ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 1\nNODATA_value abc\n",
       "line 6: the header's nodata_value 'abc' is not a number"},
      {"ncols 3\nnrows 2\nxllcorner abc\nyllcorner 0\ncellsize 1\n", "line 3: the header's xllcorner 'abc'"},
      {"north: 2\nsouth: 0x\neast: 3\nwest: 0\nrows: 2\ncols: 3\n", "line 2: the header's south '0x'"},
      {"ncols 3\nnrows 2\nxllcorner 0\nyllcorner 0\ncellsize 0\n", "the geotransform's pixel size is 0"}};
  HeightFieldReadOptions given;  // (with --cell-size too)
  given.cell_size_x = given.cell_size_y = 1.0;
  for (const auto& [header, reason] : headers) {
    SCOPED_TRACE(header);
    { std::ofstream(path) << header << "0 2 3\n4 5 6\n"; }
    try {
      readHeightField(path, given);
      ADD_FAILURE() << "read";
    } catch (const IoError& error) {
      EXPECT_NE(error.reason().find(reason), std::string::npos) << error.what();
    }
  }
}

}  // namespace
}  // namespace hfvis
