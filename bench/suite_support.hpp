// bench/suite_support.hpp: what the benchmark suites share: CSV rows and their writer, the
// input fields of a mode, and the timestamped log line.
#pragma once

#include <fstream>
#include <map>
#include <string>
#include <vector>

#include <functional>

#include "hfvis/height_field.hpp"
#include "metrics.hpp"
#include "suite.hpp"

namespace hfvis::bench {

// One CSV row: column -> value; columns a row does not use stay empty.
using Row = std::map<std::string, std::string>;

// A number as the CSVs write it (%.6g).
std::string num(double v);

// Writes the header, then one line per row, flushed (a run cut short keeps its rows).
class CsvWriter {
 public:
  CsvWriter(const std::string& path, std::vector<std::string> columns);
  void write(const Row& row);

 private:
  std::ofstream out_;
  std::vector<std::string> columns_;
};

// The top-left width x height of a field.
HeightField crop(const HeightField& field, int width, int height);

struct Content {
  std::string name;   // "fractal", ..., "dem"
  std::string label;  // name with size, for the cache and the log
  HeightField field;
};

// Field `name` at size n for options.mode: tiny mode makes small synthetic stand-ins (no
// files); otherwise <data_dir>/<name>_<n>.exr, or for "dem" the central n x n of the DEM.
Content loadContent(const SuiteOptions& options, const std::string& name, int n);

// The suites' timing: `warm_up` once (a small run that builds and caches the program), one
// `run` that is discarded as warm-up when it takes under a second (else it counts), then
// timeRepeated(run, policy) for the rest.
Timing timeWithWarmUp(const std::function<void()>& warm_up, const std::function<void()>& run,
                      const TimingPolicy& policy);

int threads();

// printf to stdout, prefixed with the seconds since the first line and flushed, so a log
// shows where a run spends its time.
void say(const char* format, ...) __attribute__((format(printf, 1, 2)));

}  // namespace hfvis::bench
