// cli/arguments.cpp: parsing and validating the hfvis command line: every option declared once
// (optionTable(): its flag, value, help, group and the field it binds), the parser that reads
// the option and command tables (cli/table.hpp), and the library options a run asks for.
#include "arguments.hpp"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <limits>
#include <set>
#include <tuple>

#include "core/number_text.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/insolation.hpp"
#include "hfvis/sun.hpp"
#include "hfvis/sun_shading.hpp"
#include "table.hpp"

namespace hfvis::cli {
namespace {

constexpr double kPi = 3.14159265358979323846;

// The options every sweep operation shares, as typed (degrees become radians).
template <typename Options>
void setSweepOptions(const RunArguments& run, Options& options) {
  options.directions = run.directions;
  options.azimuth_offset = run.azimuth_offset_deg * (kPi / 180.0);
  options.samples_per_unit = run.samples_per_unit;
  options.memory_budget_bytes = run.memory_budget_bytes;
  options.curvature = run.curvature ? earthCurvature(run.refraction) : 0.0;
  options.max_distance = run.max_distance;
}

bool isHelpFlag(const std::string& arg) { return arg == "-h" || arg == "--help"; }

}  // namespace

std::string inQuotes(const std::string& text) { return "'" + text + "'"; }

namespace {

// A value as a message shows it: at most 40 characters of what was typed.
std::string shortened(const std::string& text) {
  return text.size() > 40 ? text.substr(0, 40) + "... (" + std::to_string(text.size()) + " characters)"
                          : text;
}

// Strict number parsing: the whole text must be a finite decimal number. One that double cannot
// hold (1e400, or 5e-324 below its normal numbers) is named as such, not as "not a number".
double parseNumber(const std::string& option, const std::string& text) {
  double value = 0.0;
  if (detail::decimalNumber(text, value)) return value;
  char* end = nullptr;
  errno = 0;
  const double read = std::strtod(text.c_str(), &end);
  if (!text.empty() && !std::isspace(static_cast<unsigned char>(text[0])) && end == text.c_str() + text.size() &&
      errno == ERANGE && text.find_first_of("xX") == std::string::npos && !std::isnan(read))
    throw UsageError(option + ": " + inQuotes(shortened(text)) +
                     " is beyond the numbers hfvis computes with (magnitudes about 2.2e-308 .. 1.8e308, or 0)");
  throw UsageError(option + ": expected a number, got " + inQuotes(shortened(text)));
}

// A nodata value for float32 bands: "nan" (any case), or a finite number float32 holds.
float parseNodata(const std::string& option, const std::string& text) {
  std::string lower = text;
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (lower == "nan") return std::numeric_limits<float>::quiet_NaN();
  double value = 0.0;
  if (!detail::decimalNumber(text, value) || std::fabs(value) > std::numeric_limits<float>::max())
    throw UsageError(option +
                     ": expected nan or a decimal number within float32's range (about 3.4e38), got " +
                     inQuotes(shortened(text)));
  return static_cast<float>(value);
}

double parsePositive(const std::string& option, const std::string& text) {
  const double value = parseNumber(option, text);
  if (!(value > 0.0)) throw UsageError(option + ": must be greater than 0, got " + inQuotes(text));
  return value;
}

// A number within [lo, hi]: what single precision and the method hold (the kernels compute in
// float32; a value beyond them gives NaN or infinite results, not an error).
double parseBounded(const std::string& option, const std::string& text, double lo, double hi,
                    const char* why) {
  const double value = parseNumber(option, text);
  if (!(value >= lo && value <= hi))
    throw UsageError(option + ": must be in " + detail::shortNumber(lo) + " .. " + detail::shortNumber(hi) + " (" + why +
                     "), got " + inQuotes(shortened(text)));
  return value;
}

// Limits of the ground and height values (ground units): within them, distances, their squares
// and areas over a field of 2^31 pixels stay inside float32's range with room for the sums.
// (the cell sizes' range, kLeastCellSize .. kMostCellSize: hfvis/height_field.hpp)
constexpr double kMostLength = 1e12;
// The sweep's largest azimuth tolerance, 0.1 radian (computeHorizons), in degrees as the help
// gives it (rounded up: the conversion to radians clamps it to 0.1).
constexpr double kMostAzimuthTolerance = 5.72958;
constexpr const char* kFloatRange = "what the kernels' single precision holds";

int parseDirectionCount(const std::string& option, const std::string& text) {
  long value = 0;
  if (!detail::wholeNumber(text, value)) {
    throw UsageError(option + ": expected a whole number of directions, got " + inQuotes(text));
  }
  if (value < 1 || value > kMaxDirections) {
    throw UsageError(option + ": the number of directions must be in 1 .. " + std::to_string(kMaxDirections) +
                     ", got " + inQuotes(text));
  }
  return static_cast<int>(value);
}

HorizonMethod parseMethod(const std::string& option, const std::string& text) {
  if (text == "sweep") return HorizonMethod::Sweep;
  if (text == "naive") return HorizonMethod::Naive;
  throw UsageError(option + ": expected 'sweep' or 'naive', got " + inQuotes(text));
}

IntervisibilityMethod parseVisibilityMethod(const std::string& option, const std::string& text) {
  if (text == "tree") return IntervisibilityMethod::HullTree;
  if (text == "naive") return IntervisibilityMethod::Naive;
  throw UsageError(option + ": expected 'tree' or 'naive', got " + inQuotes(text));
}

// "COL,ROW": a pixel, zero-based. Whether it lies inside the field is checked once the
// field's size is known (checkReceivers).
ReceiverPixel parseReceiver(const std::string& option, const std::string& text) {
  const std::string expected =
      option + ": expected COL,ROW (zero-based pixel column and row, e.g. 12,40), got " + inQuotes(text);
  const std::size_t comma = text.find(',');
  if (comma == std::string::npos) throw UsageError(expected);
  auto whole = [&](const std::string& part) {
    long value = 0;
    if (!detail::wholeNumber(part, value) || value > std::numeric_limits<int>::max() ||
        value < std::numeric_limits<int>::min()) {
      throw UsageError(expected);
    }
    return static_cast<int>(value);
  };
  ReceiverPixel pixel{whole(text.substr(0, comma)), whole(text.substr(comma + 1))};
  if (pixel.col < 0 || pixel.row < 0) {
    throw UsageError(option + " " + text + ": outside the field (column and row count from 0)");
  }
  return pixel;
}

}  // namespace

bool hasExtension(const std::string& path, const char* wanted) {
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension == wanted;
}

std::string namedAs(const std::string& path) {
  const std::string file = std::filesystem::path(path).filename().string();
  const bool extension_alone = file.size() > 1 && file[0] == '.' && file.find('.', 1) == std::string::npos;
  return inQuotes(path) + (extension_alone ? " (an extension alone: give a name before it)" : "");
}

namespace {

// "X" or "X,Y", ground units per pixel along columns and rows.
void parseCellSize(const std::string& option, const std::string& text, RunArguments& run) {
  const std::size_t comma = text.find(',');
  const auto size = [&](const std::string& part) {
    parsePositive(option, part);
    return parseBounded(option, part, kLeastCellSize, kMostCellSize, kFloatRange);
  };
  if (comma == std::string::npos) {
    run.cell_size_x = run.cell_size_y = size(text);
  } else {
    run.cell_size_x = size(text.substr(0, comma));
    run.cell_size_y = size(text.substr(comma + 1));
  }
}

std::size_t parseMemoryBudget(const std::string& option, const std::string& text) {
  const double megabytes = parsePositive(option, text);
  const double bytes = std::ceil(megabytes * 1024.0 * 1024.0);
  if (bytes > static_cast<double>(std::numeric_limits<std::size_t>::max() / 2)) {
    throw UsageError(option + ": " + inQuotes(text) + " MB is too large");
  }
  return static_cast<std::size_t>(bytes);
}

// A path value: any text but empty.
void requireNonEmpty(const std::string& option, const std::string& value) {
  if (value.empty()) throw UsageError(option + ": the value must not be empty");
}

// "AZ,EL"-like pairs: "FIRST,SECOND" split at the first comma, or `expected` thrown.
std::pair<std::string, std::string> splitPair(const std::string& typed, const std::string& value,
                                              const std::string& expected) {
  const std::size_t comma = value.find(',');
  if (comma == std::string::npos) throw UsageError(typed + expected + inQuotes(value));
  return {value.substr(0, comma), value.substr(comma + 1)};
}

void parseUtcTimeInto(const std::string& typed, const std::string& value, std::optional<double>& time) {
  try {
    time = parseUtcTime(value);
  } catch (const InvalidArgument& error) {
    throw UsageError(typed + ": " + error.what());
  }
}

// "C0,R0,C1,R1": a rectangle of grid points, its corners included, in any order (the library
// orders them). Whether it lies inside the field is checked once the field's size is known.
PixelRectangle parseRectangle(const std::string& typed, const std::string& value) {
  const std::string expected =
      typed +
      ": expected C0,R0,C1,R1 (two corner pixels' zero-based columns and rows, e.g. 10,0,20,5), got " +
      inQuotes(shortened(value));
  std::vector<int> corners;
  std::size_t begin = 0;
  while (true) {
    const std::size_t comma = value.find(',', begin);
    const std::string part =
        value.substr(begin, comma == std::string::npos ? std::string::npos : comma - begin);
    long number = 0;
    if (!detail::wholeNumber(part, number) || number > std::numeric_limits<int>::max() ||
        number < std::numeric_limits<int>::min())
      throw UsageError(expected);
    corners.push_back(static_cast<int>(number));
    if (comma == std::string::npos) break;
    begin = comma + 1;
  }
  if (corners.size() != 4) throw UsageError(expected);
  for (const int c : corners)
    if (c < 0) throw UsageError(typed + " " + value + ": outside the field (columns and rows count from 0)");
  return {corners[0], corners[1], corners[2], corners[3]};
}

// A height of a region's samples, as --observer-height: what single precision holds.
double parseRegionHeight(const std::string& typed, const std::string& value) {
  return parseBounded(typed, value, -kMostLength, kMostLength, kFloatRange);
}

// A sampling seed: a whole number that 32 bits hold.
std::uint32_t parseSeed(const std::string& typed, const std::string& value) {
  const double n = parseNumber(typed, value);
  if (!(n >= 0.0 && n <= 4294967295.0 && n == std::floor(n)))
    throw UsageError(typed + ": expected a whole number in 0 .. 4294967295, got " + inQuotes(shortened(value)));
  return static_cast<std::uint32_t>(n);
}

// A whole number of `what` in lo .. hi (`range`: the message's words for them).
double parseWholeIn(const std::string& typed, const std::string& value, double lo, double hi,
                    const char* what, const char* range) {
  const double n = parseNumber(typed, value);
  if (!(n >= lo && n <= hi && n == std::floor(n)))
    throw UsageError(typed + ": expected a whole number of " + what + ", " + range + ", got " +
                     inQuotes(shortened(value)));
  return n;
}

// A count of cells a side (pvs's --view-cell and --tile): a whole number >= 1 (the field's size
// bounds it once read).
int parseCellCount(const std::string& typed, const std::string& value) {
  const double n = parseNumber(typed, value);
  if (!(n >= 1.0 && n <= 1e9 && n == std::floor(n)))
    throw UsageError(typed + ": expected a whole number of cells >= 1, got " + inQuotes(shortened(value)));
  return static_cast<int>(n);
}

// A flag that sets one bool field.
#define HFVIS_FLAG(field) [](const std::string&, const std::string&, RunArguments& run) { run.field = true; }
// A path or name: any non-empty text.
#define HFVIS_TEXT(field)                                                     \
  [](const std::string& typed, const std::string& value, RunArguments& run) { \
    requireNonEmpty(typed, value);                                            \
    run.field = value;                                                        \
  }

}  // namespace

// The options, one line each where they take what they say; the help lists them in this order.
const std::vector<OptionSpec>& optionTable() {
  static const std::vector<OptionSpec> table{
      {"--output", "-o", "FILE", kOutputGroup, false,
       "output image (required): float32 EXR, or a float32 GeoTIFF when the\n"
       "name ends in .tif or .tiff (the input's georeference kept; see\n"
       "Conventions, GIS); horizon-lists: OUT.json or OUT.csv; region, pvs: OUT.json",
       HFVIS_TEXT(output)},
      {"--quiet", "-q", nullptr, kOutputGroup, false, "print neither progress nor the summary line",
       HFVIS_FLAG(quiet)},
      {"--channel", nullptr, "NAME|INDEX", kInputGroup, false,
       "input channel (a raster's band: its description or zero-based index)\n"
       "to read; needed for multi-channel images",
       HFVIS_TEXT(channel)},
      {"--cell-size", nullptr, "X[,Y]", kInputGroup, false,
       "ground units per pixel along columns (X) and rows (Y)\n"
       "(default: from the file (a raster's geotransform, the\n"
       "hfvis:cell_size_x/y attributes), else 1)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         parseCellSize(typed, value, run);
       }},
      {"--z-scale", nullptr, "Z", kInputGroup, false,
       "multiplies every height, e.g. 0.3048 for feet over metre cells (default 1)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         parsePositive(typed, value);
         run.z_scale = parseBounded(typed, value, 1e-12, 1e12, kFloatRange);
       }},
      {"--preview", nullptr, "PNG", kImageGroup, false, "also write an 8-bit PNG preview",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         requireNonEmpty(typed, value);
         if (!hasExtension(value, ".png"))
           throw UsageError(typed + ": the preview is a PNG file; its name must end in .png, got " +
                            namedAs(value));
         run.preview = value;
       }},
      {"--nodata", nullptr, "VALUE", kImageGroup, false,
       "GeoTIFF outputs: write VALUE (a finite float32 number, or nan) in\n"
       "nodata cells and declare it as every band's nodata value (default\n"
       "nan); EXR outputs keep NaN. Needs a .tif/.tiff output",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.nodata = parseNodata(typed, value);
       }},
      {"--device", nullptr, "SEL", kDeviceGroup, false,
       "device index, \"gpu\", \"cpu\" or part of a device/platform name\n"
       "(default: env HFVIS_DEVICE, else a GPU, else the first CPU)",
       HFVIS_TEXT(device)},
      {"--memory-budget", nullptr, "MB", kDeviceGroup, false,
       "device memory for one batch of directions, MiB (default: half the\n"
       "device's memory; on a CPU device half the host's); horizon,\n"
       "sky-view-factor and ambient-occlusion run a field beyond it in strips\n"
       "of rows, with the same result",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.memory_budget_bytes = parseMemoryBudget(typed, value);
       }},
      {"--directions", "-k", "K", kSweepGroup, false,
       "number of azimuth directions, K >= 1 (default 64); shade: with --env only",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.directions = parseDirectionCount(typed, value);
         run.directions_given = run.sweep_options_given = true;
       }},
      {"--azimuth-offset", nullptr, "DEG", kSweepGroup, false,
       "added to every direction's azimuth, degrees (default 0)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.azimuth_offset_deg =
             parseBounded(typed, value, -360.0, 360.0, "every direction has an offset in it");
         run.sweep_options_given = true;
       }},
      {"--samples-per-unit", nullptr, "S", kSamplingGroup, false,
       "naive, intervisibility, bounce: height samples per pixel length along a\n"
       "line or ray; sweep: every grid-line crossing of the ray (exact heights)\n"
       "and, for S > 1, about S points per pixel length between crossings\n"
       "(default 1: the crossings alone)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.samples_per_unit = parsePositive(typed, value);
         if (run.samples_per_unit > 64.0)  // (the library's bound, named here with the option)
           throw UsageError(typed + ": at most 64 samples per pixel length, got " + inQuotes(value));
       }},
      {"--curvature", nullptr, nullptr, kEarthGroup, false,
       "lower every point at ground distance d by the Earth's drop\n"
       "d^2 (1 - K) / (2 R), R = 6370997 m, K = 1/7 (GRASS and GDAL's\n"
       "convention; cell sizes must be in metres)",
       HFVIS_FLAG(curvature)},
      {"--refraction", nullptr, "K", kEarthGroup, false,
       "the same with refraction coefficient K in -1 .. 1 (implies --curvature)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.refraction = parseNumber(typed, value);
         if (!(run.refraction >= -1.0 && run.refraction <= 1.0))
           throw UsageError(typed + ": the refraction coefficient must be in -1 .. 1, got " +
                            inQuotes(value));
         run.curvature = true;  // refraction bends rays over the curved Earth
       }},
      {"--max-distance", nullptr, "D", kReachGroup, false,
       "only terrain within D ground units of the receiver counts (farther\n"
       "terrain neither casts a horizon nor hides anything nearer; r.horizon's\n"
       "maxdistance, RVT's svf_r_max); viewshed: only targets within D;\n"
       "region, arealight, pvs: only pairs of points within D",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         parsePositive(typed, value);
         run.max_distance = parseBounded(typed, value, 0.0, kMostLength, kFloatRange);
       }},
      {"--method", nullptr, "sweep|naive", kSweepMethodGroup, false,
       "sweep = convex-hull-stack sweep along lines through every pixel\n"
       "centre, linear time per direction, exact over the samples of each\n"
       "receiver's own ray; naive = per-pixel ray march, slow reference\n"
       "(default sweep). The sweep's directions are integer pixel steps:\n"
       "within 0.25 deg of phi_k for horizon, within half the spacing\n"
       "(weighted) for sky-view-factor and ambient-occlusion; the\n"
       "hfvis:azimuths_deg attribute lists those used",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.method = parseMethod(typed, value);
         run.sweep_options_given = true;
       }},
      {"--hull-tree", nullptr, "T", kHullTreeGroup, false,
       "how the convex hull tree does its work; the results are the same for\n"
       "every T: plain = Algorithm 1 as written, deferred = link writes only\n"
       "where a link changes (Algorithm 2's aim), default = deferred + the old\n"
       "root's last child checked first, zone = default + the safe zone\n"
       "(Algorithm 3) (default: default)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         const auto tuning = hullTreeTuningNamed(value);
         if (!tuning)
           throw UsageError(typed + ": expected plain, deferred, default or zone, got " + inQuotes(value));
         run.hull_tree = *tuning;
         run.hull_tree_name = value;
       }},
      {"--lat", nullptr, "LAT", kSunPlaceGroup, false, "the place's latitude, degrees (north positive)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.latitude = parseNumber(typed, value);
         if (*run.latitude < -90.0 || *run.latitude > 90.0)
           throw UsageError(typed + ": expected a latitude in -90 .. 90 degrees, got " + inQuotes(value));
       }},
      {"--lon", nullptr, "LON", kSunPlaceGroup, false, "the place's longitude, degrees (east positive)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.longitude = parseNumber(typed, value);
         if (*run.longitude < -180.0 || *run.longitude > 360.0)
           throw UsageError(typed + ": expected a longitude in -180 .. 360 degrees, got " + inQuotes(value));
       }},
      {"--sun-size", nullptr, "DEG", kSunPlaceGroup, false,
       "the sun's angular diameter (default 0.53; 0 = a point sun, hard shadows)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.sun_size_deg = parseNumber(typed, value);
         if (!(run.sun_size_deg >= 0.0 && run.sun_size_deg <= 10.0))
           throw UsageError(typed +
                            ": the sun's diameter must be in 0 (a point: hard shadows) .. 10 degrees, got " +
                            inQuotes(value));
       }},
      {"--max-error", nullptr, "E", kErrorTargetGroup, false,
       "choose K for this error instead of taking -k: the 99th percentile over\n"
       "the pixels of the error estimate (see --error-out) at most E, 0 < E < 1\n"
       "(absolute for the sky-view factor and occlusion; intervisibility: of\n"
       "the count, relative to its mean; shade --env: relative to the mean\n"
       "irradiance); a first run at 16 directions predicts the K needed,\n"
       "refused when beyond 4096 (see --error-tile); for the sky-view factor\n"
       "and occlusion the estimate is then that of the K result itself (the\n"
       "halves' difference over 2^p - 1, p as the runs measured it, 1 .. 1.1;\n"
       "occlusion's plus its swaths' bias from the pixel's tilt;\n"
       "docs/COMMAND_LINE.md); the largest K and the\n"
       "estimate go into the summary and the hfvis:directions and\n"
       "hfvis:estimated_error attributes, the sky-view factor and occlusion\n"
       "also hfvis:richardson_divisor (2^p - 1) and hfvis:runs (each run's K)\n"
       "(with --error-tile also hfvis:directions_range, the least and most\n"
       "K, and --error-out's channel directions, each pixel's, NaN at nodata)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.max_error = parseNumber(typed, value);
         if (!(run.max_error > 0.0 && run.max_error < 1.0))
           throw UsageError(typed +
                            ": the maximum error must lie in (0, 1) (absolute in the sky-view factor's and "
                            "occlusion's 0..1, relative for intervisibility and shade --env), got " +
                            inQuotes(value));
       }},
      {"--error-tile", nullptr, "N", kErrorTargetGroup, false,
       "sky-view-factor and ambient-occlusion, with --max-error: refine\n"
       "in tiles of N x N pixels (N >= 16), each run again at its own K\n"
       "over the lines that reach it, where the estimate asks for more\n"
       "(default 0: the whole field takes one K, which costs less on the\n"
       "benchmark's contents, bench/report/error_target.md)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         const double tile = parseNumber(typed, value);
         if (!(tile >= 0.0 && tile <= 1e6 && tile == std::floor(tile)))
           throw UsageError(typed + ": a tile is a whole number of pixels (0: the whole field), got " +
                            inQuotes(value));
         if (tile > 0.0 && tile < kMinErrorTile)
           throw UsageError(typed + ": a tile is at least " + std::to_string(kMinErrorTile) +
                            " pixels (0: the whole field): a smaller one stops on a few pixels' estimates, "
                            "low by chance, and misses the error asked for; got " +
                            inQuotes(value));
         run.error_tile = static_cast<int>(tile);
       }},
      {"--error-out", nullptr, "FILE", kErrorTargetGroup, false,
       "also write the per-pixel error estimate (channel \"error\"): half the\n"
       "difference between the results of the even- and of the odd-numbered\n"
       "directions alone (with --max-error over the divisor its runs measured,\n"
       "see there; intervisibility: their whole difference in the\n"
       "count, over the field's mean count), which lies above the error\n"
       "against the dense azimuthal integral on the benchmark's contents;\n"
       "with -k or --max-error (shade --env: with --max-error only, the\n"
       "larger difference from the runs at K / 2 on K's even and odd\n"
       "directions, over the mean irradiance)",
       HFVIS_TEXT(error_output)},
      {"--distance-out", nullptr, "FILE", kHorizonGroup, false,
       "also write K channels d000.. of ground distance to the\n"
       "horizon point (ground units), computed in the same run",
       HFVIS_TEXT(distance_output)},
      {"--max-error", nullptr, "E", kHorizonGroup, false,
       "choose K for this error instead of taking -k: the mean over the pixels\n"
       "and azimuths of the error of the K channels, interpolated linearly in\n"
       "azimuth between the directions' azimuths, against the true horizon,\n"
       "at most E degrees (its estimate, see --error-out), 0 < E < 90; runs at\n"
       "8 and 16 directions predict the K needed (the least work within 1.25x\n"
       "of it, or a multiple of the last K, extending that run, where that costs\n"
       "less), refused when beyond 4096; the samples per unit stay as given.\n"
       "K and the estimate go into the summary and the hfvis:directions and\n"
       "hfvis:estimated_error (degrees) attributes",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.horizon_max_error_deg = parseNumber(typed, value);
         if (!(run.horizon_max_error_deg > 0.0 && run.horizon_max_error_deg < 90.0))
           throw UsageError(typed +
                            ": the maximum error must lie in (0, 90) degrees (the mean error of horizon angles "
                            "in -90 .. 90), got " +
                            inQuotes(value));
       }},
      {"--error-out", nullptr, "FILE", kHorizonGroup, false,
       "also write the per-pixel error estimate (channel \"error\", degrees):\n"
       "each direction against the interpolation of its neighbours in\n"
       "azimuth (the error at K / 2), scaled to K by the order the pixel's\n"
       "neighbours two places away show and by 0.75 (2/3, an interval's mean\n"
       "against its midpoint's, calibrated up by 1.125), averaged over\n"
       "azimuth; with -k (K >= 5) or --max-error",
       HFVIS_TEXT(error_output)},
      {"--azimuth-tolerance", nullptr, "DEG", kHorizonGroup, false,
       "the sweep's direction k is the cheapest integer pixel step within\n"
       "DEG of phi_k (default 0.25; at most 5.72958, 0.1 radian), the\n"
       "closest step of up to 64 pixels where none is (the azimuths used:\n"
       "hfvis:azimuths_deg). Smaller is closer to phi_k and slower: steps\n"
       "with more grid crossings per pixel",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         parsePositive(typed, value);
         run.azimuth_tolerance_deg = parseBounded(typed, value, 0.0, kMostAzimuthTolerance,
                                                  "the azimuth tolerance is 0.1 radian at most");
       }},
      {"--method", nullptr, "tree|naive", kIntervisibilityGroup, false,
       "tree = convex hull tree sweep (Timonen 2013); naive = per-pixel\n"
       "visibility march, slow reference (default tree)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.visibility_method = parseVisibilityMethod(typed, value);
       }},
      {"--stats", nullptr, nullptr, kIntervisibilityGroup, false,
       "also print, for the tree method, the statistics of Timonen (2013)'s\n"
       "Table 2 per point and direction: m_a (visibility horizons), t_a\n"
       "(convexity checks made), visible samples and naive iterations (the\n"
       "samples the naive method tests); also stored as hfvis:stats_* EXR\n"
       "attributes. Printed even with --quiet. Table 2's t_a is Algorithm\n"
       "1's: add --hull-tree plain.",
       HFVIS_FLAG(statistics)},
      {"--at", nullptr, "COL,ROW", kHorizonListsGroup, true,
       "a receiver pixel (zero-based column, row); repeat for more. A pixel\n"
       "outside the field is a usage error (status 2).",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.receivers.push_back(parseReceiver(typed, value));
       }},
      {"--radiance", nullptr, "RAD.exr", kBounceGroup, false,
       "exit radiance of every surface point: an image of the input's size\n"
       "with 1 to 4 channels (grey, RGB, ...), finite and >= 0 where the\n"
       "height is valid. The output has the same channel names.",
       HFVIS_TEXT(radiance)},
      {"--env", nullptr, "ENV.exr", kEnvironmentLightGroup, false,
       "an HDR environment, equirectangular (latitude / longitude, 2:1)", HFVIS_TEXT(environment)},
      {"--env-rotate", nullptr, "DEG", kEnvironmentLightGroup, false,
       "the environment's left edge looks toward compass azimuth DEG (default 0)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.environment_rotation_deg =
             parseBounded(typed, value, -360.0, 360.0, "every rotation has an angle in it");
       }},
      {"--env-rows", nullptr, "N", kEnvironmentLightGroup, false,
       "bands of zenith angle in the tables (default the map's rows)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         const double rows = parsePositive(typed, value);
         if (rows != std::floor(rows) || rows > 65536)
           throw UsageError(typed + ": expected a whole number of bands in 1 .. 65536, got " +
                            inQuotes(value));
         run.environment_rows = static_cast<int>(rows);
       }},
      {"--sun", nullptr, "AZ,EL", kSunShadingGroup, false,
       "the sun's compass azimuth (degrees clockwise from north) and elevation",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         const auto [az, el] =
             splitPair(typed, value, ": expected AZ,EL (compass azimuth and elevation, degrees), got ");
         const double azimuth =
             parseBounded(typed, az, -360.0, 360.0, "every azimuth has an equal one in it");
         const double elevation = parseNumber(typed, el);
         if (elevation < -90.0 || elevation > 90.0)
           throw UsageError(typed + ": the elevation must be in -90 .. 90 degrees, got " + inQuotes(value));
         run.sun = std::make_pair(azimuth, elevation);
       }},
      {"--at", nullptr, "TIME", kSunShadingGroup, false,
       "the sun where it stands at TIME (ISO 8601 with a zone), with --lat, --lon",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         parseUtcTimeInto(typed, value, run.sun_time);
       }},
      {"--albedo", nullptr, "A|FILE", kSunShadingGroup, false,
       "also the radiance a Lambertian surface of albedo A (0..1, or an image)\n"
       "sends out",
       HFVIS_TEXT(albedo)},
      {"--sun-irradiance", nullptr, "E", kSunShadingGroup, false,
       "the sun's normal irradiance in the radiance (default 1; needs --albedo)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         parsePositive(typed, value);
         run.sun_irradiance = parseBounded(typed, value, 0.0, 1e12, kFloatRange);
       }},
      {"--from", nullptr, "TIME", kInsolationGroup, false, "the span's start (ISO 8601 with a zone)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         parseUtcTimeInto(typed, value, run.from_time);
       }},
      {"--to", nullptr, "TIME", kInsolationGroup, false, "the span's end",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         parseUtcTimeInto(typed, value, run.to_time);
       }},
      {"--step", nullptr, "MINUTES", kInsolationGroup, false, "the time step (default 10, at most 1440)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.step_minutes = parsePositive(typed, value);
         if (run.step_minutes > 1440.0)
           throw UsageError(typed + ": at most 1440 minutes, got " + inQuotes(value));
       }},
      {"--azimuth-bucket", nullptr, "DEG", kInsolationGroup, false,
       "steps whose sun azimuths fall in one bucket share one sweep\n"
       "(default 0.25, 0.001 .. 10)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.azimuth_bucket_deg = parsePositive(typed, value);
         if (run.azimuth_bucket_deg > 10.0 || run.azimuth_bucket_deg < kLeastAzimuthBucketDeg)
           throw UsageError(typed + ": 0.001 .. 10 degrees, got " + inQuotes(value));
       }},
      {"--apparent", nullptr, nullptr, kInsolationGroup, false, "lift the sun by the atmosphere's refraction",
       HFVIS_FLAG(apparent)},
      {"--observer", nullptr, "COL,ROW", kViewshedGroup, true, "an observer's grid point; repeat for more",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.observers.push_back(parseReceiver(typed, value));
       }},
      {"--observers", nullptr, "FILE.csv", kViewshedGroup, false,
       "observers, one col,row[,height] a line (a header line allowed: row,col\n"
       "for that order; map coordinates x,y refused)",
       HFVIS_TEXT(observers_file)},
      {"--observer-height", nullptr, "H", kViewshedGroup, false,
       "the eye's height above the surface (default 2)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.observer_height = parseBounded(typed, value, -kMostLength, kMostLength, kFloatRange);
       }},
      {"--target-height", nullptr, "T", kViewshedGroup, false,
       "the target's height above the surface (default 0)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         if (parseNumber(typed, value) < 0.0)
           throw UsageError(typed + ": must be >= 0, got " + inQuotes(value));
         run.target_height = parseBounded(typed, value, 0.0, kMostLength, kFloatRange);
       }},
      {"--absolute", nullptr, nullptr, kViewshedGroup, false, "the eye at height H, not H above the surface",
       HFVIS_FLAG(absolute)},
      {"--fov", nullptr, "FROM,TO", kViewshedGroup, false,
       "targets whose compass azimuth lies clockwise from FROM to TO",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         const auto [from, to] =
             splitPair(typed, value, ": expected FROM,TO (compass degrees, clockwise from FROM), got ");
         const double a = parseNumber(typed, from), b = parseNumber(typed, to);
         if (!(a >= 0.0 && a <= 360.0 && b >= 0.0 && b <= 360.0))
           throw UsageError(typed + ": compass azimuths are in 0 .. 360 degrees, got " + inQuotes(value));
         // (the library takes FROM = TO for the whole circle: 90,90 saw everything, exit 0)
         if (a == b)
           throw UsageError(typed + ": " + inQuotes(value) +
                            " is no field of view (FROM = TO); leave --fov out, or give 0,360, for the whole "
                            "circle");
         run.field_of_view = std::make_pair(a, b);
       }},
      {"--elevation-range", nullptr, "LO,HI", kViewshedGroup, false,
       "targets seen between LO and HI degrees above the eye's horizontal",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         const auto [lo, hi] = splitPair(typed, value, ": expected LO,HI (elevation degrees), got ");
         const double a = parseNumber(typed, lo), b = parseNumber(typed, hi);
         if (!(a >= -90.0 && b <= 90.0 && a <= b))
           throw UsageError(typed + ": expected -90 <= LO <= HI <= 90 degrees, got " + inQuotes(value));
         run.elevation_range = std::make_pair(a, b);
       }},
      {"--angle", nullptr, nullptr, kViewshedGroup, false, "also channel \"angle\" (one observer)",
       HFVIS_FLAG(with_angle)},
      {"--needed-height", nullptr, nullptr, kViewshedGroup, false,
       "also channel \"needed_height\" (one observer)", HFVIS_FLAG(with_needed_height)},
      {"--method", nullptr, "exact|culled", kViewshedGroup, false,
       "culled: through Stewart's culling pyramid, the same result (default exact)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         if (value != "exact" && value != "culled")
           throw UsageError(typed + ": expected 'exact' or 'culled', got " + inQuotes(value));
         run.culled = value == "culled";
       }},
      {"--cull-level", nullptr, "K", kViewshedGroup, false,
       "the pyramid's finest nodes, 2^K points a side (default 2)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         const double k = parseNumber(typed, value);
         if (!(k >= 1.0 && k <= 12.0 && k == std::floor(k)))
           throw UsageError(typed + ": expected a whole number 1 .. 12 (nodes of 2^K x 2^K points), got " +
                            inQuotes(value));
         run.cull_level = static_cast<int>(k);
         run.cull_level_given = true;
       }},
      {"--samples", nullptr, "N", kRegionSamplingGroup, false,
       "samples of each region, 1 .. 4096 (default 16): stratified over the\n"
       "rectangle, each jittered in its stratum",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         const double n = parseNumber(typed, value);
         if (!(n >= 1.0 && n <= kMaxRegionSamples && n == std::floor(n)))
           throw UsageError(typed + ": expected a whole number of samples in 1 .. " +
                            std::to_string(kMaxRegionSamples) + " (the bitmasks' bits), got " +
                            inQuotes(shortened(value)));
         run.region_samples = static_cast<int>(n);
         run.region_samples_given = true;
       }},
      {"--method", nullptr, "auto|exact|culled|viewsheds|bitmask", kRegionSamplingGroup, false,
       "exact: one sight line per pair (the reference); culled: the same\n"
       "sight lines leaping over blocks of cells far below them, the exact\n"
       "bits sooner; viewsheds: one viewshed per source sample, for sources\n"
       "on grid points (--sources, or a one-pixel --light), shared samples;\n"
       "may decide grazing lines the other way; bitmask (arealight):\n"
       "Eisemann & Decoret's scatter for a light at an --absolute height,\n"
       "the exact bits; auto (default): bitmask where it takes the light\n"
       "and --samples is 64 or more (faster there), else culled",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         if (value != "auto" && value != "exact" && value != "culled" && value != "viewsheds" && value != "bitmask")
           throw UsageError(typed + ": expected 'auto', 'exact', 'culled', 'viewsheds' or 'bitmask', got " +
                            inQuotes(shortened(value)));
         run.region_method = value == "exact"     ? RegionVisibilityMethod::Exact
                             : value == "culled"  ? RegionVisibilityMethod::Culled
                             : value == "bitmask" ? RegionVisibilityMethod::Bitmask
                             : value == "auto"    ? RegionVisibilityMethod::Auto
                                                  : RegionVisibilityMethod::Viewsheds;
       }},
      {"--absolute", nullptr, nullptr, kRegionSamplingGroup, false,
       "the regions' heights absolute (z-scaled), not above the surface", HFVIS_FLAG(absolute)},
      {"--seed", nullptr, "N", kRegionSamplingGroup, false,
       "the jitter's seed, 0 .. 4294967295 (default 1): the same seed, the\n"
       "same samples",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.seed = parseSeed(typed, value);
         run.seed_given = true;
       }},
      {"--light", nullptr, "C0,R0,C1,R1", kAreaLightGroup, false,
       "the light: the rectangle of grid points between two corner pixels\n"
       "(columns and rows, inclusive, in any order)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.light = parseRectangle(typed, value);
       }},
      {"--light-height", nullptr, "H", kAreaLightGroup, false,
       "the light's samples H above the surface under each (--absolute: at\n"
       "height H); the default height of --sources rows (default 2)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.light_height = parseRegionHeight(typed, value);
       }},
      {"--sources", nullptr, "FILE.csv", kAreaLightGroup, false,
       "the light's samples, one col,row[,height] a line (a header line\n"
       "allowed: row,col for that order; map coordinates x,y refused;\n"
       "fractional columns and rows lie between pixel centres)",
       HFVIS_TEXT(sources_file)},
      {"--light-image", nullptr, "FILE", kAreaLightGroup, false,
       "colours the --light rectangle: an R, G, B image (or one grey\n"
       "channel) stretched over it; adds channels R, G, B, the light's\n"
       "colours each pixel sees, summed over the samples / N",
       HFVIS_TEXT(light_image)},
      {"--target-height", nullptr, "T", kAreaLightGroup, false,
       "every pixel receives T above the surface (default 0)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         if (parseNumber(typed, value) < 0.0)
           throw UsageError(typed + ": must be >= 0, got " + inQuotes(value));
         run.target_height = parseBounded(typed, value, 0.0, kMostLength, kFloatRange);
       }},
      {"--decorrelate", nullptr, nullptr, kAreaLightGroup, false,
       "each pixel draws its own jitter of the light's samples: noise\n"
       "instead of the banding of shared samples (--method exact)",
       HFVIS_FLAG(decorrelate)},
      {"--masks", nullptr, "FILE", kAreaLightGroup, false,
       "also the bitmasks of the samples each pixel sees, lossless: float32\n"
       "channels m000.., channel k holding samples 16k .. 16k+15 as the\n"
       "whole number sum of 2^b for each visible sample 16k+b (.exr, .tif)",
       HFVIS_TEXT(masks_output)},
      {"--from", nullptr, "C0,R0,C1,R1", kRegionPairGroup, false,
       "the source rectangle of grid points (inclusive corners, any order)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.from_region = parseRectangle(typed, value);
       }},
      {"--to", nullptr, "C0,R0,C1,R1", kRegionPairGroup, false, "the receiving rectangle",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.to_region = parseRectangle(typed, value);
       }},
      {"--from-height", nullptr, "H", kRegionPairGroup, false,
       "the source samples' height above the surface (default 2)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.from_height = parseRegionHeight(typed, value);
       }},
      {"--to-height", nullptr, "H", kRegionPairGroup, false,
       "the receiving samples' height above the surface (default 2)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.to_height = parseRegionHeight(typed, value);
       }},
      {"--rays", nullptr, "RAYS.csv", kRegionPairGroup, false,
       "also every clear ray's end points, one a line (pixel columns and\n"
       "rows, heights; map x, y for a georeferenced input)",
       HFVIS_TEXT(rays_output)},
      {"--view-cell", nullptr, "C", kPvsGroup, false,
       "view cells of C x C cells (squares between grid points), 1 .. the\n"
       "field's larger side - 1 (default 32)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.pvs_grid.view_cell = parseCellCount(typed, value);
       }},
      {"--view-height", nullptr, "H0[,H1]", kPvsGroup, false,
       "the viewer's eye H0 above the surface, or anywhere in the band\n"
       "H0 .. H1 (z-scaled units; default 1.7)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         const std::size_t comma = value.find(',');
         const double lo = parseBounded(typed, value.substr(0, comma), 0.0, kMostLength, kFloatRange);
         const double hi =
             comma == std::string::npos ? lo : parseBounded(typed, value.substr(comma + 1), 0.0, kMostLength, kFloatRange);
         if (hi < lo)
           throw UsageError(typed + ": H1 below H0 in " + inQuotes(value) + " (the band is H0 .. H1)");
         run.pvs_grid.band_low = lo;
         run.pvs_grid.band_high = hi;
       }},
      {"--view-mask", nullptr, "MASK", kPvsGroup, false,
       "compute only the view cells holding a non-zero pixel of MASK, a\n"
       "raster of the field's size (a trail, a site; its first channel)",
       HFVIS_TEXT(pvs_mask)},
      {"--tile", nullptr, "T", kPvsGroup, false, "tiles (the objects) of T x T cells (default 16)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.pvs_grid.tile = parseCellCount(typed, value);
       }},
      {"--method", nullptr, "agvs|sgvs|per-cell", kPvsGroup, false,
       "agvs: adaptive global sampling (default); sgvs: stationary global\n"
       "sampling; per-cell: random rays from each view cell in turn",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         if (value == "agvs")
           run.pvs.method = PvsMethod::Agvs;
         else if (value == "sgvs")
           run.pvs.method = PvsMethod::Sgvs;
         else if (value == "per-cell")
           run.pvs.method = PvsMethod::PerCell;
         else
           throw UsageError(typed + ": expected 'agvs', 'sgvs' or 'per-cell', got " + inQuotes(shortened(value)));
       }},
      {"--samples", nullptr, "N", kPvsGroup, false, "stop after N visibility samples",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.pvs.samples =
             static_cast<std::uint64_t>(parseWholeIn(typed, value, 1.0, 1e15, "samples", "1 .. 1e15"));
       }},
      {"--pixel-error", nullptr, "E", kPvsGroup, false,
       "stop once the estimated pixel error is at most E (pixels per\n"
       "million-pixel camera)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.pvs.pixel_error = parsePositive(typed, value);
       }},
      {"--seconds", nullptr, "S", kPvsGroup, false,
       "stop after S seconds (settling the estimate may then take as long\n"
       "again: --estimate-entries)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.pvs.seconds = parsePositive(typed, value);
       }},
      {"--estimate-entries", nullptr, "N", kPvsGroup, false,
       "settle the estimate: after the budget, uniform view rays go on until N\n"
       "entries found once carry it, at most as many samples (and seconds) as\n"
       "the run took before them (default 20; 0: off)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.pvs.estimate_entries =
             static_cast<std::size_t>(parseWholeIn(typed, value, 0.0, 1e6, "entries", "0 .. 1e6"));
       }},
      {"--filter", nullptr, "K", kPvsGroup, false,
       "the visibility filter: add the tiles within K times the sampling's\n"
       "gap of a visible tile (no witness; default 0, none)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.pvs.filter = parseBounded(typed, value, 0.0, 1e6, "1e6");
       }},
      {"--view-filter", nullptr, "N", kPvsGroup, false,
       "the view-space filter: each view cell also takes the sampled sets of\n"
       "its N neighbours (0 .. 8) whose sets are the most like its own (no\n"
       "witness; default 0, none)",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.pvs.view_filter = static_cast<int>(parseWholeIn(typed, value, 0.0, 8.0, "neighbours", "0 .. 8"));
       }},
      {"--seed", nullptr, "N", kPvsGroup, false,
       "the sampling's seed, 0 .. 4294967295 (default 1): the same seed and\n"
       "budget of samples, the same sets",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.seed = parseSeed(typed, value);
         run.seed_given = true;
       }},
      {"--preview-view-cell", nullptr, "COL,ROW", kPvsGroup, false,
       "the preview shows the tiles seen from the view cell holding pixel\n"
       "COL,ROW (outlined) instead of every view cell's PVS size",
       [](const std::string& typed, const std::string& value, RunArguments& run) {
         run.pvs_preview_cell = parseReceiver(typed, value);
         run.pvs_preview_cell_given = true;
       }},
      {"--resume", nullptr, "PREV.bin", kPvsGroup, false,
       "start from the sets of an earlier run's --bitset file (the same field,\n"
       "view band, grid, curvature and maximum distance, run without --filter\n"
       "or --view-filter; its view mask unless --view-mask is given) and go on\n"
       "sampling; needs a --seed the earlier runs did not use",
       HFVIS_TEXT(pvs_resume)},
      {"--bitset", nullptr, "OUT.bin", kPvsGroup, false,
       "also the sets as one bitset per view cell (docs/PVS.md, byte by byte)", HFVIS_TEXT(bitset_output)},
  };
  return table;
}

#undef HFVIS_FLAG
#undef HFVIS_TEXT

bool samePath(const std::string& a, const std::string& b) {
  // ("lnk/../y.exr" is not "y.exr" when lnk is a link to another directory: a path with ".." is
  // left to the check that resolves it, before the input is read)
  const auto up = [](const std::filesystem::path& p) {
    return std::any_of(p.begin(), p.end(), [](const std::filesystem::path& part) { return part == ".."; });
  };
  if (up(a) || up(b)) return false;
  return std::filesystem::path(a).lexically_normal() == std::filesystem::path(b).lexically_normal();
}

namespace {

// Checks that involve more than one option: every command's, and its own (CommandSpec::check).
void validateRun(const CommandSpec& command, const std::string& name, const RunArguments& run) {
  const std::string out = command.id == Command::HorizonLists ? "OUT.json|OUT.csv"
                          : command.id == Command::Region || command.id == Command::Pvs ? "OUT.json"
                                                              : "OUT.exr";
  if (run.input.empty())
    throw UsageError("missing the input height field (hfvis " + name + " IN -o " + out + ")");
  if (run.output.empty())
    throw UsageError("missing -o " + out + " (the output file of 'hfvis " + name + "')");
  if (command.check) command.check(name, run);
  // Each output file once: -o, then the others in the order the help lists them.
  const std::vector<std::pair<const char*, const std::string*>> files{{"-o", &run.output},
                                                                      {"--distance-out", &run.distance_output},
                                                                      {"--error-out", &run.error_output},
                                                                      {"--preview", &run.preview}};
  for (std::size_t j = 1; j < files.size(); ++j)
    for (std::size_t i = 0; i < j; ++i)
      if (!files[i].second->empty() && !files[j].second->empty() && samePath(*files[i].second, *files[j].second))
        throw UsageError(std::string(files[j].first) + " must differ from " + files[i].first + ", both are " +
                         inQuotes(*files[j].second));
  // Only a GeoTIFF declares a nodata value; other outputs keep NaN, so the option would do nothing.
  if (run.nodata && !writesGeoTiff(run.output) &&
      (run.distance_output.empty() || !writesGeoTiff(run.distance_output)) &&
      (run.error_output.empty() || !writesGeoTiff(run.error_output)) &&
      (run.masks_output.empty() || !writesGeoTiff(run.masks_output))) {
    throw UsageError(
        "--nodata: only GeoTIFF outputs (.tif, .tiff) hold a nodata value, and no output is one; "
        "other outputs keep NaN");
  }
  // A nodata value the outputs can hold as data would make those cells nodata for every reader
  // (a viewshed's hidden 0 or visible 1): it must lie below every value the command writes.
  if (run.nodata && !std::isnan(*run.nodata)) {
    // (in float32, as the outputs hold both: -1.57079638 rounds to the angles' float(-pi/2))
    const float lowest = static_cast<float>(command.lowest_value ? command.lowest_value(run) : 0.0);
    if (*run.nodata >= lowest)
      throw UsageError("--nodata " + detail::exactNumber(*run.nodata) + ": 'hfvis " + name +
                       "' writes data values from " + detail::exactNumber(lowest) +
                       " up (in float32), so a reader could not tell those cells from nodata; give a value "
                       "below " +
                       detail::shortNumber(lowest) + " (such as -9999) or nan");
  }
}

// The options called `typed` (a flag may stand for one option of some commands and another of
// others, as --method and --at): the one `command` takes, else the first (to report).
const OptionSpec* findOption(const std::string& typed, const CommandSpec& command) {
  const OptionSpec* found = nullptr;
  for (const OptionSpec& spec : optionTable()) {
    if (typed != spec.name && !(spec.short_name && typed == spec.short_name)) continue;
    if (command.groups & spec.group) return &spec;
    if (!found) found = &spec;
  }
  return found;
}

// `typed` is an option, but not one of `command`'s: say which command takes it where one does.
[[noreturn]] void throwNotTaken(const std::string& typed, const std::string& name) {
  std::vector<const char*> takers;
  for (const CommandSpec* command : commandTable())
    for (const OptionSpec& spec : optionTable())
      if ((typed == spec.name || (spec.short_name && typed == spec.short_name)) &&
          (command->groups & spec.group)) {
        takers.push_back(command->name);
        break;
      }
  if (takers.size() == 1) throw UsageError(typed + " is only available with 'hfvis " + takers[0] + "'");
  throw UsageError(typed + " is not available with 'hfvis " + name + "'");
}

RunArguments parseRunArguments(const CommandSpec& command, const std::string& name,
                               const std::vector<std::string>& args) {
  RunArguments run;
  std::vector<std::string> positional;
  std::set<const OptionSpec*> given;
  bool options_ended = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    if (options_ended || arg.size() < 2 || arg[0] != '-') {
      positional.push_back(arg);
      continue;
    }
    if (arg == "--") {
      options_ended = true;
      continue;
    }
    // Split "--name=value" and "-kVALUE"; otherwise the value is the next argument.
    std::string typed = arg;
    std::optional<std::string> attached;
    if (arg.rfind("--", 0) == 0) {
      const std::size_t equals = arg.find('=');
      if (equals != std::string::npos) {
        typed = arg.substr(0, equals);
        attached = arg.substr(equals + 1);
      }
    } else if (arg.size() > 2) {
      typed = arg.substr(0, 2);
      attached = arg.substr(2);
    }
    const OptionSpec* spec = findOption(typed, command);
    if (!spec) {
      // Name what was typed ("-foo", not "-f") unless it was "--name=value".
      const std::string shown = attached && typed.size() > 2 ? typed : arg;
      throw UsageError("unknown option " + inQuotes(shown) + " for 'hfvis " + name + "'");
    }
    // ("-o=x.exr" wrote a file named "=x.exr": a short option takes its value attached or next)
    if (attached && typed.size() == 2 && attached->front() == '=')
      throw UsageError(inQuotes(arg) + ": a short option takes its value as " + typed + "VALUE or " + typed +
                       " VALUE, without '='");
    // One rule for every option: once, but for those that add one more of a list (a second -o
    // or -k silently replacing the first would hide a typo).
    if (!spec->repeats && !given.insert(spec).second)
      throw UsageError(typed + " given twice (only --observer and the receivers' --at may repeat)");
    std::string value;
    if (!spec->value) {
      if (attached) throw UsageError(typed + " takes no value, got " + inQuotes(arg));
    } else if (attached) {
      value = *attached;
    } else {
      // A following option ("-o --quiet") is a forgotten value, not a file name; a
      // negative number ("--azimuth-offset -45") is a value.
      if (i + 1 >= args.size() || args[i + 1].rfind("--", 0) == 0) {
        throw UsageError(typed + ": missing value");
      }
      value = args[++i];
    }
    if (!(command.groups & spec->group)) throwNotTaken(typed, name);
    spec->bind(typed, value, run);
  }
  if (positional.size() > 1) {
    throw UsageError("unexpected argument " + inQuotes(positional[1]) + " ('hfvis " + name +
                     "' reads one input file)");
  }
  if (!positional.empty()) run.input = positional[0];
  validateRun(command, name, run);
  return run;
}

// "hfvis sunpos --lat LAT --lon LON --at TIME [--apparent]": each once, all but --apparent required.
SunArguments parseSunArguments(const std::string& name, const std::vector<std::string>& args) {
  SunArguments sun;
  bool lat = false, lon = false, at = false;
  for (std::size_t i = 0; i < args.size(); ++i) {
    const std::string& arg = args[i];
    auto value = [&]() -> const std::string& {
      if (i + 1 >= args.size()) throw UsageError(arg + " needs a value");
      return args[++i];
    };
    auto once = [&](bool& seen) {
      if (seen) throw UsageError(arg + " given twice");
      seen = true;
    };
    if (arg == "--lat") {
      once(lat);
      sun.latitude_deg = parseNumber(arg, value());
      if (sun.latitude_deg < -90.0 || sun.latitude_deg > 90.0)
        throw UsageError("--lat: expected a latitude in -90 .. 90 degrees, got " + inQuotes(args[i]));
    } else if (arg == "--lon") {
      once(lon);
      sun.longitude_deg = parseNumber(arg, value());
      if (sun.longitude_deg < -180.0 || sun.longitude_deg > 360.0)
        throw UsageError("--lon: expected a longitude in -180 .. 360 degrees, got " + inQuotes(args[i]));
    } else if (arg == "--at") {
      once(at);
      try {
        sun.utc_seconds = parseUtcTime(value());
      } catch (const InvalidArgument& error) {
        throw UsageError(std::string("--at: ") + error.what());
      }
    } else if (arg == "--apparent") {
      if (sun.apparent) throw UsageError("--apparent given twice");
      sun.apparent = true;
    } else {
      throw UsageError("'hfvis " + name + "' takes --lat, --lon, --at and --apparent, not " + inQuotes(arg));
    }
  }
  if (!lat || !lon || !at) throw UsageError("'hfvis " + name + "' needs --lat LAT --lon LON --at TIME");
  try {  // the algorithm's range of years
    sunPosition(sun.utc_seconds, sun.latitude_deg, sun.longitude_deg);
  } catch (const InvalidArgument& error) {
    throw UsageError(std::string("--at: ") + error.what());
  }
  return sun;
}

}  // namespace

CommandLine parseCommandLine(const std::vector<std::string>& args) {
  CommandLine line;
  if (args.empty()) throw UsageError("no command given (" + commandList() + ")");
  const std::string& first = args[0];
  if (isHelpFlag(first)) return line;  // Command::Help, no topic
  if (!first.empty() && first[0] == '-') {
    throw UsageError("unknown option " + inQuotes(first) + " (give a command first: " + commandList() + ")");
  }
  const std::vector<std::string> rest(args.begin() + 1, args.end());
  if (first == "help") {  // "hfvis help [COMMAND]"
    if (rest.size() > 1) throw UsageError("unexpected argument " + inQuotes(rest[1]) + " after 'help'");
    if (!rest.empty() && rest[0] != "help") {
      const CommandSpec* topic = findCommand(rest[0]);
      if (!topic)
        throw UsageError("unknown command " + inQuotes(rest[0]) + " (expected " + commandList() + ")");
      line.help_topic = topic->id;
    }
    return line;
  }
  const CommandSpec* command = findCommand(first);
  if (!command) throw UsageError("unknown command " + inQuotes(first) + " (expected " + commandList() + ")");

  // "--help" anywhere before "--" wins over everything else on the line.
  for (const std::string& arg : rest) {
    if (arg == "--") break;
    if (isHelpFlag(arg)) {
      line.help_topic = command->id;
      return line;
    }
  }

  line.command = command->id;
  line.name = first;
  if (command->id == Command::Devices) {
    if (!rest.empty()) throw UsageError("'hfvis " + first + "' takes no arguments, got " + inQuotes(rest[0]));
    return line;
  }
  if (command->id == Command::SunPosition) {
    line.sun = parseSunArguments(first, rest);
    return line;
  }
  line.run = parseRunArguments(*command, first, rest);
  return line;
}

HorizonOptions horizonOptions(const RunArguments& run) {
  HorizonOptions options;
  setSweepOptions(run, options);
  options.method = run.method;
  // (the largest tolerance in degrees may round to a hair above 0.1 radian)
  options.azimuth_tolerance = std::min(0.1, run.azimuth_tolerance_deg * (kPi / 180.0));
  // (horizon's --max-error is in degrees; it takes no other)
  options.max_error = run.max_error > 0.0 ? run.max_error : run.horizon_max_error_deg * (kPi / 180.0);
  options.error_tile = run.error_tile;
  return options;
}

HorizonOutputs horizonOutputs(Command command, const RunArguments& run) {
  HorizonOutputs outputs;
  switch (command) {
    case Command::Horizon:
      outputs.horizon_angles = true;
      outputs.horizon_distances = !run.distance_output.empty();
      outputs.error_estimate = !run.error_output.empty();
      break;
    case Command::SkyViewFactor:
      outputs.sky_view_factor = true;
      outputs.error_estimate = !run.error_output.empty();
      break;
    case Command::AmbientOcclusion:
      outputs.ambient_occlusion = true;
      outputs.error_estimate = !run.error_output.empty();
      break;
    default:
      break;
  }
  return outputs;
}

IntervisibilityOptions intervisibilityOptions(const RunArguments& run) {
  IntervisibilityOptions options;
  setSweepOptions(run, options);
  options.method = run.visibility_method;
  options.tree = run.hull_tree;
  options.max_error = run.max_error;
  return options;
}

IntervisibilityOutputs intervisibilityOutputs(const RunArguments& run) {
  IntervisibilityOutputs outputs;
  outputs.visible_count = true;
  outputs.visible_area = true;
  outputs.statistics = run.statistics;
  outputs.error_estimate = !run.error_output.empty();
  return outputs;
}

SweepOptions horizonListOptions(const RunArguments& run) {
  SweepOptions options;
  setSweepOptions(run, options);
  return options;
}

InsolationOptions insolationOptions(const RunArguments& run) {
  InsolationOptions options;
  options.latitude_deg = run.latitude.value_or(0.0);
  options.longitude_deg = run.longitude.value_or(0.0);
  options.from_utc = run.from_time.value_or(0.0);
  options.to_utc = run.to_time.value_or(0.0);
  options.step_minutes = run.step_minutes;
  options.size_deg = run.sun_size_deg;
  options.azimuth_bucket_deg = run.azimuth_bucket_deg;
  options.apparent = run.apparent;
  return options;
}

ViewshedOptions viewshedOptions(const RunArguments& run) {
  ViewshedOptions options;
  options.absolute = run.absolute;
  options.target_height = run.target_height;
  options.max_distance = run.max_distance;
  options.curvature = run.curvature ? earthCurvature(run.refraction) : 0.0;
  if (run.field_of_view) std::tie(options.azimuth_from_deg, options.azimuth_to_deg) = *run.field_of_view;
  if (run.elevation_range) std::tie(options.elevation_min_deg, options.elevation_max_deg) = *run.elevation_range;
  options.memory_budget_bytes = run.memory_budget_bytes;
  return options;
}

RegionVisibilityOptions regionVisibilityOptions(const RunArguments& run) {
  RegionVisibilityOptions options;
  options.method = run.region_method;
  options.target_height = run.target_height;
  options.max_distance = run.max_distance;
  options.curvature = run.curvature ? earthCurvature(run.refraction) : 0.0;
  options.seed = run.seed;
  options.decorrelate = run.decorrelate;
  return options;
}

BounceOptions bounceOptions(const RunArguments& run) {
  BounceOptions options;
  setSweepOptions(run, options);
  options.tree = run.hull_tree;
  return options;
}

HeightFieldReadOptions readOptions(const RunArguments& run) {
  HeightFieldReadOptions options;
  options.channel = run.channel;
  options.cell_size_x = run.cell_size_x;
  options.cell_size_y = run.cell_size_y;
  options.z_scale = run.z_scale;
  return options;
}

}  // namespace hfvis::cli
