// bench/suite.hpp: the standard benchmark suites, horizons (issue 3) and intervisibility
// (issue 4): which methods, sizes, contents and directions are measured in each mode, and
// the CSVs the measurements go to.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/height_field.hpp"
#include "methods.hpp"
#include "metrics.hpp"

namespace hfvis::bench {

struct SuiteOptions {
  std::string mode = "full";  // "full", "quick" (under 3 minutes) or "tiny" (the smoke test)
  std::string data_dir;       // generated fields: <content>_<N>.exr (not read in tiny mode)
  std::string dem_path;       // the real DEM (not read in tiny mode)
  std::string out_dir;        // results.csv, environment.txt
  std::string cache_dir;      // ground-truth cache
  std::string commit;         // recorded in environment.txt
  std::string self_path;      // this program, re-run for the vectorisation remarks
  // The intervisibility suite's sections to run (visibilitySections()); empty = all.
  std::vector<std::string> sections;
  // Its accuracy section's contents and K (empty: the mode's).
  std::vector<std::string> accuracy_contents;
  std::vector<int> accuracy_ks;
};

// The generated fields a mode reads from data_dir: (content, N) pairs, N x N each, for
// data/make_data.py (bench/run_report.sh generates them from this list).
std::vector<std::pair<std::string, int>> requiredInputs(const std::string& mode);

// Runs the suite; returns the process exit status.
int runSuite(const ComputeContext& context, const SuiteOptions& options);

// The intervisibility suite (bench/visibility_suite.cpp): DIR/visibility.csv and
// DIR/visibility_environment.txt; its generated inputs.
int runVisibilitySuite(const ComputeContext& context, const SuiteOptions& options);
std::vector<std::pair<std::string, int>> visibilityInputs(const std::string& mode);
// The names `hfvis_bench visibility --sections` takes: time (vis_time), stats, zone, scale,
// accuracy (vis_accuracy).
const std::vector<std::string>& visibilitySections();

// One timed measurement as the suite takes it: a warm-up run on a 64 x 64 crop (builds and
// caches the program), one full-size run discarded as warm-up when it takes under a second,
// then timeRepeated; `output` is the last run's.
struct Measured {
  Timing timing;
  MethodOutput output;
};
Measured measureMethod(const ComputeContext& context, const HeightField& field, const MethodSpec& spec,
                       const TimingPolicy& policy);

// The vectorisation remarks of the per-pixel march kernels: re-runs `self_path` with
// POCL_VECTORIZER_REMARKS=1 (and PoCL's kernel cache off, debug lines on) and returns, per
// kernel, "vectorized width W at line L" / "not vectorized at line L: reason" lines.
std::string vectorizationRemarks(const std::string& self_path);

// What `hfvis_bench vectorize-run` does in that child: runs each march kernel once.
int runKernelsOnce(const ComputeContext& context, const std::string& which);

}  // namespace hfvis::bench
