// cli/pipeline.hpp: what every command that reads a height field shares. The pipeline, written
// once (runPipeline): the outputs checked -> the input read -> the command's other inputs
// (Computation::prepare) -> the device's context -> progress and timing around the computation
// (Computation::compute) -> its images and previews staged (Computation::write) -> all committed
// or none -> the summary line. Each command (cli/commands/) supplies the three steps.
#pragma once

#include <chrono>
#include <cstddef>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "arguments.hpp"
#include "hfvis/device.hpp"
#include "hfvis/height_field.hpp"
#include "hfvis/image_io.hpp"
#include "hfvis/viewshed.hpp"
#include "image_outputs.hpp"
#include "table.hpp"

namespace hfvis::cli {

std::string formatNumber(double value);
// `digits` decimals; a value that would print as 0 or with 10 digits or more before the point, in
// `digits` significant digits instead.
std::string formatFixed(double value, int digits);
// A JSON string: quoted, with its escapes (the JSON outputs of horizon-lists, region and pvs);
// UTF-8 passes through, a byte that is not part of it (a file name in another encoding) becomes
// \u00XX, so that the output stays valid JSON.
std::string jsonString(const std::string& text);
// Mean over the finite values (nodata pixels are NaN and do not count).
double finiteMean(const std::vector<float>& values);
// `count` planes of `pixels` values, one after another, as separate planes.
std::vector<std::vector<float>> splitPlanes(const std::vector<float>& planes, std::size_t pixels, int count);

// The library's result must hold what was asked for; a mismatch is a library bug, caught
// here rather than written out as a corrupt image.
void requireSize(const std::vector<float>& values, std::size_t expected, const char* what);
void requireResultSize(int width, int height, const HeightField& field);
// A result that is not finite where the height is (the planes of a multi-plane result one after
// another): the numbers went beyond what the kernels' single precision holds somewhere no bound
// on the options caught. An error, rather than NaN or infinity written as data.
void requireFiniteResult(const std::vector<float>& planes, const HeightField& field, const char* what);

// Progress on stderr when it is a terminal: one line rewritten in place, at most a few
// times a second (batches can be tiny). Wrap the computation in run() so that an error
// message after a half-written progress line starts on a line of its own.
class Progress {
 public:
  explicit Progress(bool quiet);

  // Sets the options' callbacks: "done/total directions", the strip under way when the field
  // runs in strips, and once some are done the time left at the pace so far.
  void attach(SweepOptions& options);

  // A callback for a run over other things than directions: "done/total <unit>".
  std::function<void(int, int)> callback(int total, const char* unit);

  template <typename Body>
  auto run(Body&& body) -> decltype(body()) {
    try {
      return body();
    } catch (...) {
      endLine();
      throw;
    }
  }

 private:
  // `finished_batch`: a batch of directions just ended (the last one ends the line).
  void report(bool finished_batch = true);
  void endLine();

  bool enabled_;
  bool line_open_ = false;
  int done_ = 0, total_ = 0, strip_ = 0, strips_ = 0;
  const char* unit_ = "directions";
  std::chrono::steady_clock::time_point start_, last_{};
};

// Lighting assumes row 0 is north and column 0 west (compass azimuth = hfvis azimuth + 90
// degrees). A raster whose geotransform runs south-up (t[5] > 0) or west-up (t[1] < 0: column 0
// is east), or both, is lit flipped north-up and east-right, and its results flipped back.
struct NorthUp {
  const HeightField* input = nullptr;
  HeightField flipped_copy;  // the input flipped, when it needs it
  bool flip_rows = false, flip_columns = false;
  bool flipped() const { return flip_rows || flip_columns; }
  // The field to compute on: the input itself (no copy), or its flipped copy.
  const HeightField& field() const { return flipped() ? flipped_copy : *input; }
  // A plane of the field's size (or several, one after another) back in the input's order.
  void restore(std::vector<float>& planes) const;
  // A pixel of the input, where it lies in the field computed on.
  void place(Observer& o) const;
};
// `field` must outlive the result.
NorthUp northUp(const HeightField& field);

using Attributes = std::vector<std::pair<std::string, std::string>>;

// The summary line: "wrote FILES (WxH, COUNT UNITs, METHOD, T s on DEVICE)NOTE".
struct Summary {
  Summary(int count, std::string note = "", std::string unit = "direction")
      : count(count), note(std::move(note)), unit(std::move(unit)) {}
  int count;
  std::string note, unit;
  std::string always;  // a line printed after it, even with --quiet ("" = none)
};

// What the pipeline hands a command's compute and write steps.
struct Job {
  const CommandSpec& command;
  const RunArguments& run;
  const HeightField& input;       // as read
  const ComputeContext* context;  // nullptr for a command that runs on the host
  Progress& progress;
  std::string method;  // hfvis:method and the summary's

  // The string attributes describing the run, written into every output (EXR attributes,
  // GeoTIFF metadata items); `field` gives the cell size. `swept` false: the run has no
  // directions or sampling density (a viewshed, region visibility), so none are recorded.
  Attributes attributes(const HeightField& field, bool swept = true) const;
  // An output of the field's size. A GeoTIFF output also carries the field's georeference, so
  // that it overlays its input, and the --nodata value.
  ImageChannels image(const HeightField& field, std::vector<std::string> names,
                      std::vector<std::vector<float>> planes, Attributes attributes,
                      const std::string& quantity, const std::string& units) const;
};

// One command's steps of the pipeline.
class Computation {
 public:
  explicit Computation(const RunArguments& run) : run_(run) {}
  virtual ~Computation() = default;

  // Every output, checked before the input is read: -o, then --distance-out, --preview.
  virtual std::vector<std::string> outputs() const;
  // Inputs besides the height field, which no output may replace.
  virtual std::vector<std::string> otherInputs() const { return {}; }
  // false: text outputs (no image writer needed), computed on the host (no device) unless
  // usesDevice() says otherwise.
  virtual bool writesImages() const { return true; }
  // Whether it computes on the device: those that write images, and text outputs computed there
  // (region's JSON).
  virtual bool usesDevice() const { return writesImages(); }
  // hfvis:method and the summary's method.
  virtual std::string method() const;
  // After the height field is read, before the device is set up: the command's own inputs read
  // and checked against the field. A command that computes on a copy of the field may drop the
  // field's heights here (its size and cell size stay).
  virtual void prepare(HeightField& /*field*/) {}
  // The computation (timed).
  virtual void compute(Job& job) = 0;
  // Stages every output into `outputs` (committed all together by the pipeline).
  virtual Summary write(Job& job, OutputFiles& outputs) = 0;

 protected:
  const RunArguments& run_;
};

int runPipeline(const CommandLine& line, Computation& computation);

// A CommandSpec::run for a Computation.
template <typename C>
int pipelined(const CommandLine& line) {
  C computation(line.run);
  return runPipeline(line, computation);
}

}  // namespace hfvis::cli
