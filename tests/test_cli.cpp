// tests/test_cli.cpp: the hfvis command line tool, run as a separate process: exit status,
// messages, outputs read back with OpenImageIO, and no partial output after a failure.
#include <OpenImageIO/imageio.h>
#include <gtest/gtest.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "hfvis/image_io.hpp"

namespace {

namespace fs = std::filesystem;

constexpr double kHalfPi = 1.57079632679489661923;

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

// Each test gets fresh directories: `inputs` for what the test writes, `outputs` for what
// the tool writes (so "nothing left behind" is simply "outputs is empty").
class Cli : public ::testing::Test {
 protected:
  void SetUp() override {
    const auto* info = ::testing::UnitTest::GetInstance()->current_test_info();
    // The process id keeps concurrent runs of the suite (ctest -j, two build trees' users)
    // out of each other's directories.
    root_ = fs::path(HFVIS_TEST_TMP_DIR) /
            ("cli_" + std::string(info->name()) + "_" + std::to_string(::getpid()));
    fs::remove_all(root_);
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

  // Runs `hfvis ARGS` (ARGS already shell-quoted where needed), capturing both streams.
  CliResult run(const std::string& args) const {
    const fs::path out_file = root_ / "stdout.txt";
    const fs::path err_file = root_ / "stderr.txt";
    const std::string command = shellQuoted(HFVIS_CLI_PATH) + " " + args + " >" +
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

TEST_F(Cli, ZeroDirections) {
  const CliResult result =
      run("horizon " + shellQuoted(ramp()) + " -o " + shellQuoted(out("o.exr")) + " -k 0");
  expectFailure(result, 2, "-k");
  EXPECT_NE(result.err.find("at least 1"), std::string::npos) << result.err;
}

TEST_F(Cli, NonNumericValues) {
  const std::string base = "svf " + shellQuoted(ramp()) + " -o " + shellQuoted(out("o.exr"));
  expectFailure(run(base + " -k eight"), 2, "'eight'");
  expectFailure(run(base + " -k 8x"), 2, "'8x'");
  expectFailure(run(base + " --z-scale tall"), 2, "--z-scale");
  expectFailure(run(base + " --cell-size 1,abc"), 2, "--cell-size");
  expectFailure(run(base + " --samples-per-unit -1"), 2, "--samples-per-unit");
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

TEST_F(Cli, FailedRunLeavesAnExistingOutputUntouched) {
  { std::ofstream(out("o.exr")) << "previous result"; }
  const CliResult result =
      run("horizon " + shellQuoted(in("absent.exr")) + " -o " + shellQuoted(out("o.exr")));
  EXPECT_EQ(result.status, 1) << result.err;
  EXPECT_EQ(readText(out("o.exr")), "previous result");
  EXPECT_EQ(listDirectory(outputs()), std::vector<std::string>{"o.exr"});
}

TEST_F(Cli, FailedLaterWriteLeavesNoOutputs) {
  // The outputs are computed and staged first; the preview cannot be written (/proc is
  // read-only even for root), so neither the horizon map nor the distances may appear,
  // and an older result at -o stays as it was.
  { std::ofstream(out("h.exr")) << "previous result"; }
  const std::string preview = "/proc/hfvis_cli_test_preview.png";
  const CliResult result = run("horizon " + shellQuoted(ramp()) + " -o " + shellQuoted(out("h.exr")) +
                               " -k 4 --distance-out " + shellQuoted(out("d.exr")) + " --preview " + preview);
  EXPECT_EQ(result.status, 1) << result.err;
  EXPECT_NE(result.err.find(preview), std::string::npos) << result.err;
  EXPECT_EQ(readText(out("h.exr")), "previous result");
  EXPECT_EQ(listDirectory(outputs()), std::vector<std::string>{"h.exr"});
}

// ---- help and devices ----

TEST_F(Cli, HelpDocumentsTheConventions) {
  const CliResult general = run("--help");
  EXPECT_EQ(general.status, 0) << general.err;
  for (const char* text : {"phi_k = 360*k/K", "compass azimuth = 90 + phi_k", "-pi/2", "radians",
                           "1 - mean_k sin(max(0, elevation_k))", "Nodata", "float32 EXR", "Exit status"}) {
    EXPECT_NE(general.out.find(text), std::string::npos) << "hfvis --help lacks '" << text << "'";
  }
  for (const char* command : {"horizon", "svf", "ao", "devices"}) {
    const CliResult help = run(std::string(command) + " --help");
    EXPECT_EQ(help.status, 0) << command;
    EXPECT_NE(help.out.find(std::string("hfvis ") + command), std::string::npos) << help.out;
  }
  EXPECT_NE(run("horizon -h").out.find("h000"), std::string::npos);
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
  for (const std::string& args :
       {std::string("devices"), "svf " + shellQuoted(ramp()) + " -o " + shellQuoted(out("o.exr")) + " -k 4"}) {
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

// ---- successful runs ----

TEST_F(Cli, HorizonWritesOneChannelPerDirection) {
  const CliResult result = run("horizon " + shellQuoted(ramp()) + " -o " + shellQuoted(out("h.exr")) +
                               " -k 8" + " --distance-out " + shellQuoted(out("d.exr")));
  ASSERT_EQ(result.status, 0) << result.err;
  EXPECT_NE(result.out.find("wrote "), std::string::npos) << result.out;
  EXPECT_NE(result.out.find("8 directions"), std::string::npos) << result.out;

  const ReadBack horizons = readBack(out("h.exr"));
  ASSERT_EQ(horizons.width, 16);
  ASSERT_EQ(horizons.height, 12);
  EXPECT_EQ(horizons.channels, hfvis::directionChannelNames("h", 8));
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

  const ReadBack distances = readBack(out("d.exr"));
  EXPECT_EQ(distances.channels, hfvis::directionChannelNames("d", 8));
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
  EXPECT_EQ(horizons.channels, hfvis::directionChannelNames("h", 4));
  EXPECT_EQ(horizons.spec.get_string_attribute("hfvis:method"), "naive");
  EXPECT_EQ(horizons.spec.get_string_attribute("hfvis:azimuth_offset_deg"), "45");
  EXPECT_EQ(horizons.spec.get_string_attribute("hfvis:cell_size_x"), "2");
  EXPECT_EQ(horizons.spec.get_string_attribute("hfvis:cell_size_y"), "1");
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
  for (const char* command : {"horizon", "svf", "ao"}) {
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
  EXPECT_EQ(listDirectory(outputs()).size(), 6u);
}

TEST_F(Cli, PreviewMustBeAPng) {
  expectFailure(run("svf " + shellQuoted(ramp()) + " -o " + shellQuoted(out("o.exr")) + " --preview " +
                    shellQuoted(out("p.jpg"))),
                2, "p.jpg");
}

}  // namespace
