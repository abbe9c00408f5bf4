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

// A CSV file's header and rows; column() names the index of a column (a failure when absent).
struct CsvTable {
  std::vector<std::string> columns;
  std::vector<std::vector<std::string>> rows;
  std::size_t column(const std::string& name) const {
    for (std::size_t i = 0; i < columns.size(); ++i)
      if (columns[i] == name) return i;
    ADD_FAILURE() << "no column " << name;
    return 0;
  }
};

CsvTable readCsv(const fs::path& path) {
  CsvTable table;
  std::ifstream in(path);
  std::string line;
  if (!std::getline(in, line)) {
    ADD_FAILURE() << path << " is empty or missing";
    return table;
  }
  table.columns = splitCsv(line);
  while (std::getline(in, line)) {
    table.rows.push_back(splitCsv(line));
    EXPECT_EQ(table.rows.back().size(), table.columns.size()) << line;
  }
  return table;
}

class BenchSmoke : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!fs::exists(benchBinary())) GTEST_SKIP() << benchBinary() << " is not built (HFVIS_BUILD_BENCH=OFF?)";
    // One directory per test: CTest runs the tests of this fixture in parallel processes.
    dir_ = fs::path(HFVIS_TEST_TMP_DIR) /
           (std::string("bench_smoke_") + ::testing::UnitTest::GetInstance()->current_test_info()->name());
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
  const CsvTable csv = readCsv(dir_ / "report" / "results.csv");
  const std::size_t section = csv.column("section"), method = csv.column("method");
  const std::size_t error = csv.column("err_mean_deg"), metric = csv.column("metric"), value = csv.column("value");
  const std::size_t outputs = csv.column("outputs"), spu = csv.column("spu"), svf_error = csv.column("svf_mean_abs");
  std::set<std::string> sections, methods, plane_sweep_spus;
  int rows_with_errors = 0, svf_only_with_errors = 0;
  for (const auto& f : csv.rows) {
    if (f.size() != csv.columns.size()) continue;  // reported by readCsv
    const std::string line = f[section] + "," + f[method] + ",...";
    sections.insert(f[section]);
    if (!f[method].empty()) methods.insert(f[method]);
    if (f[section] == "plane" && !f[error].empty()) {
      ++rows_with_errors;
      EXPECT_TRUE(std::isfinite(std::stod(f[error]))) << line;
    }
    if (f[section] == "plane" && f[method] == "sweep") plane_sweep_spus.insert(f[spu]);
    // The headline's SVF-only runs (sweep and naive) carry their SVF error against the truth.
    if (f[section] == "headline" && f[outputs] == "svf") {
      EXPECT_FALSE(f[svf_error].empty()) << line;
      if (!f[svf_error].empty()) {
        EXPECT_TRUE(std::isfinite(std::stod(f[svf_error]))) << line;
        EXPECT_LT(std::stod(f[svf_error]), 0.2) << line;
        ++svf_only_with_errors;
      }
    }
    // The baselines' march (radius_R's kernel, unbounded) and the library's naive march are
    // the same method.
    if (f[metric] == "baseline_march_vs_library_naive_max_deg") {
      EXPECT_LT(std::stod(f[value]), 0.01) << line;
    }
    // One naive kernel: no bench-only naive march, and the horizon sweep has no lines per unit.
    EXPECT_NE(f[method], "naive_bench") << line;
  }
  for (const char* s :
       {"checks", "truth", "plane", "sources", "azimuth", "stack", "lattice", "headline", "scale_n", "scale_k"})
    EXPECT_TRUE(sections.count(s)) << "no rows for section " << s;
  for (const char* m : {"sweep", "naive", "radius_4", "pyramid_4", "floor"})
    EXPECT_TRUE(methods.count(m)) << "no rows for method " << m;
  for (const char* s : {"1", "4"}) EXPECT_TRUE(plane_sweep_spus.count(s)) << "no plane rows for the sweep at spu " << s;
  for (const auto& c : csv.columns) EXPECT_NE(c, "lpu");
  EXPECT_GT(rows_with_errors, 0);
  EXPECT_EQ(svf_only_with_errors, 2);  // sweep and naive
  EXPECT_TRUE(fs::exists(dir_ / "report" / "environment.txt"));
}

// The intervisibility suite on tiny fields: every section, every tuning, the naive march;
// statistics are present and the tunings agree on the horizons (they change only the work).
TEST_F(BenchSmoke, TinyVisibilitySuiteMeasuresEverySection) {
  const fs::path log = dir_ / "visibility.log";
  ASSERT_EQ(runBench("visibility --tiny --out '" + (dir_ / "report").string() + "'", log), 0) << readText(log);
  const CsvTable csv = readCsv(dir_ / "report" / "visibility.csv");
  const std::size_t section = csv.column("section"), method = csv.column("method"), tuning = csv.column("tuning");
  const std::size_t content = csv.column("content"), m_a = csv.column("m_a");
  const std::size_t over = csv.column("lines_over_bound");
  std::set<std::string> sections, methods, tunings;
  std::map<std::string, std::string> horizons;  // vis_time content -> m_a of every tuning
  for (const auto& f : csv.rows) {
    if (f.size() != csv.columns.size()) continue;  // reported by readCsv
    const std::string line = f[section] + "," + f[content] + "," + f[method] + "," + f[tuning];
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
