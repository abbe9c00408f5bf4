// tests/test_cli.cpp: the hfvis command line tool, run as a separate process: exit status,
// messages, outputs read back with OpenImageIO (GeoTIFFs with GDAL), and no partial output
// after a failure.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <chrono>
#include <cmath>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <limits>
#include <map>
#include <optional>
#include <random>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "geotiff_support.hpp"
#include "hfvis/environment_light.hpp"
#include "hfvis/horizon_lists.hpp"
#include "hfvis/image_io.hpp"
#include "hfvis/intervisibility.hpp"
#include "hfvis/pvs.hpp"
#include "hfvis/region_visibility.hpp"
#include "hfvis/sky_view_factor.hpp"
#include "image_outputs.hpp"
#include "test_support.hpp"

namespace {

namespace fs = std::filesystem;

constexpr double kHalfPi = 1.57079632679489661923;
constexpr double kPi = 2.0 * kHalfPi;

struct CliResult {
  int status = -1;  // exit status, or -1 when the process did not exit normally
  std::string out;
  std::string err;
};

std::string shellQuoted(const std::string& text) {
  std::string quoted = "'";
  for (const char c : text) quoted += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return quoted + "'";
}

std::string readText(const fs::path& path) {
  std::ifstream in(path, std::ios::binary);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Names of every entry of a directory, hidden ones (temporary files) included.
std::vector<std::string> listDirectory(const fs::path& directory) {
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(directory))
    names.push_back(entry.path().filename().string());
  return names;
}

struct ReadBack {
  int width = 0;
  int height = 0;
  std::vector<std::string> channels;
  std::vector<float> pixels;  // interleaved
  OIIO::ImageSpec spec;
  float at(int x, int y, int c) const {
    return pixels[(static_cast<std::size_t>(y) * width + x) * channels.size() + c];
  }
};

ReadBack readBack(const fs::path& path) {
  ReadBack image;
  auto in = OIIO::ImageInput::open(path.string());
  if (!in) {
    ADD_FAILURE() << "cannot open " << path << ": " << OIIO::geterror();
    return image;
  }
  image.spec = in->spec();
  image.width = image.spec.width;
  image.height = image.spec.height;
  image.channels = image.spec.channelnames;
  image.pixels.resize(image.spec.image_pixels() * image.spec.nchannels);
  EXPECT_TRUE(in->read_image(0, 0, 0, image.spec.nchannels, OIIO::TypeDesc::FLOAT, image.pixels.data()))
      << in->geterror();
  return image;
}

// A small strict JSON reader (RFC 8259 values; \uXXXX escapes only below 0x80), enough to
// check that `hfvis horizons` writes well-formed JSON and to read its values back.
struct Json {
  enum class Type { Null, Bool, Number, String, Array, Object } type = Type::Null;
  bool boolean = false;
  double number = 0.0;
  std::string text;
  std::vector<Json> items;
  std::map<std::string, Json> members;

  const Json& operator[](const std::string& key) const {
    const auto it = members.find(key);
    if (type != Type::Object || it == members.end()) throw std::runtime_error("no member '" + key + "'");
    return it->second;
  }
  const Json& operator[](std::size_t i) const {
    if (type != Type::Array || i >= items.size()) throw std::runtime_error("no item " + std::to_string(i));
    return items[i];
  }
};

class JsonParser {
 public:
  static Json parse(const std::string& text) {
    JsonParser p(text);
    Json value = p.value();
    p.space();
    if (p.at_ != text.size()) p.fail("trailing characters");
    return value;
  }

 private:
  explicit JsonParser(const std::string& text) : s_(text) {}
  [[noreturn]] void fail(const std::string& what) const {
    throw std::runtime_error("JSON: " + what + " at offset " + std::to_string(at_));
  }
  void space() {
    while (at_ < s_.size() && (s_[at_] == ' ' || s_[at_] == '\n' || s_[at_] == '\r' || s_[at_] == '\t'))
      ++at_;
  }
  void expect(char c) {
    space();
    if (at_ >= s_.size() || s_[at_] != c) fail(std::string("expected '") + c + "'");
    ++at_;
  }
  bool word(const char* w) {
    const std::string text(w);
    if (s_.compare(at_, text.size(), text) != 0) return false;
    at_ += text.size();
    return true;
  }
  std::string string() {
    expect('"');
    std::string out;
    while (true) {
      if (at_ >= s_.size()) fail("unterminated string");
      const char c = s_[at_++];
      if (c == '"') return out;
      if (static_cast<unsigned char>(c) < 0x20) fail("control character in a string");
      if (c != '\\') {
        out += c;
        continue;
      }
      if (at_ >= s_.size()) fail("unterminated escape");
      const char e = s_[at_++];
      const std::string simple = "\"\\/bfnrt", meaning = "\"\\/\b\f\n\r\t";
      if (const auto k = simple.find(e); k != std::string::npos) {
        out += meaning[k];
      } else if (e == 'u' && at_ + 4 <= s_.size()) {
        const int code = std::stoi(s_.substr(at_, 4), nullptr, 16);
        if (code >= 0x80) fail("non-ASCII escape");
        out += static_cast<char>(code);
        at_ += 4;
      } else {
        fail("bad escape");
      }
    }
  }
  Json value() {
    space();
    if (at_ >= s_.size()) fail("missing value");
    Json v;
    const char c = s_[at_];
    if (c == '{') {
      v.type = Json::Type::Object;
      ++at_;
      space();
      if (at_ < s_.size() && s_[at_] == '}') return ++at_, v;
      do {
        const std::string key = string();
        expect(':');
        if (!v.members.emplace(key, value()).second) fail("duplicate key '" + key + "'");
        space();
      } while (at_ < s_.size() && s_[at_] == ',' && ++at_);
      expect('}');
    } else if (c == '[') {
      v.type = Json::Type::Array;
      ++at_;
      space();
      if (at_ < s_.size() && s_[at_] == ']') return ++at_, v;
      do {
        v.items.push_back(value());
        space();
      } while (at_ < s_.size() && s_[at_] == ',' && ++at_);
      expect(']');
    } else if (c == '"') {
      v.type = Json::Type::String;
      v.text = string();
    } else if (word("true") || word("false")) {
      v.type = Json::Type::Bool;
      v.boolean = s_[at_ - 1] == 'e' && s_[at_ - 2] == 'u';
    } else if (word("null")) {
      v.type = Json::Type::Null;
    } else {
      // -?(0|[1-9][0-9]*)(\.[0-9]+)?([eE][+-]?[0-9]+)?
      const std::size_t begin = at_;
      auto digits = [&] {
        const std::size_t from = at_;
        while (at_ < s_.size() && std::isdigit(static_cast<unsigned char>(s_[at_]))) ++at_;
        if (at_ == from) fail("expected a digit");
      };
      if (s_[at_] == '-') ++at_;
      if (at_ < s_.size() && s_[at_] == '0') {
        ++at_;
      } else {
        digits();
      }
      if (at_ < s_.size() && s_[at_] == '.') ++at_, digits();
      if (at_ < s_.size() && (s_[at_] == 'e' || s_[at_] == 'E')) {
        ++at_;
        if (at_ < s_.size() && (s_[at_] == '+' || s_[at_] == '-')) ++at_;
        digits();
      }
      v.type = Json::Type::Number;
      v.number = std::stod(s_.substr(begin, at_ - begin));
    }
    return v;
  }

  const std::string& s_;
  std::size_t at_ = 0;
};

std::vector<std::string> splitText(const std::string& text, char separator) {
  std::vector<std::string> parts;
  std::string part;
  std::istringstream in(text);
  while (std::getline(in, part, separator)) parts.push_back(part);
  if (!text.empty() && text.back() == separator) parts.emplace_back();
  return parts;
}

// Each test gets fresh directories: `inputs` for what the test writes, `outputs` for what
// the tool writes (so "nothing left behind" is simply "outputs is empty").
class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    root_ = hfvis::testing::freshTestDirectory("cli");
    fs::create_directories(inputs());
    fs::create_directories(outputs());
  }

  // Kept after a failure, for a look at what the tool wrote.
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(root_);
  }

  fs::path inputs() const { return root_ / "inputs"; }
  fs::path outputs() const { return root_ / "outputs"; }
  std::string in(const std::string& name) const { return (inputs() / name).string(); }
  std::string out(const std::string& name) const { return (outputs() / name).string(); }

  // Runs `hfvis ARGS` (ARGS already shell-quoted where needed), capturing both streams; `prefix`
  // goes before the program ("env NAME=VALUE").
  CliResult run(const std::string& args, const std::string& prefix = "") const {
    const fs::path out_file = root_ / "stdout.txt";
    const fs::path err_file = root_ / "stderr.txt";
    const std::string command = prefix + " " + shellQuoted(HFVIS_CLI_PATH) + " " + args + " >" +
                                shellQuoted(out_file.string()) + " 2>" + shellQuoted(err_file.string()) +
                                " </dev/null";
    const int raw = std::system(command.c_str());
    CliResult result;
    result.status = (raw != -1 && WIFEXITED(raw)) ? WEXITSTATUS(raw) : -1;
    result.out = readText(out_file);
    result.err = readText(err_file);
    return result;
  }

  // A width x height height field of heights(col, row), written as a one-channel EXR.
  template <typename Heights>
  std::string writeField(const std::string& name, int width, int height, Heights heights) const {
    hfvis::ImageChannels image;
    image.width = width;
    image.height = height;
    image.names = {"Y"};
    image.planes.emplace_back();
    for (int row = 0; row < height; ++row) {
      for (int col = 0; col < width; ++col) image.planes[0].push_back(heights(col, row));
    }
    hfvis::writeImage(in(name), image);
    return in(name);
  }

  // The PVS tests' field: 30 x 22 hills with a wall along column 15.
  std::string pvsHills() const {
    return writeField("hills.exr", 30, 22, [](int col, int row) {
      return 4.0f * std::sin(0.4f * col) * std::cos(0.3f * row) + (col == 15 ? 12.0f : 0.0f);
    });
  }

  std::string ramp() const {
    return writeField("ramp.exr", 16, 12, [](int col, int row) { return 0.5f * col + 0.25f * row; });
  }
  std::string flat() const {
    return writeField("flat.exr", 16, 12, [](int, int) { return 3.0f; });
  }

  // The common checks of every failure: status, a message naming `named`, nothing written.
  void expectFailure(const CliResult& result, int status, const std::string& named) const {
    EXPECT_EQ(result.status, status) << result.err;
    EXPECT_NE(result.err.find("hfvis: error: "), std::string::npos) << result.err;
    EXPECT_NE(result.err.find(named), std::string::npos) << "stderr does not name '" << named << "':\n"
                                                         << result.err;
    EXPECT_TRUE(listDirectory(outputs()).empty()) << "left behind in " << outputs();
  }

  fs::path root_;
};

// ---- failures: argument errors (status 2) are found before the input is read ----

TEST_F(Cli, NoArgumentsIsAUsageError) {
  const CliResult result = run("");
  EXPECT_EQ(result.status, 2);
  EXPECT_NE(result.err.find("no command"), std::string::npos) << result.err;
}

TEST_F(Cli, UnknownSubcommand) {
  expectFailure(run("frobnicate " + shellQuoted(ramp()) + " -o " + shellQuoted(out("o.exr"))), 2,
                "'frobnicate'");
}

TEST_F(Cli, UnknownOption) {
  expectFailure(
      run("horizon " + shellQuoted(ramp()) + " -o " + shellQuoted(out("o.exr")) + " --frobnicate 3"), 2,
      "--frobnicate");
}

// A short option's value comes attached or next, never after '=' ("-o=x.exr" wrote "=x.exr").
TEST_F(Cli, AShortOptionWithAnEqualsSignIsAUsageError) {
  const CliResult result =
      run("horizon " + shellQuoted(ramp()) + " -o=" + shellQuoted(out("o.exr")) + " -k 4");
  expectFailure(result, 2, "without '='");
}

TEST_F(Cli, DirectionsOutOfRange) {
  for (const char* k : {"0", "65537", "100000000"}) {
    const CliResult result =
        run("horizon " + shellQuoted(ramp()) + " -o " + shellQuoted(out("o.exr")) + " -k " + k);
    expectFailure(result, 2, "-k");
    EXPECT_NE(result.err.find("in 1 .. 65536"), std::string::npos) << result.err;
  }
}

// A horizon map that cannot fit in host memory (65536 planes of a 1024 x 1024 field: 256 GiB)
// is refused before anything is computed, saying what to ask for instead; nothing is written.
TEST_F(Cli, HorizonMapBeyondHostMemoryIsRefusedBeforeComputing) {
  const std::string big = writeField("big.exr", 1024, 1024, [](int x, int y) { return float(x ^ y); });
  const auto start = std::chrono::steady_clock::now();
  const CliResult result = run("horizon " + shellQuoted(big) + " -o " + shellQuoted(out("o.exr")) + " -k 65536");
  expectFailure(result, 1, "GiB of host memory");
  EXPECT_NE(result.err.find("ask for svf or ao"), std::string::npos) << result.err;
  EXPECT_FALSE(fs::exists(out("o.exr")));
  // Refused, not computed: a sweep of 65536 directions would take minutes.
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 30.0);
}

TEST_F(Cli, UnknownOutputFormatIsRefusedBeforeComputing) {
  const CliResult result = run("svf " + shellQuoted(ramp()) + " -o " + shellQuoted(out("o.xyz")) + " -k 4");
  expectFailure(result, 1, "o.xyz");
  EXPECT_NE(result.err.find("no image writer for the extension '.xyz'"), std::string::npos) << result.err;
  EXPECT_EQ(result.err.find("hfvis-tmp"), std::string::npos) << "names a temporary file: " << result.err;
}

TEST_F(Cli, NonNumericValues) {
  const std::string base = "svf " + shellQuoted(ramp()) + " -o " + shellQuoted(out("o.exr"));
  expectFailure(run(base + " -k eight"), 2, "'eight'");
  expectFailure(run(base + " -k 8x"), 2, "'8x'");
  expectFailure(run(base + " --z-scale tall"), 2, "--z-scale");
  expectFailure(run(base + " --cell-size 1,abc"), 2, "--cell-size");
  expectFailure(run(base + " --samples-per-unit -1"), 2, "--samples-per-unit");
  expectFailure(run(base + " --samples-per-unit 1000"), 2, "--samples-per-unit: at most 64");
  expectFailure(run(base + " --method fast"), 2, "'fast'");
}

TEST_F(Cli, MissingOutput) { expectFailure(run("horizon " + shellQuoted(ramp()) + " -k 4"), 2, "-o"); }

TEST_F(Cli, MissingValue) {
  expectFailure(run("ao " + shellQuoted(ramp()) + " -o " + shellQuoted(out("o.exr")) + " -k"), 2, "-k");
  expectFailure(run("ao " + shellQuoted(ramp()) + " -o --quiet"), 2, "-o");
}

TEST_F(Cli, MissingInputArgument) { expectFailure(run("svf -o " + shellQuoted(out("o.exr"))), 2, "input"); }

TEST_F(Cli, DistanceOutputOnlyForHorizon) {
  expectFailure(run("svf " + shellQuoted(ramp()) + " -o " + shellQuoted(out("o.exr")) + " --distance-out " +
                    shellQuoted(out("d.exr"))),
                2, "--distance-out");
}

TEST_F(Cli, AzimuthToleranceOnlyForHorizonAndInRange) {
  const std::string base = shellQuoted(ramp()) + " -o " + shellQuoted(out("o.exr")) + " -k 7";
  expectFailure(run("svf " + base + " --azimuth-tolerance 1"), 2, "--azimuth-tolerance");
  expectFailure(run("horizon " + base + " --azimuth-tolerance 6"), 2, "azimuth tolerance");
  expectFailure(run("horizon " + base + " --azimuth-tolerance 0"), 2, "--azimuth-tolerance");
  const CliResult loose = run("horizon " + base + " --azimuth-tolerance 5");
  ASSERT_EQ(loose.status, 0) << loose.err;
  // The attribute lists the azimuths the sweep used, each within the tolerance of 360 k / 7.
  std::istringstream azimuths(readBack(out("o.exr")).spec.get_string_attribute("hfvis:azimuths_deg"));
  int k = 0;
  for (std::string item; std::getline(azimuths, item, ','); ++k)
    EXPECT_NEAR(std::stod(item), 360.0 * k / 7, 5.0);
  EXPECT_EQ(k, 7);
}

TEST_F(Cli, ArgumentsAreCheckedBeforeTheInputIsRead) {
  // The input does not exist, yet the bad -k is what is reported (status 2, not 1).
  const CliResult result =
      run("horizon " + shellQuoted(in("absent.exr")) + " -o " + shellQuoted(out("o.exr")) + " -k 0");
  expectFailure(result, 2, "-k");
}

// ---- failures: runtime errors (status 1) name the file ----

TEST_F(Cli, MissingInputFile) {
  expectFailure(
      run("horizon " + shellQuoted(in("absent.exr")) + " -o " + shellQuoted(out("o.exr")) + " -k 4"), 1,
      "absent.exr");
}

TEST_F(Cli, GarbageInputFile) {
  {
    std::ofstream file(in("x.exr"), std::ios::binary);
    std::mt19937 random(7);
    for (int i = 0; i < 4096; ++i) file.put(static_cast<char>(random() & 0xff));
  }
  expectFailure(run("horizon " + shellQuoted(in("x.exr")) + " -o " + shellQuoted(out("o.exr")) + " -k 4"), 1,
                "x.exr");
}

TEST_F(Cli, ZeroByteInputFile) {
  std::ofstream(in("empty.exr"), std::ios::binary).close();
  expectFailure(run("svf " + shellQuoted(in("empty.exr")) + " -o " + shellQuoted(out("o.exr")) + " -k 4"), 1,
                "empty.exr");
}

TEST_F(Cli, MissingOutputDirectory) {
  const std::string target = out("no/such/dir/o.exr");
  const CliResult result = run("svf " + shellQuoted(ramp()) + " -o " + shellQuoted(target) + " -k 4");
  expectFailure(result, 1, "no/such/dir");
}

// An output never replaces an input: the same path, the same file through another path or a
// symbolic link, the bounce's radiance input or the viewshed's observers file; refused before
// anything is read or written.
TEST_F(Cli, OutputNeverReplacesAnInput) {
  const std::string field = ramp();
  const std::string before = readText(field);
  const std::string link = in("link.exr");
  fs::create_symlink(field, link);
  const std::string via_parent = (inputs() / ".." / "inputs" / "ramp.exr").string();
  for (const std::string& output : {field, via_parent, link}) {
    SCOPED_TRACE(output);
    const CliResult result = run("svf " + shellQuoted(field) + " -o " + shellQuoted(output) + " -k 4");
    EXPECT_EQ(result.status, 2) << result.err;
    EXPECT_NE(result.err.find("outputs never replace an input"), std::string::npos) << result.err;
    EXPECT_EQ(readText(field), before);
  }
  const CliResult preview = run("svf " + shellQuoted(field) + " -o " + shellQuoted(out("svf.exr")) +
                                " --preview " + shellQuoted(field) + " -k 4");
  EXPECT_EQ(preview.status, 2) << preview.err;
  // Nor by taking away a file GDAL reads as part of a GeoTIFF output (here the input, an EXR read
  // by its content, at the output's overview name), which writing the output removes.
  fs::copy_file(field, out("s.tif.ovr"));
  const CliResult side =
      run("svf " + shellQuoted(out("s.tif.ovr")) + " -o " + shellQuoted(out("s.tif")) + " -k 4");
  EXPECT_EQ(side.status, 2) << side.err;
  EXPECT_NE(side.err.find("would take away"), std::string::npos) << side.err;
  EXPECT_EQ(readText(out("s.tif.ovr")), before);
  EXPECT_FALSE(fs::exists(out("s.tif")));
  fs::remove(out("s.tif.ovr"));
  const std::string radiance = writeField("radiance.exr", 16, 12, [](int, int) { return 1.0f; });
  const std::string radiance_before = readText(radiance);
  const std::string radiance_link = in("radiance_link.exr");
  fs::create_symlink(radiance, radiance_link);
  const CliResult bounce = run("bounce " + shellQuoted(field) + " --radiance " + shellQuoted(radiance) +
                               " -o " + shellQuoted(radiance_link) + " -k 4");
  EXPECT_EQ(bounce.status, 2) << bounce.err;
  EXPECT_NE(bounce.err.find("outputs never replace an input"), std::string::npos) << bounce.err;
  EXPECT_EQ(readText(radiance), radiance_before);
  // The viewshed's observers file (a CSV whatever its name: here one a preview's name fits), as
  // the preview or through a link to it as -o.
  const std::string observers = in("observers.png");
  { std::ofstream(observers) << "col,row\n3,4\n"; }
  const std::string observers_before = readText(observers);
  const std::string observers_link = in("observers_link.tif");
  fs::create_symlink(observers, observers_link);
  for (const std::string& outputs_part : {"-o " + shellQuoted(out("seen.exr")) + " --preview " + shellQuoted(observers),
                                          "-o " + shellQuoted(observers_link)}) {
    SCOPED_TRACE(outputs_part);
    const CliResult viewshed = run("viewshed " + shellQuoted(field) + " --observers " + shellQuoted(observers) + " " +
                                   outputs_part);
    EXPECT_EQ(viewshed.status, 2) << viewshed.err;
    EXPECT_NE(viewshed.err.find("outputs never replace an input"), std::string::npos) << viewshed.err;
    EXPECT_EQ(readText(observers), observers_before);
  }
  EXPECT_EQ(readText(field), before);
  EXPECT_TRUE(listDirectory(outputs()).empty());
}

// Two outputs that are one file not there yet, spelt two ways (relative and absolute, or through
// a dangling link to the other): refused before the computation. weakly_canonical left a relative
// path of nothing that exists relative, so "h.tif" and "$PWD/h.tif" compared unequal, and the
// distances replaced the angles with exit 0.
TEST_F(Cli, TwoOutputsThatAreOneNewFileAreRefused) {
  const std::string field = ramp();
  const std::string cd = "cd " + shellQuoted(outputs().string()) + " &&";
  for (const std::string& outputs_part : {"-o " + shellQuoted(out("h.tif")) + " --distance-out h.tif",
                                          std::string("-o h.tif --distance-out ../outputs/h.tif")}) {
    SCOPED_TRACE(outputs_part);
    const CliResult result = run("horizon " + shellQuoted(field) + " -k 4 " + outputs_part, cd);
    expectFailure(result, 2, "are the same file");
  }
  // Through a linked directory and "..": "sub/../h.exr" lies in the link's target's parent.
  fs::create_directories(root_ / "elsewhere" / "sub");
  fs::create_directory_symlink(root_ / "elsewhere" / "sub", out("sub"));
  const CliResult through_link =
      run("horizon " + shellQuoted(field) + " -k 4 -o sub/../h.exr --distance-out " +
              shellQuoted((root_ / "elsewhere" / "h.exr").string()),
          cd);
  EXPECT_EQ(through_link.status, 2) << through_link.err;
  EXPECT_NE(through_link.err.find("are the same file"), std::string::npos) << through_link.err;
  fs::remove(out("sub"));
  fs::create_symlink("h.exr", out("link.exr"));  // dangling: it names the other output
  const CliResult linked = run("horizon " + shellQuoted(field) + " -k 4 -o " + shellQuoted(out("h.exr")) +
                               " --distance-out " + shellQuoted(out("link.exr")));
  EXPECT_EQ(linked.status, 2) << linked.err;
  EXPECT_NE(linked.err.find("are the same file"), std::string::npos) << linked.err;
  EXPECT_EQ(listDirectory(outputs()), std::vector<std::string>{"link.exr"});
  fs::remove(out("link.exr"));
  // Names that differ in case alone: one file where the directory ignores case (the second
  // rename replaced the first), two where it does not; the check's probe leaves nothing behind.
  const bool ignores_case = [&] {
    std::ofstream(out("probe")) << "x";
    const bool one = fs::exists(out("PROBE"));
    fs::remove(out("probe"));
    return one;
  }();
  const CliResult cased = run("horizon " + shellQuoted(field) + " -k 4 -o " + shellQuoted(out("H.exr")) +
                              " --distance-out " + shellQuoted(out("h.exr")));
  if (ignores_case) {
    expectFailure(cased, 2, "are the same file");
    EXPECT_TRUE(listDirectory(outputs()).empty());
  } else {
    EXPECT_EQ(cased.status, 0) << cased.err;
    EXPECT_EQ(listDirectory(outputs()), (std::vector<std::string>{"H.exr", "h.exr"}));
    // One of the names there already (an input, an earlier output) is another file: the probe
    // refused both.
    const CliResult again = run("horizon " + shellQuoted(field) + " -k 4 -o " + shellQuoted(out("H.exr")) +
                                " --distance-out " + shellQuoted(out("h.exr")));
    EXPECT_EQ(again.status, 0) << again.err;
    fs::copy_file(field, out("in.exr"));
    const CliResult beside_input =
        run("svf " + shellQuoted(out("in.exr")) + " -k 4 -o " + shellQuoted(out("IN.exr")));
    EXPECT_EQ(beside_input.status, 0) << beside_input.err;
  }
}

// One directory under two paths (a bind mount): a new file's name in it under either is one
// file; the distances replaced the angles, exit 0. A bind mount needs privileges a container may
// lack: the test says so and is skipped then.
TEST_F(Cli, TwoOutputsInOneDirectoryMountedTwiceAreRefused) {
  fs::create_directories(out("a"));
  fs::create_directories(out("b"));
  const std::string a = out("a"), b = out("b");
  if (std::system(("mount --bind " + shellQuoted(a) + " " + shellQuoted(b) + " 2>/dev/null").c_str()) != 0)
    GTEST_SKIP() << "mount --bind is not permitted here";
  const CliResult result = run("horizon " + shellQuoted(ramp()) + " -k 4 -o " + shellQuoted(a + "/h.exr") +
                               " --distance-out " + shellQuoted(b + "/h.exr"));
  std::system(("umount " + shellQuoted(b)).c_str());
  EXPECT_EQ(result.status, 2) << result.err;
  EXPECT_NE(result.err.find("are the same file"), std::string::npos) << result.err;
  EXPECT_TRUE(listDirectory(out("a")).empty());
}

// A raster read beside a georeferenced field and taken pixel by pixel (an albedo, an exit radiance,
// a view mask) must lie on the field's grid: a south-up one beside a north-up field lay mirrored,
// one of another place or CRS was taken, exit 0. Without a georeference it is taken by position.
TEST_F(Cli, SideRastersOnAnotherGridAreRefused) {
  const std::string tif = in("dem.tif");
  std::vector<float> values, albedo(20 * 16, 0.5f);
  for (int i = 0; i < 20 * 16; ++i) values.push_back(static_cast<float>((i * 7) % 13));
  const std::array<double, 6> north = hfvis::testing::kUtmGeotransform;
  const std::array<double, 6> south = {north[0], north[1], 0.0, north[3] + 16 * north[5], 0.0, -north[5]};
  const std::array<double, 6> shifted = {north[0] + 30.0, north[1], 0.0, north[3], 0.0, north[5]};
  const std::string utm33 = hfvis::testing::crsWkt("EPSG:32633");
  hfvis::testing::writeGdalGeoTiff(tif, 20, 16, values, north, utm33, -9999.0);
  struct Case {
    const char* name;
    std::array<double, 6> transform;
    std::string crs;
    const char* words;  // "" = taken
  };
  for (const Case& c :
       {Case{"same", north, utm33, ""}, Case{"datum", north, hfvis::testing::crsWkt("EPSG:32633+5773"), ""},
        Case{"south", south, utm33, "lies on another grid"},
        Case{"shifted", shifted, utm33, "lies on another grid"},
        Case{"zone34", north, hfvis::testing::crsWkt("EPSG:32634"), "is in another CRS"}}) {
    SCOPED_TRACE(c.name);
    const std::string side = in(std::string(c.name) + ".tif");
    hfvis::testing::writeGdalGeoTiff(side, 20, 16, albedo, c.transform, c.crs, std::nullopt);
    for (const std::string& command :
         {"shade " + shellQuoted(tif) + " --sun 120,25 --albedo " + shellQuoted(side),
          "bounce " + shellQuoted(tif) + " -k 4 --radiance " + shellQuoted(side),
          "pvs " + shellQuoted(tif) + " --samples 1000 --view-cell 8 --view-mask " + shellQuoted(side)}) {
      const std::string output = out(std::string(c.name) + (command[0] == 'p' ? ".json" : ".tif"));
      const CliResult r = run(command + " -o " + shellQuoted(output) + " -q");
      if (*c.words == 0) {
        EXPECT_EQ(r.status, 0) << command << ": " << r.err;
        continue;
      }
      EXPECT_EQ(r.status, 1) << command;
      EXPECT_NE(r.err.find(c.words), std::string::npos) << r.err;
      EXPECT_FALSE(fs::exists(output)) << command;
    }
  }
}

// A VRT input reads the files it names: none of them may be an output (the source GeoTIFF was
// replaced, exit 0), and one that is not a regular file (a FIFO: GDAL opened a raw band's file
// with the VRT and blocked for good), or standard input, is refused before it is opened.
TEST_F(Cli, AVrtsSourcesAreInputsToo) {
  const std::string tif = in("dem.tif");
  std::vector<float> values;
  for (int i = 0; i < 20 * 16; ++i) values.push_back(static_cast<float>((i * 7) % 13));
  hfvis::testing::writeGdalGeoTiff(tif, 20, 16, values, hfvis::testing::kUtmGeotransform,
                                   hfvis::testing::crsWkt("EPSG:32633"), -9999.0);
  const std::string tif_before = readText(tif);
  const std::string vrt = in("wrap.vrt");
  {
    std::ofstream(vrt) << "<VRTDataset rasterXSize=\"20\" rasterYSize=\"16\">\n"
                          "  <VRTRasterBand dataType=\"Float32\" band=\"1\">\n"
                          "    <SimpleSource><SourceFilename relativeToVRT=\"1\">dem.tif</SourceFilename>"
                          "<SourceBand>1</SourceBand></SimpleSource>\n"
                          "  </VRTRasterBand>\n</VRTDataset>\n";
  }
  const CliResult replaced = run("svf " + shellQuoted(vrt) + " -o " + shellQuoted(tif) + " -k 4");
  EXPECT_EQ(replaced.status, 2) << replaced.err;
  EXPECT_NE(replaced.err.find("outputs never replace an input"), std::string::npos) << replaced.err;
  EXPECT_EQ(readText(tif), tif_before);
  // Nor through the names GDAL gives a file: a VRT, a GeoTIFF directory, a part of a file.
  for (const std::string& spelt : {"vrt://" + tif, "GTIFF_DIR:1:" + tif, "/vsisubfile/0_0," + tif}) {
    SCOPED_TRACE(spelt);
    {
      std::ofstream(in("spelt.vrt")) << "<VRTDataset rasterXSize=\"20\" rasterYSize=\"16\">\n"
                                        "  <VRTRasterBand dataType=\"Float32\" band=\"1\">\n"
                                        "    <SimpleSource><SourceFilename>"
                                     << spelt
                                     << "</SourceFilename><SourceBand>1</SourceBand></SimpleSource>\n"
                                        "  </VRTRasterBand>\n</VRTDataset>\n";
    }
    const CliResult spelt_over =
        run("svf " + shellQuoted(in("spelt.vrt")) + " -o " + shellQuoted(tif) + " -k 4");
    EXPECT_EQ(spelt_over.status, 2) << spelt_over.err;
    EXPECT_EQ(readText(tif), tif_before);
  }
  // (the VRT itself reads as its source does)
  const CliResult through = run("svf " + shellQuoted(vrt) + " -o " + shellQuoted(out("s.exr")) + " -k 4 -q");
  EXPECT_EQ(through.status, 0) << through.err;
  fs::remove(out("s.exr"));
  ASSERT_EQ(::mkfifo(in("heights.raw").c_str(), 0600), 0);
  const std::string raw_band =
      "<VRTDataset rasterXSize=\"8\" rasterYSize=\"8\">\n"
      "  <VRTRasterBand dataType=\"Float32\" band=\"1\" subClass=\"VRTRawRasterBand\">\n"
      "    <SourceFilename relativeToVRT=\"1\">NAME</SourceFilename>\n"
      "    <ImageOffset>0</ImageOffset><PixelOffset>4</PixelOffset><LineOffset>32</LineOffset>\n"
      "  </VRTRasterBand>\n</VRTDataset>\n";
  // (as GDAL reads a VRT: an XML prolog before it, relativeToVRT spelt with spaces)
  const std::string prolog = "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n";
  for (const std::string name : {"heights.raw", "/vsistdin/", "prolog:heights.raw", "spaced:heights.raw"}) {
    SCOPED_TRACE(name);
    std::string text = raw_band;
    if (name.rfind("prolog:", 0) == 0) text = prolog + text;
    if (name.rfind("spaced:", 0) == 0)
      text.replace(text.find("relativeToVRT=\"1\""), std::strlen("relativeToVRT=\"1\""), "relativeToVRT = \"1\"");
    text.replace(text.find("NAME"), 4, name.substr(name.find(':') + 1));
    { std::ofstream(in("raw.vrt")) << text; }
    // (`timeout`: a hang fails the test instead of stopping the suite)
    const CliResult blocked =
        run("svf " + shellQuoted(in("raw.vrt")) + " -o " + shellQuoted(out("s.exr")) + " -k 4", "timeout 60");
    expectFailure(blocked, 1, name.substr(name.find(':') + 1));
  }
  // A FIFO beside a raster, where GDAL looks for its auxiliary metadata, blocked the read too.
  ASSERT_EQ(::mkfifo((tif + ".aux.xml").c_str(), 0600), 0);
  const CliResult sidecar =
      run("svf " + shellQuoted(tif) + " -o " + shellQuoted(out("s.exr")) + " -k 4", "timeout 60");
  expectFailure(sidecar, 1, "dem.tif.aux.xml");
}

// A cell size from the file's georeference goes through --cell-size's range as the option does:
// a pixel of 1e-30 gave a visible area of 0 everywhere, exit 0. --cell-size still overrides it.
TEST_F(Cli, AFilesCellSizeOutsideWhatTheKernelsHoldIsRefused) {
  const std::string tif = in("tiny.tif");
  std::vector<float> values;
  for (int i = 0; i < 20 * 16; ++i) values.push_back(static_cast<float>((i * 7) % 13));
  for (const double pixel : {1e-30, 1e12}) {
    SCOPED_TRACE(pixel);
    hfvis::testing::writeGdalGeoTiff(tif, 20, 16, values, {500000.0, pixel, 0.0, 4100000.0, 0.0, -pixel},
                                     hfvis::testing::crsWkt("EPSG:32633"), -9999.0);
    const CliResult refused =
        run("viewcount " + shellQuoted(tif) + " -o " + shellQuoted(out("v.tif")) + " -k 8");
    expectFailure(refused, 1, "outside 1e-06 .. 1e+09");
    EXPECT_NE(refused.err.find("give one with --cell-size"), std::string::npos) << refused.err;
  }
  const CliResult given =
      run("viewcount " + shellQuoted(tif) + " -o " + shellQuoted(out("v.tif")) + " -k 8 -q --cell-size 2");
  EXPECT_EQ(given.status, 0) << given.err;
}

TEST_F(Cli, FailedRunLeavesAnExistingOutputUntouched) {
  { std::ofstream(out("o.exr")) << "previous result"; }
  const CliResult result =
      run("horizon " + shellQuoted(in("absent.exr")) + " -o " + shellQuoted(out("o.exr")));
  EXPECT_EQ(result.status, 1) << result.err;
  EXPECT_EQ(readText(out("o.exr")), "previous result");
  EXPECT_EQ(listDirectory(outputs()), std::vector<std::string>{"o.exr"});
}

TEST_F(Cli, FailedLaterWriteLeavesNoOutputs) {
  // The outputs are computed and staged first, each in a temporary file. Under a file size limit
  // that a flat field's horizon angles fit (about 130 kB) and their distances (about 8.8 MB) do
  // not, the distances' write fails: neither output may appear, and an older result at -o stays.
  // (3 MB: the OpenCL driver under PoCL writes files of about 1 MB even with its kernels cached.)
  const std::string field = writeField("flat.exr", 1024, 1024, [](int, int) { return 3.0f; });
  const std::string outputs_args = " -k 16 --distance-out ";
  // First without the limit, so that the driver has the compiled kernels in its cache.
  ASSERT_EQ(run("horizon " + shellQuoted(field) + " -o " + shellQuoted(in("h.exr")) + outputs_args +
                shellQuoted(in("d.exr")))
                .status,
            0);
  { std::ofstream(out("h.exr")) << "previous result"; }
  const CliResult result = run("horizon " + shellQuoted(field) + " -o " + shellQuoted(out("h.exr")) +
                                   outputs_args + shellQuoted(out("d.exr")),
                               "ulimit -f 5859;");  // (sh counts blocks of 512 bytes: 3 MB)
  EXPECT_EQ(result.status, 1) << result.err;
  EXPECT_NE(result.err.find(out("d.exr") + ": cannot write"), std::string::npos) << result.err;
  EXPECT_NE(result.err.find("ulimit -f"), std::string::npos) << result.err;
  EXPECT_EQ(readText(out("h.exr")), "previous result");
  EXPECT_EQ(listDirectory(outputs()), std::vector<std::string>{"h.exr"});
}

// Under a file size limit too small for the OpenCL driver's own files (PoCL compiles through
// files; LLVM then ends the process with a line of its own), the error still comes from hfvis and
// names the limit; nothing is written. (On a driver that writes no files, the output's own write
// fails the same way: 130 kB against 10 kB.)
TEST_F(Cli, AFileSizeLimitTooSmallForTheDriverIsNamed) {
  const std::string field = writeField("flat.exr", 1024, 1024, [](int, int) { return 3.0f; });
  const fs::path cache = root_ / "pocl-cache";
  fs::create_directories(cache);
  const CliResult result = run("horizon " + shellQuoted(field) + " -o " + shellQuoted(out("h.exr")) + " -k 4",
                               "ulimit -f 20; env POCL_CACHE_DIR=" + shellQuoted(cache.string()));  // (10 kB)
  expectFailure(result, 1, "ulimit -f");
}

TEST_F(Cli, AnOutputWhereNoFileCanBeCreatedIsRefusedBeforeComputing) {
  // /proc passes the superuser's permission check but takes no new files: the preview is refused
  // by the check before the computation (its words), not when it is first written, and nothing
  // else appears.
  const std::string preview = "/proc/hfvis_cli_test_preview.png";
  const CliResult result = run("horizon " + shellQuoted(ramp()) + " -o " + shellQuoted(out("h.exr")) +
                               " -k 4 --preview " + preview);
  expectFailure(result, 1, preview);
  EXPECT_NE(result.err.find(::geteuid() == 0 ? "creating a file in '/proc' fails" : "cannot write here"),
            std::string::npos)
      << result.err;
}

// ---- help and devices ----

TEST_F(Cli, HelpDocumentsTheConventions) {
  const CliResult general = run("--help");
  EXPECT_EQ(general.status, 0) << general.err;
  for (const char* text : {"phi_k = 360*k/K", "compass azimuth = 90 + phi_k", "-pi/2", "radians",
                           "1 - mean_k sin(max(0, elevation_k))", "Nodata", "float32 EXR", "Exit status"}) {
    EXPECT_NE(general.out.find(text), std::string::npos) << "hfvis --help lacks '" << text << "'";
  }
  for (const char* text : {"viewcount", "horizons", "bounce", "grazing samples are visible",
                           "ground units squared", "projected solid angle", "steradians"}) {
    EXPECT_NE(general.out.find(text), std::string::npos) << "hfvis --help lacks '" << text << "'";
  }
  for (const char* command : {"horizon", "svf", "ao", "viewcount", "horizons", "bounce", "devices"}) {
    const CliResult help = run(std::string(command) + " --help");
    EXPECT_EQ(help.status, 0) << command;
    EXPECT_NE(help.out.find(std::string("hfvis ") + command), std::string::npos) << help.out;
  }
  EXPECT_NE(run("horizon -h").out.find("h000"), std::string::npos);
}

// Issue 27: each command's name is the library's word; its earlier name stays an alias that
// keeps working. Both write the same files, byte for byte.
TEST_F(Cli, AnAliasAndItsCommandWriteTheSameFiles) {
  const std::string field = ramp();
  struct Named {
    const char* alias;
    const char* name;
    const char* args;
    const char* extension;
  };
  for (const Named& command : {Named{"svf", "sky-view-factor", "-k 4 --preview PNG", ".exr"},
                               Named{"ao", "ambient-occlusion", "-k 4", ".tif"},
                               Named{"viewcount", "intervisibility", "-k 4 --stats", ".exr"},
                               Named{"horizons", "horizon-lists", "-k 4 --at 3,3 --at 10,5", ".json"}}) {
    SCOPED_TRACE(command.name);
    std::vector<std::string> written;
    for (const char* typed : {command.alias, command.name}) {
      std::string args = command.args;
      const std::string preview = out(std::string(typed) + ".png");
      if (const std::size_t at = args.find("PNG"); at != std::string::npos)
        args.replace(at, 3, shellQuoted(preview));
      const std::string output = out(std::string(typed) + command.extension);
      const CliResult result =
          run(std::string(typed) + " " + shellQuoted(field) + " -o " + shellQuoted(output) + " " + args);
      ASSERT_EQ(result.status, 0) << result.err;
      written.push_back(readText(output));
      if (args.find(".png") != std::string::npos) written.push_back(readText(preview));
    }
    ASSERT_EQ(written.size() % 2, 0u);
    for (std::size_t i = 0; i < written.size() / 2; ++i)
      EXPECT_EQ(written[i], written[i + written.size() / 2]);
    EXPECT_FALSE(written[0].empty());
  }
  const std::string when = " --lat 45 --lon 7 --at 2026-06-21T12:00:00Z";
  const CliResult alias = run("sunpos" + when), name = run("sun-position" + when);
  EXPECT_EQ(alias.status, 0) << alias.err;
  EXPECT_NE(alias.out.find("azimuth="), std::string::npos) << alias.out;
  EXPECT_EQ(alias.out, name.out);
}

// The help lists every command by its name and its alias, each gives the same help, and a
// command's help lists the options it takes and no other.
TEST_F(Cli, HelpListsEveryCommandByItsNameAndItsAlias) {
  const CliResult general = run("--help");
  ASSERT_EQ(general.status, 0) << general.err;
  for (const auto& [name, alias] :
       std::vector<std::pair<std::string, std::string>>{{"sky-view-factor", "svf"},
                                                        {"ambient-occlusion", "ao"},
                                                        {"intervisibility", "viewcount"},
                                                        {"horizon-lists", "horizons"},
                                                        {"sun-position", "sunpos"}}) {
    SCOPED_TRACE(name);
    EXPECT_NE(general.out.find("hfvis " + name + " "), std::string::npos) << general.out;
    EXPECT_NE(general.out.find(name + " (" + alias + ")"), std::string::npos) << general.out;
    const CliResult by_name = run(name + " --help"), by_alias = run(alias + " --help");
    EXPECT_EQ(by_name.status, 0) << by_name.err;
    EXPECT_EQ(by_alias.out, by_name.out);
    EXPECT_EQ(run("help " + alias).out, by_name.out);
    EXPECT_EQ(by_name.out.rfind("hfvis " + name + " ", 0), 0u) << by_name.out;
    EXPECT_NE(by_name.out.find("'hfvis " + alias + "'"), std::string::npos) << by_name.out;
  }
  for (const char* name :
       {"horizon", "bounce", "shade", "insolation", "viewshed", "arealight", "region", "devices"})
    EXPECT_NE(general.out.find(std::string("hfvis ") + name), std::string::npos) << name;
  // horizon-lists runs on the host and writes text: no device, no preview; the parser agrees.
  const std::string lists = run("horizon-lists --help").out;
  EXPECT_EQ(lists.find("--preview"), std::string::npos) << lists;
  EXPECT_EQ(lists.find("--device"), std::string::npos) << lists;
  EXPECT_NE(lists.find("--at COL,ROW"), std::string::npos) << lists;
  expectFailure(run("horizons " + shellQuoted(ramp()) + " --at 1,1 -o " + shellQuoted(out("h.json")) +
                    " --preview " + shellQuoted(out("h.png"))),
                2, "--preview is not available with 'hfvis horizons'");
  const std::string counts = run("intervisibility --help").out;
  EXPECT_NE(counts.find("--stats"), std::string::npos) << counts;
  EXPECT_NE(counts.find("--hull-tree T"), std::string::npos) << counts;
  EXPECT_EQ(counts.find("--distance-out"), std::string::npos) << counts;
}

TEST_F(Cli, DevicesListsAndMarksTheAutomaticChoice) {
  const CliResult result = run("devices");
  EXPECT_EQ(result.status, 0) << result.err;
  EXPECT_NE(result.out.find("index"), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("\n* "), std::string::npos) << "no device marked:\n" << result.out;
}

TEST_F(Cli, NoOpenClPlatformSaysWhichPackageProvidesOne) {
  // ocl-icd reads its vendor list from OCL_ICD_VENDORS: an empty directory means no
  // platform at all, as on a machine without any OpenCL driver.
  fs::create_directories(root_ / "no_vendors");
  const std::string no_platform = "OCL_ICD_VENDORS=" + shellQuoted((root_ / "no_vendors").string()) + " ";
  for (const std::string& args : {std::string("devices"), "svf " + shellQuoted(ramp()) + " -o " +
                                                              shellQuoted(out("o.exr")) + " -k 4"}) {
    const fs::path err_file = root_ / "stderr.txt";
    const std::string command = no_platform + shellQuoted(HFVIS_CLI_PATH) + " " + args + " >/dev/null 2>" +
                                shellQuoted(err_file.string()) + " </dev/null";
    const int raw = std::system(command.c_str());
    ASSERT_TRUE(raw != -1 && WIFEXITED(raw)) << args;
    EXPECT_EQ(WEXITSTATUS(raw), 1) << args;
    const std::string err = readText(err_file);
    EXPECT_NE(err.find("no OpenCL platform"), std::string::npos) << err;
    EXPECT_NE(err.find("pocl-opencl-icd"), std::string::npos) << err;
    EXPECT_TRUE(listDirectory(outputs()).empty());
  }
}

TEST_F(Cli, OpenImageIoIsLoadedOnlyForTheImagesThatNeedIt) {
  // The program itself does not link OpenImageIO (a start loads none of its libraries); it
  // links OpenEXR, which reads and writes every EXR...
  const fs::path ldd_out = root_ / "ldd.txt";
  ASSERT_EQ(
      std::system(("ldd " + shellQuoted(HFVIS_CLI_PATH) + " >" + shellQuoted(ldd_out.string())).c_str()), 0);
  const std::string libraries = readText(ldd_out);
  EXPECT_NE(libraries.find("libgdal"), std::string::npos) << libraries;
  EXPECT_NE(libraries.find("libOpenEXR"), std::string::npos) << libraries;
  EXPECT_EQ(libraries.find("libOpenImageIO"), std::string::npos) << libraries;
  // ...so a copy of it without the module beside it still runs on GeoTIFFs and EXRs, while a PNG
  // preview says what is missing and writes nothing.
  const fs::path bare = root_ / "bare";
  fs::create_directories(bare);
  fs::copy_file(HFVIS_CLI_PATH, bare / "hfvis");
  const std::string tif = in("dem.tif");
  std::vector<float> values;
  for (int i = 0; i < 20 * 16; ++i) values.push_back(static_cast<float>((i * 7) % 13));
  hfvis::testing::writeGdalGeoTiff(tif, 20, 16, values, hfvis::testing::kUtmGeotransform,
                                   hfvis::testing::crsWkt("EPSG:32633"), -9999.0);
  const auto run_bare = [&](const std::string& args) {
    const fs::path err_file = root_ / "bare_stderr.txt";
    const int raw = std::system((shellQuoted((bare / "hfvis").string()) + " " + args + " >/dev/null 2>" +
                                 shellQuoted(err_file.string()) + " </dev/null")
                                    .c_str());
    return std::make_pair(raw != -1 && WIFEXITED(raw) ? WEXITSTATUS(raw) : -1, readText(err_file));
  };
  const auto geotiff =
      run_bare("viewshed " + shellQuoted(tif) + " -o " + shellQuoted(out("v.tif")) + " --observer 10,8 -q");
  EXPECT_EQ(geotiff.first, 0) << geotiff.second;
  EXPECT_TRUE(fs::exists(out("v.tif")));
  const auto exr = run_bare("svf " + shellQuoted(ramp()) + " -o " + shellQuoted(out("s.exr")) + " -k 4 -q");
  EXPECT_EQ(exr.first, 0) << exr.second;
  EXPECT_EQ(readBack(out("s.exr")).channels, std::vector<std::string>{"svf"});
  const auto png = run_bare("svf " + shellQuoted(ramp()) + " -o " + shellQuoted(out("p.exr")) +
                            " -k 4 -q --preview " + shellQuoted(out("p.png")));
  EXPECT_EQ(png.first, 1);
  EXPECT_NE(png.second.find("libhfvis_oiio.so"), std::string::npos) << png.second;
  EXPECT_FALSE(fs::exists(out("p.exr")));
  EXPECT_FALSE(fs::exists(out("p.png")));
}

// ---- successful runs ----

// --max-error chooses K and --error-out writes the estimate: the same K, values and estimate as the
// library's call (hfvis:directions the K run, not -k's default), in both files' attributes; a
// refused E (beyond 4096 directions) writes neither file. With --error-tile the estimate file also
// holds each pixel's K (channel directions), and hfvis:directions_range the least and most;
// hfvis:richardson_divisor the tiles' least..most divisor and hfvis:runs each run's K, as the
// library's result has them; at nodata every channel is NaN (the directions too).
TEST_F(Cli, MaxErrorWritesTheChosenKAndTheEstimate) {
  const std::string field = writeField("bumps.exr", 40, 33, [](int col, int row) {
    if (row == 5 && col < 3) return std::numeric_limits<float>::quiet_NaN();
    return 3.0f * std::sin(0.7f * col) * std::cos(0.5f * row) + ((col / 5 + row / 4) % 3 == 0 ? 4.0f : 0.0f);
  });
  const CliResult r = run("svf " + shellQuoted(field) + " -o " + shellQuoted(out("s.exr")) +
                          " --max-error 0.02 --error-tile 16 --error-out " + shellQuoted(out("e.exr")));
  ASSERT_EQ(r.status, 0) << r.err;
  hfvis::HorizonOptions options;
  options.max_error = 0.02;
  options.error_tile = 16;
  const hfvis::SkyViewFactorResult lib =
      hfvis::computeSkyViewFactor(hfvis::testing::testContext(), hfvis::readHeightField(field), options);
  ASSERT_NE(lib.directions, 64);  // (else the attribute could not tell -k's default from the K run)
  EXPECT_NE(r.out.find(std::to_string(lib.directions) + " directions"), std::string::npos) << r.out;
  const ReadBack svf = readBack(out("s.exr")), estimate = readBack(out("e.exr"));
  // (OpenEXR keeps its channels sorted by name)
  std::vector<std::string> channels = estimate.channels;
  std::sort(channels.begin(), channels.end());
  ASSERT_EQ(channels, (std::vector<std::string>{"directions", "error"}));
  const std::size_t error_channel = estimate.channels[0] == "error" ? 0 : 1;
  ASSERT_EQ(svf.pixels.size(), lib.values.size());
  ASSERT_EQ(estimate.pixels.size(), 2 * lib.error_estimate.size());
  hfvis::HorizonOutputs svf_only;
  svf_only.sky_view_factor = true;
  const hfvis::HorizonResult runs =
      hfvis::computeHorizons(hfvis::testing::testContext(), hfvis::readHeightField(field), options, svf_only);
  const std::vector<int>& taken = runs.pixel_directions;
  ASSERT_EQ(taken.size(), lib.values.size());
  int least = 1 << 30, most = 0, nodata = 0;
  for (std::size_t p = 0; p < lib.values.size(); ++p) {
    if (p / 40 == 5 && p % 40 < 3) {
      ++nodata;
      ASSERT_TRUE(std::isnan(svf.pixels[p]) && std::isnan(estimate.pixels[2 * p + error_channel]) &&
                  std::isnan(estimate.pixels[2 * p + 1 - error_channel]))
          << p;
      continue;
    }
    ASSERT_EQ(svf.pixels[p], lib.values[p]) << p;
    ASSERT_EQ(estimate.pixels[2 * p + error_channel], lib.error_estimate[p]) << p;
    ASSERT_EQ(estimate.pixels[2 * p + 1 - error_channel], static_cast<float>(taken[p])) << p;
    least = std::min(least, taken[p]), most = std::max(most, taken[p]);
  }
  EXPECT_EQ(nodata, 3);
  for (const ReadBack* image : {&svf, &estimate}) {
    EXPECT_EQ(image->spec.get_string_attribute("hfvis:directions"), std::to_string(lib.directions));
    EXPECT_EQ(image->spec.get_string_attribute("hfvis:directions_range"),
              std::to_string(least) + ".." + std::to_string(most));
    EXPECT_EQ(image->spec.get_string_attribute("hfvis:max_error"), "0.02");
    EXPECT_NEAR(std::stod(image->spec.get_string_attribute("hfvis:estimated_error")), lib.estimated_error,
                1e-9);
    // The divisor the raw estimate was divided by (per tile: least..most), each 1 .. 2^1.1 - 1,
    // and each run's K.
    const std::string divisor = image->spec.get_string_attribute("hfvis:richardson_divisor");
    const std::size_t dots = divisor.find("..");
    if (runs.richardson_divisor_least == runs.richardson_divisor_most) {
      ASSERT_EQ(dots, std::string::npos) << divisor;
    }
    ASSERT_FALSE(divisor.empty());
    EXPECT_NEAR(std::stod(divisor.substr(0, dots)), runs.richardson_divisor_least, 1e-9) << divisor;
    EXPECT_NEAR(std::stod(divisor.substr(dots == std::string::npos ? 0 : dots + 2)), runs.richardson_divisor_most,
                1e-9)
        << divisor;
    std::string list;
    for (int K : runs.runs) list += (list.empty() ? "" : ",") + std::to_string(K);
    EXPECT_EQ(image->spec.get_string_attribute("hfvis:runs"), list);
  }
  ASSERT_GE(runs.runs.size(), 2u);  // (tiles refined)
  EXPECT_EQ(runs.runs.front(), 16);
  EXPECT_GE(runs.richardson_divisor_least, 1.0);
  EXPECT_LE(runs.richardson_divisor_least, runs.richardson_divisor_most);
  EXPECT_LE(runs.richardson_divisor_most, std::pow(2.0, 1.1) - 1.0 + 1e-12);
  EXPECT_LE(lib.estimated_error, 0.02);
  fs::remove(out("s.exr"));
  fs::remove(out("e.exr"));
  expectFailure(run("svf " + shellQuoted(field) + " -o " + shellQuoted(out("s.exr")) +
                    " --max-error 1e-7 --error-out " + shellQuoted(out("e.exr"))),
                1, "directions");
  // A tile of fewer than 16 pixels a side stops on a few pixels' estimates and misses E: refused.
  for (const char* tile : {"1", "8", "15"})
    expectFailure(run("svf " + shellQuoted(field) + " -o " + shellQuoted(out("s.exr")) + " --max-error 0.02" +
                      " --error-tile " + tile + " --error-out " + shellQuoted(out("e.exr"))),
                  2, "at least 16");
}

// --error-out with -k (no --max-error): the estimate at the K given, as the library's run asking for
// it (it once wrote nothing: the CLI never asked the library for the estimate).
TEST_F(Cli, ErrorOutWithAFixedKWritesTheEstimate) {
  const std::string field = writeField("bumps.exr", 40, 33, [](int col, int row) {
    return 3.0f * std::sin(0.7f * col) * std::cos(0.5f * row) + ((col / 5 + row / 4) % 3 == 0 ? 4.0f : 0.0f);
  });
  for (const char* command : {"svf", "ao"}) {
    const CliResult r = run(std::string(command) + " " + shellQuoted(field) + " -o " +
                            shellQuoted(out("s.exr")) + " -k 8 --error-out " + shellQuoted(out("e.exr")));
    ASSERT_EQ(r.status, 0) << r.err;
    hfvis::HorizonOptions options;
    options.directions = 8;
    hfvis::HorizonOutputs wanted;
    (command == std::string("svf") ? wanted.sky_view_factor : wanted.ambient_occlusion) = true;
    wanted.error_estimate = true;
    const hfvis::HorizonResult lib =
        hfvis::computeHorizons(hfvis::testing::testContext(), hfvis::readHeightField(field), options, wanted);
    const std::vector<float>& values = wanted.sky_view_factor ? lib.sky_view_factor : lib.ambient_occlusion;
    const ReadBack quantity = readBack(out("s.exr")), estimate = readBack(out("e.exr"));
    ASSERT_EQ(estimate.channels, (std::vector<std::string>{"error"}));
    ASSERT_EQ(quantity.pixels.size(), values.size());
    ASSERT_EQ(estimate.pixels.size(), lib.error_estimate.size());
    for (std::size_t p = 0; p < values.size(); ++p) {
      ASSERT_EQ(quantity.pixels[p], values[p]) << command << " " << p;
      ASSERT_EQ(estimate.pixels[p], lib.error_estimate[p]) << command << " " << p;
    }
    EXPECT_EQ(estimate.spec.get_string_attribute("hfvis:directions"), "8");
    // (no runs chose K: no divisor, no run list)
    EXPECT_EQ(estimate.spec.get_string_attribute("hfvis:richardson_divisor"), "");
    EXPECT_EQ(estimate.spec.get_string_attribute("hfvis:runs"), "");
    fs::remove(out("s.exr"));
    fs::remove(out("e.exr"));
  }
}

// viewcount --max-error chooses K and --error-out writes the count's relative estimate: the same
// K, count and estimate as the library's call, the attributes in both files; with -k, the estimate
// at the K given; a refused E (beyond 4096 directions) writes neither file.
TEST_F(Cli, ViewcountMaxErrorWritesTheChosenKAndTheEstimate) {
  const std::string field = writeField("bumps.exr", 40, 33, [](int col, int row) {
    return 3.0f * std::sin(0.7f * col) * std::cos(0.5f * row) + ((col / 5 + row / 4) % 3 == 0 ? 4.0f : 0.0f);
  });
  const CliResult r = run("viewcount " + shellQuoted(field) + " -o " + shellQuoted(out("v.exr")) +
                          " --max-error 0.3 --error-out " + shellQuoted(out("e.exr")));
  ASSERT_EQ(r.status, 0) << r.err;
  hfvis::IntervisibilityOptions options;
  options.max_error = 0.3;
  hfvis::IntervisibilityOutputs wanted;
  wanted.visible_count = wanted.visible_area = true;
  const hfvis::IntervisibilityResult lib = hfvis::computeIntervisibility(
      hfvis::testing::testContext(), hfvis::readHeightField(field), options, wanted);
  ASSERT_NE(lib.directions, 64);  // (else the attribute could not tell -k's default from the K run)
  EXPECT_LE(lib.estimated_error, 0.3);
  EXPECT_NE(r.out.find(std::to_string(lib.directions) + " directions"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("for --max-error 0.3"), std::string::npos) << r.out;
  const ReadBack counts = readBack(out("v.exr")), estimate = readBack(out("e.exr"));
  ASSERT_EQ(estimate.channels, (std::vector<std::string>{"error"}));
  ASSERT_EQ(counts.channels, (std::vector<std::string>{"count", "visible_area"}));
  ASSERT_EQ(estimate.pixels.size(), lib.error_estimate.size());
  for (std::size_t p = 0; p < lib.visible_count.size(); ++p) {
    ASSERT_EQ(counts.pixels[2 * p], lib.visible_count[p]) << p;
    ASSERT_EQ(counts.pixels[2 * p + 1], lib.visible_area[p]) << p;
    ASSERT_EQ(estimate.pixels[p], lib.error_estimate[p]) << p;
  }
  for (const ReadBack* image : {&counts, &estimate}) {
    EXPECT_EQ(image->spec.get_string_attribute("hfvis:directions"), std::to_string(lib.directions));
    EXPECT_EQ(image->spec.get_string_attribute("hfvis:max_error"), "0.3");
    EXPECT_NEAR(std::stod(image->spec.get_string_attribute("hfvis:estimated_error")), lib.estimated_error,
                1e-9);
  }
  // --error-out with -k: the estimate at the K given.
  fs::remove(out("v.exr"));
  fs::remove(out("e.exr"));
  ASSERT_EQ(run("viewcount " + shellQuoted(field) + " -o " + shellQuoted(out("v.exr")) +
                " -k 8 --error-out " + shellQuoted(out("e.exr")))
                .status,
            0);
  options.max_error = 0.0;
  options.directions = 8;
  wanted.error_estimate = true;
  const hfvis::IntervisibilityResult fixed = hfvis::computeIntervisibility(
      hfvis::testing::testContext(), hfvis::readHeightField(field), options, wanted);
  const ReadBack fixed_estimate = readBack(out("e.exr"));
  ASSERT_EQ(fixed_estimate.pixels.size(), fixed.error_estimate.size());
  for (std::size_t p = 0; p < fixed.error_estimate.size(); ++p)
    ASSERT_EQ(fixed_estimate.pixels[p], fixed.error_estimate[p]) << p;
  EXPECT_EQ(fixed_estimate.spec.get_string_attribute("hfvis:directions"), "8");
  fs::remove(out("v.exr"));
  fs::remove(out("e.exr"));
  expectFailure(run("viewcount " + shellQuoted(field) + " -o " + shellQuoted(out("v.exr")) +
                    " --max-error 1e-7 --error-out " + shellQuoted(out("e.exr"))),
                1, "directions");
}

// shade --env --max-error chooses K and --error-out writes the estimate (|at K - at K / 2| over the
// mean irradiance): the same K, irradiance and estimate as the library's call, the attributes in
// both files; a refused E writes neither file.
TEST_F(Cli, ShadeEnvironmentMaxErrorWritesTheChosenKAndTheEstimate) {
  const std::string field = writeField("bumps.exr", 40, 33, [](int col, int row) {
    return 3.0f * std::sin(0.7f * col) * std::cos(0.5f * row) + ((col / 5 + row / 4) % 3 == 0 ? 4.0f : 0.0f);
  });
  // A sky without a sun (a sun's shadow makes the difference jump with K: docs/COMMAND_LINE.md):
  // brighter toward the zenith and toward one azimuth, 32 x 16.
  hfvis::ImageChannels map;
  map.width = 32;
  map.height = 16;
  map.names = {"Y"};
  map.planes.emplace_back();
  for (int row = 0; row < map.height; ++row)
    for (int col = 0; col < map.width; ++col)
      map.planes[0].push_back(row < 8 ? 2.0f - row / 8.0f + 0.5f * std::cos(col * 2.0f * float(M_PI) / 32)
                                      : 0.2f);
  const std::string sky = in("sky.exr");
  hfvis::writeImage(sky, map);
  const CliResult r =
      run("shade " + shellQuoted(field) + " --env " + shellQuoted(sky) + " -o " + shellQuoted(out("s.exr")) +
          " --max-error 0.1 --error-out " + shellQuoted(out("e.exr")));
  ASSERT_EQ(r.status, 0) << r.err;
  hfvis::HorizonOptions options;
  options.max_error = 0.1;
  const hfvis::EnvironmentLightResult lib = hfvis::computeEnvironmentLight(
      hfvis::testing::testContext(), hfvis::readHeightField(field), hfvis::readEnvironmentMap(sky), options);
  ASSERT_NE(lib.directions, 64);  // (else the attribute could not tell -k's default from the K run)
  EXPECT_LE(lib.estimated_error, 0.1);
  EXPECT_NE(r.out.find(std::to_string(lib.directions) + " directions"), std::string::npos) << r.out;
  const ReadBack lit = readBack(out("s.exr")), estimate = readBack(out("e.exr"));
  ASSERT_EQ(estimate.channels, (std::vector<std::string>{"error"}));
  const std::size_t pixels = lib.error_estimate.size(), channels = lit.channels.size();
  ASSERT_EQ(lib.irradiance.size(), pixels * channels);
  for (std::size_t c = 0; c < channels; ++c) {
    const auto at = std::find(lib.names.begin(), lib.names.end(), lit.channels[c]) - lib.names.begin();
    for (std::size_t p = 0; p < pixels; ++p)
      ASSERT_EQ(lit.pixels[p * channels + c], lib.irradiance[at * pixels + p]);
  }
  for (std::size_t p = 0; p < pixels; ++p) ASSERT_EQ(estimate.pixels[p], lib.error_estimate[p]) << p;
  for (const ReadBack* image : {&lit, &estimate}) {
    EXPECT_EQ(image->spec.get_string_attribute("hfvis:directions"), std::to_string(lib.directions));
    EXPECT_EQ(image->spec.get_string_attribute("hfvis:max_error"), "0.1");
    EXPECT_NEAR(std::stod(image->spec.get_string_attribute("hfvis:estimated_error")), lib.estimated_error,
                1e-9);
  }
  fs::remove(out("s.exr"));
  fs::remove(out("e.exr"));
  expectFailure(run("shade " + shellQuoted(field) + " --env " + shellQuoted(sky) + " -o " +
                    shellQuoted(out("s.exr")) + " --max-error 1e-9 --error-out " + shellQuoted(out("e.exr"))),
                1, "directions");
}

// horizon --max-error E (degrees) chooses K and --error-out writes the estimate (degrees): the
// same K, planes and estimate as the library's call with E in radians, K channels of the K chosen,
// hfvis:directions that K and hfvis:estimated_error / hfvis:max_error in degrees, and the summary
// line saying both.
TEST_F(Cli, HorizonMaxErrorWritesTheChosenKAndTheEstimate) {
  const std::string field = writeField("bumps.exr", 40, 33, [](int col, int row) {
    return 3.0f * std::sin(0.7f * col) * std::cos(0.5f * row) + ((col / 5 + row / 4) % 3 == 0 ? 4.0f : 0.0f);
  });
  const CliResult r = run("horizon " + shellQuoted(field) + " -o " + shellQuoted(out("h.exr")) +
                          " --max-error 2 --error-out " + shellQuoted(out("e.exr")));
  ASSERT_EQ(r.status, 0) << r.err;
  hfvis::HorizonOptions options;
  options.max_error = 2.0 * kPi / 180.0;
  hfvis::HorizonOutputs wanted;
  wanted.horizon_angles = true;
  const hfvis::HorizonResult lib =
      hfvis::computeHorizons(hfvis::testing::testContext(), hfvis::readHeightField(field), options, wanted);
  ASSERT_NE(lib.directions, 64);  // (else the attribute could not tell -k's default from the K run)
  ASSERT_LE(lib.estimated_error, options.max_error);
  EXPECT_NE(r.out.find(std::to_string(lib.directions) + " directions"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("estimated mean error"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("for --max-error 2"), std::string::npos) << r.out;
  const ReadBack horizons = readBack(out("h.exr")), estimate = readBack(out("e.exr"));
  EXPECT_EQ(horizons.channels, hfvis::cli::directionChannelNames("h", lib.directions));
  ASSERT_EQ(estimate.channels, std::vector<std::string>{"error"});
  const std::size_t pixels = lib.error_estimate.size(), K = lib.directions;
  ASSERT_EQ(horizons.pixels.size(), pixels * K);
  ASSERT_EQ(estimate.pixels.size(), pixels);
  for (std::size_t p = 0; p < pixels; ++p) {
    for (std::size_t k = 0; k < K; ++k) ASSERT_EQ(horizons.pixels[p * K + k], lib.angles[k * pixels + p]) << p;
    ASSERT_NEAR(estimate.pixels[p], lib.error_estimate[p] * 180.0 / kPi, 1e-5) << p;
  }
  for (const ReadBack* image : {&horizons, &estimate}) {
    EXPECT_EQ(image->spec.get_string_attribute("hfvis:directions"), std::to_string(lib.directions));
    EXPECT_EQ(image->spec.get_string_attribute("hfvis:max_error"), "2");
    EXPECT_NEAR(std::stod(image->spec.get_string_attribute("hfvis:estimated_error")),
                lib.estimated_error * 180.0 / kPi, 1e-6);
    EXPECT_FALSE(image->spec.get_string_attribute("hfvis:samples_per_unit").empty());
  }
  // --error-out with -k: the estimate at the K given.
  fs::remove(out("h.exr"));
  fs::remove(out("e.exr"));
  ASSERT_EQ(run("horizon " + shellQuoted(field) + " -o " + shellQuoted(out("h.exr")) + " -k 12 --error-out " +
                shellQuoted(out("e.exr")))
                .status,
            0);
  hfvis::HorizonOptions fixed;
  fixed.directions = 12;
  wanted.error_estimate = true;
  const hfvis::HorizonResult at12 =
      hfvis::computeHorizons(hfvis::testing::testContext(), hfvis::readHeightField(field), fixed, wanted);
  EXPECT_NEAR(std::stod(readBack(out("e.exr")).spec.get_string_attribute("hfvis:estimated_error")),
              at12.estimated_error * 180.0 / kPi, 1e-6);
  EXPECT_EQ(readBack(out("h.exr")).spec.get_string_attribute("hfvis:directions"), "12");
}

// Bad requests: E not positive, not finite, 90 degrees or more, beyond 4096 directions, with -k,
// --error-tile, --error-out under 5 directions: a clear error and nothing written.
TEST_F(Cli, HorizonMaxErrorBadRequestsWriteNothing) {
  const std::string h = "horizon " + shellQuoted(ramp()) + " -o " + shellQuoted(out("h.exr")) + " --error-out " +
                        shellQuoted(out("e.exr"));
  for (const char* E : {"0", "-1", "nan", "inf", "90", "1e9"}) expectFailure(run(h + " --max-error " + E), 2, "--max-error");
  expectFailure(run(h + " --max-error 1 -k 32"), 2, "-k");
  expectFailure(run(h + " --max-error 1 --error-tile 16"), 2, "--error-tile");
  expectFailure(run(h + " -k 4"), 2, "-k 5");
  expectFailure(run(h + " --max-error 1e-7"), 1, "4096");
}

TEST_F(Cli, HorizonWritesOneChannelPerDirection) {
  const CliResult result = run("horizon " + shellQuoted(ramp()) + " -o " + shellQuoted(out("h.exr")) +
                               " -k 8" + " --distance-out " + shellQuoted(out("d.exr")));
  ASSERT_EQ(result.status, 0) << result.err;
  EXPECT_NE(result.out.find("wrote "), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("8 directions"), std::string::npos) << result.out;

  const ReadBack horizons = readBack(out("h.exr"));
  ASSERT_EQ(horizons.width, 16);
  ASSERT_EQ(horizons.height, 12);
  EXPECT_EQ(horizons.channels, hfvis::cli::directionChannelNames("h", 8));
  EXPECT_EQ(horizons.channels.front(), "h000");
  EXPECT_EQ(horizons.channels.back(), "h007");
  EXPECT_EQ(horizons.spec.format, OIIO::TypeDesc::FLOAT);
  for (const float value : horizons.pixels) {
    ASSERT_TRUE(std::isfinite(value));
    ASSERT_GE(value, -kHalfPi - 1e-6);
    ASSERT_LE(value, kHalfPi + 1e-6);
  }
  // The ramp rises toward +column: direction 0 (phi = 0) sees it rise from an inner pixel,
  // direction 4 (phi = 180 deg) looks downhill.
  EXPECT_GT(horizons.at(4, 6, 0), 0.0f);
  EXPECT_LT(horizons.at(8, 6, 4), 0.0f + 1e-6f);
  EXPECT_EQ(horizons.spec.get_string_attribute("hfvis:command"), "horizon");
  EXPECT_EQ(horizons.spec.get_string_attribute("hfvis:directions"), "8");
  EXPECT_EQ(horizons.spec.get_string_attribute("hfvis:method"), "sweep");
  // K = 8 lands on the axes and diagonals exactly.
  EXPECT_EQ(horizons.spec.get_string_attribute("hfvis:azimuths_deg"), "0,45,90,135,180,225,270,315");

  const ReadBack distances = readBack(out("d.exr"));
  EXPECT_EQ(distances.channels, hfvis::cli::directionChannelNames("d", 8));
  for (const float value : distances.pixels) {
    ASSERT_TRUE(std::isfinite(value));
    ASSERT_GE(value, 0.0f);
  }
  EXPECT_EQ(listDirectory(outputs()).size(), 2u);  // no temporary files left
}

TEST_F(Cli, SkyViewFactorOfAFlatPlaneIsOne) {
  for (const char* method : {"sweep", "naive"}) {
    fs::remove(out("svf.exr"));
    const CliResult result =
        run("svf " + shellQuoted(flat()) + " -o " + shellQuoted(out("svf.exr")) + " -k 8 --method " + method);
    ASSERT_EQ(result.status, 0) << method << ": " << result.err;
    EXPECT_NE(result.out.find("mean svf 1.0000"), std::string::npos) << result.out;
    const ReadBack svf = readBack(out("svf.exr"));
    EXPECT_EQ(svf.channels, std::vector<std::string>{"svf"});
    for (const float value : svf.pixels) ASSERT_NEAR(value, 1.0f, 1e-5f) << method;
  }
}

TEST_F(Cli, AmbientOcclusionOfAFlatPlaneIsOne) {
  const CliResult result =
      run("ao " + shellQuoted(flat()) + " -o " + shellQuoted(out("ao.exr")) + " -k 8 --quiet");
  ASSERT_EQ(result.status, 0) << result.err;
  EXPECT_TRUE(result.out.empty()) << "--quiet printed: " << result.out;
  const ReadBack ao = readBack(out("ao.exr"));
  EXPECT_EQ(ao.channels, std::vector<std::string>{"ao"});
  for (const float value : ao.pixels) ASSERT_NEAR(value, 1.0f, 1e-4f);
}

TEST_F(Cli, NaiveMethodAndOptionsRun) {
  const CliResult result =
      run("horizon " + shellQuoted(ramp()) + " -o " + shellQuoted(out("h.exr")) +
          " -k 4 --method naive --azimuth-offset 45 --samples-per-unit 2 --cell-size 2,1" +
          " --z-scale 0.5 --channel Y --memory-budget 64");
  ASSERT_EQ(result.status, 0) << result.err;
  const ReadBack horizons = readBack(out("h.exr"));
  EXPECT_EQ(horizons.channels, hfvis::cli::directionChannelNames("h", 4));
  EXPECT_EQ(horizons.spec.get_string_attribute("hfvis:method"), "naive");
  EXPECT_EQ(horizons.spec.get_string_attribute("hfvis:azimuth_offset_deg"), "45");
  EXPECT_EQ(horizons.spec.get_string_attribute("hfvis:cell_size_x"), "2");
  EXPECT_EQ(horizons.spec.get_string_attribute("hfvis:cell_size_y"), "1");
}

// ---- options change the results as the conventions (docs/CONVENTIONS.md) say ----

// On the ramp h = 0.5 col + 0.25 row (pixel units, cell size 1) an inner pixel's horizon
// toward +columns (h000) is the ramp's slope along columns, toward +rows (h001) along rows:
// atan(rise per ground unit). --z-scale multiplies the heights, --cell-size the ground.
TEST_F(Cli, ZScaleAndCellSizeSetTheSlopes) {
  const std::string ramp_field = ramp();
  auto horizon = [&](const std::string& options) {
    fs::remove(out("h.exr"));
    const CliResult result = run("horizon " + shellQuoted(ramp_field) + " -o " + shellQuoted(out("h.exr")) +
                                 " -k 4 --quiet " + options);
    EXPECT_EQ(result.status, 0) << options << ": " << result.err;
    const ReadBack h = readBack(out("h.exr"));
    return std::make_pair(h.at(4, 6, 0), h.at(4, 6, 1));
  };
  const auto plain = horizon("");
  EXPECT_NEAR(plain.first, std::atan(0.5), 1e-5);
  EXPECT_NEAR(plain.second, std::atan(0.25), 1e-5);
  const auto taller = horizon("--z-scale 2");
  EXPECT_NEAR(taller.first, std::atan(1.0), 1e-5);
  EXPECT_NEAR(taller.second, std::atan(0.5), 1e-5);
  const auto wider = horizon("--cell-size 2,4");
  EXPECT_NEAR(wider.first, std::atan(0.25), 1e-5);
  EXPECT_NEAR(wider.second, std::atan(0.0625), 1e-5);
  const auto square = horizon("--cell-size 2");  // one value: both axes
  EXPECT_NEAR(square.first, std::atan(0.25), 1e-5);
  EXPECT_NEAR(square.second, std::atan(0.125), 1e-5);
}

// --samples-per-unit S: the samples at S = 2 include those at S = 1 (the naive march's unit
// steps; the sweep's grid crossings), so no horizon is lower, and on a bumpy field some
// are higher (a peak between the unit samples).
TEST_F(Cli, DenserSamplesNeverLowerAHorizon) {
  const std::string bumps = writeField("bumps.exr", 24, 20, [](int col, int row) {
    return static_cast<float>(3.0 * std::sin(1.7 * col) * std::cos(1.3 * row) + 0.2 * col);
  });
  for (const char* method : {"sweep", "naive"}) {
    SCOPED_TRACE(method);
    std::vector<ReadBack> results;
    for (const char* spu : {"1", "2"}) {
      fs::remove(out("h.exr"));
      const CliResult result = run("horizon " + shellQuoted(bumps) + " -o " + shellQuoted(out("h.exr")) +
                                   " -k 8 --quiet --method " + method + " --samples-per-unit " + spu);
      ASSERT_EQ(result.status, 0) << result.err;
      results.push_back(readBack(out("h.exr")));
    }
    ASSERT_EQ(results[0].pixels.size(), results[1].pixels.size());
    int higher = 0;
    for (std::size_t i = 0; i < results[0].pixels.size(); ++i) {
      ASSERT_GE(results[1].pixels[i], results[0].pixels[i] - 1e-6f) << "entry " << i;
      higher += results[1].pixels[i] > results[0].pixels[i] + 1e-4f;
    }
    EXPECT_GT(higher, 0);
  }
}

// --curvature lowers far points by the Earth's drop: a wall 30 units high 500 m of ground
// away appears lower than without it (by atan(drop / d), drop = d^2 (1 - 1/7) / (2 R));
// --refraction 1 bends rays along the Earth, no drop at all; the options are refused where
// they are not implemented (the bounce) and out of range.
TEST_F(Cli, CurvatureLowersFarTerrainByTheEarthsDrop) {
  const std::string wall = writeField("wall.exr", 40, 5, [](int x, int) { return x >= 30 ? 30.0f : 0.0f; });
  auto angle = [&](const std::string& options) {
    fs::remove(out("h.exr"));
    const CliResult result = run("horizon " + shellQuoted(wall) + " -o " + shellQuoted(out("h.exr")) +
                                 " -k 4 --cell-size 50 " + options);
    EXPECT_EQ(result.status, 0) << options << ": " << result.err;
    const ReadBack h = readBack(out("h.exr"));
    EXPECT_EQ(h.spec.get_string_attribute("hfvis:curvature").empty(), options.find("--") == std::string::npos);
    return h.at(20, 2, 0);  // toward +x, 10 pixels = 500 m from the wall
  };
  const double d = 500.0, drop = d * d * (1.0 - 1.0 / 7.0) / (2.0 * 6370997.0);
  EXPECT_NEAR(angle(""), std::atan(30.0 / d), 1e-6);
  EXPECT_NEAR(angle("--curvature"), std::atan((30.0 - drop) / d), 1e-6);
  EXPECT_NEAR(angle("--refraction 1"), std::atan(30.0 / d), 1e-6);
  fs::remove(out("h.exr"));
  expectFailure(run("bounce " + shellQuoted(wall) + " --radiance " + shellQuoted(wall) + " -o " +
                    shellQuoted(out("b.exr")) + " --curvature"),
                2, "--curvature");
  expectFailure(run("svf " + shellQuoted(wall) + " -o " + shellQuoted(out("s.exr")) + " --refraction 2"), 2,
                "--refraction");
  // A CRS in US survey feet: its cells are no metres, and the drop would be 3.28 times too small
  // (a probe's find: exit 0); refused unless --cell-size gives metres. A CRS in metres runs.
  const std::string feet = in("feet.tif"), metres = in("metres.tif");
  hfvis::testing::writeGdalGeoTiff(feet, 20, 16, std::vector<float>(20 * 16, 1.0f),
                                   hfvis::testing::kUtmGeotransform, hfvis::testing::crsWkt("EPSG:2230"),
                                   std::nullopt);
  hfvis::testing::writeGdalGeoTiff(metres, 20, 16, std::vector<float>(20 * 16, 1.0f),
                                   hfvis::testing::kUtmGeotransform, hfvis::testing::crsWkt("EPSG:32633"),
                                   std::nullopt);
  expectFailure(run("svf " + shellQuoted(feet) + " -o " + shellQuoted(out("s.exr")) + " -k 4 --curvature"), 2,
                "US survey foot");
  EXPECT_EQ(run("svf " + shellQuoted(feet) + " -o " + shellQuoted(out("s.exr")) + " -k 4 -q").status, 0);
  fs::remove(out("s.exr"));
  EXPECT_EQ(run("svf " + shellQuoted(feet) + " -o " + shellQuoted(out("s.exr")) +
                " -k 4 -q --curvature --cell-size 9.144")
                .status,
            0);
  fs::remove(out("s.exr"));
  EXPECT_EQ(
      run("svf " + shellQuoted(metres) + " -o " + shellQuoted(out("s.exr")) + " -k 4 -q --curvature").status,
      0);
}

// --max-distance D: a wall 30 high 500 m of ground away is the horizon with D = 600 m and
// gone with D = 400 m (flat ground: 0), in horizon, svf and ao (whose values rise to those of
// flat ground); the attribute records D; horizon lists and the bounce refuse it.
TEST_F(Cli, MaxDistanceLimitsTheTerrainThatCounts) {
  const std::string wall = writeField("wall.exr", 40, 5, [](int x, int) { return x >= 30 ? 30.0f : 0.0f; });
  auto value = [&](const std::string& command, const std::string& options) {
    fs::remove(out("h.exr"));
    const CliResult result = run(command + " " + shellQuoted(wall) + " -o " + shellQuoted(out("h.exr")) +
                                 " -k 4 --cell-size 50 " + options);
    EXPECT_EQ(result.status, 0) << options << ": " << result.err;
    const ReadBack h = readBack(out("h.exr"));
    EXPECT_EQ(h.spec.get_string_attribute("hfvis:max_distance").empty(),
              options.find("--max-distance") == std::string::npos)
        << options;
    return h.at(20, 2, 0);  // horizon: toward +x, 10 pixels = 500 m from the wall
  };
  for (const char* method : {"sweep", "naive"}) {
    SCOPED_TRACE(method);
    const std::string m = std::string(" --method ") + method;
    EXPECT_NEAR(value("horizon", m), std::atan(30.0 / 500.0), 1e-6);
    EXPECT_NEAR(value("horizon", m + " --max-distance 600"), std::atan(30.0 / 500.0), 1e-6);
    EXPECT_NEAR(value("horizon", m + " --max-distance 400"), 0.0, 1e-6);
    EXPECT_LT(value("svf", m), 1.0f);
    EXPECT_NEAR(value("svf", m + " --max-distance 400"), 1.0, 1e-6);
    EXPECT_LT(value("ao", m), 1.0f);
    EXPECT_NEAR(value("ao", m + " --max-distance 400"), 1.0, 1e-5);
  }
  fs::remove(out("h.exr"));
  expectFailure(run("horizons " + shellQuoted(wall) + " --at 1,1 -o " + shellQuoted(out("h.json")) +
                    " --max-distance 10"),
                2, "--max-distance");
  expectFailure(run("bounce " + shellQuoted(wall) + " --radiance " + shellQuoted(wall) + " -o " +
                    shellQuoted(out("b.exr")) + " --max-distance 10"),
                2, "--max-distance");
}

// viewcount on a flat plane, K = 4 (the axes): every sample is visible, and a pixel's
// rays along its row and column hold (W - 1) S + (H - 1) S samples at S samples per pixel
// length; the line samples swept (--stats) grow S-fold.
TEST_F(Cli, SamplesPerUnitInViewcount) {
  const std::string plane = flat();  // 16 x 12
  auto viewcount = [&](const std::string& options, std::string* stats) {
    fs::remove(out("v.exr"));
    const CliResult result = run("viewcount " + shellQuoted(plane) + " -o " + shellQuoted(out("v.exr")) +
                                 " -k 4 --stats " + options);
    EXPECT_EQ(result.status, 0) << options << ": " << result.err;
    *stats = result.out;
    return readBack(out("v.exr"));
  };
  auto lineSamples = [](const std::string& stats) {
    const auto at = stats.find(" line samples");
    const auto start = stats.rfind('(', at);
    return at == std::string::npos || start == std::string::npos ? -1.0 : std::stod(stats.substr(start + 1));
  };
  std::string stats1, stats2;
  const ReadBack base = viewcount("", &stats1);
  const ReadBack denser = viewcount("--samples-per-unit 2", &stats2);
  for (int y = 0; y < 12; ++y) {
    for (int x = 0; x < 16; ++x) {
      ASSERT_EQ(base.at(x, y, 0), 26.0f) << x << "," << y;
      ASSERT_EQ(denser.at(x, y, 0), 52.0f) << x << "," << y;
    }
  }
  const double samples1 = lineSamples(stats1), samples2 = lineSamples(stats2);
  ASSERT_GT(samples1, 0.0) << stats1;
  EXPECT_NEAR(samples2 / samples1, 2.0, 0.15) << stats2;
}

TEST_F(Cli, BundledDemKeepsItsCellSize) {
  // The DEM stores its ground spacing (hfvis:cell_size_x/y); the output carries it on.
  const std::string dem = std::string(HFVIS_DATA_DIR) + "/jacksboro_fault_dem.exr";
  const CliResult result = run("svf " + shellQuoted(dem) + " -o " + shellQuoted(out("svf.exr")) + " -k 4");
  ASSERT_EQ(result.status, 0) << result.err;
  EXPECT_NE(result.out.find("403x344"), std::string::npos) << result.out;
  const ReadBack svf = readBack(out("svf.exr"));
  EXPECT_EQ(svf.spec.get_string_attribute("hfvis:cell_size_x"), "74.573");
  EXPECT_EQ(svf.spec.get_string_attribute("hfvis:cell_size_y"), "92.475");
  for (const float value : svf.pixels) {
    ASSERT_GE(value, 0.0f);
    ASSERT_LE(value, 1.0f);
  }
}

TEST_F(Cli, PreviewIsAnEightBitPng) {
  for (const char* command : {"horizon", "svf", "ao", "viewcount"}) {
    const std::string exr = out(std::string(command) + ".exr");
    const std::string png = out(std::string(command) + ".png");
    const CliResult result = run(std::string(command) + " " + shellQuoted(ramp()) + " -o " +
                                 shellQuoted(exr) + " -k 4 --preview " + shellQuoted(png));
    ASSERT_EQ(result.status, 0) << command << ": " << result.err;
    auto input = OIIO::ImageInput::open(png);
    ASSERT_TRUE(input) << png << ": " << OIIO::geterror();
    EXPECT_EQ(std::string(input->format_name()), "png");
    EXPECT_EQ(input->spec().width, 16);
    EXPECT_EQ(input->spec().height, 12);
    EXPECT_EQ(input->spec().format, OIIO::TypeDesc::UINT8);
  }
  EXPECT_EQ(listDirectory(outputs()).size(), 8u);
}

TEST_F(Cli, PreviewMustBeAPng) {
  expectFailure(run("svf " + shellQuoted(ramp()) + " -o " + shellQuoted(out("o.exr")) + " --preview " +
                    shellQuoted(out("p.jpg"))),
                2, "p.jpg");
}

// ---- viewcount ----

// The contract of issue 4: channel 0 = visible samples summed over the K directions. On a
// 16 x 12 flat plane at K = 4 every pixel sees the rest of its row and column: 15 + 11.
TEST_F(Cli, ViewcountChannelZeroIsTheVisibleCount) {
  for (const char* method : {"tree", "naive"}) {
    fs::remove(out("v.exr"));
    const CliResult result = run("viewcount " + shellQuoted(flat()) + " -o " + shellQuoted(out("v.exr")) +
                                 " -k 4 --method " + method);
    ASSERT_EQ(result.status, 0) << method << ": " << result.err;
    EXPECT_NE(result.out.find("mean count 26.00"), std::string::npos) << result.out;
    const ReadBack image = readBack(out("v.exr"));
    ASSERT_EQ(image.channels, (std::vector<std::string>{"count", "visible_area"}));
    EXPECT_EQ(image.spec.format, OIIO::TypeDesc::FLOAT);
    for (int y = 0; y < image.height; ++y) {
      for (int x = 0; x < image.width; ++x) {
        ASSERT_EQ(image.at(x, y, 0), 26.0f) << method << " pixel " << x << "," << y;
        ASSERT_GT(image.at(x, y, 1), 0.0f);
      }
    }
    EXPECT_EQ(image.spec.get_string_attribute("hfvis:command"), "viewcount");
    EXPECT_EQ(image.spec.get_string_attribute("hfvis:method"), method);
    EXPECT_NE(image.spec.get_string_attribute("hfvis:tie_rule").find(">="), std::string::npos);
  }
}

// A memory budget below the whole field's needs (256 x 256 svf and ao: 1.5 MiB of heights, sums
// and normals; viewcount 0.75 MiB of heights and sums; against 0.4 MiB) runs the field in
// strips, with the very same values.
TEST_F(Cli, ATinyMemoryBudgetRunsInStripsWithTheSameResult) {
  const std::string dem = std::string(HFVIS_DATA_DIR) + "/fractal_256.exr";
  for (const char* command : {"svf", "ao", "viewcount"}) {
    const CliResult whole = run(std::string(command) + " " + shellQuoted(dem) + " -o " +
                                shellQuoted(out("whole.exr")) + " -k 16 --quiet");
    ASSERT_EQ(whole.status, 0) << whole.err;
    const CliResult strips = run(std::string(command) + " " + shellQuoted(dem) + " -o " +
                                 shellQuoted(out("strips.exr")) + " -k 16 --quiet --memory-budget 0.4");
    ASSERT_EQ(strips.status, 0) << strips.err;
    EXPECT_EQ(readBack(out("strips.exr")).pixels, readBack(out("whole.exr")).pixels) << command;
    fs::remove(out("whole.exr"));
    fs::remove(out("strips.exr"));
  }
}

// "hfvis sunpos" prints the compass azimuth and the elevation (tests/test_sun.cpp checks the
// algorithm): the SPA worked example's azimuth, 194.34 degrees; --apparent raises the elevation.
// "hfvis shade": on flat ground every point sees the whole sun and receives sin(elevation), with
// the sun given by azimuth and elevation or by a time and place; the sun given both ways or not
// at all, or with options shade does not take, is a usage error with nothing written.
TEST_F(Cli, ShadeLightsFlatGroundWithTheSun) {
  const std::string field = flat();
  const CliResult given = run("shade " + shellQuoted(field) + " -o " + shellQuoted(out("s.exr")) + " --sun 200,30 -q");
  ASSERT_EQ(given.status, 0) << given.err;
  const ReadBack s = readBack(out("s.exr"));
  ASSERT_EQ(s.channels, (std::vector<std::string>{"direct", "sun"}));
  for (int y = 0; y < s.height; ++y)
    for (int x = 0; x < s.width; ++x) {
      ASSERT_EQ(s.at(x, y, 1), 1.0f) << x << "," << y;
      ASSERT_NEAR(s.at(x, y, 0), 0.5f, 1e-6f) << x << "," << y;
    }
  EXPECT_EQ(s.spec.get_string_attribute("hfvis:sun_elevation_deg"), "30");
  // One azimuth swept, no K: no hfvis:directions (it said the default 64).
  EXPECT_EQ(s.spec.get_string_attribute("hfvis:directions"), "");
  EXPECT_EQ(s.spec.get_string_attribute("hfvis:samples_per_unit"), "1");
  // At the SPA worked example's time and place the sun stands 39.87 degrees up.
  const CliResult placed = run("shade " + shellQuoted(field) + " -o " + shellQuoted(out("p.exr")) +
                               " --at 2003-10-17T12:30:30-07:00 --lat 39.742476 --lon -105.1786 -q");
  ASSERT_EQ(placed.status, 0) << placed.err;
  EXPECT_NEAR(readBack(out("p.exr")).at(3, 3, 0), std::sin(39.872 * M_PI / 180.0), 1e-4);
  for (const char* bad : {"", " --sun 200,30 --lat 40", " --sun 200", " --sun 200,95", " --sun 200,30 -k 8",
                          " --at 2026-06-21T12:00Z --lat 40", " --sun 200,30 --sun-size 20"}) {
    const CliResult r = run("shade " + shellQuoted(field) + " -o " + shellQuoted(out("bad.exr")) + bad);
    EXPECT_EQ(r.status, 2) << bad << ": " << r.err;
    EXPECT_FALSE(fs::exists(out("bad.exr"))) << bad;
  }
  // A placed sun missing a part is told which.
  const CliResult no_lon = run("shade " + shellQuoted(field) + " -o " + shellQuoted(out("bad.exr")) +
                               " --at 2026-06-21T12:00Z --lat 40");
  EXPECT_NE(no_lon.err.find("missing --lon LON"), std::string::npos) << no_lon.err;
}

// "hfvis shade --env": a uniform one-channel environment of radiance 2 gives channel Y = 2 pi on
// flat ground; an RGB map gives R, G, B, and with --albedo the radiance albedo / pi times the
// irradiance (plus the sun's direct light); bad maps are runtime errors naming the file, with
// nothing written.
TEST_F(Cli, ShadeLightsWithAnEnvironment) {
  const std::string field = flat();
  auto writeMap = [&](const std::string& name, int width, int height, std::vector<std::string> names, float value) {
    hfvis::ImageChannels image;
    image.width = width;
    image.height = height;
    image.names = std::move(names);
    for (std::size_t c = 0; c < image.names.size(); ++c)
      image.planes.emplace_back(static_cast<std::size_t>(width) * height, value * (1.0f + c));
    hfvis::writeImage(in(name), image);
    return in(name);
  };
  const std::string grey = writeMap("grey.exr", 16, 8, {"Y"}, 2.0f);
  const CliResult y = run("shade " + shellQuoted(field) + " -o " + shellQuoted(out("y.exr")) + " --env " +
                          shellQuoted(grey) + " -k 16 -q");
  ASSERT_EQ(y.status, 0) << y.err;
  const ReadBack ry = readBack(out("y.exr"));
  ASSERT_EQ(ry.channels, (std::vector<std::string>{"Y"}));
  for (int row = 0; row < ry.height; ++row)
    for (int col = 0; col < ry.width; ++col) ASSERT_NEAR(ry.at(col, row, 0), 2.0 * M_PI, 1e-4) << col << "," << row;
  const std::string rgb = writeMap("rgb.exr", 16, 8, {"R", "G", "B"}, 1.0f);  // R 1, G 2, B 3
  const CliResult c = run("shade " + shellQuoted(field) + " -o " + shellQuoted(out("c.exr")) + " --env " +
                          shellQuoted(rgb) + " --sun 100,30 --albedo 0.5 --sun-irradiance 4 -q --preview " +
                          shellQuoted(out("c.png")));
  ASSERT_EQ(c.status, 0) << c.err;
  const ReadBack rc = readBack(out("c.exr"));
  std::vector<std::string> names = rc.channels;
  std::sort(names.begin(), names.end());
  ASSERT_EQ(names, (std::vector<std::string>{"B", "G", "R", "direct", "radiance.B", "radiance.G", "radiance.R",
                                             "sun"}));
  auto channel = [&](const std::string& name) {
    return static_cast<int>(std::find(rc.channels.begin(), rc.channels.end(), name) - rc.channels.begin());
  };
  for (int ch = 0; ch < 3; ++ch) {
    const std::string colour(1, "RGB"[ch]);
    EXPECT_NEAR(rc.at(5, 5, channel(colour)), M_PI * (1 + ch), 1e-4) << ch;
    // 0.5 / pi (pi (1, 2, 3) + 4 sin(30 degrees)).
    EXPECT_NEAR(rc.at(5, 5, channel("radiance." + colour)), 0.5 / M_PI * (M_PI * (1 + ch) + 4 * 0.5), 1e-4) << ch;
  }
  EXPECT_TRUE(fs::exists(out("c.png")));
  // Bad maps: not 2:1, a negative or non-finite radiance, two channels, unreadable.
  const std::string narrow = writeMap("narrow.exr", 12, 8, {"Y"}, 1.0f);
  const std::string negative = writeMap("negative.exr", 16, 8, {"Y"}, -1.0f);
  const std::string infinite = writeMap("infinite.exr", 16, 8, {"Y"}, INFINITY);
  const std::string two = writeMap("two.exr", 16, 8, {"U", "V"}, 1.0f);
  const std::string garbage = in("garbage.exr");
  std::ofstream(garbage) << "not an image";
  fs::remove_all(outputs());
  fs::create_directories(outputs());
  for (const auto& [map, named] :
       std::vector<std::pair<std::string, std::string>>{{narrow, "twice as wide"},
                                                        {negative, "radiance must be finite, >= 0"},
                                                        {infinite, "radiance must be finite"},
                                                        {two, "one channel or R, G, B"},
                                                        {garbage, "garbage.exr"}}) {
    const CliResult r = run("shade " + shellQuoted(field) + " -o " + shellQuoted(out("bad.exr")) + " --env " +
                            shellQuoted(map) + " -q");
    expectFailure(r, 1, named);
  }
  // Usage errors: --env-rotate without --env, --albedo out of range, an environment as the output.
  for (const std::string& bad : {std::string(" --sun 100,30 --env-rotate 10"), " --env " + shellQuoted(grey) +
                                     " --albedo 1.5", " --env " + shellQuoted(out("bad.exr"))}) {
    const CliResult r = run("shade " + shellQuoted(field) + " -o " + shellQuoted(out("bad.exr")) + bad);
    EXPECT_EQ(r.status, 2) << bad << ": " << r.err;
    EXPECT_TRUE(listDirectory(outputs()).empty()) << bad;
  }
  // An albedo of NaN where the height is valid is refused, naming the pixel (that pixel's radiance
  // was NaN, exit 0); where the height is nodata too, it is that pixel's nodata.
  const std::string holed_albedo = writeField("holed_albedo.exr", 16, 12, [](int col, int row) {
    return col == 3 && row == 5 ? std::numeric_limits<float>::quiet_NaN() : 0.5f;
  });
  expectFailure(run("shade " + shellQuoted(field) + " -o " + shellQuoted(out("bad.exr")) +
                    " --sun 100,30 --albedo " + shellQuoted(holed_albedo)),
                1, "NaN (nodata) at column 3, row 5, where the height is valid");
  const std::string holed = writeField("holed.exr", 16, 12, [](int col, int row) {
    return col == 3 && row == 5 ? std::numeric_limits<float>::quiet_NaN() : 3.0f;
  });
  const CliResult both = run("shade " + shellQuoted(holed) + " -o " + shellQuoted(out("both.exr")) +
                             " --sun 100,30 --albedo " + shellQuoted(holed_albedo) + " -q");
  EXPECT_EQ(both.status, 0) << both.err;
}

// "hfvis insolation": flat ground at the equator on the 2026 March equinox has 12 hours of sun
// (the geometric centre above the horizon; the equinox falls at 14:46 UTC that day, so the
// declination moves by 0.4 degree over the day: a minute or two); direct is the integral of
// sin(elevation) over the day. A south-up GeoTIFF is lit north-up: a wall's shadow falls on its
// north side at noon in the northern winter.
TEST_F(Cli, InsolationCountsSunHours) {
  const std::string field = flat();
  const CliResult r = run("insolation " + shellQuoted(field) + " -o " + shellQuoted(out("i.exr")) +
                          " --lat 0 --lon 0 --from 2026-03-20T00:00:00Z --to 2026-03-21T00:00:00Z --step 2 -q");
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_EQ(r.err.find("warning"), std::string::npos) << r.err;
  const ReadBack i = readBack(out("i.exr"));
  ASSERT_EQ(i.channels, (std::vector<std::string>{"direct", "sun_hours"}));
  EXPECT_EQ(i.spec.get_string_attribute("hfvis:directions"), "");  // (one sweep per azimuth bucket)
  EXPECT_NE(i.spec.get_string_attribute("hfvis:sweeps"), "");
  // Steps of hours alias the day (one of 720 minutes counts the whole day sunny): a warning.
  const CliResult coarse =
      run("insolation " + shellQuoted(field) + " -o " + shellQuoted(out("c.exr")) +
          " --lat 0 --lon 0 --from 2026-03-20T00:00:00Z --to 2026-03-21T00:00:00Z --step 720 -q");
  ASSERT_EQ(coarse.status, 0) << coarse.err;
  EXPECT_NE(coarse.err.find("hfvis: warning: --step 720 minutes"), std::string::npos) << coarse.err;
  // The worst of them, the day in one step (every hour sunny), warns too; a span of an hour in
  // one step of 1440 does not (the step is the span's hour).
  for (const auto& [to, warns] : {std::pair{"2026-03-21T00:00:00Z", true}, {"2026-03-20T01:00:00Z", false}}) {
    const CliResult day = run("insolation " + shellQuoted(field) + " -o " + shellQuoted(out("d.exr")) +
                              " --lat 0 --lon 0 --from 2026-03-20T00:00:00Z --to " + to + " --step 1440 -q");
    ASSERT_EQ(day.status, 0) << day.err;
    EXPECT_EQ(day.err.find("hfvis: warning: --step 1440 minutes") != std::string::npos, warns)
        << to << day.err;
  }
  EXPECT_NEAR(i.at(4, 4, 1), 12.0, 0.05);
  // The integral of sin(elevation) over a day at the equator's equinox: 24 / pi hours.
  EXPECT_NEAR(i.at(4, 4, 0), 24.0 / M_PI, 0.01);
  // North-up and south-up rasters of a wall along the rows at row 6 (of 12): at noon on the
  // December solstice at 45 N the sun stands 21.6 degrees up in the south, so the wall (4 high,
  // 1 m cells) shades the 10 m north of it.
  const int width = 8, height = 24;
  std::vector<float> north_up(width * height, 0.0f), south_up(width * height, 0.0f);
  for (int c = 0; c < width; ++c) north_up[12 * width + c] = south_up[11 * width + c] = 4.0f;
  const std::string n = in("north.tif"), s = in("south.tif");
  hfvis::testing::writeGdalGeoTiff(n, width, height, north_up, {500000.0, 1.0, 0.0, 5000024.0, 0.0, -1.0},
                                   "EPSG:32631", std::nullopt);
  hfvis::testing::writeGdalGeoTiff(s, width, height, south_up, {500000.0, 1.0, 0.0, 5000000.0, 0.0, 1.0},
                                   "EPSG:32631", std::nullopt);
  // An albedo raster beside each, of its orientation: 0.2 over the northern half, 0.8 over the
  // southern; the radiance takes each pixel's own (the field is lit flipped, the albedo is not).
  std::vector<float> albedo_north(width * height), albedo_south(width * height);
  for (int r = 0; r < height; ++r)
    for (int c = 0; c < width; ++c) {
      albedo_north[r * width + c] = r < height / 2 ? 0.2f : 0.8f;
      albedo_south[r * width + c] = r < height / 2 ? 0.8f : 0.2f;
    }
  hfvis::testing::writeGdalGeoTiff(in("north_albedo.tif"), width, height, albedo_north,
                                   {500000.0, 1.0, 0.0, 5000024.0, 0.0, -1.0}, "EPSG:32631", std::nullopt);
  hfvis::testing::writeGdalGeoTiff(in("south_albedo.tif"), width, height, albedo_south,
                                   {500000.0, 1.0, 0.0, 5000000.0, 0.0, 1.0}, "EPSG:32631", std::nullopt);
  for (const std::string& tif : {n, s}) {
    const std::string o = out(fs::path(tif).stem().string() + ".exr");
    const std::string albedo = in(fs::path(tif).stem().string() + "_albedo.tif");
    const CliResult w = run("shade " + shellQuoted(tif) + " -o " + shellQuoted(o) +
                            " --at 2026-12-21T11:47:00Z --lat 45 --lon 3 --albedo " + shellQuoted(albedo) +
                            " --sun-irradiance 2 -q");
    ASSERT_EQ(w.status, 0) << w.err;
    const ReadBack shade = readBack(o);
    const auto channel = [&](const std::string& name) {
      return int(std::find(shade.channels.begin(), shade.channels.end(), name) - shade.channels.begin());
    };
    const int direct = channel("direct"), sun = channel("sun"), radiance = channel("radiance");
    ASSERT_LT(std::max({direct, sun, radiance}), int(shade.channels.size()));
    const bool south = tif == s;
    // The rows 2 m north of the wall (in file order) are in shadow, 2 m south lit.
    const int north_row = south ? 13 : 10, south_row = south ? 9 : 14;
    EXPECT_EQ(shade.at(3, north_row, sun), 0.0f) << tif;
    EXPECT_EQ(shade.at(3, south_row, sun), 1.0f) << tif;
    // Radiance albedo / pi times the irradiance, the albedo of the pixel's own place.
    for (const int north_up_row : {1, 14, 18, 22}) {
      const int row = south ? height - 1 - north_up_row : north_up_row;
      const float a = (south ? albedo_south : albedo_north)[row * width + 3];
      EXPECT_GT(shade.at(3, row, direct), 0.1f) << tif << " row " << row;
      EXPECT_NEAR(shade.at(3, row, radiance), a / M_PI * 2.0 * shade.at(3, row, direct), 1e-6)
          << tif << " row " << row;
    }
  }
  for (const char* bad : {" --lat 0 --lon 0 --from 2026-03-20T00:00:00Z",
                          " --lat 0 --lon 0 --from 2026-03-21T00:00:00Z --to 2026-03-20T00:00:00Z",
                          " --lat 0 --lon 0 --from 2026-03-20T00:00:00Z --to 2026-03-21T00:00:00Z --step 0",
                          " --lat 0 --lon 0 --from 2026-03-20T00:00:00Z --to 2026-03-21T00:00:00Z -k 8",
                          " --lat 95 --lon 0 --from 2026-03-20T00:00:00Z --to 2026-03-21T00:00:00Z"}) {
    const CliResult b = run("insolation " + shellQuoted(field) + " -o " + shellQuoted(out("bad.exr")) + bad);
    EXPECT_EQ(b.status, 2) << bad << ": " << b.err;
    EXPECT_FALSE(fs::exists(out("bad.exr"))) << bad;
  }
}

TEST_F(Cli, SunPositionPrintsAzimuthAndElevation) {
  const CliResult result = run("sunpos --lat 39.742476 --lon -105.1786 --at 2003-10-17T12:30:30-07:00");
  ASSERT_EQ(result.status, 0) << result.err;
  double azimuth = 0.0, elevation = 0.0;
  ASSERT_EQ(std::sscanf(result.out.c_str(), "azimuth=%lf elevation=%lf", &azimuth, &elevation), 2) << result.out;
  EXPECT_NEAR(azimuth, 194.34024, 0.005);
  EXPECT_NEAR(elevation, 39.874, 0.005);
  const CliResult apparent = run("sunpos --lat 39.742476 --lon -105.1786 --at 2003-10-17T12:30:30-07:00 --apparent");
  ASSERT_EQ(apparent.status, 0) << apparent.err;
  double apparent_elevation = 0.0;
  ASSERT_EQ(std::sscanf(apparent.out.c_str(), "azimuth=%lf elevation=%lf", &azimuth, &apparent_elevation), 2);
  EXPECT_NEAR(apparent_elevation - elevation, 0.02, 0.005);  // a standard atmosphere at 40 degrees
  for (const char* bad : {"sunpos --lat 45 --lon 7", "sunpos --lat 45 --lon 7 --at noon",
                          "sunpos --lat 45 --lon 7 --at 2026-06-21T12:00:00Z --lat 46", "sunpos --lat 45 --lon 7 --at"}) {
    const CliResult r = run(bad);
    EXPECT_EQ(r.status, 2) << bad;
    EXPECT_TRUE(r.out.empty()) << bad;
  }
}

TEST_F(Cli, ViewcountStatistics) {
  const std::string dem = std::string(HFVIS_DATA_DIR) + "/fractal_256.exr";
  const CliResult result =
      run("viewcount " + shellQuoted(dem) + " -o " + shellQuoted(out("v.exr")) + " -k 4 --stats --quiet");
  ASSERT_EQ(result.status, 0) << result.err;
  EXPECT_EQ(result.out.find("wrote"), std::string::npos) << "--quiet printed the summary:\n" << result.out;
  for (const char* text : {"m_a ", "t_a ", "visible ", "naive iterations ", "0 lines over"}) {
    EXPECT_NE(result.out.find(text), std::string::npos) << "--stats lacks '" << text << "':\n" << result.out;
  }
  const ReadBack image = readBack(out("v.exr"));
  const double m_a = std::stod(image.spec.get_string_attribute("hfvis:stats_m_a"));
  const double t_a = std::stod(image.spec.get_string_attribute("hfvis:stats_t_a"));
  EXPECT_GT(m_a, 1.0);
  EXPECT_LE(t_a, 2 * m_a + 1);
  fs::remove(out("v.exr"));
  expectFailure(
      run("viewcount " + shellQuoted(dem) + " -o " + shellQuoted(out("w.exr")) + " --stats --method naive"),
      2, "--stats");
}

// --hull-tree changes the work (t_a), never the counts; Algorithm 1 as written ("plain")
// makes at least as many checks as the default minus one per receiver (see
// tests/test_intervisibility.cpp), on this terrain many more.
TEST_F(Cli, ViewcountHullTreeTuningsGiveTheSameCounts) {
  const std::string dem = std::string(HFVIS_DATA_DIR) + "/fractal_256.exr";
  std::vector<std::vector<float>> counts;
  std::vector<double> t_a;
  for (const char* tuning : {"plain", "deferred", "default", "zone"}) {
    const std::string file = out(std::string(tuning) + ".exr");
    const CliResult result = run("viewcount " + shellQuoted(dem) + " -o " + shellQuoted(file) +
                                 " -k 4 --stats --quiet --hull-tree " + tuning);
    ASSERT_EQ(result.status, 0) << tuning << ": " << result.err;
    EXPECT_NE(result.out.find(std::string("(--hull-tree ") + tuning + ")"), std::string::npos) << result.out;
    const ReadBack image = readBack(file);
    counts.emplace_back();
    for (int y = 0; y < image.height; ++y)
      for (int x = 0; x < image.width; ++x) counts.back().push_back(image.at(x, y, 0));
    t_a.push_back(std::stod(image.spec.get_string_attribute("hfvis:stats_t_a")));
  }
  for (std::size_t i = 1; i < counts.size(); ++i) EXPECT_EQ(counts[i], counts[0]) << "tuning " << i;
  EXPECT_EQ(t_a[1], t_a[0]);        // deferred writes: the same checks
  EXPECT_LT(t_a[2], 0.9 * t_a[0]);  // the replacement check saves many
  EXPECT_LE(t_a[3], t_a[2]);        // the safe zone skips walks
  for (const char* tuning : {"plain", "deferred", "default", "zone"})
    fs::remove(out(std::string(tuning) + ".exr"));
  const std::string base = "viewcount " + shellQuoted(dem) + " -o " + shellQuoted(out("bad.exr"));
  expectFailure(run(base + " --hull-tree fast"), 2, "--hull-tree");
  expectFailure(run(base + " --hull-tree plain --method naive"), 2, "--hull-tree");
  expectFailure(run("svf " + shellQuoted(dem) + " -o " + shellQuoted(out("bad.exr")) + " --hull-tree plain"),
                2, "--hull-tree");
}

TEST_F(Cli, ViewcountOptionsAreChecked) {
  const std::string base = "viewcount " + shellQuoted(ramp()) + " -o " + shellQuoted(out("o.exr"));
  expectFailure(run(base + " --method sweep"), 2, "'sweep'");
  expectFailure(run(base + " --radiance " + shellQuoted(ramp())), 2, "--radiance");
  expectFailure(run(base + " --at 1,1"), 2, "--at");
  expectFailure(run("svf " + shellQuoted(ramp()) + " -o " + shellQuoted(out("o.exr")) + " --stats"), 2,
                "--stats");
}

// ---- horizons ----

// Level ground with a wall 100 high at column 10 (as tests/test_horizon_lists.cpp).
std::vector<float> wallHeights(int width, int height) {
  std::vector<float> h(width * height, 0.0f);
  for (int r = 0; r < height; ++r) h[r * width + 10] = 100.0f;
  return h;
}

TEST_F(Cli, HorizonsJsonIsWellFormedAndMatchesTheLibrary) {
  const int w = 21, h = 5;
  const std::vector<float> heights = wallHeights(w, h);
  const std::string field = writeField("wall.exr", w, h, [&](int c, int r) { return heights[r * w + c]; });
  const CliResult result =
      run("horizons " + shellQuoted(field) + " --at 3,2 --at 15,4 -k 8 --azimuth-offset 10 -o " +
          shellQuoted(out("h.json")));
  ASSERT_EQ(result.status, 0) << result.err;
  EXPECT_NE(result.out.find("2 receivers"), std::string::npos) << result.out;
  Json json;
  ASSERT_NO_THROW(json = JsonParser::parse(readText(out("h.json")))) << readText(out("h.json"));

  hfvis::HeightField library_field;
  library_field.width = w;
  library_field.height = h;
  library_field.heights = heights;
  hfvis::SweepOptions options;
  options.directions = 8;
  options.azimuth_offset = 10.0 * M_PI / 180.0;
  const auto lists = hfvis::computeHorizonLists(library_field, options, {{3, 2}, {15, 4}});

  EXPECT_EQ(json["width"].number, w);
  EXPECT_EQ(json["directions"].number, 8);
  EXPECT_EQ(json["conventions"]["visible"].type, Json::Type::String);
  ASSERT_EQ(json["receivers"].items.size(), 2u);
  int horizons = 0, lists_without = 0;
  for (std::size_t n = 0; n < 2; ++n) {
    const Json& receiver = json["receivers"][n];
    EXPECT_EQ(receiver["col"].number, lists[n].pixel.col);
    EXPECT_FALSE(receiver["nodata"].boolean);
    ASSERT_EQ(receiver["directions"].items.size(), 8u);
    for (std::size_t k = 0; k < 8; ++k) {
      const Json& d = receiver["directions"][k];
      const auto& expected = lists[n].directions[k];
      EXPECT_DOUBLE_EQ(d["azimuth_rad"].number, expected.azimuth);
      EXPECT_EQ(d["visible_samples"].number, expected.visible_samples);
      ASSERT_EQ(d["horizons"].items.size(), expected.horizons.size());
      lists_without += expected.horizons.empty();
      for (std::size_t i = 0; i < expected.horizons.size(); ++i) {
        const Json& z = d["horizons"][i];
        EXPECT_EQ(z["sample"].number, expected.horizons[i].sample);
        EXPECT_DOUBLE_EQ(z["distance"].number, expected.horizons[i].distance);
        EXPECT_DOUBLE_EQ(z["elevation_rad"].number, expected.horizons[i].elevation);
        EXPECT_EQ(z["segment_begin"].number, expected.horizons[i].segment_begin);
        EXPECT_EQ(z["segment_end"].number, expected.horizons[i].segment_end);
        EXPECT_DOUBLE_EQ(z["near_distance"].number, expected.horizons[i].near_distance);
        EXPECT_EQ(z["visible_samples"].number, expected.horizons[i].visible_samples);
        ++horizons;
      }
    }
  }
  EXPECT_GE(horizons, 12);
  EXPECT_EQ(lists_without, 4);  // (15, 4) is on the last row: the rays at 10, 55, 100, 145 deg leave at once
  // From (3, 2) toward the wall (k = 0, 10 degrees off the row), the wall is the one horizon.
  const Json& toward_wall = json["receivers"][0]["directions"][0]["horizons"];
  ASSERT_EQ(toward_wall.items.size(), 1u);
  EXPECT_GT(toward_wall[0]["elevation_rad"].number, 1.4);
  EXPECT_EQ(listDirectory(outputs()), std::vector<std::string>{"h.json"});
}

TEST_F(Cli, HorizonsCsvIsWellFormed) {
  const int w = 21, h = 5;
  const std::vector<float> heights = wallHeights(w, h);
  const std::string field = writeField("wall.exr", w, h, [&](int c, int r) { return heights[r * w + c]; });
  const CliResult result = run("horizons " + shellQuoted(field) +
                               " --at 3,2 --at 20,2 -k 4 --cell-size 2 -o " + shellQuoted(out("h.CSV")));
  ASSERT_EQ(result.status, 0) << result.err;
  std::vector<std::string> lines = splitText(readText(out("h.CSV")), '\n');
  ASSERT_FALSE(lines.empty());
  ASSERT_EQ(lines.back(), "");
  lines.pop_back();
  const std::vector<std::string> header = splitText(lines[0], ',');
  ASSERT_EQ(header.size(), 13u) << lines[0];
  EXPECT_EQ(header[12], "nodata");
  EXPECT_EQ(header[0], "col");
  EXPECT_EQ(header[7], "elevation_rad");
  int rows_without = 0;
  bool wall_seen = false;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    const std::vector<std::string> fields = splitText(lines[i], ',');
    ASSERT_EQ(fields.size(), 13u) << lines[i];
    if (fields[4].empty()) {  // a direction without horizons: (20, 2) looking out of the field
      ++rows_without;
      EXPECT_EQ(fields[0], "20");
      EXPECT_EQ(fields[11], "0");
      continue;
    }
    for (const std::string& f : fields) EXPECT_NO_THROW(std::stod(f)) << lines[i];
    // (3, 2) toward +x: the wall, 7 samples (14 ground units) away, segment [1, 8).
    if (fields[0] == "3" && fields[2] == "0") {
      wall_seen = true;
      EXPECT_EQ(fields[5], "7");
      EXPECT_DOUBLE_EQ(std::stod(fields[6]), 14.0);
      EXPECT_DOUBLE_EQ(std::stod(fields[7]), std::atan2(100.0, 14.0));
      EXPECT_EQ(fields[8], "1");
      EXPECT_EQ(fields[9], "8");
      EXPECT_EQ(fields[11], "7");
    }
  }
  EXPECT_TRUE(wall_seen);
  EXPECT_EQ(rows_without, 1);  // (20, 2) is on the last column: direction 0 leaves at once
}

TEST_F(Cli, HorizonsBadReceiversAreUsageErrors) {
  const std::string base = "horizons " + shellQuoted(ramp()) + " -o " + shellQuoted(out("h.json")) + " -k 4";
  const CliResult outside = run(base + " --at 3,3 --at 16,2");  // the ramp is 16 x 12
  expectFailure(outside, 2, "--at 16,2");
  EXPECT_NE(outside.err.find("16x12"), std::string::npos) << outside.err;
  expectFailure(run(base + " --at 3,12"), 2, "--at 3,12");
  expectFailure(run(base + " --at -1,2"), 2, "--at");
  expectFailure(run(base + " --at 3"), 2, "'3'");
  expectFailure(run(base + " --at 3,x"), 2, "'3,x'");
  expectFailure(run(base), 2, "--at");
  expectFailure(run("horizons " + shellQuoted(ramp()) + " --at 1,1 -o " + shellQuoted(out("h.txt"))), 2,
                "h.txt");
  expectFailure(run(base + " --at 1,1 --preview " + shellQuoted(out("p.png"))), 2, "--preview");
  expectFailure(run(base + " --at 1,1 --device cpu"), 2, "--device");
}

// ---- bounce ----

TEST_F(Cli, BounceKeepsTheRadianceChannels) {
  // A V valley along the rows; exit radiance R = 1, G = 2, B = 0.5 everywhere.
  const std::string field =
      writeField("valley.exr", 24, 10, [](int c, int) { return std::abs(static_cast<float>(c - 12)); });
  hfvis::ImageChannels radiance;
  radiance.width = 24;
  radiance.height = 10;
  radiance.names = {"R", "G", "B"};
  radiance.planes = {std::vector<float>(240, 1.0f), std::vector<float>(240, 2.0f),
                     std::vector<float>(240, 0.5f)};
  hfvis::writeImage(in("radiance.exr"), radiance);
  const CliResult result =
      run("bounce " + shellQuoted(field) + " --radiance " + shellQuoted(in("radiance.exr")) + " -o " +
          shellQuoted(out("b.exr")) + " -k 8 --preview " + shellQuoted(out("b.png")));
  ASSERT_EQ(result.status, 0) << result.err;
  EXPECT_NE(result.out.find("mean irradiance R "), std::string::npos) << result.out;
  const ReadBack image = readBack(out("b.exr"));
  ASSERT_EQ(image.channels, (std::vector<std::string>{"R", "G", "B"}));
  EXPECT_EQ(image.spec.get_string_attribute("hfvis:command"), "bounce");
  EXPECT_EQ(image.spec.get_string_attribute("hfvis:radiance"), in("radiance.exr"));
  double largest = 0.0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const float r = image.at(x, y, 0);
      ASSERT_GE(r, -1e-6f);
      ASSERT_NEAR(image.at(x, y, 1), 2.0f * r, 1e-5f * (1.0f + r));  // linear in the radiance
      ASSERT_NEAR(image.at(x, y, 2), 0.5f * r, 1e-5f * (1.0f + r));
      largest = std::max(largest, double(r));
    }
  }
  EXPECT_GT(largest, 0.1) << "the flanks see each other";
  EXPECT_EQ(listDirectory(outputs()).size(), 2u);
}

TEST_F(Cli, BounceOfAFlatPlaneIsZero) {
  hfvis::ImageChannels radiance;
  radiance.width = 16;
  radiance.height = 12;
  radiance.names = {"Y"};
  radiance.planes = {std::vector<float>(16 * 12, 3.0f)};
  hfvis::writeImage(in("radiance.exr"), radiance);
  const CliResult result =
      run("bounce " + shellQuoted(flat()) + " --radiance " + shellQuoted(in("radiance.exr")) + " -o " +
          shellQuoted(out("b.exr")) + " -k 4 -q");
  ASSERT_EQ(result.status, 0) << result.err;
  const ReadBack image = readBack(out("b.exr"));
  EXPECT_EQ(image.channels, std::vector<std::string>{"Y"});
  for (const float v : image.pixels) ASSERT_EQ(v, 0.0f);
}

TEST_F(Cli, BounceBadRadiance) {
  const std::string base = "bounce " + shellQuoted(flat()) + " -o " + shellQuoted(out("b.exr")) + " -k 4";
  expectFailure(run(base), 2, "--radiance");
  expectFailure(run(base + " --radiance " + shellQuoted(out("b.exr"))), 2, "--radiance");
  expectFailure(run(base + " --radiance " + shellQuoted(in("absent.exr"))), 1, "absent.exr");
  expectFailure(run(base + " --radiance " + shellQuoted(ramp()) + " --method naive"), 2, "--method");
  hfvis::ImageChannels radiance;
  radiance.width = 16;
  radiance.height = 11;  // the field is 16 x 12
  radiance.names = {"Y"};
  radiance.planes = {std::vector<float>(16 * 11, 1.0f)};
  hfvis::writeImage(in("small.exr"), radiance);
  const CliResult small = run(base + " --radiance " + shellQuoted(in("small.exr")));
  expectFailure(small, 1, "small.exr");
  EXPECT_NE(small.err.find("16x11"), std::string::npos) << small.err;
  radiance.height = 12;
  radiance.planes = {std::vector<float>(16 * 12, 1.0f)};
  radiance.planes[0][5] = std::nanf("");
  hfvis::writeImage(in("nan.exr"), radiance);
  expectFailure(run(base + " --radiance " + shellQuoted(in("nan.exr"))), 1, "nan.exr");
  radiance.names = {"a", "b", "c", "d", "e"};
  radiance.planes.assign(5, std::vector<float>(16 * 12, 1.0f));
  hfvis::writeImage(in("five.exr"), radiance);
  expectFailure(run(base + " --radiance " + shellQuoted(in("five.exr"))), 1, "5 channels");
}

// ---- GeoTIFF: the input's georeference and nodata carried into the outputs ----

// A 24 x 20 bumpy DEM in UTM zone 33N (30 m cells, row 0 north), its nodata value -9999 in a
// corner, a pair of neighbours in the middle and one cell near the border: as a GeoTIFF made
// with GDAL, and the same heights as an EXR with NaN in those cells.
class CliGeoTiff : public Cli {
 protected:
  static constexpr int kWidth = 24;
  static constexpr int kHeight = 20;

  static bool isNodataCell(int col, int row) {
    return (col == 0 && row == 0) || (row == 8 && (col == 10 || col == 11)) || (col == 3 && row == 15);
  }
  static float height(int col, int row) {
    return static_cast<float>(40.0 * std::sin(0.45 * col) * std::cos(0.35 * row) + 2.0 * col);
  }
  std::string geoTiffInput(const std::string& name = "dem.tif",
                           const std::array<double, 6>& geotransform = hfvis::testing::kUtmGeotransform,
                           const std::string& crs = "EPSG:32633") const {
    std::vector<float> values;
    for (int row = 0; row < kHeight; ++row)
      for (int col = 0; col < kWidth; ++col)
        values.push_back(isNodataCell(col, row) ? -9999.0f : height(col, row));
    hfvis::testing::writeGdalGeoTiff(in(name), kWidth, kHeight, values, geotransform, crs, -9999.0);
    return in(name);
  }
  std::string exrInput() const {
    return writeField("dem.exr", kWidth, kHeight, [](int col, int row) {
      return isNodataCell(col, row) ? std::nanf("") : height(col, row);
    });
  }

  // The checks every GeoTIFF output of the UTM input gets, through GDAL itself.
  static hfvis::testing::GdalRaster checkGeoTiffOutput(const std::string& path,
                                                       const std::vector<std::string>& bands,
                                                       const std::string& command) {
    SCOPED_TRACE(path);
    hfvis::testing::GdalRaster raster = hfvis::testing::readGdalRaster(path);
    EXPECT_EQ(raster.driver, "GTiff");
    EXPECT_EQ(raster.width, kWidth);
    EXPECT_EQ(raster.height, kHeight);
    EXPECT_EQ(raster.descriptions, bands);
    EXPECT_TRUE(raster.geotransform && *raster.geotransform == hfvis::testing::kUtmGeotransform);
    EXPECT_TRUE(hfvis::testing::sameCrs(raster.crs_wkt, hfvis::testing::crsWkt("EPSG:32633")))
        << raster.crs_wkt;
    for (std::size_t b = 0; b < raster.bands.size(); ++b) {
      EXPECT_TRUE(raster.nodata[b].has_value()) << "band " << b << " declares no nodata";
      EXPECT_EQ(raster.block_sizes[b], (std::array<int, 2>{256, 256})) << "band " << b << " is not tiled";
    }
    EXPECT_EQ(raster.image_structure["COMPRESSION"], "DEFLATE");
    // The floating-point predictor, unless every value is a whole number (distances along the
    // axes of a 30 m grid).
    bool whole = true;
    for (const std::vector<float>& band : raster.bands)
      for (float v : band) whole = whole && (std::isnan(v) || v == std::nearbyint(v));
    EXPECT_EQ(raster.image_structure["PREDICTOR"], whole ? "" : "3");
    EXPECT_EQ(raster.metadata["hfvis_command"], command);
    EXPECT_EQ(raster.metadata["hfvis_cell_size_x"], "30");
    return raster;
  }
};

// Every command that writes a raster (and --distance-out) writes GeoTIFF bands in the input's
// CRS and geotransform; its -9999 cells are NaN, and every other cell, the nodata cells' valid
// neighbours included, holds exactly what the same heights with NaN holes in an EXR give:
// nodata cells neither cast nor receive.
TEST_F(CliGeoTiff, EveryRasterCommandCarriesTheGeoreferenceAndTheNodata) {
  const std::string tif = geoTiffInput();
  const std::string exr = exrInput();
  hfvis::ImageChannels radiance;
  radiance.width = kWidth;
  radiance.height = kHeight;
  radiance.names = {"Y"};
  radiance.planes = {std::vector<float>(kWidth * kHeight, 1.0f)};
  hfvis::writeImage(in("radiance.exr"), radiance);
  struct Case {
    std::string command, options;
    std::vector<std::string> bands;
    std::string distance_option;  // horizon: --distance-out too
  };
  const std::vector<Case> cases = {
      {"svf", "-k 8", {"svf"}, ""},
      {"ao", "-k 8", {"ao"}, ""},
      {"viewcount", "-k 4", {"count", "visible_area"}, ""},
      {"bounce", "-k 4 --radiance " + shellQuoted(in("radiance.exr")), {"Y"}, ""},
      {"horizon", "-k 4", hfvis::cli::directionChannelNames("h", 4), "--distance-out"},
  };
  for (const Case& c : cases) {
    SCOPED_TRACE(c.command);
    const std::string tif_out = out(c.command + ".tif"), exr_out = out(c.command + ".exr");
    const std::string tif_distance = out(c.command + "_d.tiff"), exr_distance = out(c.command + "_d.exr");
    const auto distance = [&](const std::string& file) {
      return c.distance_option.empty() ? std::string() : " " + c.distance_option + " " + shellQuoted(file);
    };
    const CliResult from_tif = run(c.command + " " + shellQuoted(tif) + " -o " + shellQuoted(tif_out) + " " +
                                   c.options + distance(tif_distance) + " -q");
    ASSERT_EQ(from_tif.status, 0) << from_tif.err;
    const CliResult from_exr = run(c.command + " " + shellQuoted(exr) + " --cell-size 30 -o " +
                                   shellQuoted(exr_out) + " " + c.options + distance(exr_distance) + " -q");
    ASSERT_EQ(from_exr.status, 0) << from_exr.err;

    std::vector<std::pair<std::string, std::string>> pairs = {{tif_out, exr_out}};
    std::vector<std::vector<std::string>> names = {c.bands};
    if (!c.distance_option.empty()) {
      pairs.emplace_back(tif_distance, exr_distance);
      names.push_back(hfvis::cli::directionChannelNames("d", 4));
    }
    for (std::size_t p = 0; p < pairs.size(); ++p) {
      const hfvis::testing::GdalRaster raster = checkGeoTiffOutput(pairs[p].first, names[p], c.command);
      const ReadBack reference = readBack(pairs[p].second);
      ASSERT_EQ(raster.bands.size(), names[p].size());
      for (std::size_t b = 0; b < names[p].size(); ++b) {
        SCOPED_TRACE(names[p][b]);
        EXPECT_TRUE(raster.nodata[b] && std::isnan(*raster.nodata[b]));  // NaN by default
        const auto channel = std::find(reference.channels.begin(), reference.channels.end(), names[p][b]);
        ASSERT_NE(channel, reference.channels.end());
        const int exr_channel = static_cast<int>(channel - reference.channels.begin());
        int finite_neighbours = 0;
        for (int row = 0; row < kHeight; ++row) {
          for (int col = 0; col < kWidth; ++col) {
            const float value = raster.bands[b][static_cast<std::size_t>(row) * kWidth + col];
            const float expected = reference.at(col, row, exr_channel);
            if (isNodataCell(col, row)) {
              ASSERT_TRUE(std::isnan(value)) << col << "," << row;
              continue;
            }
            ASSERT_TRUE(std::isfinite(value)) << col << "," << row;
            ASSERT_EQ(value, expected) << col << "," << row;
            bool next_to_nodata = false;
            for (int dr = -1; dr <= 1; ++dr)
              for (int dc = -1; dc <= 1; ++dc) next_to_nodata |= isNodataCell(col + dc, row + dr);
            finite_neighbours += next_to_nodata;
          }
        }
        EXPECT_EQ(finite_neighbours, 3 + 10 + 8);  // the corner's, the pair's and the single cell's
      }
    }
  }
  EXPECT_EQ(listDirectory(outputs()).size(), 12u);  // nothing beside the outputs (no .aux.xml)
}

// --nodata VALUE: written in the nodata cells and declared on every band of a GeoTIFF output;
// hfvis reads it back as nodata. An EXR output of the same run keeps NaN.
TEST_F(CliGeoTiff, NodataValueIsWrittenAndDeclared) {
  const std::string tif = geoTiffInput();
  const CliResult nan_run =
      run("svf " + shellQuoted(tif) + " -o " + shellQuoted(out("nan.tif")) + " -k 8 -q");
  ASSERT_EQ(nan_run.status, 0) << nan_run.err;
  const CliResult value_run =
      run("svf " + shellQuoted(tif) + " -o " + shellQuoted(out("v.tif")) + " -k 8 -q --nodata -9999");
  ASSERT_EQ(value_run.status, 0) << value_run.err;
  const hfvis::testing::GdalRaster with_nan = checkGeoTiffOutput(out("nan.tif"), {"svf"}, "svf");
  const hfvis::testing::GdalRaster with_value = checkGeoTiffOutput(out("v.tif"), {"svf"}, "svf");
  ASSERT_TRUE(with_value.nodata[0]);
  EXPECT_EQ(*with_value.nodata[0], -9999.0);
  EXPECT_NE(with_value.metadata.at("hfvis_nodata").find("-9999"), std::string::npos);
  const hfvis::HeightField back = hfvis::readHeightField(out("v.tif"));
  for (int row = 0; row < kHeight; ++row) {
    for (int col = 0; col < kWidth; ++col) {
      const std::size_t i = static_cast<std::size_t>(row) * kWidth + col;
      if (isNodataCell(col, row)) {
        EXPECT_EQ(with_value.bands[0][i], -9999.0f) << col << "," << row;
        EXPECT_TRUE(std::isnan(back.heights[i])) << col << "," << row;
      } else {
        EXPECT_EQ(with_value.bands[0][i], with_nan.bands[0][i]) << col << "," << row;
        EXPECT_EQ(back.heights[i], with_nan.bands[0][i]) << col << "," << row;
      }
    }
  }
  // The distances as EXR beside the angles as GeoTIFF: only the GeoTIFF holds the value.
  const CliResult mixed = run("horizon " + shellQuoted(tif) + " -o " + shellQuoted(out("h.tif")) +
                              " --distance-out " + shellQuoted(out("d.exr")) + " -k 4 -q --nodata -32768");
  ASSERT_EQ(mixed.status, 0) << mixed.err;
  const hfvis::testing::GdalRaster angles =
      checkGeoTiffOutput(out("h.tif"), hfvis::cli::directionChannelNames("h", 4), "horizon");
  EXPECT_EQ(angles.nodata[3], std::optional<double>(-32768.0));
  EXPECT_EQ(angles.bands[3][0], -32768.0f);
  EXPECT_TRUE(std::isnan(readBack(out("d.exr")).at(0, 0, 0)));
  // An area light's masks as the one GeoTIFF (the light as EXR): the value goes there (it was
  // refused, as if no output were a GeoTIFF).
  const CliResult masks =
      run("arealight " + shellQuoted(tif) + " -o " + shellQuoted(out("a.exr")) +
          " --light 1,1,3,3 --samples 8 --masks " + shellQuoted(out("m.tif")) + " -q --nodata -9999");
  ASSERT_EQ(masks.status, 0) << masks.err;
  const hfvis::testing::GdalRaster mask_raster = hfvis::testing::readGdalRaster(out("m.tif"));
  ASSERT_TRUE(mask_raster.nodata[0]);
  EXPECT_EQ(*mask_raster.nodata[0], -9999.0);

  // An output is an input again: a band by its description or its index, its nodata as nodata,
  // its georeference carried on.
  for (const char* channel : {"h002", "2"}) {
    SCOPED_TRACE(channel);
    const std::string again = out(std::string("again_") + channel + ".tif");
    const CliResult result = run("svf " + shellQuoted(out("h.tif")) + " --channel " + channel + " -o " +
                                 shellQuoted(again) + " -k 4 -q");
    ASSERT_EQ(result.status, 0) << result.err;
    const hfvis::testing::GdalRaster raster = checkGeoTiffOutput(again, {"svf"}, "svf");
    EXPECT_TRUE(std::isnan(raster.bands[0][0]));
    EXPECT_TRUE(std::isfinite(raster.bands[0][1]));
  }
  const std::vector<float> by_name = hfvis::testing::readGdalRaster(out("again_h002.tif")).bands.at(0);
  const std::vector<float> by_index = hfvis::testing::readGdalRaster(out("again_2.tif")).bands.at(0);
  ASSERT_EQ(by_name.size(), by_index.size());
  for (std::size_t i = 0; i < by_name.size(); ++i)
    EXPECT_TRUE(by_name[i] == by_index[i] || (std::isnan(by_name[i]) && std::isnan(by_index[i]))) << i;
}

TEST_F(CliGeoTiff, BadNodataValuesAreUsageErrors) {
  const std::string tif = geoTiffInput();
  const std::string base = "svf " + shellQuoted(tif) + " -o " + shellQuoted(out("o.tif")) + " -k 4 --nodata ";
  for (const char* value : {"abc", "inf", "-inf", "1e39", "nan(1)", "", "-9999x"}) {
    SCOPED_TRACE(value);
    const CliResult result = run(base + shellQuoted(value));
    expectFailure(result, 2, "--nodata");
    EXPECT_NE(result.err.find(std::string("'") + value + "'"), std::string::npos) << result.err;
  }
  expectFailure(run("svf " + shellQuoted(tif) + " -o " + shellQuoted(out("o.tif")) + " --nodata"), 2,
                "--nodata");
  const CliResult exr =
      run("svf " + shellQuoted(tif) + " -o " + shellQuoted(out("o.exr")) + " --nodata -9999");
  expectFailure(exr, 2, "--nodata");
  EXPECT_NE(exr.err.find("GeoTIFF"), std::string::npos) << exr.err;
  expectFailure(
      run("horizons " + shellQuoted(tif) + " --at 1,1 -o " + shellQuoted(out("h.json")) + " --nodata 0"), 2,
      "--nodata");
  // (0 and above are svf values: refused, CliGeoTiff.NodataThatTheDataCanHoldIsRefused)
  for (const char* value : {"nan", "NaN", "-1", "-3.4e38"}) {
    SCOPED_TRACE(value);
    const CliResult good = run(base + shellQuoted(value) + " -q");
    EXPECT_EQ(good.status, 0) << good.err;
    fs::remove(out("o.tif"));
  }
}

// No output replaces an input, GeoTIFF or not: the same path, another path to it, a symbolic
// link or a hard link to it are refused before anything is read or written.
TEST_F(CliGeoTiff, GeoTiffOutputNeverReplacesTheInput) {
  const std::string tif = geoTiffInput();
  const std::string before = readText(tif);
  fs::create_symlink(tif, in("symlink.tif"));
  fs::create_hard_link(tif, in("hardlink.tif"));
  const std::string via_parent = (inputs() / ".." / "inputs" / "dem.tif").string();
  for (const std::string& output : {tif, via_parent, in("symlink.tif"), in("hardlink.tif")}) {
    SCOPED_TRACE(output);
    const CliResult result = run("svf " + shellQuoted(tif) + " -o " + shellQuoted(output) + " -k 4");
    expectFailure(result, 2, "outputs never replace an input");
    const CliResult distance = run("horizon " + shellQuoted(tif) + " -o " + shellQuoted(out("h.tif")) +
                                   " --distance-out " + shellQuoted(output) + " -k 4");
    expectFailure(distance, 2, "outputs never replace an input");
    EXPECT_EQ(readText(tif), before);
  }
  EXPECT_EQ(listDirectory(inputs()).size(), 3u);  // no temporary file beside the input
}

// A geographic (lat/lon) input stays geographic: its CRS and geotransform in degrees are copied
// as they are; only the cell size that the computation uses is in metres.
TEST_F(CliGeoTiff, GeographicInputStaysGeographic) {
  const double arcsec = 1.0 / 3600.0;
  const std::array<double, 6> degrees = {7.0, arcsec, 0.0, 45.0 + 10 * arcsec, 0.0, -arcsec};
  const std::string tif = geoTiffInput("wgs84.tif", degrees, "EPSG:4326");
  const CliResult result =
      run("svf " + shellQuoted(tif) + " -o " + shellQuoted(out("svf.TIFF")) + " -k 4 -q");
  ASSERT_EQ(result.status, 0) << result.err;
  const hfvis::testing::GdalRaster raster = hfvis::testing::readGdalRaster(out("svf.TIFF"));
  ASSERT_TRUE(raster.geotransform);
  EXPECT_EQ(*raster.geotransform, degrees);
  EXPECT_TRUE(hfvis::testing::sameCrs(raster.crs_wkt, hfvis::testing::crsWkt("EPSG:4326"))) << raster.crs_wkt;
  // WGS84 near 45 N: about 78847 m per degree of longitude, 111133 m per degree of latitude.
  EXPECT_NEAR(std::stod(raster.metadata.at("hfvis_cell_size_x")), 78846.8 * arcsec, 0.05);
  EXPECT_NEAR(std::stod(raster.metadata.at("hfvis_cell_size_y")), 111133.0 * arcsec, 0.05);
}

// A tall latitude / longitude grid (1 degree cells, rows centred on 65 .. 55 N): a wall 4 cells
// east of the receivers is seen from 4 times each row's own east-west spacing on the WGS84
// ellipsoid (47.2 km per cell at 65 N, 64.0 km at 55 N), not the centre row's, also within a
// maximum distance (both methods); on flat ground the visible area of viewcount sums each
// row's own spacing too.
TEST_F(Cli, GeographicGridTakesEachRowsSpacing) {
  const int width = 8, height = 11;
  std::vector<float> values(width * height, 0.0f);
  for (int r = 0; r < height; ++r)
    for (int c = 6; c < width; ++c) values[r * width + c] = 1000.0f;
  const std::string tif = in("tall.tif");
  hfvis::testing::writeGdalGeoTiff(tif, width, height, values, {10.0, 1.0, 0.0, 65.5, 0.0, -1.0}, "EPSG:4326",
                                   std::nullopt);
  const CliResult result = run("horizon " + shellQuoted(tif) + " -o " + shellQuoted(out("h.exr")) +
                               " --distance-out " + shellQuoted(out("d.exr")) + " -k 4 -q");
  ASSERT_EQ(result.status, 0) << result.err;
  const ReadBack d = readBack(out("d.exr"));
  for (int r = 0; r < height; ++r) {
    const double lat = (65.0 - r) * M_PI / 180.0, a = 6378137.0, e2 = 0.00669437999014132;
    const double east = a / std::sqrt(1.0 - e2 * std::sin(lat) * std::sin(lat)) * std::cos(lat) * M_PI / 180.0;
    EXPECT_NEAR(d.at(2, r, 0), 4.0 * east, 1e-5 * 4.0 * east) << "row " << r;
  }
  fs::remove(out("h.exr"));
  fs::remove(out("d.exr"));
  // Within --max-distance 220 km the rows whose wall lies nearer (4 x 47.2 to 55 km, the
  // northern rows) see it, the others see flat ground.
  const CliResult within = run("horizon " + shellQuoted(tif) + " -o " + shellQuoted(out("h.exr")) +
                               " -k 4 -q --max-distance 220000");
  ASSERT_EQ(within.status, 0) << within.err;
  const ReadBack h = readBack(out("h.exr"));
  int seen = 0;
  for (int r = 0; r < height; ++r) {
    const double lat = (65.0 - r) * M_PI / 180.0, a = 6378137.0, e2 = 0.00669437999014132;
    const double east = a / std::sqrt(1.0 - e2 * std::sin(lat) * std::sin(lat)) * std::cos(lat) * M_PI / 180.0;
    if (4.0 * east < 219000.0) {
      EXPECT_NEAR(h.at(2, r, 0), std::atan(1000.0 / (4.0 * east)), 1e-6) << "row " << r;
      ++seen;
    } else if (4.0 * east > 221000.0) {
      EXPECT_NEAR(h.at(2, r, 0), 0.0, 1e-6) << "row " << r;
    }
  }
  EXPECT_GT(seen, 2);
  EXPECT_LT(seen, height - 2);

  // The naive march cuts at the same ground length: along a row it samples the same pixels.
  const CliResult naive = run("horizon " + shellQuoted(tif) + " -o " + shellQuoted(out("n.exr")) +
                              " -k 4 -q --max-distance 220000 --method naive");
  ASSERT_EQ(naive.status, 0) << naive.err;
  const ReadBack n = readBack(out("n.exr"));
  for (int r = 0; r < height; ++r) EXPECT_NEAR(n.at(2, r, 0), h.at(2, r, 0), 1e-6) << "row " << r;
  fs::remove(out("h.exr"));
  fs::remove(out("n.exr"));
  // Flat ground: from column 2 every sample is seen, 5 east, 2 west, r north and 10 - r south.
  // Each axis stands for a quarter of the circle, so the area is pi / 2 times the sum over
  // the samples of their distance times their step toward the receiver: along the row the
  // row's east-west spacing, along the column the north-south spacing at each step's middle.
  const std::string flat = in("flat.tif");
  hfvis::testing::writeGdalGeoTiff(flat, width, height, std::vector<float>(width * height, 0.0f),
                                   {10.0, 1.0, 0.0, 65.5, 0.0, -1.0}, "EPSG:4326", std::nullopt);
  const CliResult counts = run("viewcount " + shellQuoted(flat) + " -o " + shellQuoted(out("v.exr")) + " -k 4 -q");
  ASSERT_EQ(counts.status, 0) << counts.err;
  EXPECT_EQ(counts.err.find("centre latitude"), std::string::npos) << counts.err;
  const ReadBack v = readBack(out("v.exr"));
  std::vector<double> east(height), north(height);  // per row, metres per degree
  for (int r = 0; r < height; ++r) {
    const double lat = (65.0 - r) * M_PI / 180.0, a = 6378137.0, e2 = 0.00669437999014132;
    const double w = 1.0 - e2 * std::sin(lat) * std::sin(lat);
    east[r] = a / std::sqrt(w) * std::cos(lat) * M_PI / 180.0;
    north[r] = a * (1.0 - e2) / (w * std::sqrt(w)) * M_PI / 180.0;
  }
  for (int r = 0; r < height; ++r) {
    double sum = east[r] * east[r] * (5.0 * 6.0 / 2.0 + 2.0 * 3.0 / 2.0);
    for (int dir : {-1, 1}) {
      double along = 0.0;
      for (int row = r + dir; row >= 0 && row < height; row += dir) {
        const double step = 0.5 * (north[row] + north[row - dir]);
        along += step;
        sum += along * step;
      }
    }
    EXPECT_EQ(v.at(2, r, 0), 7.0f + float(height - 1)) << "row " << r;
    EXPECT_NEAR(v.at(2, r, 1), M_PI / 2.0 * sum, 1e-4 * M_PI / 2.0 * sum) << "row " << r;
  }
}

}  // namespace

TEST_F(Cli, ViewshedSeesOverAWall) {
  // A wall 5 high across column 8 of flat ground at 0; the eye 2 above the ground at column 2.
  const std::string field = writeField("wall.exr", 16, 6, [](int col, int) { return col == 8 ? 5.0f : 0.0f; });
  const CliResult r = run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("v.exr")) +
                          " --observer 2,3 --angle --preview " + shellQuoted(out("v.png")));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("1 observer"), std::string::npos) << r.out;
  const ReadBack v = readBack(out("v.exr"));
  ASSERT_EQ(v.channels, (std::vector<std::string>{"angle", "visible"}));
  EXPECT_EQ(v.at(5, 3, 1), 1.0f);   // before the wall
  EXPECT_EQ(v.at(8, 3, 1), 1.0f);   // the wall's top
  EXPECT_EQ(v.at(12, 3, 1), 0.0f);  // behind it
  EXPECT_NEAR(v.at(8, 3, 0), std::atan2(3.0, 6.0) * 180.0 / M_PI, 1e-4);  // degrees above the eye's horizontal
  // Behind the wall a target needs the sight line over the wall's top: 2 + 10 * 3 / 6 = 7.
  ASSERT_EQ(run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("n.exr")) +
                " --observer 2,3 --needed-height -q").status, 0);
  const ReadBack needed = readBack(out("n.exr"));
  ASSERT_EQ(needed.channels, (std::vector<std::string>{"needed_height", "visible"}));
  EXPECT_NEAR(needed.at(12, 3, 0), 7.0f, 1e-4);
  EXPECT_EQ(needed.at(5, 3, 0), 0.0f);
  // A target 7 high behind the wall is seen over it; an eye 10 up sees the ground behind it.
  ASSERT_EQ(run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("t.exr")) +
                " --observer 2,3 --target-height 7 -q").status, 0);
  EXPECT_EQ(readBack(out("t.exr")).at(12, 3, 0), 1.0f);
  ASSERT_EQ(run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("a.exr")) +
                " --observer 2,3 --observer-height 10 --absolute -q").status, 0);
  EXPECT_EQ(readBack(out("a.exr")).at(15, 3, 0), 1.0f);
  // Several observers, on the command line and in a CSV: how many see each point.
  {
    std::ofstream csv(in("observers.csv"));
    csv << "col,row,height\n14,3\n# a comment\n\n8,0,1\n";
  }
  const CliResult c = run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("c.exr")) +
                          " --observer 2,3 --observers " + shellQuoted(in("observers.csv")) + " -q");
  ASSERT_EQ(c.status, 0) << c.err;
  const ReadBack count = readBack(out("c.exr"));
  ASSERT_EQ(count.channels, (std::vector<std::string>{"count"}));
  EXPECT_EQ(count.at(8, 3, 0), 3.0f);   // the wall's top: everyone
  // Behind the wall from column 2, in front of it from 14, and seen from the eye on the wall's end.
  EXPECT_EQ(count.at(12, 3, 0), 2.0f);
  // The header says the columns' order: row,col gives the same observers; one naming map coordinates
  // is refused (every header was passed over: row,col read as col,row, exit 0); others (x_pixel)
  // are taken as col,row. Each file holds the observers above, with its header.
  const auto sameObservers = [&](const std::string& name, const std::string& text) {
    {
      std::ofstream csv(in(name + ".csv"));
      csv << text;
    }
    const CliResult r = run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out(name + ".exr")) +
                            " --observer 2,3 --observers " + shellQuoted(in(name + ".csv")) + " -q");
    ASSERT_EQ(r.status, 0) << name << ": " << r.err;
    EXPECT_EQ(readBack(out(name + ".exr")).pixels, count.pixels) << name;
  };
  sameObservers("row_first", "Row,Col,Height\n3,14\n# a comment\n\n0,8,1\n");
  sameObservers("pixels", "x_pixel,y_pixel,observer_height\n14,3\n8,0,1\n");
  sameObservers("line", "col,line\n14,3\n8,0,1\n");  // (names it does not know stay col,row)
  sameObservers("pixel_col", "pixel_col,row,eye\n14,3\n8,0,1\n");
  for (const char* header : {"x,y", "lat,lon", "Easting,Northing,height"}) {
    {
      std::ofstream csv(in("named.csv"));
      csv << header << "\n3,4\n";
    }
    const CliResult named = run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("named.exr")) +
                                " --observers " + shellQuoted(in("named.csv")));
    EXPECT_EQ(named.status, 1) << header;
    EXPECT_NE(named.err.find("names map coordinates"), std::string::npos) << named.err;
    EXPECT_FALSE(fs::exists(out("named.exr"))) << header;
  }
  // The fields are read by position: a header naming a column or a row elsewhere, or a height
  // among the first two, is refused (id,col,row was read as column 7, row 30, height 40, exit 0).
  for (const char* header : {"id,col,row", "height,col,row", "col,col", "row,height", "a,b,col", "h,row,col",
                             "id,col", "row,line"}) {
    {
      std::ofstream csv(in("other.csv"));
      csv << header << "\n3,4,1\n";
    }
    const CliResult other = run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("other.exr")) +
                                " --observers " + shellQuoted(in("other.csv")));
    EXPECT_EQ(other.status, 1) << header;
    EXPECT_NE(other.err.find("lays the columns out otherwise"), std::string::npos) << other.err;
    EXPECT_FALSE(fs::exists(out("other.exr"))) << header;
  }
  // A height that is no number is named as such (the message spoke of whole columns and rows).
  for (const char* height : {"nan", "inf", "abc"}) {
    {
      std::ofstream csv(in("height.csv"));
      csv << "1,1," << height << "\n";
    }
    const CliResult bad = run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("h.exr")) +
                              " --observers " + shellQuoted(in("height.csv")));
    EXPECT_EQ(bad.status, 1) << height;
    EXPECT_NE(bad.err.find("the height '" + std::string(height) + "' is not a finite number"),
              std::string::npos)
        << bad.err;
  }
}

TEST_F(Cli, ViewshedCulledEqualsExact) {
  // Walls on flat ground: much lies in their shadows, which the pyramid culls.
  const std::string field = writeField("walls.exr", 48, 40, [](int col, int row) {
    return (col == 20 && row > 4) || (row == 30 && col < 40) ? 6.0f : 0.1f * ((col * 7 + row * 3) % 5);
  });
  const CliResult exact = run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("e.exr")) + " --observer 30,10");
  ASSERT_EQ(exact.status, 0) << exact.err;
  const CliResult culled = run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("c.exr")) +
                               " --observer 30,10 --method culled --cull-level 1");
  ASSERT_EQ(culled.status, 0) << culled.err;
  EXPECT_NE(culled.out.find("culled"), std::string::npos) << culled.out;
  EXPECT_NE(culled.out.find("% of the points culled"), std::string::npos) << culled.out;
  const ReadBack e = readBack(out("e.exr")), c = readBack(out("c.exr"));
  EXPECT_EQ(e.pixels, c.pixels);
  EXPECT_EQ(c.spec.get_string_attribute("hfvis:method"), "culled");
  // Several observers share one pyramid.
  ASSERT_EQ(run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("ce.exr")) +
                " --observer 30,10 --observer 5,35 -q").status, 0);
  ASSERT_EQ(run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("cc.exr")) +
                " --observer 30,10 --observer 5,35 --method culled -q").status, 0);
  EXPECT_EQ(readBack(out("ce.exr")).pixels, readBack(out("cc.exr")).pixels);
}

TEST_F(Cli, ViewshedRefusesBadObservers) {
  const std::string field = flat();
  expectFailure(run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("v.exr"))), 2, "--observer");
  expectFailure(run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("v.exr")) + " --observer 16,2"), 2,
                "outside");
  expectFailure(run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("v.exr")) +
                    " --observer 1,2 --observer 3,4 --angle"),
                2, "--angle");
  expectFailure(run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("v.exr")) +
                    " --observer 1,2 --cull-level 2"),
                2, "--method culled");
  expectFailure(run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("v.exr")) +
                    " --observer 1,2 --method culled --cull-level 13"),
                2, "--cull-level");
  expectFailure(run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("v.exr")) +
                    " --observer 1,2 --target-height -1"),
                2, "--target-height");
  expectFailure(run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("v.exr")) +
                    " --observer 1,2 --fov 10,400"),
                2, "--fov");
  // (FROM = TO, the library's whole circle, saw everything where the user asked for nothing)
  expectFailure(run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("v.exr")) +
                    " --observer 1,2 --fov 90,90"),
                2, "is no field of view");
  expectFailure(run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("v.exr")) + " --observer 1,2 -k 4"), 2,
                "-k");
  const std::string holes = writeField("holes.exr", 8, 8, [](int col, int row) {
    return col == 3 && row == 3 ? std::numeric_limits<float>::quiet_NaN() : 1.0f;
  });
  expectFailure(run("viewshed " + shellQuoted(holes) + " -o " + shellQuoted(out("v.exr")) + " --observer 3,3"), 2,
                "nodata");
  {
    std::ofstream csv(in("bad.csv"));
    csv << "col,row\n1,2\n3,x\n";
  }
  expectFailure(run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("v.exr")) + " --observers " +
                    shellQuoted(in("bad.csv"))),
                1, "line 3");
  // UTF-16 without a byte-order mark (zero bytes between the characters), and a point beyond any
  // field: said as such, not as a malformed line.
  {
    std::ofstream csv(in("utf16.csv"), std::ios::binary);
    for (char c : std::string("1,2\n")) csv << c << '\0';
  }
  expectFailure(run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("v.exr")) + " --observers " +
                    shellQuoted(in("utf16.csv"))),
                1, "UTF-16 text without a byte-order mark");
  {
    std::ofstream csv(in("far.csv"));
    csv << "1,2\n3e9,4\n";
  }
  expectFailure(run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("v.exr")) + " --observers " +
                    shellQuoted(in("far.csv"))),
                1, "line 2: the point 3e+09,4 lies outside the field");
  // A trailing comma is an empty field, not the end of the line (a height left out by mistake).
  for (const char* line : {"1,2,", "1,2,3,", "1,2 , "}) {
    SCOPED_TRACE(line);
    {
      std::ofstream csv(in("comma.csv"));
      csv << "3,3\n" << line << "\n";
    }
    expectFailure(run("viewshed " + shellQuoted(field) + " -o " + shellQuoted(out("v.exr")) +
                      " --observers " + shellQuoted(in("comma.csv"))),
                  1, "line 2");
  }
}

// ---- issue 26: no data loss, no silent garbage ----

namespace {

// Starts `hfvis ARGS` as a child process (its output to files under the test's directory) and
// returns its process id, so that a test can act while it runs.
pid_t startCli(const fs::path& root, const std::vector<std::string>& args) {
  const pid_t child = ::fork();
  if (child == 0) {
    std::freopen((root / "stdout.txt").c_str(), "w", stdout);
    std::freopen((root / "stderr.txt").c_str(), "w", stderr);
    std::vector<char*> argv{const_cast<char*>(HFVIS_CLI_PATH)};
    for (const std::string& arg : args) argv.push_back(const_cast<char*>(arg.c_str()));
    argv.push_back(nullptr);
    ::execv(HFVIS_CLI_PATH, argv.data());
    ::_exit(127);
  }
  return child;
}

// Waits until `directory` holds an entry whose name starts with `prefix` (a temporary file being
// written), or the process has ended, or 60 s have passed. Whether it appeared.
bool awaitEntry(const fs::path& directory, const std::string& prefix, pid_t process) {
  const auto end = std::chrono::steady_clock::now() + std::chrono::seconds(60);
  while (std::chrono::steady_clock::now() < end) {
    for (const std::string& name : listDirectory(directory))
      if (name.rfind(prefix, 0) == 0) return true;
    if (::waitpid(process, nullptr, WNOHANG) == process) return false;
    ::usleep(200);
  }
  return false;
}

}  // namespace

// Item 2: a later output that cannot be put in place (a directory appeared at its path while the
// run computed) used to take the earlier output's new file away with the file it had replaced.
// Every file that was there stays as it was.
TEST_F(Cli, ALaterOutputThatFailsLeavesTheEarlierOnesAsTheyWere) {
  const std::string field = writeField("busy.exr", 256, 256, [](int col, int row) {
    return static_cast<float>(10.0 * std::sin(0.11 * col) * std::cos(0.07 * row));
  });
  { std::ofstream(out("h.tif")) << "previous horizons"; }
  const pid_t hfvis = startCli(
      root_, {"horizon", field, "-o", out("h.tif"), "--distance-out", out("d.tif"), "-k", "16", "-q"});
  // Once h.tif's temporary file is being written, the run is past its first checks.
  const bool staged = awaitEntry(outputs(), ".h.", hfvis);
  fs::create_directory(out("d.tif"));
  int status = 0;
  ::waitpid(hfvis, &status, 0);
  ASSERT_TRUE(staged) << "the run ended before writing its outputs: " << readText(root_ / "stderr.txt");
  ASSERT_TRUE(WIFEXITED(status));
  EXPECT_EQ(WEXITSTATUS(status), 1) << "the directory came too late to test anything";
  const std::string err = readText(root_ / "stderr.txt");
  EXPECT_NE(err.find(out("d.tif")), std::string::npos) << err;
  EXPECT_EQ(readText(out("h.tif")), "previous horizons");
  std::vector<std::string> left = listDirectory(outputs());
  std::sort(left.begin(), left.end());
  EXPECT_EQ(left, (std::vector<std::string>{"d.tif", "h.tif"}));
}

// Item 6: renaming a new file over a write-protected one would bypass the protection (and leave
// the file writable): it is refused before anything is computed, and stays as it was.
TEST_F(Cli, AWriteProtectedOutputIsRefusedAndKept) {
  { std::ofstream(out("prot.tif")) << "protected"; }
  fs::permissions(out("prot.tif"), fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
  const CliResult result =
      run("svf " + shellQuoted(ramp()) + " -o " + shellQuoted(out("prot.tif")) + " -k 4");
  EXPECT_EQ(result.status, 1) << result.err;
  EXPECT_NE(result.err.find("write-protected"), std::string::npos) << result.err;
  EXPECT_EQ(readText(out("prot.tif")), "protected");
  EXPECT_EQ(fs::status(out("prot.tif")).permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
  EXPECT_EQ(listDirectory(outputs()), std::vector<std::string>{"prot.tif"});
}

// Item 6: an output at a symbolic link replaces the file the link names; the link stays a link.
TEST_F(Cli, AnOutputAtASymbolicLinkReplacesWhatItNames) {
  fs::create_directories(outputs() / "store");
  { std::ofstream(out("store/svf.exr")) << "old"; }
  fs::create_symlink("store/svf.exr", out("svf.exr"));
  const CliResult result =
      run("svf " + shellQuoted(flat()) + " -o " + shellQuoted(out("svf.exr")) + " -k 4 -q");
  ASSERT_EQ(result.status, 0) << result.err;
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(out("svf.exr"))));
  const ReadBack image = readBack(out("store/svf.exr"));
  EXPECT_EQ(image.channels, std::vector<std::string>{"svf"});
}

// Item 7: SIGINT, SIGTERM and SIGHUP during the write phase leave no temporary file behind, and
// the earlier result stays.
TEST_F(Cli, AnInterruptedRunLeavesNoTemporaryFiles) {
  const std::string field = writeField("busy.exr", 256, 256, [](int col, int row) {
    return static_cast<float>(10.0 * std::sin(0.11 * col) * std::cos(0.07 * row));
  });
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP}) {
    SCOPED_TRACE(signal_number);
    { std::ofstream(out("h.exr")) << "previous horizons"; }
    const pid_t hfvis = startCli(
        root_, {"horizon", field, "-o", out("h.exr"), "--distance-out", out("d.exr"), "-k", "16", "-q"});
    const bool staged = awaitEntry(outputs(), ".h.", hfvis);
    ::kill(hfvis, signal_number);
    int status = 0;
    ::waitpid(hfvis, &status, 0);
    ASSERT_TRUE(staged) << "the run ended before writing its outputs: " << readText(root_ / "stderr.txt");
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == signal_number) << "status " << status;
    EXPECT_EQ(listDirectory(outputs()), std::vector<std::string>{"h.exr"});
    EXPECT_EQ(readText(out("h.exr")), "previous horizons");
  }
}

// Item 11: a device, FIFO or directory given as a file is refused at once, with what it is
// (/dev/zero was read forever; a FIFO would block the open).
TEST_F(Cli, NonRegularFilesAreRefusedAtOnce) {
  const std::string fifo = in("pipe.exr");
  ASSERT_EQ(::mkfifo(fifo.c_str(), 0600), 0);
  const std::string field = flat();
  const std::string o = " -o " + shellQuoted(out("o.tif"));
  const std::vector<std::pair<std::string, std::string>> cases{
      {"svf /dev/zero" + o + " -k 4", "character device"},
      {"svf " + shellQuoted(fifo) + o + " -k 4", "FIFO"},
      {"svf " + shellQuoted(inputs().string()) + o, "directory"},
      {"svf /dev/null" + o, "character device"},
      {"viewshed " + shellQuoted(field) + o + " --observers /dev/zero", "character device"},
      {"shade " + shellQuoted(field) + o + " --env /dev/zero", "character device"},
      {"shade " + shellQuoted(field) + o + " --sun 180,30 --albedo " + shellQuoted(fifo), "FIFO"},
      {"bounce " + shellQuoted(field) + o + " --radiance /dev/zero", "character device"},
  };
  for (const auto& [args, named] : cases) {
    SCOPED_TRACE(args);
    const auto start = std::chrono::steady_clock::now();
    const CliResult result = run(args);
    EXPECT_LT(std::chrono::steady_clock::now() - start, std::chrono::seconds(30));
    expectFailure(result, 1, named);
  }
}

// Item 4: data outputs are float32 (EXR or GeoTIFF); an 8-bit format would clip negative angles
// to 0 and saturate counts at 255 without a word.
TEST_F(Cli, DataOutputsAreNeverEightBitImages) {
  for (const char* name : {"o.png", "o.jpg", "o.bmp", "o.PNG"}) {
    SCOPED_TRACE(name);
    const CliResult result =
        run("horizon " + shellQuoted(ramp()) + " -o " + shellQuoted(out(name)) + " -k 4");
    expectFailure(result, 1, "--preview");
  }
}

// Item 8: a --nodata value the output can hold as data (a viewshed's hidden 0 or visible 1, an
// svf of 1) is refused: readers would take those cells for nodata.
TEST_F(CliGeoTiff, NodataThatTheDataCanHoldIsRefused) {
  const std::string tif = geoTiffInput();
  for (const char* args :
       {"viewshed --observer 5,5 --nodata 0", "viewshed --observer 5,5 --nodata 1", "svf -k 4 --nodata 1",
        "horizon -k 4 --nodata -1", "viewshed --observer 5,5 --angle --nodata -45",
        // (below -pi/2 in double, float32's -pi/2 itself: the angles hold it)
        "horizon -k 4 --nodata -1.57079638"}) {
    SCOPED_TRACE(args);
    const std::string command(args);
    const std::size_t space = command.find(' ');
    const CliResult result = run(command.substr(0, space) + " " + shellQuoted(tif) + " -o " +
                                 shellQuoted(out("o.tif")) + command.substr(space));
    expectFailure(result, 2, "--nodata");
  }
  const CliResult fine = run("viewshed " + shellQuoted(tif) + " -o " + shellQuoted(out("v.tif")) +
                             " --observer 5,5 --nodata -1 -q");
  ASSERT_EQ(fine.status, 0) << fine.err;
  const hfvis::testing::GdalRaster raster = hfvis::testing::readGdalRaster(out("v.tif"));
  ASSERT_TRUE(raster.nodata[0].has_value());
  EXPECT_EQ(*raster.nodata[0], -1.0);
  for (float v : raster.bands[0]) EXPECT_TRUE(v == 0.0f || v == 1.0f || v == -1.0f) << v;
}

// Item 9: numbers the single-precision kernels cannot hold are refused instead of giving NaN,
// infinite or meaningless results with exit status 0; messages never print 300 digits.
TEST_F(Cli, NumbersBeyondWhatTheMethodHoldsAreRefused) {
  const std::string field = flat();
  const std::string o = " -o " + shellQuoted(out("o.exr"));
  for (const std::string& args :
       {"svf " + shellQuoted(field) + o + " --azimuth-offset 1e20",
        "svf " + shellQuoted(field) + o + " --cell-size 1e-300",
        "svf " + shellQuoted(field) + o + " --cell-size 1e300",
        "viewcount " + shellQuoted(field) + o + " --cell-size 1e18",
        "shade " + shellQuoted(field) + o + " --sun 180,30 --sun-irradiance 1e300",
        "viewshed " + shellQuoted(field) + o + " --observer 1,1 --observer-height 1e300",
        "svf " + shellQuoted(field) + o + " --max-distance 1e300",
        "svf " + shellQuoted(field) + o + " --z-scale 1e-300",
        "horizon " + shellQuoted(field) + o + " --azimuth-tolerance 5.73"}) {
    SCOPED_TRACE(args);
    const CliResult result = run(args);
    expectFailure(result, 2, "must be in");
    EXPECT_LT(result.err.size(), 400u) << result.err;
  }
  // The environment's rotation, whose every value has an equal one within a turn.
  const CliResult rotated =
      run("shade " + shellQuoted(field) + o + " --env " + shellQuoted(field) + " --env-rotate 1e308");
  expectFailure(rotated, 2, "--env-rotate");
  // The largest tolerance the help gives is accepted.
  const CliResult widest = run("horizon " + shellQuoted(field) + o + " -k 4 -q --azimuth-tolerance 5.72958");
  EXPECT_EQ(widest.status, 0) << widest.err;
}

// Items 10 and 13: shade agrees with insolation that a sun below elevation 0 lights nothing, and
// takes a point sun (--sun-size 0: hard shadows).
TEST_F(Cli, ShadeWithTheSunDownOrAPointSun) {
  const std::string field = flat();
  const CliResult down =
      run("shade " + shellQuoted(field) + " -o " + shellQuoted(out("down.exr")) + " --sun 180,-30 -q");
  ASSERT_EQ(down.status, 0) << down.err;
  for (float v : readBack(out("down.exr")).pixels) EXPECT_EQ(v, 0.0f);
  // At midnight at 45 N in June the sun is 21 degrees down: no pixel sees it, not even at the border.
  const CliResult night = run("shade " + shellQuoted(ramp()) + " -o " + shellQuoted(out("night.exr")) +
                              " --at 2026-06-21T00:00:00Z --lat 45 --lon 7 -q");
  ASSERT_EQ(night.status, 0) << night.err;
  for (float v : readBack(out("night.exr")).pixels) EXPECT_EQ(v, 0.0f);
  const CliResult point = run("shade " + shellQuoted(field) + " -o " + shellQuoted(out("point.exr")) +
                              " --sun 200,30 --sun-size 0 -q");
  ASSERT_EQ(point.status, 0) << point.err;
  const ReadBack p = readBack(out("point.exr"));
  for (int y = 0; y < p.height; ++y)
    for (int x = 0; x < p.width; ++x) EXPECT_EQ(p.at(x, y, 1), 1.0f);
  EXPECT_EQ(p.spec.get_string_attribute("hfvis:sun_size_deg"), "0");
}

// Item 5: where PoCL's kernel cache cannot be written (the user nobody, a read-only home), hfvis
// uses a private one instead of reporting no OpenCL device; a POCL_CACHE_DIR that cannot be used
// is named as the problem, instead of PoCL's assertion (exit 134) or a failed build.
TEST_F(Cli, AnUnwritableKernelCacheIsNotAMissingDriver) {
  const std::string field = flat();
  // /proc takes no new directories, even from the superuser.
  const CliResult homeless =
      run("svf " + shellQuoted(field) + " -o " + shellQuoted(out("o.exr")) + " -k 4 -q",
          "env -u POCL_CACHE_DIR HOME=/proc/hfvis-no-home XDG_CACHE_HOME=");
  EXPECT_EQ(homeless.status, 0) << homeless.err;
  const std::string file = in("not_a_directory");
  { std::ofstream(file) << "x"; }
  for (const std::string& setting : {std::string("POCL_CACHE_DIR="), "POCL_CACHE_DIR=" + shellQuoted(file),
                                     std::string("POCL_CACHE_DIR=/proc/hfvis-cache")}) {
    SCOPED_TRACE(setting);
    for (const std::string& args :
         {"svf " + shellQuoted(field) + " -o " + shellQuoted(out("p.exr")) + " -k 4",
          std::string("devices")}) {
      const CliResult result = run(args, "env " + setting);
      EXPECT_EQ(result.status, 1) << result.err;
      EXPECT_NE(result.err.find("POCL_CACHE_DIR"), std::string::npos) << result.err;
    }
  }
  EXPECT_FALSE(fs::exists(out("p.exr")));
}

// Item 3: a raster whose columns run east to west (negative pixel width), or whose rows run south
// to north, or both (an ESRI grid with a negative cell size), is lit and looked at as it lies:
// each gives, cell for cell, what the same ground stored north-up gives.
TEST_F(CliGeoTiff, EveryFlipOfTheGridIsLitAsItLies) {
  const int w = kWidth, h = kHeight;
  std::vector<float> north_up;
  for (int row = 0; row < h; ++row)
    for (int col = 0; col < w; ++col) north_up.push_back(height(col, row));
  const double west = 500000.0, east = west + 30.0 * w, north = 4100000.0, south = north - 30.0 * h;
  struct Layout {
    const char* name;
    bool mirror_columns, mirror_rows;
    std::array<double, 6> transform;
  };
  const std::vector<Layout> layouts{{"north_up", false, false, {west, 30.0, 0.0, north, 0.0, -30.0}},
                                    {"west_up", true, false, {east, -30.0, 0.0, north, 0.0, -30.0}},
                                    {"south_up", false, true, {west, 30.0, 0.0, south, 0.0, 30.0}},
                                    {"upside_down", true, true, {east, -30.0, 0.0, south, 0.0, 30.0}}};
  const auto stored = [&](const Layout& l, int col, int row) {
    return (l.mirror_rows ? h - 1 - row : row) * w + (l.mirror_columns ? w - 1 - col : col);
  };
  std::map<std::string, std::vector<std::vector<float>>> results;  // per layout, per run, north-up order
  for (const Layout& l : layouts) {
    SCOPED_TRACE(l.name);
    std::vector<float> values(north_up.size());
    for (int row = 0; row < h; ++row)
      for (int col = 0; col < w; ++col) values[stored(l, col, row)] = north_up[row * w + col];
    const std::string tif = in(std::string(l.name) + ".tif");
    hfvis::testing::writeGdalGeoTiff(tif, w, h, values, l.transform, "EPSG:32633", std::nullopt);
    // The observer on the same ground cell (column 5, row 7 north-up).
    const int col = l.mirror_columns ? w - 1 - 5 : 5, row = l.mirror_rows ? h - 1 - 7 : 7;
    for (const std::string& args :
         {std::string("shade --sun 135,20"),
          std::string("insolation --lat 45 --lon 7 --from 2026-06-21T04:00:00Z "
                      "--to 2026-06-21T10:00:00Z --step 60"),
          "viewshed --fov 0,90 --observer " + std::to_string(col) + "," + std::to_string(row)}) {
      const std::size_t space = args.find(' ');
      const CliResult result =
          run(args.substr(0, space) + " " + shellQuoted(tif) + " -o " +
              shellQuoted(out(std::string(l.name) + ".tif")) + args.substr(space) + " -q");
      ASSERT_EQ(result.status, 0) << args << ": " << result.err;
      const hfvis::testing::GdalRaster raster =
          hfvis::testing::readGdalRaster(out(std::string(l.name) + ".tif"));
      for (const std::vector<float>& band : raster.bands) {
        std::vector<float> ordered(band.size());
        for (int r = 0; r < h; ++r)
          for (int c = 0; c < w; ++c) ordered[r * w + c] = band[stored(l, c, r)];
        results[l.name].push_back(ordered);
      }
    }
  }
  for (const Layout& l : layouts) {
    ASSERT_EQ(results[l.name].size(), results["north_up"].size()) << l.name;
    for (std::size_t i = 0; i < results[l.name].size(); ++i)
      for (std::size_t p = 0; p < results[l.name][i].size(); ++p)
        EXPECT_NEAR(results[l.name][i][p], results["north_up"][i][p], 1e-4)
            << l.name << ", band " << i << ", column " << p % w << ", row " << p / w;
  }
}

// Item 12: in the horizon lists' CSV a nodata receiver is told apart from one without horizons.
TEST_F(Cli, HorizonsCsvMarksANodataReceiver) {
  const std::string field = writeField("hole.exr", 8, 8, [](int col, int row) {
    return col == 3 && row == 3 ? std::numeric_limits<float>::quiet_NaN() : 1.0f;
  });
  const CliResult result =
      run("horizons " + shellQuoted(field) + " --at 3,3 --at 0,0 -k 4 -q -o " + shellQuoted(out("h.csv")));
  ASSERT_EQ(result.status, 0) << result.err;
  const std::vector<std::string> lines = splitText(readText(out("h.csv")), '\n');
  int nodata = 0, data = 0;
  for (std::size_t i = 1; i < lines.size(); ++i) {
    if (lines[i].empty()) continue;
    const std::vector<std::string> fields = splitText(lines[i], ',');
    ASSERT_EQ(fields.size(), 13u) << lines[i];
    (fields[0] == "3" ? nodata : data) += 1;
    EXPECT_EQ(fields[12], fields[0] == "3" ? "1" : "0") << lines[i];
  }
  EXPECT_EQ(nodata, 4);
  EXPECT_GE(data, 4);
}

// Item 12: an RGB GeoTIFF (bands without descriptions, colour interpretation Red, Green, Blue) is
// an albedo of three channels, as the help says; --sun-irradiance without --albedo, which changed
// nothing, is a usage error.
TEST_F(CliGeoTiff, AnRgbGeoTiffIsAnAlbedo) {
  const std::string tif = geoTiffInput();
  const std::string rgb = in("albedo.tif");
  hfvis::testing::registerGdal();
  char** options = CSLSetNameValue(nullptr, "PHOTOMETRIC", "RGB");
  GDALDatasetH dataset =
      GDALCreate(GDALGetDriverByName("GTiff"), rgb.c_str(), kWidth, kHeight, 3, GDT_Byte, options);
  CSLDestroy(options);
  ASSERT_NE(dataset, nullptr);
  std::array<double, 6> transform = hfvis::testing::kUtmGeotransform;
  GDALSetGeoTransform(dataset, transform.data());
  for (int b = 0; b < 3; ++b) {
    std::vector<unsigned char> values(kWidth * kHeight, static_cast<unsigned char>(b == 0 ? 0 : 1));
    EXPECT_EQ(GDALRasterIO(GDALGetRasterBand(dataset, b + 1), GF_Write, 0, 0, kWidth, kHeight, values.data(),
                           kWidth, kHeight, GDT_Byte, 0, 0),
              CE_None);
  }
  GDALClose(dataset);
  const CliResult result = run("shade " + shellQuoted(tif) + " -o " + shellQuoted(out("s.tif")) +
                               " --sun 180,40 --albedo " + shellQuoted(rgb) + " -q");
  ASSERT_EQ(result.status, 0) << result.err;
  const hfvis::testing::GdalRaster raster = hfvis::testing::readGdalRaster(out("s.tif"));
  EXPECT_EQ(raster.descriptions,
            (std::vector<std::string>{"direct", "sun", "radiance.R", "radiance.G", "radiance.B"}));
  fs::remove(out("s.tif"));
  expectFailure(run("shade " + shellQuoted(tif) + " -o " + shellQuoted(out("t.tif")) +
                    " --sun 180,40 --sun-irradiance 3"),
                2, "--albedo");
}

// Item 12: one rule for repeated options: each once, but --observer and the receivers' --at,
// which add to a list (a second -o, -k or --method used to replace the first silently).
TEST_F(Cli, EachOptionIsGivenOnce) {
  const std::string field = flat();
  const std::string o = " -o " + shellQuoted(out("a.exr"));
  for (const std::string& twice : {o + " -k 4 -k 8", o + " -o " + shellQuoted(out("b.exr")),
                                   o + " --method sweep --method naive", o + " -q -q"}) {
    SCOPED_TRACE(twice);
    expectFailure(run("svf " + shellQuoted(field) + twice), 2, "given twice");
  }
  expectFailure(
      run("viewshed " + shellQuoted(field) + o + " --observer 1,1 --observers a.csv --observers b.csv"), 2,
      "given twice");
  const CliResult lists =
      run("horizons " + shellQuoted(field) + " --at 1,1 --at 2,2 -k 4 -q -o " + shellQuoted(out("h.json")));
  EXPECT_EQ(lists.status, 0) << lists.err;
}

// Item 12: a file whose georeference or cell size cannot be right is refused with what is wrong
// (a rotated grid even with --cell-size, latitudes beyond the poles, a damaged
// hfvis:cell_size_x), where it used to run with a wrong or default spacing.
TEST_F(CliGeoTiff, ImpossibleGeoreferencesAndCellSizesAreRefused) {
  std::vector<float> values(kWidth * kHeight, 1.0f);
  hfvis::testing::writeGdalGeoTiff(in("rotated.tif"), kWidth, kHeight, values,
                                   {500000.0, 30.0, 5.0, 4100000.0, 5.0, -30.0}, "EPSG:32633", std::nullopt);
  expectFailure(run("svf " + shellQuoted(in("rotated.tif")) + " -o " + shellQuoted(out("o.tif")) +
                    " -k 4 --cell-size 30"),
                1, "rotated");
  hfvis::testing::writeGdalGeoTiff(in("polar.tif"), kWidth, kHeight, values,
                                   {10.0, 0.5, 0.0, 95.0, 0.0, -0.5}, "EPSG:4326", std::nullopt);
  expectFailure(run("svf " + shellQuoted(in("polar.tif")) + " -o " + shellQuoted(out("o.tif")) + " -k 4"), 1,
                "beyond the poles");
  hfvis::ImageChannels image;
  image.width = kWidth;
  image.height = kHeight;
  image.names = {"Y"};
  image.planes = {values};
  image.attributes = {{"hfvis:cell_size_x", "abc"}, {"hfvis:cell_size_y", "30"}};
  hfvis::writeImage(in("damaged.exr"), image);
  expectFailure(run("svf " + shellQuoted(in("damaged.exr")) + " -o " + shellQuoted(out("o.exr")) + " -k 4"),
                1, "hfvis:cell_size_x");
  // With --cell-size the attributes are not read.
  const CliResult given = run("svf " + shellQuoted(in("damaged.exr")) + " -o " + shellQuoted(out("o.exr")) +
                              " -k 4 -q --cell-size 30");
  EXPECT_EQ(given.status, 0) << given.err;
}

// ---- arealight and region (hfvis/region_visibility.hpp) ----

namespace {
// A 16 x 12 field: ground at 0, a wall 5 high across column 8 (every row).
constexpr int kWallWidth = 16, kWallHeight = 12;
float wallHeight(int col, int) { return col == 8 ? 5.0f : 0.0f; }
}  // namespace

TEST_F(Cli, AreaLightOnFlatGroundSeesEverySample) {
  const std::string field = writeField("flat1.exr", 16, 12, [](int, int) { return 1.0f; });
  const CliResult r = run("arealight " + shellQuoted(field) + " -o " + shellQuoted(out("a.exr")) +
                          " --light 2,2,5,4 --samples 20 --masks " + shellQuoted(out("m.exr")) +
                          " --preview " + shellQuoted(out("a.png")));
  ASSERT_EQ(r.status, 0) << r.err;
  EXPECT_NE(r.out.find("20 light samples"), std::string::npos) << r.out;
  const ReadBack a = readBack(out("a.exr"));
  ASSERT_EQ(a.channels, (std::vector<std::string>{"visible"}));
  for (float v : a.pixels) ASSERT_EQ(v, 1.0f);
  EXPECT_EQ(a.spec.get_string_attribute("hfvis:command"), "arealight");
  EXPECT_EQ(a.spec.get_string_attribute("hfvis:light_samples"), "20");
  // 20 samples: channel m000 all 16 bits, m001 the 4 bits of samples 16 .. 19.
  const ReadBack m = readBack(out("m.exr"));
  ASSERT_EQ(m.channels, (std::vector<std::string>{"m000", "m001"}));
  for (int y = 0; y < m.height; ++y)
    for (int x = 0; x < m.width; ++x) {
      ASSERT_EQ(m.at(x, y, 0), 65535.0f);
      ASSERT_EQ(m.at(x, y, 1), 15.0f);
    }
  EXPECT_TRUE(fs::exists(out("a.png")));
}

TEST_F(Cli, AreaLightImageColoursTheLight) {
  // A 3 x 2 RGB image over the light behind the wall: channels R, G, B as the library's, and a
  // grey image the same value in all three.
  const std::string field = writeField("wall.exr", kWallWidth, kWallHeight, wallHeight);
  hfvis::ImageChannels image;
  image.width = 3;
  image.height = 2;
  image.names = {"R", "G", "B"};
  image.planes = {{1, 2, 3, 4, 5, 6}, {0, 0, 1, 1, 0, 0}, {0.5f, 0.25f, 0, 0, 2, 8}};
  hfvis::writeImage(in("light.exr"), image);
  const CliResult r = run("arealight " + shellQuoted(field) + " -o " + shellQuoted(out("a.exr")) +
                          " --light 1,2,3,9 --light-height 1 --samples 37 --decorrelate --light-image " +
                          shellQuoted(in("light.exr")) + " -q");
  ASSERT_EQ(r.status, 0) << r.err;
  const ReadBack a = readBack(out("a.exr"));
  // (an EXR lists R, G, B first)
  ASSERT_EQ(a.channels, (std::vector<std::string>{"R", "G", "B", "visible"}));
  EXPECT_EQ(a.spec.get_string_attribute("hfvis:light_image"), in("light.exr"));
  const hfvis::HeightField f = hfvis::readHeightField(field);
  hfvis::RegionSampling light;
  light.rectangle = {1, 2, 3, 9};
  light.height = 1.0;
  light.samples = 37;
  hfvis::RegionVisibilityOptions options;
  options.decorrelate = true;
  options.light_image.width = 3;
  options.light_image.height = 2;
  for (const auto& plane : image.planes)
    options.light_image.rgb.insert(options.light_image.rgb.end(), plane.begin(), plane.end());
  const hfvis::RegionVisibilityResult lib =
      hfvis::computeRegionVisibility(hfvis::testing::testContext(), f, light, options);
  for (int y = 0; y < kWallHeight; ++y)
    for (int x = 0; x < kWallWidth; ++x) {
      const std::size_t p = std::size_t(y) * kWallWidth + x;
      ASSERT_EQ(a.at(x, y, 0), lib.red[p]) << x << "," << y;
      ASSERT_EQ(a.at(x, y, 1), lib.green[p]) << x << "," << y;
      ASSERT_EQ(a.at(x, y, 2), lib.blue[p]) << x << "," << y;
      ASSERT_EQ(a.at(x, y, 3), lib.fraction[p]) << x << "," << y;
    }
  EXPECT_GT(a.at(5, 5, 0), 0.0f);  // lit in front of the wall, dark behind
  EXPECT_EQ(a.at(12, 5, 0), 0.0f);
  // One grey channel: R = G = B.
  hfvis::ImageChannels grey;
  grey.width = 2;
  grey.height = 2;
  grey.names = {"Y"};
  grey.planes = {{1, 3, 0.5f, 2}};
  hfvis::writeImage(in("grey.exr"), grey);
  ASSERT_EQ(run("arealight " + shellQuoted(field) + " -o " + shellQuoted(out("g.exr")) +
                " --light 1,2,3,9 --light-height 1 --samples 37 --light-image " +
                shellQuoted(in("grey.exr")) + " -q")
                .status,
            0);
  const ReadBack g = readBack(out("g.exr"));
  ASSERT_EQ(g.channels, (std::vector<std::string>{"R", "G", "B", "visible"}));
  for (int y = 0; y < kWallHeight; ++y)
    for (int x = 0; x < kWallWidth; ++x) {
      ASSERT_EQ(g.at(x, y, 0), g.at(x, y, 1));
      ASSERT_EQ(g.at(x, y, 0), g.at(x, y, 2));
    }
  EXPECT_GT(g.at(5, 5, 0), 0.0f);
}

TEST_F(Cli, AreaLightBehindAWallIsHiddenAndAgreesWithTheLibrary) {
  const std::string field = writeField("wall.exr", kWallWidth, kWallHeight, wallHeight);
  // The light on the ground's near side, 1 above it: the wall hides it from the ground behind.
  const CliResult r =
      run("arealight " + shellQuoted(field) + " -o " + shellQuoted(out("a.exr")) +
          " --light 1,2,3,9 --light-height 1 --samples 37 --masks " + shellQuoted(out("m.tif")) + " -q");
  ASSERT_EQ(r.status, 0) << r.err;
  const ReadBack a = readBack(out("a.exr"));
  ASSERT_EQ(a.channels, (std::vector<std::string>{"visible"}));
  for (int y = 0; y < kWallHeight; ++y) {
    EXPECT_EQ(a.at(5, y, 0), 1.0f) << "row " << y;   // in front of the wall
    EXPECT_EQ(a.at(12, y, 0), 0.0f) << "row " << y;  // behind it
  }
  // The same numbers as the library's own call.
  const hfvis::HeightField f = hfvis::readHeightField(field);
  hfvis::RegionSampling light;
  light.rectangle = {1, 2, 3, 9};
  light.height = 1.0;
  light.samples = 37;
  const hfvis::RegionVisibilityResult lib = hfvis::computeRegionVisibility(
      hfvis::testing::testContext(), f, light, hfvis::RegionVisibilityOptions{});
  ASSERT_EQ(lib.fraction.size(), a.pixels.size());
  for (std::size_t p = 0; p < lib.fraction.size(); ++p)
    ASSERT_EQ(a.pixels[p], lib.fraction[p]) << "pixel " << p;
  // The masks, bit for bit: 37 samples in three 16-bit channels, read back from the GeoTIFF.
  const ReadBack m = readBack(out("m.tif"));
  ASSERT_EQ(m.channels.size(), 3u);
  for (int y = 0; y < kWallHeight; ++y)
    for (int x = 0; x < kWallWidth; ++x) {
      const std::size_t p = std::size_t(y) * kWallWidth + x;
      for (int s = 0; s < 37; ++s) {
        const auto bits = static_cast<std::uint32_t>(m.at(x, y, s / 16));
        ASSERT_EQ((bits >> (s % 16)) & 1u, lib.visible(p, s) ? 1u : 0u) << x << "," << y << " sample " << s;
      }
    }
  // The corners in any order: the same rectangle, the same samples.
  ASSERT_EQ(run("arealight " + shellQuoted(field) + " -o " + shellQuoted(out("r.exr")) +
                " --light 3,9,1,2 --light-height 1 --samples 37 -q")
                .status,
            0);
  EXPECT_EQ(readBack(out("r.exr")).pixels, a.pixels);
  // A light in the plane 20 high (--absolute): every line from it to the ground at column 12
  // passes column 8 above 7, over the wall.
  ASSERT_EQ(run("arealight " + shellQuoted(field) + " -o " + shellQuoted(out("h.exr")) +
                " --light 1,2,3,9 --light-height 20 --absolute -q")
                .status,
            0);
  EXPECT_EQ(readBack(out("h.exr")).at(12, 5, 0), 1.0f);
  // The culled method (the default's at 16 samples), the exact one and the bitmask scatter write the same
  // picture, each naming itself.
  for (const char* method : {"exact", "culled", "bitmask"})
    ASSERT_EQ(
        run("arealight " + shellQuoted(field) + " -o " + shellQuoted(out(std::string(method) + ".exr")) +
            " --light 1,2,3,9 --light-height 20 --absolute --method " + method + " -q")
            .status,
        0);
  const ReadBack exact = readBack(out("exact.exr")), culled = readBack(out("culled.exr"));
  EXPECT_EQ(exact.pixels, culled.pixels);
  const ReadBack bitmask = readBack(out("bitmask.exr"));
  EXPECT_EQ(bitmask.pixels, exact.pixels);
  EXPECT_EQ(bitmask.spec.get_string_attribute("hfvis:method"), "bitmask");
  EXPECT_EQ(exact.spec.get_string_attribute("hfvis:method"), "exact");
  EXPECT_EQ(culled.spec.get_string_attribute("hfvis:method"), "culled");
  EXPECT_EQ(readBack(out("h.exr")).spec.get_string_attribute("hfvis:method"), "culled");
  // From 64 samples of a planar light on, the default (auto) takes the bitmask scatter, and
  // names it: the same picture as the exact method's.
  for (const char* method : {"auto", "exact"})
    ASSERT_EQ(run("arealight " + shellQuoted(field) + " -o " + shellQuoted(out(std::string(method) + "64.exr")) +
                  " --light 1,2,3,9 --light-height 20 --absolute --samples 64 --method " + method + " -q")
                  .status,
              0);
  const ReadBack picked = readBack(out("auto64.exr"));
  EXPECT_EQ(picked.spec.get_string_attribute("hfvis:method"), "bitmask");
  EXPECT_EQ(picked.pixels, readBack(out("exact64.exr")).pixels);
}

TEST_F(Cli, AreaLightFromASourcesFile) {
  const std::string field = writeField("wall.exr", kWallWidth, kWallHeight, wallHeight);
  // A UTF-8 BOM, a header, CRLF, a comment, a fractional column and a row without a height.
  {
    std::ofstream csv(in("sources.csv"), std::ios::binary);
    csv << "\xEF\xBB\xBF"
           "col,row,height\r\n2,3,1\r\n# behind the wall\r\n12.5,6\r\n";
  }
  // (the BOM before a comment or a blank line too)
  for (const char* first : {"# sources\r\n", "\r\n"}) {
    SCOPED_TRACE(first);
    {
      std::ofstream csv(in("commented.csv"), std::ios::binary);
      csv << "\xEF\xBB\xBF" << first << "2,3,1\r\n12.5,6\r\n";
    }
    const CliResult commented =
        run("arealight " + shellQuoted(field) + " -o " + shellQuoted(out("c.exr")) + " --sources " +
            shellQuoted(in("commented.csv")) + " --light-height 4 -q");
    EXPECT_EQ(commented.status, 0) << commented.err;
    fs::remove(out("c.exr"));
  }
  // A first line of numbers strtod reads, nan or inf, is no header (it was passed over as one, where
  // a later one is refused): refused, naming the line.
  for (const char* first : {"nan,nan\n", "inf,Infinity,1\n"}) {
    SCOPED_TRACE(first);
    { std::ofstream(in("nan.csv"), std::ios::binary) << first << "2,3,1\n"; }
    expectFailure(run("arealight " + shellQuoted(field) + " -o " + shellQuoted(out("n.exr")) + " --sources " +
                      shellQuoted(in("nan.csv")) + " --light-height 4 -q"),
                  1, "line 1:");
  }
  const CliResult r = run("arealight " + shellQuoted(field) + " -o " + shellQuoted(out("a.exr")) +
                          " --sources " + shellQuoted(in("sources.csv")) + " --light-height 4 -q");
  ASSERT_EQ(r.status, 0) << r.err;
  const hfvis::HeightField f = hfvis::readHeightField(field);
  hfvis::RegionSampling sources;
  sources.points = {{2.0, 3.0, 1.0}, {12.5, 6.0, 4.0}};
  sources.samples = 2;
  const hfvis::RegionVisibilityResult lib = hfvis::computeRegionVisibility(
      hfvis::testing::testContext(), f, sources, hfvis::RegionVisibilityOptions{});
  const ReadBack a = readBack(out("a.exr"));
  ASSERT_EQ(a.pixels.size(), lib.fraction.size());
  for (std::size_t p = 0; p < lib.fraction.size(); ++p)
    ASSERT_EQ(a.pixels[p], lib.fraction[p]) << "pixel " << p;
  // Each side of the wall sees its own source only.
  EXPECT_EQ(a.at(4, 3, 0), 0.5f);
  EXPECT_EQ(a.at(13, 6, 0), 0.5f);
  // The viewsheds method takes sources on grid points and agrees away from grazing lines.
  {
    std::ofstream csv(in("grid.csv"));
    csv << "2,3,1\n12,6,4\n";
  }
  ASSERT_EQ(run("arealight " + shellQuoted(field) + " -o " + shellQuoted(out("v.exr")) + " --sources " +
                shellQuoted(in("grid.csv")) + " --method viewsheds -q")
                .status,
            0);
  const ReadBack v = readBack(out("v.exr"));
  EXPECT_EQ(v.at(4, 3, 0), 0.5f);
  EXPECT_EQ(v.at(13, 6, 0), 0.5f);
  EXPECT_EQ(v.spec.get_string_attribute("hfvis:method"), "viewsheds");
}

TEST_F(Cli, RegionWritesConsistentJsonAndItsClearRays) {
  // The wall stands in rows 0 .. 5 only: from the left rectangle to the right one, the pairs in
  // the lower rows see past its end, the others not.
  const std::string field = writeField("half_wall.exr", kWallWidth, kWallHeight,
                                       [](int col, int row) { return col == 8 && row <= 5 ? 9.0f : 0.0f; });
  const CliResult r =
      run("region " + shellQuoted(field) + " --from 1,0,3,11 --to 12,0,14,11 --samples 24 -o " +
          shellQuoted(out("r.json")) + " --rays " + shellQuoted(out("rays.csv")));
  ASSERT_EQ(r.status, 0) << r.err;
  const Json j = JsonParser::parse(readText(out("r.json")));
  const double pairs = j["pairs"].number, clear = j["clear_pairs"].number;
  EXPECT_EQ(pairs, 24.0 * 24.0);
  EXPECT_GT(clear, 0.0);
  EXPECT_LT(clear, pairs);
  EXPECT_DOUBLE_EQ(j["visible_fraction"].number, clear / pairs);
  ASSERT_EQ(j["from_samples"].items.size(), 24u);
  ASSERT_EQ(j["to_samples"].items.size(), 24u);
  // Each sample's fraction is its share of the clear pairs: they sum to clear / 24 on each side.
  double from_sum = 0.0, to_sum = 0.0;
  for (const Json& s : j["from_samples"].items) {
    EXPECT_GE(s["col"].number, 1.0);
    EXPECT_LE(s["col"].number, 3.0);
    from_sum += s["visible_fraction"].number;
  }
  for (const Json& s : j["to_samples"].items) to_sum += s["visible_fraction"].number;
  EXPECT_NEAR(from_sum, clear / 24.0, 1e-4);
  EXPECT_NEAR(to_sum, clear / 24.0, 1e-4);
  // One ray a line, after the header: as many as the clear pairs, each from the left to the right.
  const std::vector<std::string> lines = splitText(readText(out("rays.csv")), '\n');
  ASSERT_GE(lines.size(), 2u);
  EXPECT_EQ(lines[0], "from_col,from_row,from_height,to_col,to_row,to_height");
  EXPECT_EQ(lines.back(), "");
  EXPECT_EQ(static_cast<double>(lines.size() - 2), clear);
  for (std::size_t i = 1; i + 1 < lines.size(); ++i) {
    const std::vector<std::string> fields = splitText(lines[i], ',');
    ASSERT_EQ(fields.size(), 6u) << lines[i];
    EXPECT_LE(std::stod(fields[0]), 3.0);
    EXPECT_GE(std::stod(fields[3]), 12.0);
    // Where it crosses the wall's column: past the wall's end (row 5; the bilinear surface falls
    // from 9 to 0 between rows 5 and 6).
    const double c0 = std::stod(fields[0]), r0 = std::stod(fields[1]), c1 = std::stod(fields[3]),
                 r1 = std::stod(fields[4]);
    EXPECT_GT(r0 + (8.0 - c0) / (c1 - c0) * (r1 - r0), 5.0) << "a ray through the wall: " << lines[i];
  }
  // The library's own count.
  const hfvis::HeightField f = hfvis::readHeightField(field);
  hfvis::RegionSampling from, to;
  from.rectangle = {1, 0, 3, 11};
  to.rectangle = {12, 0, 14, 11};
  from.samples = to.samples = 24;
  const hfvis::RegionPairVisibilityResult lib = hfvis::computeRegionPairVisibility(
      hfvis::testing::testContext(), f, from, to, hfvis::RegionVisibilityOptions{});
  EXPECT_EQ(static_cast<double>(lib.clear_pairs), clear);
  // A wall across every row: no clear pair, and a rays file with its header only.
  const std::string wall = writeField("wall.exr", kWallWidth, kWallHeight, wallHeight);
  ASSERT_EQ(run("region " + shellQuoted(wall) + " --from 1,0,3,11 --to 12,0,14,11 -o " +
                shellQuoted(out("w.json")) + " --rays " + shellQuoted(out("w.csv")) + " -q")
                .status,
            0);
  EXPECT_EQ(JsonParser::parse(readText(out("w.json")))["clear_pairs"].number, 0.0);
  EXPECT_EQ(splitText(readText(out("w.csv")), '\n').size(), 2u);
}

// The library's SGVS sets on `field` with the PVS tests' grid (view cells of 8, tiles of 4), as
// `hfvis pvs --method sgvs --view-cell 8 --tile 4` computes them.
hfvis::PvsResult sgvsSets(const std::string& field, std::uint64_t samples, std::uint32_t seed,
                          std::vector<std::uint32_t> start = {}) {
  hfvis::PvsGrid grid;
  grid.view_cell = 8;
  grid.tile = 4;
  hfvis::PvsOptions options;
  options.method = hfvis::PvsMethod::Sgvs;
  options.samples = samples;
  options.seed = seed;
  options.start = std::move(start);
  return hfvis::computePvs(hfvis::testing::testContext(), hfvis::readHeightField(field), grid, options);
}

// hfvis pvs: the JSON's sets and the bitset file (docs/PVS.md's layout) are the library's for the
// same seed and budget; a mask limits the view cells computed.
TEST_F(Cli, PvsWritesTheLibrarysSetsAsJsonAndBits) {
  const std::string field = pvsHills();
  const CliResult result = run("pvs " + shellQuoted(field) + " -o " + shellQuoted(out("p.json")) +
                               " --view-cell 8 --tile 4 --samples 6000 --method sgvs --seed 3 --bitset " +
                               shellQuoted(out("p.bin")) + " --preview " + shellQuoted(out("p.png")) + " --quiet");
  ASSERT_EQ(result.status, 0) << result.err;
  const hfvis::PvsResult want = sgvsSets(field, 6000, 3);
  const std::string json = readText(out("p.json"));
  // The sets: "pvs": [ [t, t, ...], ... ] one line per view cell.
  const std::size_t sets = json.find("\"pvs\": [");
  ASSERT_NE(sets, std::string::npos);
  std::istringstream lines(json.substr(sets));
  std::string line;
  std::getline(lines, line);
  for (int v = 0; v < want.layout.viewCells(); ++v) {
    ASSERT_TRUE(std::getline(lines, line));
    std::string expected = "    [";
    int n = 0;
    for (int t = 0; t < want.layout.tiles(); ++t)
      if (want.visible(v, t)) expected += (n++ ? "," : "") + std::to_string(t);
    expected += "]";
    EXPECT_EQ(line.substr(0, line.find_last_of(']') + 1), expected) << "view cell " << v;
  }
  EXPECT_NE(json.find("\"samples\": 6000,"), std::string::npos);
  // The bitset: header, flags padded to 4 bytes, words little-endian.
  const std::string bits = readText(out("p.bin"));
  auto u32 = [&](std::size_t at) {
    std::uint32_t v = 0;
    for (int i = 0; i < 4; ++i) v |= std::uint32_t(static_cast<unsigned char>(bits[at + i])) << (8 * i);
    return v;
  };
  ASSERT_GE(bits.size(), 72u);
  EXPECT_EQ(bits.substr(0, 8), std::string("HFVPVS1", 8));
  EXPECT_EQ(u32(8), 3u);
  EXPECT_EQ(u32(12), std::uint32_t(want.layout.view_x));
  EXPECT_EQ(u32(16), std::uint32_t(want.layout.view_y));
  EXPECT_EQ(u32(20), std::uint32_t(want.layout.tiles_x));
  EXPECT_EQ(u32(24), std::uint32_t(want.layout.tiles_y));
  EXPECT_EQ(u32(28), std::uint32_t(want.words));
  EXPECT_EQ(u32(32), 8u);
  EXPECT_EQ(u32(36), 4u);
  // (40: the field's fingerprint, 48 and 52: the view band as float32, 56: no filter, 60: no
  // curvature, 64: no maximum distance, 68: reserved)
  EXPECT_EQ(u32(48), 0x3fd9999au);  // 1.7f
  EXPECT_EQ(u32(52), 0x3fd9999au);
  EXPECT_EQ(u32(56), 0u);
  EXPECT_EQ(u32(60), 0u);
  EXPECT_EQ(u32(64), 0u);
  EXPECT_EQ(u32(68), 0u);
  const std::size_t words_at = 72 + (want.layout.viewCells() + 3) / 4 * 4;
  ASSERT_EQ(bits.size(), words_at + 4 * want.bits.size());
  for (int v = 0; v < want.layout.viewCells(); ++v) EXPECT_EQ(bits[72 + v], 1);
  for (std::size_t i = 0; i < want.bits.size(); ++i) EXPECT_EQ(u32(words_at + 4 * i), want.bits[i]) << i;
  EXPECT_TRUE(fs::exists(out("p.png")));
  // A mask of the field's size selecting one corner: only view cell 0 computed.
  const std::string mask = writeField("mask.exr", 30, 22, [](int col, int row) { return col < 3 && row < 3 ? 1.0f : 0.0f; });
  const CliResult masked = run("pvs " + shellQuoted(field) + " -o " + shellQuoted(out("m.json")) +
                               " --view-cell 8 --tile 4 --samples 500 --view-mask " + shellQuoted(mask) + " --quiet");
  ASSERT_EQ(masked.status, 0) << masked.err;
  const std::string mjson = readText(out("m.json"));
  const std::size_t msets = mjson.find("\"pvs\": [");
  ASSERT_NE(msets, std::string::npos);
  std::istringstream mlines(mjson.substr(msets));
  std::getline(mlines, line);
  std::getline(mlines, line);
  EXPECT_NE(line.find('['), std::string::npos) << line;
  for (int v = 1; v < want.layout.viewCells(); ++v) {
    ASSERT_TRUE(std::getline(mlines, line));
    EXPECT_NE(line.find("null"), std::string::npos) << "view cell " << v << ": " << line;
  }
  // The same mask as grey with alpha (Y, A, alpha 1 everywhere): its first channel is the mask.
  hfvis::ImageChannels grey_alpha;
  grey_alpha.width = 30, grey_alpha.height = 22;
  grey_alpha.names = {"Y", "A"};
  grey_alpha.planes = {std::vector<float>(30 * 22, 0.0f), std::vector<float>(30 * 22, 1.0f)};
  for (int row = 0; row < 3; ++row)
    for (int col = 0; col < 3; ++col) grey_alpha.planes[0][row * 30 + col] = 1.0f;
  hfvis::writeImage(in("mask_ya.exr"), grey_alpha);
  const CliResult alpha =
      run("pvs " + shellQuoted(field) + " -o " + shellQuoted(out("a.json")) +
          " --view-cell 8 --tile 4 --samples 500 --view-mask " + shellQuoted(in("mask_ya.exr")) + " --quiet");
  ASSERT_EQ(alpha.status, 0) << alpha.err;
  const std::string ajson = readText(out("a.json"));  // (the same sets; the times differ)
  EXPECT_EQ(ajson.substr(ajson.find("\"pvs\": [")), mjson.substr(msets));
}

// The settled estimate (--estimate-entries): an AGVS budget that leaves fewer than 20 entries found
// once goes on with uniform view rays, as the library's run does; the JSON's samples include them
// and estimate_samples counts them; the summary line names them; 0 turns them off; a count that is
// not a whole number in 0 .. 1e6 is refused.
TEST_F(Cli, PvsSettlesItsEstimate) {
  const std::string field = pvsHills();
  hfvis::PvsGrid grid;
  grid.view_cell = 8;
  grid.tile = 4;
  hfvis::PvsOptions options;
  hfvis::PvsResult want;
  // (the first budget of these that leaves something to settle)
  for (std::uint64_t samples : {1000u, 2000u, 4000u, 8000u, 16000u}) {
    options.samples = samples;
    want = hfvis::computePvs(hfvis::testing::testContext(), hfvis::readHeightField(field), grid, options);
    if (want.estimate_samples > 0) break;
  }
  ASSERT_GT(want.estimate_samples, 0u);
  const std::string budget = std::to_string(options.samples);
  const std::string base =
      "pvs " + shellQuoted(field) + " --view-cell 8 --tile 4 --samples " + budget + " -o ";
  const CliResult settled = run(base + shellQuoted(out("s.json")));
  ASSERT_EQ(settled.status, 0) << settled.err;
  const Json s = JsonParser::parse(readText(out("s.json")));
  EXPECT_EQ(s["samples"].number, double(want.samples));
  EXPECT_EQ(s["estimate_samples"].number, double(want.estimate_samples));
  EXPECT_EQ(s["entries"].number, double(want.entries()));
  // The progress rows say which batches settled the estimate.
  const Json& rows = s["progress"];
  ASSERT_EQ(rows.items.size(), want.history.size());
  for (std::size_t i = 0; i < rows.items.size(); ++i)
    EXPECT_EQ(rows[i]["settling"].boolean, want.history[i].settling) << i;
  EXPECT_TRUE(rows.items.back()["settling"].boolean);
  EXPECT_NE(settled.out.find(std::to_string(want.estimate_samples) + " settling the estimate"),
            std::string::npos)
      << settled.out;
  const CliResult plain = run(base + shellQuoted(out("p.json")) + " --estimate-entries 0 --quiet");
  ASSERT_EQ(plain.status, 0) << plain.err;
  const Json p = JsonParser::parse(readText(out("p.json")));
  EXPECT_EQ(p["samples"].number, double(options.samples));
  EXPECT_EQ(p["estimate_samples"].number, 0.0);
  for (const char* bad : {"-1", "2.5", "1e7", "0x10", "nan"}) {
    const CliResult refused = run(base + shellQuoted(out("b.json")) + " --estimate-entries " + bad);
    EXPECT_EQ(refused.status, 2) << bad;
    EXPECT_NE(refused.err.find("--estimate-entries"), std::string::npos) << refused.err;
    EXPECT_FALSE(fs::exists(out("b.json"))) << bad;
  }
}

// --preview-view-cell: the preview shows one view cell's set: the pixels of the tiles it sees
// brighter than those of the tiles it does not (the same hillshade under both), its outline
// brightest; refused without --preview, outside the field, and in a view cell the mask leaves out.
TEST_F(Cli, PvsPreviewOfOneViewCell) {
  const std::string field = pvsHills();
  const std::string args = " --view-cell 8 --tile 4 --samples 6000 --method sgvs --seed 3 --quiet";
  const CliResult result = run("pvs " + shellQuoted(field) + " -o " + shellQuoted(out("p.json")) + args +
                               " --preview " + shellQuoted(out("p.png")) + " --preview-view-cell 20,3");
  ASSERT_EQ(result.status, 0) << result.err;
  const hfvis::PvsResult want = sgvsSets(field, 6000, 3);
  const int chosen = 2;  // pixel (20, 3): cell (20, 3), view cell (2, 0)
  const hfvis::ImageChannels png = hfvis::readImage(out("p.png"));
  ASSERT_EQ(png.width, 30);
  // Outside the chosen view cell, the seen tiles' pixels are brighter on average than the unseen
  // ones' (the set adds 0.35 over the same dimmed hillshade).
  double seen = 0, unseen = 0;
  int n_seen = 0, n_unseen = 0;
  for (int y = 0; y < 21; ++y)
    for (int x = 0; x < 29; ++x) {
      const int cell = y * 29 + x;
      if (want.layout.viewOfCell(cell) == chosen) continue;
      const float v = png.planes[0][std::size_t(y) * 30 + x];
      if (want.visible(chosen, want.layout.tileOfCell(cell)))
        seen += v, ++n_seen;
      else
        unseen += v, ++n_unseen;
    }
  ASSERT_GT(n_seen, 0);
  ASSERT_GT(n_unseen, 0);
  EXPECT_GT(seen / n_seen, unseen / n_unseen + 0.2) << n_seen << " seen, " << n_unseen << " unseen pixels";
  EXPECT_GT(png.planes[0][16], seen / n_seen);  // (16, 0): the chosen view cell's outline
  const auto refused = [&](const std::string& extra, const std::string& says) {
    const CliResult r = run("pvs " + shellQuoted(field) + " -o " + shellQuoted(out("q.json")) + args + extra);
    EXPECT_EQ(r.status, 2) << extra;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out("q.json")));
  };
  refused(" --preview-view-cell 20,3", "give --preview");
  refused(" --preview " + shellQuoted(out("q.png")) + " --preview-view-cell 30,3",
          "outside the 30 x 22 field");
  const std::string mask =
      writeField("corner.exr", 30, 22, [](int col, int row) { return col < 3 && row < 3 ? 1.0f : 0.0f; });
  refused(" --preview " + shellQuoted(out("q.png")) + " --view-mask " + shellQuoted(mask) +
              " --preview-view-cell 20,3",
          "which the view mask leaves out");
  // (a bitset named as an image was written as raw bits, a probe's find)
  refused(" --bitset " + shellQuoted(out("sets.exr")), "must end in .bin");
}

// --resume: a run goes on from an earlier run's --bitset file: the library's run from those sets
// with the new seed, its own samples, the file and its entries in resumed_from; refused without a
// --seed, on another grid, for a file that is not a bitset, and as an output.
TEST_F(Cli, PvsResumesFromAnEarlierBitset) {
  const std::string field = pvsHills();
  const std::string grid = " --view-cell 8 --tile 4 --method sgvs --quiet";
  ASSERT_EQ(run("pvs " + shellQuoted(field) + " -o " + shellQuoted(out("a.json")) +
                " --samples 300 --bitset " + shellQuoted(out("a.bin")) + grid)
                .status,
            0);
  const CliResult resumed = run("pvs " + shellQuoted(field) + " -o " + shellQuoted(out("b.json")) +
                                " --samples 400 --seed 7 --bitset " + shellQuoted(out("b.bin")) +
                                " --resume " + shellQuoted(out("a.bin")) + grid);
  ASSERT_EQ(resumed.status, 0) << resumed.err;
  const hfvis::PvsResult first = sgvsSets(field, 300, 1);
  const hfvis::PvsResult want = sgvsSets(field, 400, 7, first.bits);
  ASSERT_GT(want.entries(), first.entries());
  const std::string bits = readText(out("b.bin"));
  const std::size_t words_at = 72 + (want.layout.viewCells() + 3) / 4 * 4;
  ASSERT_EQ(bits.size(), words_at + 4 * want.bits.size());
  for (std::size_t i = 0; i < want.bits.size(); ++i) {
    std::uint32_t v = 0;
    for (int k = 0; k < 4; ++k)
      v |= std::uint32_t(static_cast<unsigned char>(bits[words_at + 4 * i + k])) << (8 * k);
    EXPECT_EQ(v, want.bits[i]) << i;
  }
  const std::string json = readText(out("b.json"));
  EXPECT_NE(json.find("\"samples\": 400,"), std::string::npos);
  EXPECT_NE(json.find("\"resumed_from\": {\"file\": \"" + out("a.bin") +
                      "\", \"entries\": " + std::to_string(first.entries()) + "}"),
            std::string::npos)
      << json.substr(0, 400);
  EXPECT_NE(readText(out("a.json")).find("\"resumed_from\": null"), std::string::npos);
  // Refused, nothing written.
  const auto refused = [&](const std::string& args, const std::string& says) {
    const CliResult r = run("pvs " + shellQuoted(field) + " -o " + shellQuoted(out("c.json")) +
                            " --samples 100" + args + " --quiet");
    EXPECT_EQ(r.status, 2) << args;
    EXPECT_NE(r.err.find(says), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(out("c.json"))) << args;
  };
  // A run of 300 samples with `args`, its JSON and bitset NAME.json and NAME.bin.
  const auto written = [&](const std::string& name, const std::string& args) {
    const CliResult r = run("pvs " + shellQuoted(field) + " -o " + shellQuoted(out(name + ".json")) +
                            " --samples 300 " + args + " --bitset " + shellQuoted(out(name + ".bin")) + grid);
    ASSERT_EQ(r.status, 0) << args << ": " << r.err;
  };
  refused(" --view-cell 8 --tile 4 --resume " + shellQuoted(out("a.bin")), "--resume needs --seed");
  refused(" --view-cell 8 --tile 4 --seed 3 --filter 2 --resume " + shellQuoted(out("a.bin")), "--filter with --resume");
  refused(" --view-cell 8 --tile 2 --seed 3 --resume " + shellQuoted(out("a.bin")),
          "give the same field, --view-cell and --tile");
  refused(" --view-cell 8 --tile 4 --seed 3 --bitset " + shellQuoted(out("a.bin")) + " --resume " +
              shellQuoted(out("a.bin")),
          "outputs never replace an input");
  // The sets of another field, view band or z-scale, or with the filter's entries: a bitset of a
  // field without a wall, resumed on one with it, gave every view cell the tiles behind the wall
  // (exit 0). And a version 1 file, which records none of it.
  const std::string other =
      writeField("other.exr", 30, 22, [](int col, int row) { return 0.1f * float(col * row % 7); });
  refused(" --view-cell 8 --tile 4 --seed 3 --view-height 2 --resume " + shellQuoted(out("a.bin")),
          "another field");
  refused(" --view-cell 8 --tile 4 --seed 3 --z-scale 2 --resume " + shellQuoted(out("a.bin")),
          "another field");
  const CliResult elsewhere = run("pvs " + shellQuoted(other) + " -o " + shellQuoted(out("c.json")) +
                                  " --samples 100 --seed 3 --resume " + shellQuoted(out("a.bin")) + grid);
  EXPECT_EQ(elsewhere.status, 2);
  EXPECT_NE(elsewhere.err.find("computed on another field"), std::string::npos) << elsewhere.err;
  written("f", "--filter 2");
  refused(" --view-cell 8 --tile 4 --seed 3 --resume " + shellQuoted(out("f.bin")), "written with --filter");
  written("g", "--view-filter 3");
  refused(" --view-cell 8 --tile 4 --seed 3 --resume " + shellQuoted(out("g.bin")), "--view-filter");
  // The curvature: recorded in the JSON and the bitset (byte 60), and resumed only alike.
  refused(" --view-cell 8 --tile 4 --seed 3 --curvature --resume " + shellQuoted(out("a.bin")),
          "computed without curvature");
  written("e", "--curvature");
  EXPECT_NE(readText(out("e.json")).find("\"curvature\": 6."), std::string::npos);  // 6.7e-08 per m
  EXPECT_NE(readText(out("a.json")).find("\"curvature\": 0,"), std::string::npos);
  refused(" --view-cell 8 --tile 4 --seed 3 --refraction 0.3 --resume " + shellQuoted(out("e.bin")),
          "with another curvature");
  refused(" --view-cell 8 --tile 4 --seed 3 --resume " + shellQuoted(out("e.bin")), "with curvature, which this run has not");
  ASSERT_EQ(run("pvs " + shellQuoted(field) + " -o " + shellQuoted(out("e2.json")) +
                " --samples 300 --seed 4 --curvature --resume " + shellQuoted(out("e.bin")) + grid)
                .status,
            0);
  // The maximum distance: in the JSON and the bitset (byte 64), resumed only alike.
  refused(" --view-cell 8 --tile 4 --seed 3 --max-distance 10 --resume " + shellQuoted(out("a.bin")),
          "without a maximum distance");
  written("m", "--max-distance 10");
  EXPECT_NE(readText(out("m.json")).find("\"max_distance\": 10,"), std::string::npos);
  refused(" --view-cell 8 --tile 4 --seed 3 --max-distance 12 --resume " + shellQuoted(out("m.bin")),
          "with another maximum distance");
  // A version 2 file (64-byte header: no maximum distance) is read as one without.
  {
    std::string v2 = readText(out("a.bin"));
    v2[8] = 2;
    v2.erase(64, 8);
    std::ofstream(out("v2.bin"), std::ios::binary) << v2;
  }
  const CliResult from_v2 = run("pvs " + shellQuoted(field) + " -o " + shellQuoted(out("v2.json")) +
                                " --samples 100 --seed 5 --resume " + shellQuoted(out("v2.bin")) + grid);
  EXPECT_EQ(from_v2.status, 0) << from_v2.err;
  EXPECT_NE(readText(out("v2.json")).find("\"entries\": " + std::to_string(first.entries())),
            std::string::npos);
  std::string first_version = readText(out("a.bin"));
  first_version[8] = 1;
  { std::ofstream(out("v1.bin"), std::ios::binary) << first_version; }
  refused(" --view-cell 8 --tile 4 --seed 3 --resume " + shellQuoted(out("v1.bin")), "format version 1");
  EXPECT_FALSE(fs::exists(out("c.json")));
  const CliResult not_bits = run("pvs " + shellQuoted(field) + " -o " + shellQuoted(out("c.json")) +
                                 " --samples 100 --seed 3 --resume " + shellQuoted(out("a.json")) + grid);
  EXPECT_EQ(not_bits.status, 1);
  EXPECT_NE(not_bits.err.find("not a PVS bitset file"), std::string::npos) << not_bits.err;
  EXPECT_FALSE(fs::exists(out("c.json")));
  // Bits past the last tile (a damaged file) are refused naming the file (the library's refusal
  // named none).
  const int tiles = first.layout.tiles(), words = (tiles + 31) / 32;
  ASSERT_NE(tiles % 32, 0) << "no bits past the last tile on this grid";
  std::string damaged = readText(out("a.bin"));
  const std::size_t last_word = 72 + (first.layout.viewCells() + 3) / 4 * 4 + 4 * std::size_t(words - 1);
  damaged[last_word + 3] = static_cast<char>(0x80);  // the word's highest bit
  { std::ofstream(out("damaged.bin"), std::ios::binary) << damaged; }
  const CliResult past = run("pvs " + shellQuoted(field) + " -o " + shellQuoted(out("c.json")) +
                             " --samples 100 --seed 3 --resume " + shellQuoted(out("damaged.bin")) + grid);
  EXPECT_EQ(past.status, 1);
  EXPECT_NE(
      past.err.find("damaged.bin: not a PVS bitset file of hfvis pvs --bitset (docs/PVS.md): view cell 0 has "
                    "bits past the last of the " +
                    std::to_string(tiles) + " tiles"),
      std::string::npos)
      << past.err;
  EXPECT_FALSE(fs::exists(out("c.json")));
}

TEST_F(Cli, RegionVisibilityRefusesBadInput) {
  const std::string field = flat();  // 16 x 12
  const std::string light = "arealight " + shellQuoted(field) + " -o " + shellQuoted(out("a.exr"));
  const std::string region = "region " + shellQuoted(field) + " -o " + shellQuoted(out("r.json"));
  expectFailure(run(light), 2, "missing --light");
  expectFailure(run(light + " --light 1,1,2,2 --sources " + shellQuoted(in("s.csv"))), 2, "give one");
  expectFailure(run(light + " --light 1,1,16,2"), 2, "--light 1,1,16,2");
  expectFailure(run(light + " --light 1,1,2"), 2, "C0,R0,C1,R1");
  expectFailure(run(light + " --light 1,1,2,2 --samples 4097"), 2, "4096");
  expectFailure(run(light + " --light 1,1,2,2 --samples 0"), 2, "--samples");
  expectFailure(run(light + " --light 1,1,2,2 --method viewsheds"), 2, "grid points");
  expectFailure(run(light + " --light 1,1,1,1 --method viewsheds --decorrelate"), 2, "--decorrelate");
  // The bitmask method: a planar light (--absolute), shared samples, no curvature, at most 1024.
  expectFailure(run(light + " --light 1,1,2,2 --method bitmask"), 2, "--absolute");
  expectFailure(run(light + " --light 1,1,2,2 --absolute --method bitmask --decorrelate"), 2,
                "--decorrelate");
  expectFailure(run(light + " --light 1,1,2,2 --absolute --method bitmask --curvature"), 2, "--curvature");
  expectFailure(run(light + " --light 1,1,2,2 --absolute --method bitmask --samples 1025"), 2, "1024");
  expectFailure(run(light + " --light 1,1,2,2 --light-height -1"), 2, "--light-height");
  expectFailure(run(light + " --light 1,1,2,2 --masks " + shellQuoted(out("m.png"))), 1, "m.png");
  expectFailure(run(light + " --light 1,1,2,2 --masks " + shellQuoted(field)), 2, "input");
  {
    std::ofstream csv(in("bad.csv"));
    csv << "col,row,height\n1,2,1\n3,x,1\n";
  }
  expectFailure(run(light + " --sources " + shellQuoted(in("bad.csv"))), 1, "line 3");
  {
    std::ofstream csv(in("outside.csv"));
    csv << "1,2\n30,2\n";
  }
  expectFailure(run(light + " --sources " + shellQuoted(in("outside.csv"))), 2, "--sources");
  {
    std::ofstream csv(in("s.csv"));
    csv << "1,2\n";
  }
  expectFailure(run(light + " --sources " + shellQuoted(in("s.csv")) + " --samples 4"), 2, "--samples");
  // A source on nodata.
  const std::string holes = writeField("holes.exr", 8, 8, [](int col, int row) {
    return col == 3 && row == 3 ? std::numeric_limits<float>::quiet_NaN() : 1.0f;
  });
  {
    std::ofstream csv(in("on_hole.csv"));
    csv << "3,3\n";
  }
  expectFailure(run("arealight " + shellQuoted(holes) + " -o " + shellQuoted(out("a.exr")) + " --sources " +
                    shellQuoted(in("on_hole.csv"))),
                2, "nodata");
  expectFailure(
      run("arealight " + shellQuoted(holes) + " -o " + shellQuoted(out("a.exr")) + " --light 2,2,4,4"), 2,
      "nodata");
  expectFailure(run(region + " --from 1,1,2,2"), 2, "missing --to");
  expectFailure(run(region + " --from 1,1,2,2 --to 3,3,4,12"), 2, "--to 3,3,4,12");
  expectFailure(run(region + " --from 1,1,2,2 --to 3,3,4,4 --method viewsheds"), 2, "--method");
  expectFailure(run(region + " --from 1,1,2,2 --to 3,3,4,4 --method bitmask"), 2, "--method");
  expectFailure(run(region + " --from 1,1,2,2 --to 3,3,4,4 --rays " + shellQuoted(out("r.txt"))), 2, ".csv");
  expectFailure(run("region " + shellQuoted(field) + " -o " + shellQuoted(out("r.exr")) +
                    " --from 1,1,2,2 --to 3,3,4,4"),
                2, ".json");
  expectFailure(run(region + " --from 1,1,2,2 --to 3,3,4,4 --decorrelate"), 2, "--decorrelate");
}

TEST_F(CliGeoTiff, RegionVisibilityOnAGeoreferencedField) {
  const std::string dem = geoTiffInput();
  // arealight's GeoTIFF: the georeference kept, the --nodata value at nodata.
  ASSERT_EQ(run("arealight " + shellQuoted(dem) + " -o " + shellQuoted(out("a.tif")) +
                " --light 1,1,4,4 --light-height 30 --nodata -9999 -q")
                .status,
            0);
  const hfvis::testing::GdalRaster light = checkGeoTiffOutput(out("a.tif"), {"visible"}, "arealight");
  EXPECT_EQ(light.bands[0][0], -9999.0f);  // nodata at (0, 0)
  for (std::size_t p = 1; p < light.bands[0].size(); ++p) {
    if (light.bands[0][p] != -9999.0f) {
      ASSERT_TRUE(light.bands[0][p] >= 0.0f && light.bands[0][p] <= 1.0f) << p;
    }
  }
  // region's rays: map coordinates of the pixel centres through the geotransform, to the micrometre
  // (they were cut to 10 significant digits: a millimetre apart at northings of 4e6).
  const CliResult r =
      run("region " + shellQuoted(dem) + " --from 1,1,4,4 --to 15,10,20,14 --from-height 50 -o " +
          shellQuoted(out("r.json")) + " --rays " + shellQuoted(out("r.csv")) + " -q");
  ASSERT_EQ(r.status, 0) << r.err;
  const Json j = JsonParser::parse(readText(out("r.json")));
  const std::array<double, 6>& t = hfvis::testing::kUtmGeotransform;
  for (const Json& s : j["from_samples"].items) {
    EXPECT_NEAR(s["x"].number, t[0] + (s["col"].number + 0.5) * t[1], 1e-6);
    EXPECT_NEAR(s["y"].number, t[3] + (s["row"].number + 0.5) * t[5], 1e-6);
  }
  const std::vector<std::string> lines = splitText(readText(out("r.csv")), '\n');
  EXPECT_GT(j["clear_pairs"].number, 0.0);
  EXPECT_EQ(lines[0], "from_col,from_row,from_height,to_col,to_row,to_height,from_x,from_y,to_x,to_y");
  EXPECT_EQ(static_cast<double>(lines.size() - 2), j["clear_pairs"].number);
  for (std::size_t i = 1; i + 1 < lines.size(); ++i) {
    const std::vector<std::string> f = splitText(lines[i], ',');
    ASSERT_EQ(f.size(), 10u);
    EXPECT_NEAR(std::stod(f[8]), t[0] + (std::stod(f[3]) + 0.5) * t[1], 1e-6);
    EXPECT_NEAR(std::stod(f[9]), t[3] + (std::stod(f[4]) + 0.5) * t[5], 1e-6);
  }
}

// A file name in another encoding than UTF-8 (Latin-1's e-acute, byte 0xE9): the JSON that names
// it stays valid, the byte written as the character of that number; UTF-8 names pass through.
TEST_F(Cli, JsonNamesTheInputInValidUtf8) {
  const std::string field = flat();
  const std::string latin1 = in(std::string("lat") + char(0xE9) + ".exr"), utf8 = in("\xC3\xA9t\xC3\xA9.exr");
  fs::copy_file(field, latin1);
  fs::copy_file(field, utf8);
  ASSERT_EQ(run("region " + shellQuoted(latin1) + " -o " + shellQuoted(out("l.json")) +
                " --from 1,1,2,2 --to 5,5,6,6 -q")
                .status,
            0);
  ASSERT_EQ(run("region " + shellQuoted(utf8) + " -o " + shellQuoted(out("u.json")) +
                " --from 1,1,2,2 --to 5,5,6,6 -q")
                .status,
            0);
  const std::string l = readText(out("l.json")), u = readText(out("u.json"));
  EXPECT_NE(l.find("lat\\u00e9.exr\""), std::string::npos) << l.substr(0, 200);
  EXPECT_EQ(l.find(char(0xE9)), std::string::npos);
  EXPECT_NE(u.find("\xC3\xA9t\xC3\xA9.exr\""), std::string::npos) << u.substr(0, 200);
}
