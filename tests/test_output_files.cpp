// test_output_files.cpp: writing outputs safely (hfvis::OutputFiles and the writers built on it):
// a full disk, write-protected and immutable targets, symbolic links, several outputs committed
// all together or not at all, and the temporary files a signal leaves.
#include <gtest/gtest.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <csignal>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <random>
#include <string>
#include <vector>

#include "hfvis/errors.hpp"
#include "hfvis/image_io.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

namespace fs = std::filesystem;

class OutputFilesTest : public ::testing::Test {
 protected:
  void SetUp() override {
    dir_ = testing::freshTestDirectory("output_files");
  }
  void TearDown() override {
    if (!HasFailure()) fs::remove_all(dir_);
  }
  std::string path(const std::string& name) const { return (dir_ / name).string(); }
  std::vector<std::string> filesInDir() const {
    std::vector<std::string> names;
    for (const auto& entry : fs::directory_iterator(dir_)) names.push_back(entry.path().filename().string());
    std::sort(names.begin(), names.end());
    return names;
  }
  static std::string readText(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  void writeText(const std::string& name, const std::string& text) const {
    std::ofstream(path(name), std::ios::binary) << text;
  }
  fs::path dir_;
};

// A one-channel image of noise (it does not compress): 16 x 16 floats, about 1 KB as an EXR,
// far below a stdio buffer, so that a writer that buffers writes sees their failure only at close.
ImageChannels noiseImage(int size = 16) {
  std::mt19937 random(7);
  std::uniform_real_distribution<float> uniform(0.0f, 100.0f);
  ImageChannels image;
  image.width = image.height = size;
  image.names = {"Y"};
  image.planes.emplace_back();
  for (int i = 0; i < size * size; ++i) image.planes[0].push_back(uniform(random));
  return image;
}

// The writes AFullDiskIsAnErrorAndKeepsThePreviousFile makes under a file size limit, in a
// fresh process (a fork of this one would inherit OpenEXR's and GDAL's thread pools without their
// threads, and hang): the test program, started with HFVIS_TEST_WRITE=KIND:PATH, writes one
// output before main() and exits 0 (written), 1 (an IoError naming the size limit and no
// temporary file) or 2.
[[maybe_unused]] const bool kWriteJobDone = [] {
  const char* job = std::getenv("HFVIS_TEST_WRITE");
  if (!job) return false;
  const std::string spec(job), kind = spec.substr(0, spec.find(':')), path = spec.substr(spec.find(':') + 1);
  try {
    const ImageChannels image = noiseImage();
    if (kind == "png" || kind == "text") {
      OutputFiles files;
      if (kind == "png") files.previewPng(path, image.width, image.height, image.planes[0]);
      if (kind == "text") files.text(path, std::string(5000, 'x'));
      files.commit();
    } else {
      writeImage(path, image);
    }
  } catch (const IoError& error) {
    std::fprintf(stderr, "%s\n", error.what());
    // The cause in words, and the output's name, not the temporary file's.
    const std::string message = error.what();
    ::_exit(message.find("file size limit") != std::string::npos &&
                    message.find("hfvis-tmp") == std::string::npos
                ? 1
                : 2);
  } catch (...) {
    ::_exit(2);
  }
  ::_exit(0);
}();

// Writes `path` as `kind` (exr, png, tif, text) in a child process whose files may not grow
// beyond `limit` bytes (RLIMIT_FSIZE, as `ulimit -f`; SIGXFSZ ignored, as the CLI does, so a write
// past it fails with EFBIG as one on a full disk does). Returns the child's exit status.
int writeUnderFileSizeLimit(const std::string& kind, const std::string& path, rlim_t limit) {
  const pid_t child = ::fork();
  if (child == 0) {
    std::signal(SIGXFSZ, SIG_IGN);
    const rlimit small{limit, limit};
    ::setenv("HFVIS_TEST_WRITE", (kind + ":" + path).c_str(), 1);
    if (::setrlimit(RLIMIT_FSIZE, &small) == 0)
      ::execl("/proc/self/exe", "hfvis_tests", "--gtest_list_tests", nullptr);
    ::_exit(3);
  }
  int status = 0;
  ::waitpid(child, &status, 0);
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

// Issue 26, item 1: on a full disk a small EXR or PNG came out empty, "written", replacing the
// previous file: the writers dropped the error of the buffered write, reported only at close.
TEST_F(OutputFilesTest, AFullDiskIsAnErrorAndKeepsThePreviousFile) {
  // Text outputs (the horizon lists) too.
  for (const std::string kind : {"exr", "png", "tif", "text"}) {
    SCOPED_TRACE(kind);
    const std::string name = "small." + kind;
    writeText(name, "the previous result");
    EXPECT_EQ(writeUnderFileSizeLimit(kind, path(name), 200), 1)
        << "0: reported success; 2: another error than the size limit";
    EXPECT_EQ(readText(path(name)), "the previous result");
    EXPECT_EQ(filesInDir(), std::vector<std::string>{name}) << "a temporary file was left";
    fs::remove(path(name));
  }
}

// Issue 26, item 6: a rename over a file bypasses its write protection, so protection is
// checked: a file nobody may write (mode 0444, which the superuser's access(2) would allow) is
// refused, and stays as it was.
TEST_F(OutputFilesTest, AWriteProtectedFileIsRefused) {
  writeText("prot.exr", "protected");
  fs::permissions(path("prot.exr"), fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
  try {
    writeImage(path("prot.exr"), noiseImage());
    ADD_FAILURE() << "a write-protected file was replaced";
  } catch (const IoError& error) {
    EXPECT_EQ(error.path(), path("prot.exr"));
    EXPECT_NE(error.reason().find("write-protected (mode 0444)"), std::string::npos) << error.what();
  }
  EXPECT_EQ(readText(path("prot.exr")), "protected");
  EXPECT_EQ(fs::status(path("prot.exr")).permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
  EXPECT_THROW(requireReplaceable(path("prot.exr")), IoError);
  EXPECT_EQ(filesInDir(), std::vector<std::string>{"prot.exr"});
}

// A directory whose permission bits allow writing may still take no new files: /proc, where the
// superuser's access(2) passes. It is refused before any work (the probe file removed), not
// after the computation, when the output is first created.
TEST_F(OutputFilesTest, ADirectoryThatTakesNoFilesIsRefusedBeforeAnyWork) {
  const std::string target = "/proc/hfvis-output-files-test.exr";
  try {
    requireReplaceable(target);
    ADD_FAILURE() << "/proc was taken as a place to write";
  } catch (const IoError& error) {
    EXPECT_EQ(error.path(), target);
    EXPECT_NE(error.reason().find("cannot write here"), std::string::npos) << error.what();
    // (the superuser passes the access check: the probe refuses it; others, the check)
    if (::geteuid() == 0) {
      EXPECT_NE(error.reason().find("creating a file in '/proc' fails"), std::string::npos) << error.what();
    }
  }
  // (staging needs no probe: its own temporary file fails there)
  OutputFiles outputs;
  EXPECT_THROW(outputs.text(target, "text"), IoError);
}

// An immutable file (chattr +i) cannot be replaced by anyone; it is refused before anything is
// written. Setting the attribute needs CAP_LINUX_IMMUTABLE and a file system that keeps it, which
// a container may lack: the test says so and is skipped then.
TEST_F(OutputFilesTest, AnImmutableFileIsRefused) {
  writeText("fixed.exr", "immutable");
  if (std::system(("chattr +i '" + path("fixed.exr") + "' 2>/dev/null").c_str()) != 0)
    GTEST_SKIP()
        << "chattr +i is not possible here (needs CAP_LINUX_IMMUTABLE on a file system with the attribute)";
  bool refused = false;
  try {
    writeImage(path("fixed.exr"), noiseImage());
  } catch (const IoError& error) {
    refused = std::string(error.what()).find("immutable") != std::string::npos;
    EXPECT_TRUE(refused) << error.what();
  }
  std::system(("chattr -i '" + path("fixed.exr") + "'").c_str());
  EXPECT_TRUE(refused);
  EXPECT_EQ(readText(path("fixed.exr")), "immutable");
  EXPECT_EQ(filesInDir(), std::vector<std::string>{"fixed.exr"});
}

// A sticky directory (mode 1777, as /tmp) lets only a file's owner (or the directory's, or the
// superuser) replace it. Another user's file there, mode 666, passed every check; the rename into
// place failed after the work and left the second name of the previous file, `.NAME.hfvis-tmp-*`,
// which that user could not remove either. It is refused before anything is written. Run as
// another user in a child process, which needs the superuser to set up: skipped, saying so, else.
TEST_F(OutputFilesTest, AnotherUsersFileInAStickyDirectoryIsRefusedBeforeAnyWrite) {
  if (::geteuid() != 0) GTEST_SKIP() << "needs the superuser, to give a file to another user and become one";
  const fs::path sticky = dir_ / "sticky";
  fs::create_directory(sticky);
  const std::string theirs = (sticky / "theirs.exr").string();
  { std::ofstream(theirs) << "their result"; }
  ASSERT_EQ(::chown(theirs.c_str(), 12345, 12345), 0);
  ASSERT_EQ(::chmod(theirs.c_str(), 0666), 0);
  ASSERT_EQ(::chmod(sticky.c_str(), 01777), 0);
  ::chmod(dir_.c_str(), 0755);  // (the way there, for the other user)
  const pid_t child = ::fork();
  if (child == 0) {  // as user 65534: 0 when refused, naming the sticky bit, with nothing written
    if (::setgid(65534) != 0 || ::setuid(65534) != 0) ::_exit(3);
    try {
      requireReplaceable(theirs);
      ::_exit(4);
    } catch (const IoError& error) {
      if (std::string(error.what()).find("is sticky (mode 1777)") == std::string::npos) ::_exit(5);
    }
    try {
      writeImage(theirs, noiseImage());
      ::_exit(6);
    } catch (const IoError& error) {
      ::_exit(std::string(error.what()).find("is sticky") == std::string::npos ? 7 : 0);
    }
  }
  int status = 0;
  ASSERT_EQ(::waitpid(child, &status, 0), child);
  EXPECT_TRUE(WIFEXITED(status) && WEXITSTATUS(status) == 0) << "child status " << status;
  EXPECT_EQ(readText(theirs), "their result");
  std::vector<std::string> names;
  for (const auto& entry : fs::directory_iterator(sticky)) names.push_back(entry.path().filename().string());
  EXPECT_EQ(names, std::vector<std::string>{"theirs.exr"});
  // The superuser replaces it as before.
  writeImage(theirs, noiseImage());
  EXPECT_NE(readText(theirs), "their result");
}

// Issue 26, item 6: an output at a symbolic link replaces what the link names (in that file's
// directory) and keeps the link; the replaced file's permissions stay.
TEST_F(OutputFilesTest, ASymbolicLinkIsWrittenThrough) {
  fs::create_directories(dir_ / "data");
  writeText("data/real.exr", "old");
  fs::permissions(path("data/real.exr"), fs::perms::owner_read | fs::perms::owner_write);
  // Another user's file, where this test may give it away (as the superuser): it stays theirs.
  const bool given_away = ::chown(path("data/real.exr").c_str(), 65534, 65534) == 0;
  fs::create_symlink("data/real.exr", dir_ / "link.exr");
  const ImageChannels image = noiseImage();
  writeImage(path("link.exr"), image);
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir_ / "link.exr")));
  EXPECT_EQ(readHeightField(path("data/real.exr")).heights, image.planes[0]);
  EXPECT_EQ(fs::status(path("data/real.exr")).permissions() & fs::perms::all,
            fs::perms::owner_read | fs::perms::owner_write);
  struct stat status {};
  ASSERT_EQ(::stat(path("data/real.exr").c_str(), &status), 0);
  if (given_away) {
    EXPECT_EQ(status.st_uid, 65534u);
  }
  EXPECT_EQ(filesInDir(), (std::vector<std::string>{"data", "link.exr"}));
  // A dangling link: the file it names is created.
  fs::create_symlink("data/new.exr", dir_ / "dangling.exr");
  writeImage(path("dangling.exr"), image);
  EXPECT_EQ(readHeightField(path("data/new.exr")).heights, image.planes[0]);
}

// A loop of links leads to no file: refused, naming the loop, and nothing is written.
TEST_F(OutputFilesTest, ALoopOfSymbolicLinksIsRefused) {
  fs::create_symlink("b.exr", dir_ / "a.exr");
  fs::create_symlink("a.exr", dir_ / "b.exr");
  try {
    writeImage(path("a.exr"), noiseImage());
    FAIL() << "a loop of links was written";
  } catch (const IoError& error) {
    EXPECT_NE(std::string(error.what()).find("loop"), std::string::npos) << error.what();
  }
  EXPECT_EQ(filesInDir(), (std::vector<std::string>{"a.exr", "b.exr"}));
  EXPECT_TRUE(fs::is_symlink(fs::symlink_status(dir_ / "a.exr")));
}

// A GeoTIFF replaces the files GDAL reads beside it as part of it (hfvis::OutputFiles): a stale
// FILE.aux.xml gave the new file the old one's nodata value, scale and offset (GDAL prefers it to
// the file's own); overviews and a mask too; and a TIFF's world files (a stale a.tfw gave a new
// file without georeferencing the old one's cells of 40 m, a probe's find). STEM.wld stays (any
// image of that stem may own it), as do an EXR's. Where the commit fails, every one is back as it
// was.
TEST_F(OutputFilesTest, AGeoTiffTakesTheSideFilesOfThePreviousFileWithIt) {
  const std::string pam =
      "<PAMDataset><PAMRasterBand band=\"1\"><NoDataValue>1</NoDataValue><Offset>100</Offset>"
      "<Scale>-1</Scale></PAMRasterBand></PAMDataset>\n";
  const std::vector<std::string> sides = {"a.tif.aux.xml", "a.tif.ovr", "a.tif.MSK",
                                          "a.tif.aux",     "a.tfw",     "a.TIFW"};
  const std::vector<std::string> others = {"a.wld", "a.exr.aux.xml", "a.pgw"};
  const auto previous = [&] {
    writeText("a.tif", "previous a");
    for (const std::string& name : sides) writeText(name, name == "a.tif.aux.xml" ? pam : "previous " + name);
    for (const std::string& name : others) writeText(name, "previous " + name);
  };
  ImageChannels image = noiseImage();
  image.planes[0][0] = 1.0f;  // the stale nodata value
  const auto sorted = [](std::vector<std::string> names) {
    std::sort(names.begin(), names.end());
    return names;
  };

  previous();
  writeImage(path("a.tif"), image);
  EXPECT_EQ(filesInDir(), sorted({"a.tif", "a.wld", "a.exr.aux.xml", "a.pgw"}));
  for (const std::string& name : others) EXPECT_EQ(readText(path(name)), "previous " + name);
  const ImageChannels read = readImage(path("a.tif"));
  ASSERT_EQ(read.planes.size(), 1u);
  EXPECT_EQ(read.planes[0], image.planes[0]);

  // A failed commit (the second output's finished file gone) puts the first one's side files back.
  for (const std::string& name : filesInDir()) fs::remove(dir_ / name);
  previous();
  {
    OutputFiles files;
    files.image(path("a.tif"), image);
    files.image(path("b.exr"), image);
    for (const std::string& name : filesInDir())
      if (name.rfind(".b.hfvis-tmp-", 0) == 0) fs::remove(dir_ / name);
    EXPECT_THROW(files.commit(), IoError);
  }
  std::vector<std::string> all = sides;
  all.insert(all.end(), others.begin(), others.end());
  all.push_back("a.tif");
  EXPECT_EQ(filesInDir(), sorted(all));
  EXPECT_EQ(readText(path("a.tif")), "previous a");
  EXPECT_EQ(readText(path("a.tif.aux.xml")), pam);
  EXPECT_EQ(readText(path("a.tif.ovr")), "previous a.tif.ovr");
  EXPECT_EQ(readText(path("a.tif.MSK")), "previous a.tif.MSK");
  EXPECT_EQ(readText(path("a.tfw")), "previous a.tfw");
}

// An output never replaces an input, even where its path comes to name the input during the run
// (a probe's find: a link made to the input after the CLI's check, or a directory of the output's
// path turned into a link to the input's, and the input was replaced, exit 0). Files protect()
// names are refused as each output is staged and again at the commit; nothing is written.
TEST_F(OutputFilesTest, AnOutputNeverReplacesAProtectedInputWhateverItsPathBecomes) {
  writeText("in.exr", "the input");
  const ImageChannels image = noiseImage();
  {  // a link made before the output is staged
    fs::create_symlink("in.exr", dir_ / "new.exr");
    OutputFiles files;
    files.protect({path("in.exr")});
    EXPECT_THROW(files.image(path("new.exr"), image), IoError);
    fs::remove(dir_ / "new.exr");
  }
  {  // a directory of the path turned into a link to the input's, between staging and commit
    fs::create_directories(dir_ / "od");
    OutputFiles files;
    files.protect({path("in.exr")});
    files.image(path("od/in.exr"), image);
    fs::remove_all(dir_ / "od");
    fs::create_directory_symlink(".", dir_ / "od");
    try {
      files.commit();
      ADD_FAILURE() << "the input was replaced";
    } catch (const IoError& error) {
      EXPECT_NE(std::string(error.what()).find("names the input"), std::string::npos) << error.what();
    }
    fs::remove(dir_ / "od");
  }
  EXPECT_EQ(readText(path("in.exr")), "the input");
  EXPECT_EQ(filesInDir(), std::vector<std::string>{"in.exr"});  // (no temporary file left)
}

// Outputs appear together or not at all: a later output that cannot be written leaves the earlier
// ones' previous files as they were (and removes every temporary file).
TEST_F(OutputFilesTest, AFailedOutputLeavesEveryPreviousFile) {
  writeText("a.exr", "previous a");
  writeText("b.tif", "previous b");
  fs::create_directories(dir_ / "c.png");  // a directory where the preview should go
  const ImageChannels image = noiseImage();
  {
    OutputFiles files;
    files.image(path("a.exr"), image);
    files.image(path("b.tif"), image);
    EXPECT_THROW(files.previewPng(path("c.png"), image.width, image.height, image.planes[0]), IoError);
  }
  EXPECT_EQ(readText(path("a.exr")), "previous a");
  EXPECT_EQ(readText(path("b.tif")), "previous b");
  EXPECT_EQ(filesInDir(), (std::vector<std::string>{"a.exr", "b.tif", "c.png"}));

  // A target that changes between staging and commit is checked again there: a directory now
  // at the second output stops the commit before the first file is replaced.
  {
    OutputFiles files;
    files.image(path("a.exr"), image);
    files.image(path("d.exr"), image);
    fs::create_directories(dir_ / "d.exr");
    EXPECT_THROW(files.commit(), IoError);
  }
  EXPECT_EQ(readText(path("a.exr")), "previous a");
  EXPECT_EQ(filesInDir(), (std::vector<std::string>{"a.exr", "b.tif", "c.png", "d.exr"}));
  EXPECT_TRUE(fs::is_directory(dir_ / "d.exr"));

  // A rename that fails after the first output is in place (here b's finished file is gone)
  // puts the first output's previous file back.
  writeText("b.exr", "previous b");
  {
    OutputFiles files;
    files.image(path("a.exr"), image);
    files.image(path("b.exr"), image);
    for (const std::string& name : filesInDir())
      if (name.rfind(".b.hfvis-tmp-", 0) == 0) fs::remove(dir_ / name);
    EXPECT_THROW(files.commit(), IoError);
  }
  EXPECT_EQ(readText(path("a.exr")), "previous a");
  EXPECT_EQ(readText(path("b.exr")), "previous b");
  EXPECT_EQ(filesInDir(), (std::vector<std::string>{"a.exr", "b.exr", "b.tif", "c.png", "d.exr"}));
  // And where nothing was there before, the new first output is removed again.
  {
    OutputFiles files;
    files.image(path("new.exr"), image);
    files.image(path("b.exr"), image);
    for (const std::string& name : filesInDir())
      if (name.rfind(".b.hfvis-tmp-", 0) == 0) fs::remove(dir_ / name);
    EXPECT_THROW(files.commit(), IoError);
  }
  EXPECT_FALSE(fs::exists(path("new.exr")));
  EXPECT_EQ(readText(path("b.exr")), "previous b");

  // The same file twice would replace the first output with the second.
  OutputFiles twice;
  twice.image(path("e.exr"), image);
  EXPECT_THROW(twice.image(path("./e.exr"), image), InvalidArgument);
}

// Issue 26, item 7: SIGINT, SIGTERM and SIGHUP remove the temporary files of unfinished outputs
// (removeTemporaryOutputsOnSignals), and the process still ends of the signal.
TEST_F(OutputFilesTest, SignalsRemoveTemporaryFiles) {
  // (SIGXCPU: a CPU time limit, ulimit -t; SIGALRM: an alarm; both left the files, a probe's find)
  for (const int signal_number : {SIGINT, SIGTERM, SIGHUP, SIGXCPU, SIGALRM}) {
    SCOPED_TRACE(signal_number);
    const pid_t child = ::fork();
    if (child == 0) {
      std::signal(signal_number, SIG_DFL);
      removeTemporaryOutputsOnSignals();
      OutputFiles files;  // (text: no image library's threads in a forked process)
      files.text(path("staged.json"), "{}");
      ::raise(signal_number);  // between staging and commit, as a user's Ctrl-C
      ::_exit(0);
    }
    int status = 0;
    ::waitpid(child, &status, 0);
    EXPECT_TRUE(WIFSIGNALED(status) && WTERMSIG(status) == signal_number) << "status " << status;
    EXPECT_EQ(filesInDir(), std::vector<std::string>{});
  }
}

}  // namespace
}  // namespace hfvis
