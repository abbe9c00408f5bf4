// cli/pipeline.cpp: the pipeline every command that reads a height field runs, and its helpers.
#include "pipeline.hpp"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <sstream>
#include <system_error>

#include "core/number_text.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/horizon.hpp"
#include "io/gdal_io.hpp"
#include "io/output_files.hpp"

namespace hfvis::cli {

namespace fs = std::filesystem;

std::string formatNumber(double value) {
  std::ostringstream out;
  out << std::setprecision(10) << value;
  return out.str();
}

// The length of the well-formed UTF-8 sequence at text[i] (Unicode's table of well-formed byte
// sequences: no overlong forms, no surrogates, nothing beyond U+10FFFF), 0 where there is none.
static std::size_t utf8Sequence(const std::string& text, std::size_t i) {
  const auto byte = [&](std::size_t k) { return static_cast<unsigned char>(text[i + k]); };
  const unsigned char c = byte(0);
  const std::size_t n = c < 0x80                 ? 1
                        : c >= 0xC2 && c <= 0xDF ? 2
                        : c >= 0xE0 && c <= 0xEF ? 3
                        : c >= 0xF0 && c <= 0xF4 ? 4
                                                 : 0;
  if (n == 0 || i + n > text.size()) return 0;
  for (std::size_t k = 1; k < n; ++k)
    if ((byte(k) & 0xC0) != 0x80) return 0;
  // The second byte's narrower ranges after E0, ED, F0 and F4.
  if ((c == 0xE0 && byte(1) < 0xA0) || (c == 0xED && byte(1) > 0x9F) || (c == 0xF0 && byte(1) < 0x90) ||
      (c == 0xF4 && byte(1) > 0x8F))
    return 0;
  return n;
}

std::string jsonString(const std::string& text) {
  std::string out = "\"";
  for (std::size_t i = 0; i < text.size();) {
    const unsigned char c = static_cast<unsigned char>(text[i]);
    const std::size_t n = utf8Sequence(text, i);
    if (c == '"' || c == '\\') {
      out += '\\';
      out += text[i++];
    } else if (c < 0x20 || n == 0) {
      // Control characters escaped; a byte that is not UTF-8 (a file name in another encoding)
      // as the character of that number (its Latin-1 reading), so that the JSON stays valid.
      char escaped[8];
      std::snprintf(escaped, sizeof escaped, "\\u%04x", c);
      out += escaped;
      ++i;
    } else {
      out.append(text, i, n);
      i += n;
    }
  }
  return out + "\"";
}

std::string formatFixed(double value, int digits) {
  std::ostringstream out;
  // (a mean of 2.6e-5 printed as 0.0000 and one of 1e30 as 31 digits: those in significant digits)
  if (value != 0.0 && std::isfinite(value) &&
      (std::fabs(value) < 0.5 * std::pow(10.0, -digits) || std::fabs(value) >= 1e9))
    out << std::setprecision(std::max(digits, 1)) << value;
  else
    out << std::fixed << std::setprecision(digits) << value;
  return out.str();
}

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

std::vector<std::vector<float>> splitPlanes(const std::vector<float>& planes, std::size_t pixels, int count) {
  std::vector<std::vector<float>> result;
  result.reserve(count);
  for (int k = 0; k < count; ++k) {
    const auto begin = planes.begin() + static_cast<std::ptrdiff_t>(k * pixels);
    result.emplace_back(begin, begin + static_cast<std::ptrdiff_t>(pixels));
  }
  return result;
}

void requireSize(const std::vector<float>& values, std::size_t expected, const char* what) {
  if (values.size() != expected) {
    throw Error(std::string("internal error: the computed ") + what + " holds " +
                std::to_string(values.size()) + " values, expected " + std::to_string(expected));
  }
}

void requireResultSize(int width, int height, const HeightField& field) {
  if (width != field.width || height != field.height) {
    throw Error("internal error: the result is " + std::to_string(width) + "x" + std::to_string(height) +
                ", the height field " + std::to_string(field.width) + "x" + std::to_string(field.height));
  }
}

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

Progress::Progress(bool quiet)
    : enabled_(!quiet && ::isatty(::fileno(stderr))), start_(std::chrono::steady_clock::now()) {}

void Progress::attach(SweepOptions& options) {
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

std::function<void(int, int)> Progress::callback(int total, const char* unit) {
  if (!enabled_) return nullptr;
  total_ = total;
  unit_ = unit;
  return [this](int done, int all) {
    done_ = done;
    total_ = all;
    report();
  };
}

void Progress::endLine() {
  if (line_open_) std::fputc('\n', stderr);
}

void Progress::report(bool finished_batch) {
  const auto now = std::chrono::steady_clock::now();
  const bool last = finished_batch && total_ > 0 && done_ >= total_;
  if (!last && now - last_ < std::chrono::milliseconds(250)) return;
  last_ = now;
  line_open_ = !last;
  // Directions done, and the share of the one under way in strips.
  const double fraction =
      total_ > 0 ? (done_ + (strips_ > 0 ? double(strip_) / strips_ : 0.0)) / total_ : 0.0;
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

void NorthUp::restore(std::vector<float>& planes) const {
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

void NorthUp::place(Observer& o) const {
  if (flip_rows) o.row = input->height - 1 - o.row;
  if (flip_columns) o.col = input->width - 1 - o.col;
}

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

Attributes Job::attributes(const HeightField& field, bool swept) const {
  const DeviceInfo& device = context->device();
  Attributes attributes{{"hfvis:command", command.recordedName()}, {"hfvis:input", run.input}};
  if (swept) {
    attributes.emplace_back("hfvis:directions", std::to_string(run.directions));
    attributes.emplace_back("hfvis:azimuth_offset_deg", formatNumber(run.azimuth_offset_deg));
    attributes.emplace_back("hfvis:azimuth_convention",
                            "phi_k = 360*k/K deg + offset, on the ground from the +column axis toward +row; "
                            "compass azimuth = 90 + phi_k deg when row 0 is north");
  }
  attributes.emplace_back("hfvis:method", method);
  if (swept) attributes.emplace_back("hfvis:samples_per_unit", formatNumber(run.samples_per_unit));
  // Read back by readHeightField, so an output keeps the input's ground spacing.
  attributes.emplace_back("hfvis:cell_size_x", formatNumber(field.cell_size_x));
  attributes.emplace_back("hfvis:cell_size_y", formatNumber(field.cell_size_y));
  attributes.emplace_back("hfvis:z_scale", formatNumber(field.z_scale));
  attributes.emplace_back("hfvis:nodata",
                          run.nodata && !std::isnan(*run.nodata)
                              ? "where the input height is not finite: " + formatNumber(*run.nodata) +
                                    " (the bands' nodata value) in GeoTIFF outputs, NaN in others"
                              : std::string("NaN where the input height is not finite"));
  attributes.emplace_back("hfvis:device", device.name + " (" + device.platform + ")");
  if (!run.channel.empty()) attributes.emplace_back("hfvis:channel", run.channel);
  if (run.max_distance > 0.0) attributes.emplace_back("hfvis:max_distance", formatNumber(run.max_distance));
  if (run.curvature) {
    attributes.emplace_back(
        "hfvis:curvature", "drop = d^2 (1 - K) / (2 R), R = " + formatNumber(kEarthRadius) +
                               " m, K = " + formatNumber(run.refraction) + " (ground units taken as metres)");
  }
  return attributes;
}

ImageChannels Job::image(const HeightField& field, std::vector<std::string> names,
                         std::vector<std::vector<float>> planes, Attributes attributes,
                         const std::string& quantity, const std::string& units) const {
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

std::vector<std::string> Computation::outputs() const {
  std::vector<std::string> paths{run_.output};
  if (!run_.distance_output.empty()) paths.push_back(run_.distance_output);
  if (!run_.error_output.empty()) paths.push_back(run_.error_output);
  if (!run_.preview.empty()) paths.push_back(run_.preview);
  return paths;
}

std::string Computation::method() const { return run_.method == HorizonMethod::Naive ? "naive" : "sweep"; }

namespace {

// The same file, whether or not it exists yet (links and relative paths resolved). A path not
// there yet is where a write would put it: through its links (a dangling link writes the file
// it names) and made absolute first, since weakly_canonical leaves a relative path relative when
// nothing of it exists ("h.tif" and "$PWD/h.tif" compared unequal, and one output replaced the
// other).
bool sameFile(const std::string& a, const std::string& b) {
  std::error_code error;
  const bool exists_a = fs::exists(a, error), exists_b = fs::exists(b, error);
  if (exists_a && exists_b) return fs::equivalent(a, b, error);
  const auto where = [](const std::string& path) {
    std::error_code failed;
    const fs::path target = fs::absolute(hfvis::detail::resolvedTarget(path), failed);
    // (links in it resolved before ".." is folded: "link/../h.exr" lies in the link's target's parent)
    const fs::path canonical = fs::weakly_canonical(target, failed);
    return failed ? target.lexically_normal() : canonical;
  };
  const fs::path place_a = where(a), place_b = where(b);
  if (place_a == place_b) return true;
  // One directory under two paths (a bind mount): the same name in it is the same file.
  struct stat parent_a {
  }, parent_b{};
  if (::stat(place_a.parent_path().c_str(), &parent_a) != 0 ||
      ::stat(place_b.parent_path().c_str(), &parent_b) != 0 || parent_a.st_dev != parent_b.st_dev ||
      parent_a.st_ino != parent_b.st_ino)
    return false;
  const std::string name_a = place_a.filename().string(), name_b = place_b.filename().string();
  if (name_a == name_b) return true;
  // Names that differ in case alone, neither there yet: one file where the directory ignores case
  // (vfat, exFAT, an ext4 casefold directory), where the second output's rename would replace the
  // first. Told by creating the first name (exclusively: nothing of the user's is touched) and
  // looking for the second. (Where one exists, so does the other if the directory ignores case,
  // and the check above compared the files: one there alone is another file.) ASCII letters only.
  const bool case_alone =
      name_a.size() == name_b.size() &&
      std::equal(name_a.begin(), name_a.end(), name_b.begin(), [](char x, char y) {
        return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
      });
  if (!case_alone || exists_a || exists_b) return false;
  hfvis::detail::rememberTemporary(place_a.string());  // (removed on a signal)
  const int probe = ::open(place_a.c_str(), O_CREAT | O_EXCL | O_WRONLY | O_CLOEXEC, 0600);
  bool one = false;
  if (probe >= 0) {
    ::close(probe);
    struct stat other {};
    one = ::lstat(place_b.c_str(), &other) == 0;
    ::unlink(place_a.c_str());
  }
  hfvis::detail::forgetTemporary(place_a.string());
  return one;
}

// Every file a run reads: the input and the others, with the files a GDAL raster reads beside
// itself (a VRT's sources).
std::vector<std::string> filesOfInputs(const RunArguments& run, const Computation& computation) {
  std::vector<std::string> inputs = filesRead(run.input);
  for (const std::string& input : computation.otherInputs())
    if (!input.empty())
      for (const std::string& file : filesRead(input)) inputs.push_back(file);
  return inputs;
}

// Every output can be written, none is an input (an output never replaces an input), and no
// two outputs are the same file (the second would replace the first). Checked before the
// input is read.
void requireOutputs(const RunArguments& run, const Computation& computation) {
  const std::vector<std::string> outputs = computation.outputs();
  const std::vector<std::string> inputs = filesOfInputs(run, computation);
  for (std::size_t i = 0; i < outputs.size(); ++i) {
    requireReplaceable(outputs[i]);
    if (computation.writesImages() && outputs[i] != run.preview)
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
    // A GeoTIFF takes away the files GDAL reads beside it as part of it (OutputFiles): none may be
    // an input or another output, and each must be one this user may remove, known before the work.
    if (!writesGeoTiff(outputs[i])) continue;
    for (const std::string& side : hfvis::detail::geoTiffSideFiles(outputs[i])) {
      for (const std::string& input : inputs)
        if (sameFile(side, input))
          throw UsageError("output '" + outputs[i] + "' would take away '" + side +
                           "' (GDAL reads it as part of the GeoTIFF it replaces), which is the input '" +
                           input + "': outputs never replace an input");
      for (const std::string& other : outputs)
        if (sameFile(side, other))
          throw UsageError("output '" + other + "' is '" + side + "', which GDAL reads as part of output '" +
                           outputs[i] + "': name it otherwise");
      hfvis::detail::requireReplaceableTarget(side, side);
    }
  }
}

// Reads the input height field and checks it (a bad field is the input file's fault).
HeightField readValidField(const RunArguments& run) {
  HeightField field = readHeightField(run.input, readOptions(run));
  try {
    validate(field);
  } catch (const InvalidArgument& error) {
    // A cell size from the file (its geotransform, hfvis's attributes) that the kernels cannot
    // hold: --cell-size gives another.
    throw Error(run.input + ": " + error.what() +
                (cellSizesHeld(field) ? "" : "; give one with --cell-size"));
  }
  // The Earth's drop takes distances in metres: cells of a CRS in feet counted as metres made it
  // 3.28 times too small, exit 0 (a probe's find). Given cell sizes are the user's metres.
  if (run.curvature && run.cell_size_x <= 0.0 && run.cell_size_y <= 0.0) {
    const auto unit = detail::projectedLinearUnit(field.georeference.crs_wkt);
    if (unit && std::fabs(unit->second - 1.0) > 1e-9)
      throw UsageError("--curvature needs cell sizes in metres, and " + run.input + "'s CRS counts them in " +
                       unit->first + " (" + detail::exactNumber(unit->second) +
                       " m): give --cell-size in metres (and --z-scale " + detail::exactNumber(unit->second) +
                       " for heights in " + unit->first + ")");
  }
  return field;
}

// The context of a run: the HFVIS_* environment variables (ContextOptions::fromEnvironment),
// --device taking precedence over HFVIS_DEVICE.
ComputeContext contextFor(const RunArguments& run) {
  ContextOptions options = ContextOptions::fromEnvironment();
  if (!run.device.empty()) options.device = run.device;
  return ComputeContext::create(options);
}

std::string joinPaths(const std::vector<std::string>& paths) {
  std::string joined;
  for (const std::string& path : paths) joined += (joined.empty() ? "" : ", ") + path;
  return joined;
}

}  // namespace

int runPipeline(const CommandLine& line, Computation& computation) {
  const RunArguments& run = line.run;
  requireOutputs(run, computation);
  // The inputs' files as they are read stay protected whatever their paths name by the time the
  // outputs are written (requireOutputs checked the paths before the work; a link made to an
  // input since must not let an output replace it).
  OutputFiles outputs;
  outputs.protect(filesOfInputs(run, computation));
  HeightField input = readValidField(run);
  computation.prepare(input);
  // (a command on the host, writing text, opens no device; region writes text from the device)
  std::optional<ComputeContext> context;
  if (computation.usesDevice()) context.emplace(contextFor(run));
  Progress progress(run.quiet);
  Job job{commandSpec(line.command),     run,      input,
          context ? &*context : nullptr, progress, computation.method()};
  const auto start = std::chrono::steady_clock::now();
  computation.compute(job);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();

  // Everything is computed; now stage every file, then move them all into place.
  const Summary summary = computation.write(job, outputs);
  const std::vector<std::string> written = outputs.paths();
  outputs.commit();
  if (!run.quiet) {
    std::cout << "wrote " << joinPaths(written) << " (" << input.width << "x" << input.height << ", "
              << summary.count << " " << summary.unit << (summary.count == 1 ? ", " : "s, ") << job.method
              << ", " << formatFixed(seconds, 2) << " s" << (context ? " on " + context->device().name : "")
              << ")" << summary.note << "\n";
  }
  if (!summary.always.empty()) std::cout << summary.always << "\n";
  return 0;
}

}  // namespace hfvis::cli
