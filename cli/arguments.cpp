// cli/arguments.cpp: parsing and validating the hfvis command line.
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

#include "hfvis/errors.hpp"
#include "hfvis/insolation.hpp"
#include "hfvis/sun_shading.hpp"
#include "hfvis/sun.hpp"
#include "core/message_numbers.hpp"

namespace hfvis::cli {
namespace {

constexpr double kPi = 3.14159265358979323846;
constexpr const char* kCommandList =
    "horizon, svf, ao, viewcount, horizons, bounce, shade, insolation, viewshed, sunpos or devices";

// One option of the compute commands (horizon, svf, ao, viewcount, horizons, bounce).
enum class Option {
  Output,
  Directions,
  Method,
  AzimuthOffset,
  SamplesPerUnit,
  CellSize,
  ZScale,
  Channel,
  Device,
  MemoryBudget,
  Preview,
  DistanceOutput,
  AzimuthTolerance,
  Statistics,
  HullTree,
  At,
  Radiance,
  Quiet,
  Curvature,
  Refraction,
  MaxDistance,
  Nodata,
  Sun,
  SunSize,
  Latitude,
  Longitude,
  Environment,
  EnvironmentRotation,
  EnvironmentRows,
  Albedo,
  SunIrradiance,
  From,
  To,
  Step,
  AzimuthBucket,
  Apparent,
  Observer,
  Observers,
  ObserverHeight,
  TargetHeight,
  Absolute,
  FieldOfView,
  ElevationRange,
  Angle,
  NeededHeight,
  CullLevel,
};

struct OptionSpec {
  Option option;
  const char* long_name;   // "--output"
  const char* short_name;  // "-o", or nullptr
  bool takes_value;
};

constexpr OptionSpec kOptions[] = {
    {Option::Output, "--output", "-o", true},
    {Option::Directions, "--directions", "-k", true},
    {Option::Method, "--method", nullptr, true},
    {Option::AzimuthOffset, "--azimuth-offset", nullptr, true},
    {Option::SamplesPerUnit, "--samples-per-unit", nullptr, true},
    {Option::CellSize, "--cell-size", nullptr, true},
    {Option::ZScale, "--z-scale", nullptr, true},
    {Option::Channel, "--channel", nullptr, true},
    {Option::Device, "--device", nullptr, true},
    {Option::MemoryBudget, "--memory-budget", nullptr, true},
    {Option::Preview, "--preview", nullptr, true},
    {Option::DistanceOutput, "--distance-out", nullptr, true},
    {Option::AzimuthTolerance, "--azimuth-tolerance", nullptr, true},
    {Option::Statistics, "--stats", nullptr, false},
    {Option::HullTree, "--hull-tree", nullptr, true},
    {Option::At, "--at", nullptr, true},
    {Option::Radiance, "--radiance", nullptr, true},
    {Option::Quiet, "--quiet", "-q", false},
    {Option::Curvature, "--curvature", nullptr, false},
    {Option::Refraction, "--refraction", nullptr, true},
    {Option::MaxDistance, "--max-distance", nullptr, true},
    {Option::Nodata, "--nodata", nullptr, true},
    {Option::Sun, "--sun", nullptr, true},
    {Option::SunSize, "--sun-size", nullptr, true},
    {Option::Latitude, "--lat", nullptr, true},
    {Option::Longitude, "--lon", nullptr, true},
    {Option::Environment, "--env", nullptr, true},
    {Option::EnvironmentRotation, "--env-rotate", nullptr, true},
    {Option::EnvironmentRows, "--env-rows", nullptr, true},
    {Option::Albedo, "--albedo", nullptr, true},
    {Option::SunIrradiance, "--sun-irradiance", nullptr, true},
    {Option::From, "--from", nullptr, true},
    {Option::To, "--to", nullptr, true},
    {Option::Step, "--step", nullptr, true},
    {Option::AzimuthBucket, "--azimuth-bucket", nullptr, true},
    {Option::Apparent, "--apparent", nullptr, false},
    {Option::Observer, "--observer", nullptr, true},
    {Option::Observers, "--observers", nullptr, true},
    {Option::ObserverHeight, "--observer-height", nullptr, true},
    {Option::TargetHeight, "--target-height", nullptr, true},
    {Option::Absolute, "--absolute", nullptr, false},
    {Option::FieldOfView, "--fov", nullptr, true},
    {Option::ElevationRange, "--elevation-range", nullptr, true},
    {Option::Angle, "--angle", nullptr, false},
    {Option::NeededHeight, "--needed-height", nullptr, false},
    {Option::CullLevel, "--cull-level", nullptr, true},
};

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

std::optional<Command> findCommand(const std::string& name) {
  if (name == "horizon") return Command::Horizon;
  if (name == "svf") return Command::SkyViewFactor;
  if (name == "ao") return Command::AmbientOcclusion;
  if (name == "viewcount") return Command::ViewCount;
  if (name == "horizons") return Command::HorizonLists;
  if (name == "bounce") return Command::Bounce;
  if (name == "devices") return Command::Devices;
  if (name == "sunpos") return Command::SunPosition;
  if (name == "shade") return Command::Shade;
  if (name == "insolation") return Command::Insolation;
  if (name == "viewshed") return Command::Viewshed;
  if (name == "help") return Command::Help;
  return std::nullopt;
}

const OptionSpec* findOption(const std::string& name) {
  for (const OptionSpec& spec : kOptions) {
    if (name == spec.long_name || (spec.short_name && name == spec.short_name)) return &spec;
  }
  return nullptr;
}

std::string inQuotes(const std::string& text) { return "'" + text + "'"; }

// A value as a message shows it: at most 40 characters of what was typed.
std::string shortened(const std::string& text) {
  return text.size() > 40 ? text.substr(0, 40) + "... (" + std::to_string(text.size()) + " characters)"
                          : text;
}


// Strict number parsing: the whole text must be a finite number.
double parseNumber(const std::string& option, const std::string& text) {
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(begin, &end);
  if (text.empty() || end != begin + text.size() || errno == ERANGE || !std::isfinite(value)) {
    throw UsageError(option + ": expected a number, got " + inQuotes(shortened(text)));
  }
  return value;
}

// A nodata value for float32 bands: "nan" (any case), or a finite number float32 holds.
float parseNodata(const std::string& option, const std::string& text) {
  std::string lower = text;
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (lower == "nan") return std::numeric_limits<float>::quiet_NaN();
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  const double value = std::strtod(begin, &end);
  if (text.empty() || end != begin + text.size() || std::isnan(value)) {
    throw UsageError(option + ": expected a number or nan, got " + inQuotes(text));
  }
  if (!std::isfinite(value) || errno == ERANGE || std::fabs(value) > std::numeric_limits<float>::max()) {
    throw UsageError(option +
                     ": the nodata value must be nan or a finite number within float32's range, got " +
                     inQuotes(text));
  }
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
constexpr double kLeastCellSize = 1e-6, kMostCellSize = 1e9, kMostLength = 1e12;
// The sweep's largest azimuth tolerance, 0.1 radian (computeHorizons), in degrees as the help
// gives it (rounded up: the conversion to radians clamps it to 0.1).
constexpr double kMostAzimuthTolerance = 5.72958;
constexpr const char* kFloatRange = "what the kernels' single precision holds";

int parseDirectionCount(const std::string& option, const std::string& text) {
  const char* begin = text.c_str();
  char* end = nullptr;
  errno = 0;
  const long value = std::strtol(begin, &end, 10);
  if (text.empty() || end != begin + text.size() || errno == ERANGE) {
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
    const char* begin = part.c_str();
    char* end = nullptr;
    errno = 0;
    const long value = std::strtol(begin, &end, 10);
    if (part.empty() || end != begin + part.size() || errno == ERANGE ||
        value > std::numeric_limits<int>::max() || value < std::numeric_limits<int>::min()) {
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

bool hasExtension(const std::string& path, const char* wanted) {
  std::string extension = std::filesystem::path(path).extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return extension == wanted;
}

// Which commands take an option; nullptr = every compute command.
const char* onlyFor(Option option) {
  switch (option) {
    case Option::DistanceOutput:
    case Option::AzimuthTolerance:
      return "horizon";
    case Option::Statistics:
      return "viewcount";
    case Option::Sun:
    case Option::Environment:
    case Option::EnvironmentRotation:
    case Option::EnvironmentRows:
    case Option::Albedo:
    case Option::SunIrradiance:
      return "shade";
    case Option::From:
    case Option::To:
    case Option::Step:
    case Option::AzimuthBucket:
    case Option::Apparent:
      return "insolation";
    case Option::Radiance:
      return "bounce";
    case Option::Observer:
    case Option::Observers:
    case Option::ObserverHeight:
    case Option::TargetHeight:
    case Option::Absolute:
    case Option::FieldOfView:
    case Option::ElevationRange:
    case Option::Angle:
    case Option::NeededHeight:
    case Option::CullLevel:
      return "viewshed";
    default:
      return nullptr;
  }
}

// Options that make no sense for a command (the horizon lists are computed on the host,
// one ray per receiver and direction, and written as text).
bool notFor(Option option, Command command) {
  // --at: receivers for the horizon lists, the sun's time for shade.
  if (option == Option::At) return command != Command::HorizonLists && command != Command::Shade;
  // The sun's place and size: shade and insolation.
  if (option == Option::Latitude || option == Option::Longitude || option == Option::SunSize)
    return command != Command::Shade && command != Command::Insolation;
  // A viewshed marches sight lines: no directions, sampling density or hull tree.
  if (command == Command::Viewshed)
    return option == Option::Directions || option == Option::AzimuthOffset || option == Option::SamplesPerUnit ||
           option == Option::HullTree;
  // insolation sweeps the sun's azimuths alone, by the sweep; shade takes directions for --env.
  if (command == Command::Insolation)
    return option == Option::Directions || option == Option::Method || option == Option::AzimuthOffset ||
           option == Option::MaxDistance;
  if (command == Command::HorizonLists) {
    return option == Option::Method || option == Option::Device || option == Option::MemoryBudget ||
           option == Option::Preview || option == Option::MaxDistance || option == Option::Nodata;
  }
  if (option == Option::HullTree) return command != Command::ViewCount && command != Command::Bounce;
  if (option == Option::MaxDistance) return command == Command::Bounce;
  // Earth curvature: not for the bounce (a rendering operation) so far.
  if (option == Option::Curvature || option == Option::Refraction) return command == Command::Bounce;
  return command == Command::Bounce && option == Option::Method;
}

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

bool hasPngExtension(const std::string& path) { return hasExtension(path, ".png"); }

void requireNonEmpty(const std::string& option, const std::string& value) {
  if (value.empty()) throw UsageError(option + ": the value must not be empty");
}

void applyOption(const OptionSpec& spec, const std::string& typed, const std::string& value, Command command,
                 RunArguments& run) {
  if (const char* only = onlyFor(spec.option); only && commandName(command) != std::string(only)) {
    throw UsageError(typed + " is only available with 'hfvis " + only + "'");
  }
  if (notFor(spec.option, command)) {
    throw UsageError(typed + " is not available with 'hfvis " + commandName(command) + "'");
  }
  switch (spec.option) {
    case Option::Output:
      requireNonEmpty(typed, value);
      run.output = value;
      break;
    case Option::Directions:
      run.directions = parseDirectionCount(typed, value);
      run.sweep_options_given = true;
      break;
    case Option::Method:
      run.sweep_options_given = true;
      if (command == Command::ViewCount) {
        run.visibility_method = parseVisibilityMethod(typed, value);
      } else if (command == Command::Viewshed) {
        if (value != "exact" && value != "culled")
          throw UsageError(typed + ": expected 'exact' or 'culled', got " + inQuotes(value));
        run.culled = value == "culled";
      } else {
        run.method = parseMethod(typed, value);
      }
      break;
    case Option::AzimuthOffset:
      run.azimuth_offset_deg =
          parseBounded(typed, value, -360.0, 360.0, "every direction has an offset in it");
      run.sweep_options_given = true;
      break;
    case Option::SamplesPerUnit:
      run.samples_per_unit = parsePositive(typed, value);
      break;
    case Option::CellSize:
      parseCellSize(typed, value, run);
      break;
    case Option::ZScale:
      run.z_scale = parsePositive(typed, value);
      run.z_scale = parseBounded(typed, value, 1e-12, 1e12, kFloatRange);
      break;
    case Option::Channel:
      requireNonEmpty(typed, value);
      run.channel = value;
      break;
    case Option::Device:
      requireNonEmpty(typed, value);
      run.device = value;
      break;
    case Option::MemoryBudget:
      run.memory_budget_bytes = parseMemoryBudget(typed, value);
      break;
    case Option::Preview:
      requireNonEmpty(typed, value);
      if (!hasPngExtension(value)) {
        throw UsageError(typed + ": the preview is a PNG file; its name must end in .png, got " +
                         inQuotes(value));
      }
      run.preview = value;
      break;
    case Option::DistanceOutput:
      requireNonEmpty(typed, value);
      run.distance_output = value;
      break;
    case Option::AzimuthTolerance:
      run.azimuth_tolerance_deg = parsePositive(typed, value);
      run.azimuth_tolerance_deg = parseBounded(typed, value, 0.0, kMostAzimuthTolerance,
                                               "the azimuth tolerance is 0.1 radian at most");
      break;
    case Option::Statistics:
      run.statistics = true;
      break;
    case Option::HullTree:
      if (const auto tuning = hullTreeTuningNamed(value)) {
        run.hull_tree = *tuning;
        run.hull_tree_name = value;
      } else {
        throw UsageError(typed + ": expected plain, deferred, default or zone, got " + inQuotes(value));
      }
      break;
    case Option::At:
      if (command == Command::Shade) {
        try {
          run.sun_time = parseUtcTime(value);
        } catch (const InvalidArgument& error) {
          throw UsageError(typed + ": " + error.what());
        }
      } else {
        run.receivers.push_back(parseReceiver(typed, value));
      }
      break;
    case Option::Sun: {
      const std::size_t comma = value.find(',');
      if (comma == std::string::npos)
        throw UsageError(typed + ": expected AZ,EL (compass azimuth and elevation, degrees), got " + inQuotes(value));
      const double azimuth =
          parseBounded(typed, value.substr(0, comma), -360.0, 360.0, "every azimuth has an equal one in it");
      const double elevation = parseNumber(typed, value.substr(comma + 1));
      if (elevation < -90.0 || elevation > 90.0)
        throw UsageError(typed + ": the elevation must be in -90 .. 90 degrees, got " + inQuotes(value));
      run.sun = std::make_pair(azimuth, elevation);
      break;
    }
    case Option::SunSize:
      run.sun_size_deg = parseNumber(typed, value);
      if (!(run.sun_size_deg >= 0.0 && run.sun_size_deg <= 10.0))
        throw UsageError(typed +
                         ": the sun's diameter must be in 0 (a point: hard shadows) .. 10 degrees, got " +
                         inQuotes(value));
      break;
    case Option::Latitude:
      run.latitude = parseNumber(typed, value);
      if (*run.latitude < -90.0 || *run.latitude > 90.0)
        throw UsageError(typed + ": expected a latitude in -90 .. 90 degrees, got " + inQuotes(value));
      break;
    case Option::Longitude:
      run.longitude = parseNumber(typed, value);
      if (*run.longitude < -180.0 || *run.longitude > 360.0)
        throw UsageError(typed + ": expected a longitude in -180 .. 360 degrees, got " + inQuotes(value));
      break;
    case Option::Radiance:
      requireNonEmpty(typed, value);
      run.radiance = value;
      break;
    case Option::Environment:
      requireNonEmpty(typed, value);
      run.environment = value;
      break;
    case Option::EnvironmentRotation:
      run.environment_rotation_deg =
          parseBounded(typed, value, -360.0, 360.0, "every rotation has an angle in it");
      break;
    case Option::EnvironmentRows: {
      const double rows = parsePositive(typed, value);
      if (rows != std::floor(rows) || rows > 65536)
        throw UsageError(typed + ": expected a whole number of bands in 1 .. 65536, got " + inQuotes(value));
      run.environment_rows = static_cast<int>(rows);
      break;
    }
    case Option::Albedo:
      requireNonEmpty(typed, value);
      run.albedo = value;
      break;
    case Option::SunIrradiance:
      run.sun_irradiance = parsePositive(typed, value);
      run.sun_irradiance = parseBounded(typed, value, 0.0, 1e12, kFloatRange);
      break;
    case Option::From:
    case Option::To: {
      std::optional<double>& time = spec.option == Option::From ? run.from_time : run.to_time;
      try {
        time = parseUtcTime(value);
      } catch (const InvalidArgument& error) {
        throw UsageError(typed + ": " + error.what());
      }
      break;
    }
    case Option::Step:
      run.step_minutes = parsePositive(typed, value);
      if (run.step_minutes > 1440.0) throw UsageError(typed + ": at most 1440 minutes, got " + inQuotes(value));
      break;
    case Option::AzimuthBucket:
      run.azimuth_bucket_deg = parsePositive(typed, value);
      if (run.azimuth_bucket_deg > 10.0) throw UsageError(typed + ": at most 10 degrees, got " + inQuotes(value));
      break;
    case Option::Apparent:
      run.apparent = true;
      break;
    case Option::Quiet:
      run.quiet = true;
      break;
    case Option::Curvature:
      run.curvature = true;
      break;
    case Option::Refraction:
      run.refraction = parseNumber(typed, value);
      if (!(run.refraction >= -1.0 && run.refraction <= 1.0))
        throw UsageError(typed + ": the refraction coefficient must be in -1 .. 1, got " + inQuotes(value));
      run.curvature = true;  // refraction bends rays over the curved Earth
      break;
    case Option::MaxDistance:
      run.max_distance = parsePositive(typed, value);
      run.max_distance = parseBounded(typed, value, 0.0, kMostLength, kFloatRange);
      break;
    case Option::Nodata:
      run.nodata = parseNodata(typed, value);
      break;
    case Option::Observer:
      run.observers.push_back(parseReceiver(typed, value));
      break;
    case Option::Observers:
      requireNonEmpty(typed, value);
      run.observers_file = value;
      break;
    case Option::ObserverHeight:
      run.observer_height = parseBounded(typed, value, -kMostLength, kMostLength, kFloatRange);
      break;
    case Option::TargetHeight:
      run.target_height = parseNumber(typed, value);
      if (run.target_height < 0.0) throw UsageError(typed + ": must be >= 0, got " + inQuotes(value));
      run.target_height = parseBounded(typed, value, 0.0, kMostLength, kFloatRange);
      break;
    case Option::Absolute:
      run.absolute = true;
      break;
    case Option::FieldOfView:
    case Option::ElevationRange: {
      const bool fov = spec.option == Option::FieldOfView;
      const std::size_t comma = value.find(',');
      if (comma == std::string::npos)
        throw UsageError(typed + (fov ? ": expected FROM,TO (compass degrees, clockwise from FROM), got "
                                      : ": expected LO,HI (elevation degrees), got ") +
                         inQuotes(value));
      const double a = parseNumber(typed, value.substr(0, comma)), b = parseNumber(typed, value.substr(comma + 1));
      if (fov && !(a >= 0.0 && a <= 360.0 && b >= 0.0 && b <= 360.0))
        throw UsageError(typed + ": compass azimuths are in 0 .. 360 degrees, got " + inQuotes(value));
      if (!fov && !(a >= -90.0 && b <= 90.0 && a <= b))
        throw UsageError(typed + ": expected -90 <= LO <= HI <= 90 degrees, got " + inQuotes(value));
      (fov ? run.field_of_view : run.elevation_range) = std::make_pair(a, b);
      break;
    }
    case Option::Angle:
      run.with_angle = true;
      break;
    case Option::NeededHeight:
      run.with_needed_height = true;
      break;
    case Option::CullLevel: {
      const double k = parseNumber(typed, value);
      if (!(k >= 1.0 && k <= 12.0 && k == std::floor(k)))
        throw UsageError(typed + ": expected a whole number 1 .. 12 (nodes of 2^K x 2^K points), got " + inQuotes(value));
      run.cull_level = static_cast<int>(k);
      run.cull_level_given = true;
      break;
    }
  }
}

bool samePath(const std::string& a, const std::string& b) {
  return std::filesystem::path(a).lexically_normal() == std::filesystem::path(b).lexically_normal();
}

// Checks that involve more than one option, and the library's own argument checks.
void validateRun(Command command, const RunArguments& run) {
  const std::string name = commandName(command);
  const std::string out = command == Command::HorizonLists ? "OUT.json|OUT.csv" : "OUT.exr";
  if (run.input.empty())
    throw UsageError("missing the input height field (hfvis " + name + " IN -o " + out + ")");
  if (run.output.empty())
    throw UsageError("missing -o " + out + " (the output file of 'hfvis " + name + "')");
  if (command == Command::HorizonLists) {
    if (!hasExtension(run.output, ".json") && !hasExtension(run.output, ".csv")) {
      throw UsageError(
          "-o: the horizon lists are written as JSON or CSV; the name must end in .json or .csv, got " +
          inQuotes(run.output));
    }
    if (run.receivers.empty())
      throw UsageError("missing --at COL,ROW (the receivers whose horizons to list)");
  }
  if (command == Command::Shade) {
    const bool placed = run.sun_time || run.latitude || run.longitude;
    if (run.sun && placed)
      throw UsageError("--sun AZ,EL or --at TIME --lat LAT --lon LON: give the sun one way, not both");
    const bool sun = run.sun || (run.sun_time && run.latitude && run.longitude);
    if (!sun && (placed || run.environment.empty()))
      throw UsageError(
          "missing the light: --env ENV.exr and / or the sun, --sun AZ,EL (compass azimuth, elevation) or --at TIME "
          "--lat LAT --lon LON");
    if (run.environment.empty() && run.sweep_options_given)
      throw UsageError("-k, --method and --azimuth-offset need --env (the sun alone sweeps its own azimuth)");
    if (run.environment.empty() && (run.environment_rotation_deg != 0.0 || run.environment_rows != 0))
      throw UsageError("--env-rotate and --env-rows need --env ENV.exr");
    if (!sun && run.sun_irradiance != 1.0) throw UsageError("--sun-irradiance needs the sun");
    if (run.albedo.empty() && run.sun_irradiance != 1.0)
      throw UsageError(
          "--sun-irradiance needs --albedo (it scales the sun's light in the radiance; 'direct' is "
          "for a normal irradiance of 1)");
    if (!sun && run.sun_size_deg != 0.53) throw UsageError("--sun-size needs the sun");
    if (!run.environment.empty() && samePath(run.output, run.environment))
      throw UsageError("--env must differ from -o, both are " + inQuotes(run.output));
    if (!run.albedo.empty() && samePath(run.output, run.albedo))
      throw UsageError("--albedo must differ from -o, both are " + inQuotes(run.output));
    if (run.sun_time) {
      try {  // the solar position's range of years
        sunPosition(*run.sun_time, *run.latitude, *run.longitude);
      } catch (const InvalidArgument& error) {
        throw UsageError(std::string("--at: ") + error.what());
      }
    }
  }
  if (command == Command::Insolation) {
    if (!run.latitude || !run.longitude || !run.from_time || !run.to_time)
      throw UsageError("missing the place or the span: --lat LAT --lon LON --from TIME --to TIME");
    if (!(*run.from_time < *run.to_time)) throw UsageError("--from must come before --to");
    try {
      validate(insolationOptions(run));
    } catch (const InvalidArgument& error) {
      throw UsageError(error.what());
    }
  }
  if (command == Command::Viewshed) {
    if (!run.absolute && run.observer_height < 0.0)
      throw UsageError("--observer-height: an eye below the surface sees nothing; give a height >= 0 (or --absolute)");
    if (run.observers.empty() && run.observers_file.empty())
      throw UsageError("missing --observer COL,ROW or --observers FILE.csv (who looks)");
    if ((run.with_angle || run.with_needed_height) && (run.observers.size() > 1 || !run.observers_file.empty()))
      throw UsageError(std::string(run.with_angle ? "--angle" : "--needed-height") +
                       " is for one observer (several give a count)");
    if (run.cull_level_given && !run.culled) throw UsageError("--cull-level is for --method culled");
    if (!run.observers_file.empty() && samePath(run.output, run.observers_file))
      throw UsageError("--observers must differ from -o, both are " + inQuotes(run.output));
    try {
      validate(viewshedOptions(run));
    } catch (const InvalidArgument& error) {
      throw UsageError(error.what());
    }
  }
  if (command == Command::Bounce) {
    if (run.radiance.empty()) {
      throw UsageError("missing --radiance RAD.exr (the exit radiance to bounce, same size as the input)");
    }
    if (samePath(run.output, run.radiance)) {
      throw UsageError("--radiance must differ from -o, both are " + inQuotes(run.output));
    }
    if (!run.preview.empty() && samePath(run.preview, run.radiance)) {
      throw UsageError("--preview must differ from --radiance, both are " + inQuotes(run.preview));
    }
  }
  if (!run.distance_output.empty() && samePath(run.output, run.distance_output)) {
    throw UsageError("--distance-out must differ from -o, both are " + inQuotes(run.output));
  }
  if (!run.preview.empty() && samePath(run.output, run.preview)) {
    throw UsageError("--preview must differ from -o, both are " + inQuotes(run.output));
  }
  if (!run.preview.empty() && !run.distance_output.empty() && samePath(run.preview, run.distance_output)) {
    throw UsageError("--preview must differ from --distance-out, both are " + inQuotes(run.preview));
  }
  // Only a GeoTIFF declares a nodata value; other outputs keep NaN, so the option would do nothing.
  if (run.nodata && !writesGeoTiff(run.output) &&
      (run.distance_output.empty() || !writesGeoTiff(run.distance_output))) {
    throw UsageError(
        "--nodata: only GeoTIFF outputs (.tif, .tiff) hold a nodata value, and no output is one; "
        "other outputs keep NaN");
  }
  // A nodata value the outputs can hold as data would make those cells nodata for every reader
  // (a viewshed's hidden 0 or visible 1): it must lie below every value the command writes.
  if (run.nodata && !std::isnan(*run.nodata)) {
    const double lowest = command == Command::Horizon                      ? -kPi / 2.0
                          : command == Command::Viewshed && run.with_angle ? -90.0
                                                                           : 0.0;
    if (*run.nodata >= lowest)
      throw UsageError("--nodata " + detail::shortNumber(*run.nodata) + ": 'hfvis " + name +
                       "' writes data values from " + detail::shortNumber(lowest) +
                       " up, so a reader could not tell those cells from nodata; give a value below " +
                       detail::shortNumber(lowest) + " (such as -9999) or nan");
  }
  if (command == Command::ViewCount && !run.hull_tree_name.empty() &&
      run.visibility_method != IntervisibilityMethod::HullTree) {
    throw UsageError("--hull-tree needs --method tree (the naive method builds no tree)");
  }
  try {
    switch (command) {
      case Command::ViewCount:
        validate(intervisibilityOptions(run), intervisibilityOutputs(run));
        break;
      case Command::HorizonLists:
        validate(horizonListOptions(run));
        break;
      case Command::Bounce:
        validate(bounceOptions(run));
        break;
      case Command::Shade:
      case Command::Insolation:
        validate(static_cast<const SweepOptions&>(horizonOptions(run)));
        break;
      case Command::Viewshed:
        break;  // above
      default:
        validate(horizonOptions(run), horizonOutputs(command, run));
        break;
    }
  } catch (const InvalidArgument& error) {
    // "statistics ... only for the hull-tree method" reads better in the CLI's words.
    if (command == Command::ViewCount && run.statistics &&
        run.visibility_method != IntervisibilityMethod::HullTree) {
      throw UsageError(
          "--stats needs --method tree (the naive method has no horizons or iterations to count)");
    }
    throw UsageError(error.what());
  }
}

RunArguments parseRunArguments(Command command, const std::vector<std::string>& args) {
  RunArguments run;
  std::vector<std::string> positional;
  std::set<Option> given;
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
    const OptionSpec* spec = findOption(typed);
    if (!spec) {
      // Name what was typed ("-foo", not "-f") unless it was "--name=value".
      const std::string shown = attached && typed.size() > 2 ? typed : arg;
      throw UsageError("unknown option " + inQuotes(shown) + " for 'hfvis " + commandName(command) + "'");
    }
    // One rule for every option: once, but for those that add one more of a list (a second -o
    // or -k silently replacing the first would hide a typo).
    const bool adds =
        spec->option == Option::Observer || (spec->option == Option::At && command == Command::HorizonLists);
    if (!adds && !given.insert(spec->option).second)
      throw UsageError(typed + " given twice (only --observer and the receivers' --at may repeat)");
    if (!spec->takes_value) {
      if (attached) throw UsageError(typed + " takes no value, got " + inQuotes(arg));
      applyOption(*spec, typed, "", command, run);
      continue;
    }
    std::string value;
    if (attached) {
      value = *attached;
    } else {
      // A following option ("-o --quiet") is a forgotten value, not a file name; a
      // negative number ("--azimuth-offset -45") is a value.
      if (i + 1 >= args.size() || args[i + 1].rfind("--", 0) == 0) {
        throw UsageError(typed + ": missing value");
      }
      value = args[++i];
    }
    applyOption(*spec, typed, value, command, run);
  }
  if (positional.size() > 1) {
    throw UsageError("unexpected argument " + inQuotes(positional[1]) + " ('hfvis " + commandName(command) +
                     "' reads one input file)");
  }
  if (!positional.empty()) run.input = positional[0];
  validateRun(command, run);
  return run;
}

}  // namespace

const char* commandName(Command command) {
  switch (command) {
    case Command::Help:
      return "help";
    case Command::Devices:
      return "devices";
    case Command::SunPosition:
      return "sunpos";
    case Command::Shade:
      return "shade";
    case Command::Insolation:
      return "insolation";
    case Command::Viewshed:
      return "viewshed";
    case Command::Horizon:
      return "horizon";
    case Command::SkyViewFactor:
      return "svf";
    case Command::AmbientOcclusion:
      return "ao";
    case Command::ViewCount:
      return "viewcount";
    case Command::HorizonLists:
      return "horizons";
    case Command::Bounce:
      return "bounce";
  }
  return "?";
}

namespace {

// "hfvis sunpos --lat LAT --lon LON --at TIME [--apparent]": each once, all but --apparent required.
SunArguments parseSunArguments(const std::vector<std::string>& args) {
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
      throw UsageError("'hfvis sunpos' takes --lat, --lon, --at and --apparent, not " + inQuotes(arg));
    }
  }
  if (!lat || !lon || !at) throw UsageError("'hfvis sunpos' needs --lat LAT --lon LON --at TIME");
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
  if (args.empty()) throw UsageError(std::string("no command given (") + kCommandList + ")");
  const std::string& first = args[0];
  if (isHelpFlag(first)) return line;  // Command::Help, no topic
  if (!first.empty() && first[0] == '-') {
    throw UsageError("unknown option " + inQuotes(first) + " (give a command first: " + kCommandList + ")");
  }
  const std::optional<Command> command = findCommand(first);
  if (!command) {
    throw UsageError("unknown command " + inQuotes(first) + " (expected " + kCommandList + ")");
  }
  const std::vector<std::string> rest(args.begin() + 1, args.end());

  if (*command == Command::Help) {  // "hfvis help [COMMAND]"
    if (rest.size() > 1) throw UsageError("unexpected argument " + inQuotes(rest[1]) + " after 'help'");
    if (!rest.empty()) {
      const std::optional<Command> topic = findCommand(rest[0]);
      if (!topic)
        throw UsageError("unknown command " + inQuotes(rest[0]) + " (expected " + kCommandList + ")");
      if (*topic != Command::Help) line.help_topic = topic;
    }
    return line;
  }

  // "--help" anywhere before "--" wins over everything else on the line.
  for (const std::string& arg : rest) {
    if (arg == "--") break;
    if (isHelpFlag(arg)) {
      line.help_topic = command;
      return line;
    }
  }

  line.command = *command;
  if (*command == Command::Devices) {
    if (!rest.empty()) throw UsageError("'hfvis devices' takes no arguments, got " + inQuotes(rest[0]));
    return line;
  }
  if (*command == Command::SunPosition) {
    line.sun = parseSunArguments(rest);
    return line;
  }
  line.run = parseRunArguments(*command, rest);
  return line;
}

HorizonOptions horizonOptions(const RunArguments& run) {
  HorizonOptions options;
  setSweepOptions(run, options);
  options.method = run.method;
  // (the largest tolerance in degrees may round to a hair above 0.1 radian)
  options.azimuth_tolerance = std::min(0.1, run.azimuth_tolerance_deg * (kPi / 180.0));
  return options;
}

HorizonOutputs horizonOutputs(Command command, const RunArguments& run) {
  HorizonOutputs outputs;
  switch (command) {
    case Command::Horizon:
      outputs.horizon_angles = true;
      outputs.horizon_distances = !run.distance_output.empty();
      break;
    case Command::SkyViewFactor:
      outputs.sky_view_factor = true;
      break;
    case Command::AmbientOcclusion:
      outputs.ambient_occlusion = true;
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
  return options;
}

IntervisibilityOutputs intervisibilityOutputs(const RunArguments& run) {
  IntervisibilityOutputs outputs;
  outputs.visible_count = true;
  outputs.visible_area = true;
  outputs.statistics = run.statistics;
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
