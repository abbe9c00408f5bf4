// tests/test_bench_smoke.cpp: keeps the benchmark harness (bench/) from rotting: runs
// hfvis_bench's ground-truth self-checks and its whole suite on tiny generated fields (every
// section, every method), and checks what it wrote. Timings are never checked.
#include <gtest/gtest.h>
#include <sys/wait.h>

#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <map>
#include <set>
#include <sstream>
#include <string>
#include <vector>

namespace {

namespace fs = std::filesystem;

// The benchmark program: HFVIS_BENCH_PATH when the build defines it, else where the build
// puts it beside the CLI (build/hfvis -> build/bench/hfvis_bench).
fs::path benchBinary() {
#ifdef HFVIS_BENCH_PATH
  return HFVIS_BENCH_PATH;
#else
  return fs::path(HFVIS_CLI_PATH).parent_path() / "bench" / "hfvis_bench";
#endif
}

std::string readText(const fs::path& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// Runs `arguments` with the benchmark program, output into `log`; the exit status.
int runBench(const std::string& arguments, const fs::path& log) {
  const std::string command =
      "'" + benchBinary().string() + "' " + arguments + " > '" + log.string() + "' 2>&1";
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

std::vector<std::string> splitCsv(const std::string& line) {
  std::vector<std::string> fields;
  std::string field;
  bool quoted = false;
  for (char c : line) {
    if (c == '"') {
      quoted = !quoted;
    } else if (c == ',' && !quoted) {
      fields.push_back(field);
      field.clear();
    } else {
      field += c;
    }
  }
  fields.push_back(field);
  return fields;
}

class BenchSmoke : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(benchBinary())) GTEST_SKIP() << benchBinary() << " is not built (HFVIS_BUILD_BENCH=OFF?)";
    dir_ = fs::path(HFVIS_TEST_TMP_DIR) / "bench_smoke";
    fs::remove_all(dir_);
    fs::create_directories(dir_);
  }
  fs::path dir_;
};

TEST_F(BenchSmoke, GroundTruthPassesItsSelfChecks) {
  const fs::path log = dir_ / "check.log";
  EXPECT_EQ(runBench("check-truth", log), 0) << readText(log);
}

TEST_F(BenchSmoke, TinySuiteMeasuresEveryMethodInEverySection) {
  const fs::path log = dir_ / "suite.log";
  ASSERT_EQ(runBench("suite --tiny --out '" + (dir_ / "report").string() + "'", log), 0) << readText(log);
  std::ifstream csv(dir_ / "report" / "results.csv");
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  const std::vector<std::string> columns = splitCsv(line);
  auto column = [&](const std::string& name) {
    for (std::size_t i = 0; i < columns.size(); ++i)
      if (columns[i] == name) return i;
    ADD_FAILURE() << "results.csv has no column " << name;
    return std::size_t{0};
  };
  const std::size_t section = column("section"), method = column("method"), error = column("err_mean_deg");
  const std::size_t metric = column("metric"), value = column("value");
  std::set<std::string> sections, methods;
  int rows_with_errors = 0;
  while (std::getline(csv, line)) {
    const auto f = splitCsv(line);
    ASSERT_EQ(f.size(), columns.size()) << line;
    sections.insert(f[section]);
    if (!f[method].empty()) methods.insert(f[method]);
    if (f[section] == "plane" && !f[error].empty()) {
      ++rows_with_errors;
      EXPECT_TRUE(std::isfinite(std::stod(f[error]))) << line;
    }
    // The benchmark's naive march and the library's are the same method.
    if (f[metric] == "naive_bench_vs_library_naive_max_deg") {
      EXPECT_LT(std::stod(f[value]), 0.01) << line;
    }
  }
  for (const char* s :
       {"checks", "truth", "plane", "sources", "azimuth", "stack", "headline", "scale_n", "scale_k"})
    EXPECT_TRUE(sections.count(s)) << "no rows for section " << s;
  for (const char* m : {"sweep", "naive", "naive_bench", "radius_4", "pyramid_4", "floor"})
    EXPECT_TRUE(methods.count(m)) << "no rows for method " << m;
  EXPECT_GT(rows_with_errors, 0);
  EXPECT_TRUE(fs::exists(dir_ / "report" / "environment.txt"));
}

// The intervisibility suite on tiny fields: every section, every tuning, the naive march;
// statistics are present and the tunings agree on the horizons (they change only the work).
TEST_F(BenchSmoke, TinyVisibilitySuiteMeasuresEverySection) {
  const fs::path log = dir_ / "visibility.log";
  ASSERT_EQ(runBench("visibility --tiny --out '" + (dir_ / "report").string() + "'", log), 0) << readText(log);
  std::ifstream csv(dir_ / "report" / "visibility.csv");
  std::string line;
  ASSERT_TRUE(std::getline(csv, line));
  const std::vector<std::string> columns = splitCsv(line);
  auto column = [&](const std::string& name) {
    for (std::size_t i = 0; i < columns.size(); ++i)
      if (columns[i] == name) return i;
    ADD_FAILURE() << "visibility.csv has no column " << name;
    return std::size_t{0};
  };
  const std::size_t section = column("section"), method = column("method"), tuning = column("tuning");
  const std::size_t content = column("content"), m_a = column("m_a"), over = column("lines_over_bound");
  std::set<std::string> sections, methods, tunings;
  std::map<std::string, std::string> horizons;  // vis_time content -> m_a of every tuning
  while (std::getline(csv, line)) {
    const auto f = splitCsv(line);
    ASSERT_EQ(f.size(), columns.size()) << line;
    sections.insert(f[section]);
    methods.insert(f[method]);
    if (!f[tuning].empty()) tunings.insert(f[tuning]);
    if (f[method] == "tree") {
      ASSERT_FALSE(f[m_a].empty()) << line;
      EXPECT_EQ(f[over], "0") << line;
      if (f[section] == "vis_time") {
        auto [it, fresh] = horizons.emplace(f[content], f[m_a]);
        EXPECT_EQ(it->second, f[m_a]) << "tunings disagree on m_a: " << line;
      }
    }
  }
  for (const char* s : {"vis_time", "vis_stats", "vis_zone", "vis_scale"})
    EXPECT_TRUE(sections.count(s)) << "no rows for section " << s;
  EXPECT_TRUE(methods.count("naive"));
  for (const char* t : {"plain", "deferred", "default", "zone"}) EXPECT_TRUE(tunings.count(t)) << t;
  EXPECT_TRUE(fs::exists(dir_ / "report" / "visibility_environment.txt"));
}

}  // namespace
