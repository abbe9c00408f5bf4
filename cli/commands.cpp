// cli/commands.cpp: the hfvis subcommands: listing devices, and the compute commands
// (horizon, svf, ao, viewcount, horizons, bounce): read, compute, then write every output
// all-or-nothing.
#include "commands.hpp"

#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iomanip>
#include <iostream>
#include <limits>
#include <optional>
#include <sstream>
#include <string>
#include <system_error>
#include <utility>
#include <vector>

#include "hfvis/bounce.hpp"
#include "hfvis/device.hpp"
#include "hfvis/environment_light.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/height_field.hpp"
#include "hfvis/horizon.hpp"
#include "hfvis/horizon_lists.hpp"
#include "hfvis/image_io.hpp"
#include "hfvis/intervisibility.hpp"
#include "hfvis/insolation.hpp"
#include "hfvis/sun_shading.hpp"
#include "hfvis/sun.hpp"
#include "hfvis/viewshed.hpp"
#include "horizon_list_files.hpp"
#include "observer_files.hpp"

namespace hfvis::cli {
namespace {

namespace fs = std::filesystem;

std::string formatNumber(double value) {
  std::ostringstream out;
  out << std::setprecision(10) << value;
  return out.str();
}

std::string formatFixed(double value, int digits) {
  std::ostringstream out;
  out << std::fixed << std::setprecision(digits) << value;
  return out.str();
}

std::string formatMemory(std::uint64_t bytes) {
  const double gib = static_cast<double>(bytes) / (1024.0 * 1024.0 * 1024.0);
  if (gib >= 1.0) return formatFixed(gib, 1) + " GiB";
  return formatFixed(static_cast<double>(bytes) / (1024.0 * 1024.0), 0) + " MiB";
}

std::vector<std::string> outputPaths(const RunArguments& run) {
  std::vector<std::string> paths{run.output};
  if (!run.distance_output.empty()) paths.push_back(run.distance_output);
  if (!run.preview.empty()) paths.push_back(run.preview);
  return paths;
}

// The same file, whether or not it exists yet (links and relative paths resolved).
bool sameFile(const std::string& a, const std::string& b) {
  std::error_code error;
  if (fs::exists(a, error) && fs::exists(b, error)) return fs::equivalent(a, b, error);
  std::error_code error_a, error_b;
  const fs::path canonical_a = fs::weakly_canonical(a, error_a),
                 canonical_b = fs::weakly_canonical(b, error_b);
  if (error_a || error_b)  // (an error gives empty paths, which would compare equal)
    return fs::absolute(a, error).lexically_normal() == fs::absolute(b, error).lexically_normal();
  return canonical_a == canonical_b;
}

// Every output can be written, none is an input (an output never replaces an input), and no
// two outputs are the same file (the second would replace the first). Checked before the
// input is read.
void requireOutputs(const RunArguments& run, const std::vector<std::string>& outputs, bool images = true) {
  std::vector<std::string> inputs{run.input};
  if (!run.radiance.empty()) inputs.push_back(run.radiance);
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    requireReplaceable(outputs[i]);
    if (images && outputs[i] != run.preview)
      requireImageWriter(outputs[i]);  // (the preview: a .png, checked)
    for (const std::string& input : inputs) {
      if (sameFile(outputs[i], input))
        throw UsageError("output '" + outputs[i] + "' is the input '" + input +
                         "': outputs never replace an input");
    }
    for (std::size_t j = 0; j < i; ++j) {
      if (sameFile(outputs[i], outputs[j]))
        throw UsageError("outputs '" + outputs[j] + "' and '" + outputs[i] + "' are the same file");
    }
  }
}

// Mean over the finite values (nodata pixels are NaN and do not count).
double finiteMean(const std::vector<float>& values) {
  double sum = 0.0;
  std::size_t count = 0;
  for (const float value : values) {
    if (std::isfinite(value)) {
      sum += value;
      ++count;
    }
  }
  return count ? sum / static_cast<double>(count) : std::nan("");
}

// The horizon preview: per pixel, the mean elevation over the directions whose ray stays
// in the field (-pi/2 marks a ray that leaves it at once; averaging those in would make the
// border dominate the stretch). NaN where every direction is NaN (nodata) or leaves at once.
std::vector<float> meanInFieldElevation(const std::vector<float>& planes, std::size_t pixels,
                                        int directions) {
  constexpr float kLeavesAtOnce = -1.57079632679489661923f;
  std::vector<double> sum(pixels, 0.0);
  std::vector<int> count(pixels, 0);
  for (int k = 0; k < directions; ++k) {
    const float* plane = planes.data() + static_cast<std::size_t>(k) * pixels;
    for (std::size_t i = 0; i < pixels; ++i) {
      if (std::isfinite(plane[i]) && plane[i] > kLeavesAtOnce) {
        sum[i] += plane[i];
        ++count[i];
      }
    }
  }
  std::vector<float> mean(pixels);
  for (std::size_t i = 0; i < pixels; ++i) {
    mean[i] = count[i] ? static_cast<float>(sum[i] / count[i]) : std::nanf("");
  }
  return mean;
}

std::vector<std::vector<float>> splitPlanes(const std::vector<float>& planes, std::size_t pixels, int count) {
  std::vector<std::vector<float>> result;
  result.reserve(count);
  for (int k = 0; k < count; ++k) {
    const auto begin = planes.begin() + static_cast<std::ptrdiff_t>(k * pixels);
    result.emplace_back(begin, begin + static_cast<std::ptrdiff_t>(pixels));
  }
  return result;
}

// The library's result must hold what was asked for; a mismatch is a library bug, caught
// here rather than written out as a corrupt image.
void requireSize(const std::vector<float>& values, std::size_t expected, const char* what) {
  if (values.size() != expected) {
    throw Error(std::string("internal error: the computed ") + what + " holds " +
                std::to_string(values.size()) + " values, expected " + std::to_string(expected));
  }
}

// A result that is not finite where the height is (the planes of a multi-plane result one after
// another): the numbers went beyond what the kernels' single precision holds somewhere no bound
// on the options caught. An error, rather than NaN or infinity written as data.
void requireFiniteResult(const std::vector<float>& planes, const HeightField& field, const char* what) {
  const std::size_t pixels = field.pixelCount();
  for (std::size_t i = 0; i < planes.size(); ++i) {
    const std::size_t p = i % pixels;
    if (std::isfinite(planes[i]) || !std::isfinite(field.heights[p])) continue;
    throw Error(std::string("the computed ") + what + " at column " + std::to_string(p % field.width) +
                ", row " + std::to_string(p / field.width) + " is " + formatNumber(planes[i]) +
                " although the height there is finite: the heights, cell size and z-scale go beyond what the "
                "kernels' single precision holds; rescale them (--z-scale, --cell-size)");
  }
}

const char* methodName(Command command, const RunArguments& run) {
  switch (command) {
    case Command::ViewCount:
      return run.visibility_method == IntervisibilityMethod::Naive ? "naive" : "tree";
    case Command::HorizonLists:
    case Command::Bounce:
      return "tree";
    case Command::Viewshed:
      return run.culled ? "culled" : "exact";
    default:
      return run.method == HorizonMethod::Naive ? "naive" : "sweep";
  }
}

using Attributes = std::vector<std::pair<std::string, std::string>>;

// String attributes describing the run, written into every output (EXR attributes, GeoTIFF
// metadata items).
Attributes runAttributes(Command command, const RunArguments& run, const HeightField& field,
                         const DeviceInfo& device) {
  Attributes attributes{
      {"hfvis:command", commandName(command)},
      {"hfvis:input", run.input},
      {"hfvis:directions", std::to_string(run.directions)},
      {"hfvis:azimuth_offset_deg", formatNumber(run.azimuth_offset_deg)},
      {"hfvis:azimuth_convention",
       "phi_k = 360*k/K deg + offset, on the ground from the +column axis toward +row; "
       "compass azimuth = 90 + phi_k deg when row 0 is north"},
      {"hfvis:method", methodName(command, run)},
      {"hfvis:samples_per_unit", formatNumber(run.samples_per_unit)},
      // Read back by readHeightField, so an output keeps the input's ground spacing.
      {"hfvis:cell_size_x", formatNumber(field.cell_size_x)},
      {"hfvis:cell_size_y", formatNumber(field.cell_size_y)},
      {"hfvis:z_scale", formatNumber(field.z_scale)},
      {"hfvis:nodata", run.nodata && !std::isnan(*run.nodata)
                           ? "where the input height is not finite: " + formatNumber(*run.nodata) +
                                 " (the bands' nodata value) in GeoTIFF outputs, NaN in others"
                           : std::string("NaN where the input height is not finite")},
      {"hfvis:device", device.name + " (" + device.platform + ")"},
  };
  if (!run.channel.empty()) attributes.emplace_back("hfvis:channel", run.channel);
  if (run.max_distance > 0.0) attributes.emplace_back("hfvis:max_distance", formatNumber(run.max_distance));
  if (run.curvature) {
    attributes.emplace_back("hfvis:curvature", "drop = d^2 (1 - K) / (2 R), R = " + formatNumber(kEarthRadius) +
                                                   " m, K = " + formatNumber(run.refraction) +
                                                   " (ground units taken as metres)");
  }
  return attributes;
}

// An output of the field's size. A GeoTIFF output also carries the field's georeference, so that
// it overlays its input, and the --nodata value.
ImageChannels makeImage(const HeightField& field, const RunArguments& run, std::vector<std::string> names,
                        std::vector<std::vector<float>> planes, Attributes attributes,
                        const std::string& quantity, const std::string& units) {
  ImageChannels image;
  image.width = field.width;
  image.height = field.height;
  image.georeference = field.georeference;
  if (run.nodata) image.nodata = *run.nodata;
  image.names = std::move(names);
  image.planes = std::move(planes);
  image.attributes = std::move(attributes);
  image.attributes.emplace_back("hfvis:quantity", quantity);
  image.attributes.emplace_back("hfvis:units", units);
  return image;
}

std::string joinPaths(const std::vector<std::string>& paths) {
  std::string joined;
  for (const std::string& path : paths) joined += (joined.empty() ? "" : ", ") + path;
  return joined;
}

// The host memory a run may use: what the kernel says is available (free memory plus what it
// can reclaim), else the physical memory.
double availableHostBytes() {
  std::ifstream meminfo("/proc/meminfo");
  std::string key;
  double kib = 0.0;
  std::string unit;
  while (meminfo >> key >> kib >> unit) {
    if (key == "MemAvailable:") return kib * 1024.0;
  }
  return static_cast<double>(sysconf(_SC_PHYS_PAGES)) * static_cast<double>(sysconf(_SC_PAGE_SIZE));
}

// K-channel horizon maps of a huge field outgrow the host before anything is computed: the
// planes are held about three times (the result, its channels, the writer's buffer). Refused
// then, saying what to ask for instead.
void requireHostMemoryForPlanes(Command command, const RunArguments& run, const HeightField& field) {
  if (command != Command::Horizon) return;
  const double plane = static_cast<double>(field.pixelCount()) * sizeof(float);
  const double planes = plane * run.directions * (run.distance_output.empty() ? 1 : 2);
  const double need = 3.0 * planes, available = availableHostBytes();
  if (need <= available) return;
  std::ostringstream message;
  message << std::fixed << std::setprecision(1) << "the " << run.directions << "-channel horizon map"
          << (run.distance_output.empty() ? "" : " and its distances") << " of this " << field.width << " x "
          << field.height << " field need about " << need / 1073741824.0 << " GiB of host memory ("
          << planes / 1073741824.0 << " GiB of planes, held about three times while written) but "
          << available / 1073741824.0
          << " GiB is available: ask for svf or ao (one channel each), fewer directions (-k), or a crop of the "
             "field";
  throw Error(message.str());
}

// Reads the input height field and checks it (a bad field is the input file's fault).
HeightField readValidField(const RunArguments& run) {
  HeightField field = readHeightField(run.input, readOptions(run));
  try {
    validate(field);
  } catch (const InvalidArgument& error) {
    throw Error(run.input + ": " + error.what());
  }
  return field;
}

// A latitude / longitude grid has a spacing per row, which every operation follows but the
// bounce: it takes the centre latitude's for the whole field, and says so.
void warnOfCentreRowSpacing(const HeightField& field, const char* command) {
  if (field.row_cell_size_x.empty()) return;
  const auto [narrowest, widest] =
      std::minmax_element(field.row_cell_size_x.begin(), field.row_cell_size_x.end());
  std::cerr << std::setprecision(6) << "hfvis: warning: " << command
            << " takes the centre latitude's cell size (" << field.cell_size_x << " x " << field.cell_size_y
            << ") for the whole field; its rows range from " << *narrowest << " to " << *widest
            << " along columns (per-row spacing of latitude / longitude grids is followed by horizon, svf, "
               "ao, viewcount and horizons; not by bounce)\n";
}

// Progress on stderr when it is a terminal: one line rewritten in place, at most a few
// times a second (batches can be tiny). Wrap the computation in run() so that an error
// message after a half-written progress line starts on a line of its own.
class Progress {
 public:
  explicit Progress(bool quiet)
      : enabled_(!quiet && ::isatty(::fileno(stderr))), start_(std::chrono::steady_clock::now()) {}

  // Sets the options' callbacks: "done/total directions", the strip under way when the field
  // runs in strips, and once some are done the time left at the pace so far.
  void attach(SweepOptions& options) {
    if (!enabled_) return;
    total_ = options.directions;
    options.progress = [this](int done, int total) {
      done_ = done;
      total_ = total;
      strip_ = 0;
      report();
    };
    options.strip_progress = [this](int strip, int strips) {
      strip_ = strip;
      strips_ = strips;
      report(false);
    };
  }

  // A callback for a run over other things than directions: "done/total <unit>".
  std::function<void(int, int)> callback(int total, const char* unit) {
    if (!enabled_) return nullptr;
    total_ = total;
    unit_ = unit;
    return [this](int done, int all) {
      done_ = done;
      total_ = all;
      report();
    };
  }

  template <typename Body>
  auto run(Body&& body) -> decltype(body()) {
    try {
      return body();
    } catch (...) {
      if (line_open_) std::fputc('\n', stderr);
      throw;
    }
  }

 private:
  // `finished_batch`: a batch of directions just ended (the last one ends the line).
  void report(bool finished_batch = true) {
    const auto now = std::chrono::steady_clock::now();
    const bool last = finished_batch && total_ > 0 && done_ >= total_;
    if (!last && now - last_ < std::chrono::milliseconds(250)) return;
    last_ = now;
    line_open_ = !last;
    // Directions done, and the share of the one under way in strips.
    const double fraction = total_ > 0 ? (done_ + (strips_ > 0 ? double(strip_) / strips_ : 0.0)) / total_ : 0.0;
    std::string strip, left;
    if (strip_ > 0 && !last) strip = ", strip " + std::to_string(strip_) + "/" + std::to_string(strips_);
    if (fraction > 0.0 && !last) {
      const double elapsed = std::chrono::duration<double>(now - start_).count();
      const long seconds = std::lround(elapsed * (1.0 - fraction) / fraction);
      left = ", about " + (seconds >= 60 ? std::to_string(seconds / 60) + " min " : std::string()) +
             std::to_string(seconds % 60) + " s left";
    }
    // \033[K clears what a longer line before left behind.
    std::fprintf(stderr, "\rhfvis: %d/%d %s%s%s\033[K%s", done_, total_, unit_, strip.c_str(), left.c_str(),
                 line_open_ ? "" : "\n");
    std::fflush(stderr);
  }

  bool enabled_;
  bool line_open_ = false;
  int done_ = 0, total_ = 0, strip_ = 0, strips_ = 0;
  const char* unit_ = "directions";
  std::chrono::steady_clock::time_point start_, last_{};
};

double secondsSince(std::chrono::steady_clock::time_point start) {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
}

void requireResultSize(int width, int height, const HeightField& field) {
  if (width != field.width || height != field.height) {
    throw Error("internal error: the result is " + std::to_string(width) + "x" + std::to_string(height) +
                ", the height field " + std::to_string(field.width) + "x" + std::to_string(field.height));
  }
}

// "wrote FILES (WxH, K directions, METHOD, T s on DEVICE)NOTE" (or K observers, ...).
void printSummary(const std::vector<std::string>& written, int width, int height, int directions,
                  const std::string& method, double seconds, const std::string& device,
                  const std::string& note, const std::string& unit = "direction") {
  std::cout << "wrote " << joinPaths(written) << " (" << width << "x" << height << ", " << directions << " "
            << unit << (directions == 1 ? ", " : "s, ") << method << ", "
            << formatFixed(seconds, 2) << " s" << (device.empty() ? "" : " on " + device) << ")" << note
            << "\n";
}

// The context of a run: the HFVIS_* environment variables (ContextOptions::fromEnvironment),
// --device taking precedence over HFVIS_DEVICE.
ComputeContext contextFor(const RunArguments& run) {
  ContextOptions options = ContextOptions::fromEnvironment();
  if (!run.device.empty()) options.device = run.device;
  return ComputeContext::create(options);
}

}  // namespace

namespace {

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
  void restore(std::vector<float>& planes) const {
    const std::size_t width = input->width, rows = input->height, plane = width * rows;
    for (std::size_t at = 0; at + plane <= planes.size(); at += plane) {
      if (flip_rows)
        for (std::size_t r = 0; r < rows / 2; ++r)
          std::swap_ranges(planes.begin() + at + r * width, planes.begin() + at + (r + 1) * width,
                           planes.begin() + at + (rows - 1 - r) * width);
      if (flip_columns)
        for (std::size_t r = 0; r < rows; ++r)
          std::reverse(planes.begin() + at + r * width, planes.begin() + at + (r + 1) * width);
    }
  }
  // A pixel of the input, where it lies in the field computed on.
  void place(Observer& o) const {
    if (flip_rows) o.row = input->height - 1 - o.row;
    if (flip_columns) o.col = input->width - 1 - o.col;
  }
};

// `field` must outlive the result.
NorthUp northUp(const HeightField& field) {
  NorthUp out;
  out.input = &field;
  const auto& t = field.georeference.geotransform;
  if (!t) return out;
  out.flip_rows = (*t)[5] > 0.0;
  out.flip_columns = (*t)[1] < 0.0;
  if (!out.flipped()) return out;
  out.flipped_copy = field;
  out.restore(out.flipped_copy.heights);  // each flip is its own inverse
  if (out.flip_rows) {
    std::reverse(out.flipped_copy.row_cell_size_x.begin(), out.flipped_copy.row_cell_size_x.end());
    std::reverse(out.flipped_copy.row_cell_size_y.begin(), out.flipped_copy.row_cell_size_y.end());
  }
  return out;
}

// --albedo: a number in [0, 1], or an image of the field's size (one channel, or R, G, B), as
// planes (one value for a number).
std::vector<std::vector<float>> readAlbedo(const RunArguments& run, const HeightField& field) {
  const char* begin = run.albedo.c_str();
  char* end = nullptr;
  const double number = std::strtod(begin, &end);
  if (end == begin + run.albedo.size()) {
    if (!(number >= 0.0 && number <= 1.0))
      throw UsageError("--albedo: a number must be in 0 .. 1, got '" + run.albedo + "'");
    return {std::vector<float>(field.pixelCount(), static_cast<float>(number))};
  }
  ImageChannels image = readImage(run.albedo);
  if (image.width != field.width || image.height != field.height)
    throw IoError(run.albedo, "the albedo is " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                                  ", the height field " + std::to_string(field.width) + "x" +
                                  std::to_string(field.height));
  std::vector<std::vector<float>> planes;
  for (const char* name : {"R", "G", "B"})
    for (std::size_t i = 0; i < image.names.size(); ++i)
      if (image.names[i] == name) planes.push_back(image.planes[i]);
  if (planes.size() != 3) {
    if (image.planes.size() != 1)
      throw IoError(run.albedo, "an albedo image needs one channel or R, G, B");
    planes = {image.planes[0]};
  }
  for (const auto& plane : planes)
    for (float v : plane)
      if (!(v >= 0.0f && v <= 1.0f) && !std::isnan(v))
        throw IoError(run.albedo, "albedo values must be in 0 .. 1 (found " + formatNumber(v) + ")");
  return planes;
}

}  // namespace

int runShade(const RunArguments& run) {
  std::vector<std::string> paths = outputPaths(run);
  requireOutputs(run, paths);
  for (const std::string& input : {run.environment, run.albedo})
    for (const std::string& output : paths)
      if (!input.empty() && sameFile(input, output))
        throw UsageError("output '" + output + "' is the input '" + input + "': outputs never replace an input");
  HeightField input = readValidField(run);
  const NorthUp lit = northUp(input);
  if (lit.flipped()) input.heights = {};  // only its size is read from here on (restore)
  const HeightField& field = lit.field();
  std::optional<EnvironmentMap> environment;
  if (!run.environment.empty()) {
    environment = readEnvironmentMap(run.environment);
    environment->rotation_deg = run.environment_rotation_deg;
    environment->table_rows = run.environment_rows;
  }
  const std::vector<std::vector<float>> albedo =
      run.albedo.empty() ? std::vector<std::vector<float>>{} : readAlbedo(run, field);
  const ComputeContext context = contextFor(run);
  const DeviceInfo& device = context.device();
  std::optional<SunLight> sun;
  if (run.sun || run.sun_time) {
    sun.emplace();
    sun->size_deg = run.sun_size_deg;
    sun->position = run.sun ? SunPosition{run.sun->first, run.sun->second}
                            : sunPosition(*run.sun_time, *run.latitude, *run.longitude);
  }
  HorizonOptions options = horizonOptions(run);
  Progress progress(run.quiet);
  progress.attach(options);
  const auto start = std::chrono::steady_clock::now();
  const std::size_t pixels = field.pixelCount();
  HorizonResult env;
  if (environment) {
    HorizonOutputs outputs;
    outputs.environment = &*environment;
    env = progress.run([&] { return computeHorizons(context, field, options, outputs); });
    requireSize(env.irradiance, pixels * environment->channels, "irradiances");
    requireFiniteResult(env.irradiance, field, "irradiance");
    lit.restore(env.irradiance);
  }
  SunShadingResult direct;
  if (sun) {
    direct = progress.run([&] { return computeSunShading(context, field, *sun, options); });
    requireSize(direct.sun, pixels, "sun fractions");
    requireSize(direct.direct, pixels, "direct irradiances");
    requireFiniteResult(direct.direct, field, "direct irradiance");
    lit.restore(direct.sun);
    lit.restore(direct.direct);
  }
  const double seconds = secondsSince(start);

  Attributes attributes = runAttributes(Command::Shade, run, field, device);
  std::vector<std::string> names;
  std::vector<std::vector<float>> planes;
  std::string quantity, units;
  if (environment) {
    attributes.emplace_back("hfvis:environment", run.environment);
    attributes.emplace_back("hfvis:environment_rotation_deg", formatNumber(run.environment_rotation_deg));
    attributes.emplace_back("hfvis:environment_table_rows", std::to_string(tableRows(*environment)));
    names = environment->names;
    planes = splitPlanes(env.irradiance, pixels, environment->channels);
    quantity = environment->names.size() == 1 ? "Y" : "R, G, B";
    quantity += ": the irradiance from the environment above each point's horizons, for its normal; ";
    units = "the environment's radiance times steradians (a uniform radiance of 1 gives pi on open flat ground); ";
  }
  if (sun) {
    attributes.emplace_back("hfvis:sun_azimuth_deg", formatNumber(sun->position.azimuth_deg));
    attributes.emplace_back("hfvis:sun_elevation_deg", formatNumber(sun->position.elevation_deg));
    attributes.emplace_back("hfvis:sun_size_deg", formatNumber(sun->size_deg));
    attributes.emplace_back("hfvis:swept_azimuth_deg", formatNumber(direct.azimuth * 180.0 / M_PI));
    names.insert(names.end(), {"direct", "sun"});
    planes.insert(planes.end(), {direct.direct, direct.sun});
    quantity += "sun: the fraction of the sun's disc above the pixel's horizon in the sun's azimuth; direct: sun * "
                "max(0, n . s), the irradiance from a sun of normal irradiance 1 (row 0 taken as north); ";
    units += "sun: 0..1; direct: the sun's normal irradiance; ";
  }
  // --albedo: the radiance a Lambertian surface of that albedo sends out, albedo / pi times the
  // irradiance (the environment's and the sun's at --sun-irradiance).
  std::vector<std::vector<float>> radiance;
  if (!albedo.empty()) {
    const std::size_t channels = std::max<std::size_t>(albedo.size(), environment ? environment->channels : 1);
    for (std::size_t c = 0; c < channels; ++c) {
      std::vector<float> out(pixels);
      const std::vector<float>& a = albedo[std::min(c, albedo.size() - 1)];
      for (std::size_t p = 0; p < pixels; ++p) {
        double e = 0.0;
        if (environment) e += env.irradiance[std::min<std::size_t>(c, environment->channels - 1) * pixels + p];
        if (sun) e += run.sun_irradiance * direct.direct[p];
        out[p] = static_cast<float>(a[p] / M_PI * e);
      }
      radiance.push_back(std::move(out));
    }
    const bool grey = channels == 1;
    for (const char* name : {"R", "G", "B"}) {
      names.push_back(grey ? std::string("radiance") : std::string("radiance.") + name);
      if (grey) break;
    }
    planes.insert(planes.end(), radiance.begin(), radiance.end());
    attributes.emplace_back("hfvis:albedo", run.albedo);
    attributes.emplace_back("hfvis:sun_irradiance", formatNumber(run.sun_irradiance));
    quantity += "radiance: albedo / pi times the irradiance (the environment's, and the sun's times its normal "
                "irradiance)";
    units += "radiance: per steradian";
  }
  OutputFiles outputs;
  const ImageChannels image = makeImage(field, run, names, planes, attributes, quantity, units);
  outputs.image(run.output, image);
  if (!run.preview.empty()) {
    if (!radiance.empty()) {
      outputs.toneMappedPng(run.preview, field.width, field.height, radiance);
    } else if (environment) {
      outputs.toneMappedPng(run.preview, field.width, field.height,
                            splitPlanes(env.irradiance, pixels, environment->channels));
    } else {  // a hillshade with cast shadows: the direct light, 0 .. its largest value
      outputs.previewPng(run.preview, field.width, field.height, direct.direct, 0.0f,
                         std::max(1e-6f, quantileRange(direct.direct, 0.0, 1.0).second));
    }
  }
  const std::vector<std::string> written = outputs.paths();
  outputs.commit();
  if (!run.quiet) {
    std::string note;
    if (environment) note += "; mean irradiance " + formatFixed(finiteMean(env.irradiance), 4);
    if (sun)
      note += "; sun at " + formatFixed(sun->position.azimuth_deg, 2) + " deg, " +
              formatFixed(sun->position.elevation_deg, 2) + " deg up; mean sun " + formatFixed(finiteMean(direct.sun), 3);
    printSummary(written, field.width, field.height, environment ? run.directions : 1,
                 methodName(Command::Shade, run), seconds, device.name,
                 note + (lit.flipped() ? " (lit north-up)" : ""));
  }
  return 0;
}

int runInsolation(const RunArguments& run) {
  requireOutputs(run, outputPaths(run));
  HeightField input = readValidField(run);
  const NorthUp lit = northUp(input);
  if (lit.flipped()) input.heights = {};  // only its size is read from here on (restore)
  const HeightField& field = lit.field();
  const ComputeContext context = contextFor(run);
  const DeviceInfo& device = context.device();
  const InsolationOptions options = insolationOptions(run);
  HorizonOptions sweep = horizonOptions(run);
  Progress progress(run.quiet);
  progress.attach(sweep);
  const auto start = std::chrono::steady_clock::now();
  InsolationResult result = progress.run([&] { return computeInsolation(context, field, options, sweep); });
  const double seconds = secondsSince(start);
  requireResultSize(result.width, result.height, field);
  requireSize(result.sun_hours, field.pixelCount(), "sun hours");
  requireSize(result.direct, field.pixelCount(), "direct irradiations");
  requireFiniteResult(result.direct, field, "direct irradiation");
  lit.restore(result.sun_hours);
  lit.restore(result.direct);
  Attributes attributes = runAttributes(Command::Insolation, run, field, device);
  attributes.emplace_back("hfvis:latitude_deg", formatNumber(options.latitude_deg));
  attributes.emplace_back("hfvis:longitude_deg", formatNumber(options.longitude_deg));
  attributes.emplace_back("hfvis:from_utc_s", formatNumber(options.from_utc));
  attributes.emplace_back("hfvis:to_utc_s", formatNumber(options.to_utc));
  attributes.emplace_back("hfvis:step_minutes", formatNumber(options.step_minutes));
  attributes.emplace_back("hfvis:sun_size_deg", formatNumber(options.size_deg));
  attributes.emplace_back("hfvis:azimuth_bucket_deg", formatNumber(options.azimuth_bucket_deg));
  attributes.emplace_back("hfvis:refraction", options.apparent ? "apparent (refracted) elevations" : "geometric");
  attributes.emplace_back("hfvis:steps_with_sun", std::to_string(result.steps));
  attributes.emplace_back("hfvis:sweeps", std::to_string(result.sweeps));
  OutputFiles outputs;
  // "direct" sorts before "sun_hours": channel 0 in the EXR.
  const ImageChannels image = makeImage(
      field, run, {"direct", "sun_hours"}, {result.direct, result.sun_hours}, attributes,
      "sun_hours: hours with the sun's centre above the pixel's horizon (and elevation 0); direct: the sum over "
      "steps of hours * the disc's part seen * max(0, n . s), the irradiation from a sun of normal irradiance 1",
      "sun_hours: hours; direct: hours times the sun's normal irradiance (W/m^2 gives Wh/m^2)");
  outputs.image(run.output, image);
  if (!run.preview.empty()) {
    const auto [lo, hi] = quantileRange(result.direct);
    outputs.previewPng(run.preview, field.width, field.height, result.direct, lo, hi);
  }
  const std::vector<std::string> written = outputs.paths();
  outputs.commit();
  if (!run.quiet) {
    printSummary(written, field.width, field.height, result.sweeps, "sweep", seconds, device.name,
                 "; " + std::to_string(result.steps) + " steps with the sun up, mean sun " +
                     formatFixed(finiteMean(result.sun_hours), 2) + " h" +
                     (lit.flipped() ? " (lit north-up)" : ""));
  }
  return 0;
}

namespace {

// A hillshade in 0 .. 1 (light from the north-west, 45 degrees up), under the viewshed's preview.
std::vector<float> hillshade(const HeightField& f) {
  std::vector<float> shade(f.pixelCount(), 0.0f);
  const double lx = -0.5, ly = -0.5, lz = std::sqrt(0.5);  // toward -column, -row (north-west), up
  auto at = [&](int x, int y) {
    const float v = f.at(std::clamp(x, 0, f.width - 1), std::clamp(y, 0, f.height - 1));
    return std::isfinite(v) ? v * f.z_scale : std::numeric_limits<double>::quiet_NaN();
  };
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const double gx = (at(x + 1, y) - at(x - 1, y)) / (2.0 * f.cell_size_x);
      const double gy = (at(x, y + 1) - at(x, y - 1)) / (2.0 * f.cell_size_y);
      const double n = std::sqrt(gx * gx + gy * gy + 1.0);
      const double lit = (-gx * lx - gy * ly + lz) / n;
      shade[static_cast<std::size_t>(y) * f.width + x] = std::isfinite(lit) ? static_cast<float>(std::max(lit, 0.0)) : 0.0f;
    }
  return shade;
}

}  // namespace

int runViewshed(const RunArguments& run) {
  requireOutputs(run, outputPaths(run));
  const HeightField input = readValidField(run);
  std::vector<Observer> observers;
  for (const ReceiverPixel& p : run.observers) observers.push_back({p.col, p.row, run.observer_height});
  if (!run.observers_file.empty()) {
    const std::vector<Observer> listed =
        readObserverFile(run.observers_file, run.observer_height, run.absolute);
    observers.insert(observers.end(), listed.begin(), listed.end());
  }
  for (const Observer& o : observers) {
    try {
      validate(input, o);
    } catch (const InvalidArgument& error) {
      throw UsageError(std::string(error.what()) + " (" + run.input + ")");
    }
  }
  // Compass azimuths (--fov) take row 0 as north and column 0 as west: a south-up or west-up
  // GeoTIFF is computed flipped, its observers with it, and its results flipped back.
  const NorthUp lit = northUp(input);
  const HeightField& field = lit.field();
  std::vector<Observer> placed = observers;
  for (Observer& o : placed) lit.place(o);
  const ComputeContext context = contextFor(run);
  const DeviceInfo& device = context.device();
  ViewshedOptions options = viewshedOptions(run);
  Progress progress(run.quiet || observers.size() == 1);
  const auto start = std::chrono::steady_clock::now();
  // --method culled: the pyramid first, for this field, target height and curvature.
  std::optional<ViewshedPyramid> pyramid;
  std::string cull_note;
  if (run.culled) {
    ViewshedPyramidOptions p;
    p.target_height = options.target_height;
    p.curvature = options.curvature;
    p.finest_level = run.cull_level;
    p.memory_budget_bytes = run.memory_budget_bytes;
    Progress building(run.quiet);
    p.progress = building.callback(p.sectors * p.directions_per_sector, "pyramid directions");
    pyramid = building.run([&] { return buildViewshedPyramid(context, field, p); });
    options.pyramid = &*pyramid;
    cull_note = "; culling pyramid " + formatFixed(pyramid->build_seconds, 2) + " s, " +
                formatFixed(pyramid->bytes() / (1024.0 * 1024.0), 1) + " MiB";
  }
  std::vector<std::string> names;
  std::vector<std::vector<float>> planes;
  std::string quantity, units, note;
  if (observers.size() == 1) {
    ViewshedOutputs outputs;
    outputs.angle = run.with_angle;
    outputs.needed_height = run.with_needed_height;
    ViewshedResult r = computeViewshed(context, field, placed[0], options, outputs);
    requireResultSize(r.width, r.height, field);
    lit.restore(r.visible);
    lit.restore(r.angle);
    lit.restore(r.needed_height);
    if (run.with_angle) {
      for (float& a : r.angle) a = static_cast<float>(a * (180.0 / M_PI));
      names.push_back("angle");
      planes.push_back(std::move(r.angle));
    }
    if (run.with_needed_height) {  // sorts between "angle" and "visible"
      names.push_back("needed_height");
      planes.push_back(std::move(r.needed_height));
    }
    std::size_t seen = 0, targets = 0;
    for (float v : r.visible) seen += v == 1.0f, targets += !std::isnan(v);
    note = "; " + formatFixed(100.0 * seen / std::max<std::size_t>(targets, 1), 2) + " % of the points visible";
    if (pyramid)
      note += cull_note + "; " + formatFixed(100.0 * r.culled / std::max<std::size_t>(targets, 1), 2) +
              " % of the points culled";
    names.push_back("visible");
    planes.push_back(std::move(r.visible));
    quantity = "visible: 1 where a target on the point is seen from the observer's eye, 0 where hidden or out of "
               "range" + std::string(run.with_angle ? "; angle: the target's elevation angle from the eye" : "") +
               (run.with_needed_height ? "; needed_height: the height above the surface a target there needs to be "
                                         "seen (NaN out of range)"
                                       : "");
    units = std::string("visible: 1") + (run.with_angle ? "; angle: degrees" : "") +
            (run.with_needed_height ? "; needed_height: height units" : "");
  } else {
    options.progress = progress.callback(static_cast<int>(observers.size()), "observers");
    CumulativeViewshed c = progress.run([&] { return computeCumulativeViewshed(context, field, placed, options); });
    requireResultSize(c.width, c.height, field);
    lit.restore(c.count);
    float most = 0.0f;
    for (float v : c.count)
      if (v > most) most = v;
    note = "; " + std::to_string(observers.size()) + " observers, at most " + formatNumber(most) + " see one point" +
           cull_note;
    names.push_back("count");
    planes.push_back(std::move(c.count));
    quantity = "count: how many of the observers see a target on the point (a cumulative viewshed)";
    units = "observers";
  }
  const double seconds = secondsSince(start);
  Attributes attributes = runAttributes(Command::Viewshed, run, input, device);
  // A viewshed has no directions or sampling density.
  attributes.erase(std::remove_if(attributes.begin(), attributes.end(),
                                  [](const auto& a) {
                                    return a.first == "hfvis:directions" || a.first == "hfvis:azimuth_offset_deg" ||
                                           a.first == "hfvis:azimuth_convention" ||
                                           a.first == "hfvis:samples_per_unit";
                                  }),
                   attributes.end());
  std::string where;
  for (const Observer& o : observers) {
    if (where.size() > 4000) {
      where += " ...";
      break;
    }
    where += (where.empty() ? "" : "; ") + std::to_string(o.col) + "," + std::to_string(o.row) + " at " +
             formatNumber(o.height);
  }
  attributes.emplace_back("hfvis:observers", where);
  attributes.emplace_back("hfvis:observer_height", run.absolute ? "absolute" : "above the surface");
  attributes.emplace_back("hfvis:target_height", formatNumber(options.target_height));
  if (run.field_of_view)
    attributes.emplace_back("hfvis:field_of_view_deg",
                            formatNumber(run.field_of_view->first) + " .. " + formatNumber(run.field_of_view->second));
  if (run.elevation_range)
    attributes.emplace_back("hfvis:elevation_range_deg", formatNumber(run.elevation_range->first) + " .. " +
                                                             formatNumber(run.elevation_range->second));
  const ImageChannels image = makeImage(input, run, names, std::move(planes), attributes, quantity, units);
  OutputFiles outputs;
  outputs.image(run.output, image);
  if (!run.preview.empty()) {
    // Visible points (or the count) bright over a dimmed hillshade; nodata black.
    const std::vector<float>& seen = image.planes.back();
    float most = 0.0f;
    for (float v : seen)
      if (v > most) most = v;
    const std::vector<float> shade = hillshade(input);
    std::vector<float> picture(seen.size());
    for (std::size_t p = 0; p < seen.size(); ++p)
      picture[p] =
          std::isnan(seen[p])
              ? NAN
              : 0.3f * shade[p] + (seen[p] > 0.0f ? 0.35f + 0.35f * seen[p] / std::max(most, 1.0f) : 0.0f);
    outputs.previewPng(run.preview, input.width, input.height, picture, 0.0f, 1.0f);
  }
  const std::vector<std::string> written = outputs.paths();
  outputs.commit();
  if (!run.quiet)
    printSummary(written, field.width, field.height, static_cast<int>(observers.size()),
                 methodName(Command::Viewshed, run), seconds, device.name,
                 note + (lit.flipped() ? " (computed north-up)" : ""), "observer");
  return 0;
}

int runSunPosition(const SunArguments& sun) {
  const SunPosition p = sunPosition(sun.utc_seconds, sun.latitude_deg, sun.longitude_deg, sun.apparent);
  std::cout << std::fixed << std::setprecision(4) << "azimuth=" << p.azimuth_deg << " elevation=" << p.elevation_deg
            << "\n";
  return 0;
}

int runDevices() {
  const std::vector<DeviceInfo> devices = listDevices();

  // Which device automatic selection picks (honours HFVIS_DEVICE, as every command does).
  int automatic = -1;
  std::string automatic_error;
  try {
    automatic = ComputeContext::create(ContextOptions::fromEnvironment()).device().index;
  } catch (const Error& error) {
    automatic_error = error.what();
  }

  const std::vector<std::string> header{"index", "type", "name", "platform", "driver", "memory"};
  std::vector<std::vector<std::string>> rows;
  for (const DeviceInfo& device : devices) {
    rows.push_back({std::to_string(device.index), device.type, device.name, device.platform,
                    device.driver_version, formatMemory(device.global_memory_bytes)});
  }
  std::vector<std::size_t> widths(header.size());
  for (std::size_t c = 0; c < header.size(); ++c) {
    widths[c] = header[c].size();
    for (const auto& row : rows) widths[c] = std::max(widths[c], row[c].size());
  }
  const auto printRow = [&](const std::string& mark, const std::vector<std::string>& row) {
    std::string line = mark;
    for (std::size_t c = 0; c < row.size(); ++c) {
      line += row[c];
      if (c + 1 < row.size()) line += std::string(widths[c] - row[c].size() + 2, ' ');
    }
    std::cout << line << "\n";
  };
  printRow("  ", header);
  for (std::size_t i = 0; i < rows.size(); ++i) {
    printRow(devices[i].index == automatic ? "* " : "  ", rows[i]);
  }
  if (automatic >= 0) {
    std::cout << "* = automatic selection"
              << (std::getenv("HFVIS_DEVICE")
                      ? " (HFVIS_DEVICE=" + std::string(std::getenv("HFVIS_DEVICE")) + ")"
                      : std::string(" (HFVIS_DEVICE not set)"))
              << "\n";
  } else {
    std::cerr << "hfvis: warning: automatic device selection failed: " << automatic_error << "\n";
  }
  return 0;
}

int runCompute(Command command, const RunArguments& run) {
  requireOutputs(run, outputPaths(run));

  const HeightField field = readValidField(run);
  requireHostMemoryForPlanes(command, run, field);
  const ComputeContext context = contextFor(run);
  const DeviceInfo& device = context.device();

  HorizonOptions options = horizonOptions(run);
  Progress progress(run.quiet);
  progress.attach(options);
  const auto start = std::chrono::steady_clock::now();
  const HorizonResult result =
      progress.run([&] { return computeHorizons(context, field, options, horizonOutputs(command, run)); });
  const double seconds = secondsSince(start);
  requireResultSize(result.width, result.height, field);

  const std::size_t pixels = static_cast<std::size_t>(result.width) * static_cast<std::size_t>(result.height);
  const int directions = run.directions;
  Attributes attributes = runAttributes(command, run, field, device);
  // The sweep's directions are lattice steps near phi_k (horizon planes) or quadrature
  // directions (svf, ao): record the azimuths it used.
  std::string used;
  for (double azimuth : result.azimuths)
    used += (used.empty() ? "" : ",") + formatNumber(azimuth * 180.0 / M_PI);
  attributes.emplace_back("hfvis:azimuths_deg", used);

  // Everything is computed; now stage every file, then move them all into place.
  OutputFiles outputs;
  std::string mean_note;
  if (command == Command::Horizon) {
    const std::size_t values = pixels * static_cast<std::size_t>(directions);
    requireSize(result.angles, values, "horizon angles");
    requireFiniteResult(result.angles, field, "horizon angle");
    const ImageChannels angles = makeImage(
        field, run, directionChannelNames("h", directions), splitPlanes(result.angles, pixels, directions),
        attributes, "horizon elevation angle per direction (channel k = direction k)",
        "radians above the horizontal; -pi/2 where the ray leaves the field at once");
    outputs.image(run.output, angles);
    if (!run.distance_output.empty()) {
      requireSize(result.distances, values, "horizon distances");
      requireFiniteResult(result.distances, field, "horizon distance");
      const ImageChannels distances =
          makeImage(field, run, directionChannelNames("d", directions),
                    splitPlanes(result.distances, pixels, directions), attributes,
                    "ground distance to the point casting the horizon, per direction",
                    "ground units (pixels times cell size); 0 where no point casts a horizon or the "
                    "surface's own slope at the receiver is the horizon");
      outputs.image(run.distance_output, distances);
    }
    if (!run.preview.empty()) {
      const std::vector<float> mean = meanInFieldElevation(result.angles, pixels, directions);
      outputs.previewPng(run.preview, result.width, result.height, mean);  // stretched min..max
    }
  } else {
    const bool svf = command == Command::SkyViewFactor;
    const std::vector<float>& plane = svf ? result.sky_view_factor : result.ambient_occlusion;
    const std::string channel = svf ? "svf" : "ao";
    requireSize(plane, pixels, svf ? "sky-view factor" : "ambient occlusion");
    requireFiniteResult(plane, field, svf ? "sky-view factor" : "ambient occlusion");
    const ImageChannels image =
        makeImage(field, run, {channel}, {plane}, attributes,
                  svf ? "sky-view factor 1 - mean_k sin(max(0, elevation_k))"
                      : "ambient occlusion, uniform sky of radiance 1 (Timonen & Westerholm 2010, Eq. 5)",
                  svf ? "fraction of the sky visible, 0..1" : "0..1, a flat unoccluded plane gives 1");
    outputs.image(run.output, image);
    mean_note = "; mean " + channel + " " + formatFixed(finiteMean(plane), 4);
    if (!run.preview.empty()) {
      // Stretched over the 1st to 99th percentile: most of a DEM's svf lies within 0.85 .. 1.
      const auto [lo, hi] = quantileRange(plane);
      outputs.previewPng(run.preview, result.width, result.height, plane, lo, hi);
      mean_note += "; preview black at " + formatFixed(lo, 3) + ", white at " + formatFixed(hi, 3);
    }
  }
  const std::vector<std::string> written = outputs.paths();
  outputs.commit();

  if (!run.quiet) {
    printSummary(written, result.width, result.height, directions, methodName(command, run), seconds,
                 device.name, mean_note);
  }
  return 0;
}

int runViewCount(const RunArguments& run) {
  requireOutputs(run, outputPaths(run));
  const HeightField field = readValidField(run);
  const ComputeContext context = contextFor(run);
  const DeviceInfo& device = context.device();

  IntervisibilityOptions options = intervisibilityOptions(run);
  Progress progress(run.quiet);
  progress.attach(options);
  const auto start = std::chrono::steady_clock::now();
  const IntervisibilityResult result = progress.run(
      [&] { return computeIntervisibility(context, field, options, intervisibilityOutputs(run)); });
  const double seconds = secondsSince(start);
  requireResultSize(result.width, result.height, field);
  const std::size_t pixels = field.pixelCount();
  requireSize(result.visible_count, pixels, "visible counts");
  requireSize(result.visible_area, pixels, "visible areas");
  requireFiniteResult(result.visible_count, field, "visible count");
  requireFiniteResult(result.visible_area, field, "visible area");

  Attributes attributes = runAttributes(Command::ViewCount, run, field, device);
  attributes.emplace_back("hfvis:tie_rule",
                          "a sample is visible when its slope from the receiver is >= the slope of every "
                          "sample between them (grazing samples are visible), decided exactly");
  const IntervisibilityStatistics& stats = result.statistics;
  std::string stats_line;
  if (run.statistics) {
    // Timonen (2013), Table 2: per receiver (line sample) and direction.
    attributes.emplace_back("hfvis:stats_m_a", formatNumber(stats.meanHorizons()));
    attributes.emplace_back("hfvis:stats_t_a", formatNumber(stats.meanIterations()));
    attributes.emplace_back("hfvis:stats_visible_per_point", formatNumber(stats.meanVisible()));
    attributes.emplace_back("hfvis:stats_naive_iterations_per_point",
                            formatNumber(stats.meanNaiveIterations()));
    attributes.emplace_back("hfvis:stats_receivers", std::to_string(stats.receivers));
    stats_line = "statistics per point and direction (Timonen 2013, Table 2): m_a " +
                 formatFixed(stats.meanHorizons(), 3) + ", t_a " + formatFixed(stats.meanIterations(), 3) +
                 " (--hull-tree " + (run.hull_tree_name.empty() ? "default" : run.hull_tree_name) + ")" +
                 ", visible " + formatFixed(stats.meanVisible(), 3) + ", naive iterations " +
                 formatFixed(stats.meanNaiveIterations(), 3) + " (" + std::to_string(stats.receivers) +
                 " line samples, " + std::to_string(stats.lines_over_bound) + " lines over t <= 2m + n)";
  }

  OutputFiles outputs;
  // "count" sorts before "visible_area", so the count is channel 0 in the EXR, whose
  // channels are stored sorted by name.
  const ImageChannels image = makeImage(
      field, run, {"count", "visible_area"}, {result.visible_count, result.visible_area}, attributes,
      "count: visible surface samples summed over the K directions; visible_area: the visible ground area "
      "(total viewshed), each visible sample at ground distance rho standing for (2*pi/K) * rho * drho",
      "count: samples (one per 1/S pixel lengths along each direction, S = samples per unit); "
      "visible_area: ground units squared");
  outputs.image(run.output, image);
  if (!run.preview.empty()) {
    outputs.previewPng(run.preview, field.width, field.height, result.visible_count);  // stretched min..max
  }
  const std::vector<std::string> written = outputs.paths();
  outputs.commit();

  if (!run.quiet) {
    printSummary(written, field.width, field.height, run.directions, methodName(Command::ViewCount, run),
                 seconds, device.name, "; mean count " + formatFixed(finiteMean(result.visible_count), 2));
  }
  if (run.statistics) std::cout << stats_line << "\n";  // asked for explicitly: printed even with --quiet
  return 0;
}

int runHorizonLists(const RunArguments& run) {
  requireOutputs(run, {run.output}, /*images=*/false);
  const HeightField field = readValidField(run);
  for (const ReceiverPixel& p : run.receivers) {
    if (p.col >= field.width || p.row >= field.height) {
      throw UsageError(
          "--at " + std::to_string(p.col) + "," + std::to_string(p.row) + ": outside the field " + run.input +
          ", which is " + std::to_string(field.width) + "x" + std::to_string(field.height) + " (columns 0.." +
          std::to_string(field.width - 1) + ", rows 0.." + std::to_string(field.height - 1) + ")");
    }
  }
  const auto start = std::chrono::steady_clock::now();
  const std::vector<ReceiverHorizons> lists =
      computeHorizonLists(field, horizonListOptions(run), run.receivers);
  const double seconds = secondsSince(start);
  std::size_t horizons = 0;
  for (const auto& receiver : lists)
    for (const auto& direction : receiver.directions) horizons += direction.horizons.size();

  std::string ext = fs::path(run.output).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const std::string text = ext == ".csv" ? horizonListsCsv(lists) : horizonListsJson(run, field, lists);
  OutputFiles outputs;
  outputs.text(run.output, text);
  const std::vector<std::string> written = outputs.paths();
  outputs.commit();
  if (!run.quiet) {
    printSummary(written, field.width, field.height, run.directions, "tree on the receivers' rays", seconds,
                 "",
                 "; " + std::to_string(lists.size()) + (lists.size() == 1 ? " receiver, " : " receivers, ") +
                     std::to_string(horizons) + " horizons");
  }
  return 0;
}

int runBounce(const RunArguments& run) {
  requireOutputs(run, outputPaths(run));
  const HeightField field = readValidField(run);
  warnOfCentreRowSpacing(field, "bounce");
  const ImageChannels radiance_image = readImage(run.radiance);
  if (radiance_image.width != field.width || radiance_image.height != field.height) {
    throw IoError(run.radiance,
                  "is " + std::to_string(radiance_image.width) + "x" + std::to_string(radiance_image.height) +
                      ", the height field " + run.input + " is " + std::to_string(field.width) + "x" +
                      std::to_string(field.height) + ": the exit radiance needs one value per height");
  }
  if (radiance_image.planes.size() > static_cast<std::size_t>(kMaxBounceChannels)) {
    throw IoError(run.radiance, "has " + std::to_string(radiance_image.planes.size()) +
                                    " channels; at most " + std::to_string(kMaxBounceChannels) +
                                    " are gathered in one run (split the channels into several files)");
  }
  ExitRadiance radiance;
  radiance.width = radiance_image.width;
  radiance.height = radiance_image.height;
  radiance.channels = radiance_image.planes;
  try {
    validate(field, radiance);
  } catch (const InvalidArgument& error) {
    throw Error(run.radiance + ": " + error.what());
  }

  const ComputeContext context = contextFor(run);
  const DeviceInfo& device = context.device();
  BounceOptions options = bounceOptions(run);
  Progress progress(run.quiet);
  progress.attach(options);
  const auto start = std::chrono::steady_clock::now();
  const BounceResult result = progress.run([&] { return computeBounce(context, field, radiance, options); });
  const double seconds = secondsSince(start);
  requireResultSize(result.width, result.height, field);
  if (result.irradiance.size() != radiance.channels.size()) {
    throw Error("internal error: the bounce returned " + std::to_string(result.irradiance.size()) +
                " channels for " + std::to_string(radiance.channels.size()));
  }
  for (const auto& plane : result.irradiance) {
    requireSize(plane, field.pixelCount(), "irradiance");
    requireFiniteResult(plane, field, "irradiance");
  }

  Attributes attributes = runAttributes(Command::Bounce, run, field, device);
  attributes.emplace_back("hfvis:radiance", run.radiance);
  OutputFiles outputs;
  // The radiance's channel names, so that R, G, B stay R, G, B.
  const ImageChannels image = makeImage(
      field, run, radiance_image.names, result.irradiance, attributes,
      "incident indirect irradiance of one diffuse bounce of the exit radiance (hfvis:radiance), per "
      "channel: "
      "sum over directions and visible samples of radiance times projected solid angle",
      "radiance units times steradians (W/m^2 for W m^-2 sr^-1); a Lambertian surface of albedo rho "
      "re-emits rho * E / pi");
  outputs.image(run.output, image);
  if (!run.preview.empty()) {
    std::vector<float> mean(field.pixelCount(), 0.0f);
    for (const auto& plane : result.irradiance)
      for (std::size_t p = 0; p < mean.size(); ++p)
        mean[p] += plane[p] / static_cast<float>(result.irradiance.size());
    outputs.previewPng(run.preview, field.width, field.height, mean);  // stretched min..max
  }
  const std::vector<std::string> written = outputs.paths();
  outputs.commit();

  if (!run.quiet) {
    std::string note = "; mean irradiance";
    for (std::size_t c = 0; c < result.irradiance.size(); ++c) {
      note +=
          (c ? ", " : " ") + radiance_image.names[c] + " " + formatNumber(finiteMean(result.irradiance[c]));
    }
    printSummary(written, field.width, field.height, run.directions, methodName(Command::Bounce, run),
                 seconds, device.name, note);
  }
  return 0;
}

}  // namespace hfvis::cli
