// cli/arguments.hpp: the hfvis command line, parsed and validated into plain structs.
// A small hand-written parser: every value is checked here, before any file is read or
// any device is created, so a typo costs nothing and exits with status 2.
#pragma once

#include <cstddef>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

#include "hfvis/bounce.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/horizon.hpp"
#include "hfvis/horizon_lists.hpp"
#include "hfvis/image_io.hpp"
#include "hfvis/insolation.hpp"
#include "hfvis/intervisibility.hpp"
#include "hfvis/pvs.hpp"
#include "hfvis/region_visibility.hpp"
#include "hfvis/sun_shading.hpp"
#include "hfvis/viewshed.hpp"

namespace hfvis::cli {

// A malformed command line: unknown option or subcommand, missing or bad value.
// main() prints it and exits with status 2.
class UsageError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class Command {
  Help,
  Devices,
  Horizon,
  SkyViewFactor,
  AmbientOcclusion,
  Intervisibility,  // visible samples and ground area per pixel (was "viewcount")
  HorizonLists,     // (was "horizons"): visibility horizons of chosen receivers, JSON or CSV
  Bounce,           // one diffuse bounce of a given exit radiance
  SunPosition,      // (was "sunpos"): the sun's azimuth and elevation at a time and place
  Shade,            // the surface lit by an environment and / or the sun
  Insolation,       // sunshine hours and direct irradiation over a span of time
  Viewshed,         // what one observer sees, or how many of several see each point
  AreaLight,        // the fraction of an area light's (a region's) samples each pixel sees
  Region,           // visibility between two rectangles: the share of clear sample pairs
  Pvs,              // the potentially visible sets of a field's view cells, as JSON
};

// Everything a compute command's run needs, already validated.
struct RunArguments {
  std::string input;
  std::string output;
  std::string distance_output;          // horizon only; "" = not asked for
  double azimuth_tolerance_deg = 0.25;  // horizon only: the sweep's directions within this of phi_k
  std::string preview;                  // "" = no preview
  int directions = 64;
  bool directions_given = false;  // -k typed (--max-error chooses K instead)
  // sky-view-factor and ambient-occlusion: --max-error E (0 = not asked: K as given) and
  // --error-out FILE, the per-pixel error estimate ("" = not asked for).
  double max_error = 0.0;
  // horizon: --max-error E in degrees, the mean horizon angle error (0 = not asked: K as given).
  double horizon_max_error_deg = 0.0;
  int error_tile = 0;  // --error-tile N: HorizonOptions::error_tile
  std::string error_output;
  double azimuth_offset_deg = 0.0;
  double samples_per_unit = 1.0;
  HorizonMethod method = HorizonMethod::Sweep;                                // horizon, svf, ao
  IntervisibilityMethod visibility_method = IntervisibilityMethod::HullTree;  // viewcount
  bool statistics = false;                                                    // viewcount --stats
  HullTreeTuning hull_tree;                                                   // viewcount, bounce
  std::string hull_tree_name;            // --hull-tree as given; "" = not given (the default tuning)
  std::vector<ReceiverPixel> receivers;  // horizons --at, in the order given
  std::string radiance;                  // bounce --radiance
  // shade: the sun, --sun AZ,EL (compass azimuth, elevation, degrees) or where it stands at
  // --at TIME seen from --lat, --lon; --sun-size, its angular diameter.
  std::optional<std::pair<double, double>> sun;
  std::optional<double> sun_time, latitude, longitude;
  double sun_size_deg = 0.53;
  double sun_irradiance = 1.0;          // shade --sun-irradiance: the sun's normal irradiance in --albedo's sum
  std::string environment;              // shade --env ENV.exr
  double environment_rotation_deg = 0.0;  // --env-rotate
  int environment_rows = 0;               // --env-rows: the tables' bands, 0 = the map's rows
  std::string albedo;                     // --albedo: a number in [0, 1] or an image; "" = none
  bool sweep_options_given = false;       // shade: -k, --method or --azimuth-offset (they need --env)
  // insolation: --from, --to, --step minutes, --azimuth-bucket degrees, --apparent.
  std::optional<double> from_time, to_time;
  double step_minutes = 10.0;
  double azimuth_bucket_deg = 0.25;
  bool apparent = false;
  double cell_size_x = 0.0;              // <= 0: from the file, else 1
  double cell_size_y = 0.0;
  double z_scale = 1.0;
  std::string channel;                  // "" = the only channel
  std::string device;                   // "" = HFVIS_DEVICE, else automatic
  std::size_t memory_budget_bytes = 0;  // 0 = from the device
  bool quiet = false;
  bool curvature = false;                    // --curvature (or --refraction): the Earth's drop
  double refraction = kDefaultRefraction;  // --refraction K
  double max_distance = 0.0;                 // --max-distance D (ground units); 0 = none
  // viewshed: --observer COL,ROW (in order) and --observers FILE.csv (read with the field),
  // --observer-height, --target-height, --absolute, --fov FROM,TO (compass degrees),
  // --elevation-range LO,HI (degrees), --angle (an "angle" channel, one observer).
  std::vector<ReceiverPixel> observers;
  std::string observers_file;
  double observer_height = 2.0;
  double target_height = 0.0;
  bool absolute = false;
  std::optional<std::pair<double, double>> field_of_view, elevation_range;
  bool with_angle = false;
  bool with_needed_height = false;  // --needed-height: a "needed_height" channel, one observer
  bool culled = false;              // --method culled: through Stewart's culling pyramid
  int cull_level = ViewshedPyramidOptions{}.finest_level;  // --cull-level K: its finest nodes, 2^K points a side
  bool cull_level_given = false;
  std::optional<float> nodata;               // --nodata VALUE for GeoTIFF outputs (may be NaN); none = NaN
  // arealight and region (hfvis/region_visibility.hpp): --samples N per region, --method
  // exact|culled|viewsheds, --seed of the jitter; arealight's light, --light C0,R0,C1,R1 at
  // --light-height (or --sources FILE.csv), --decorrelate, --masks FILE; region's --from and --to
  // rectangles at --from-height and --to-height, --rays FILE.csv. (--absolute and --target-height
  // set the viewshed's fields above.)
  int region_samples = RegionSampling{}.samples;
  bool region_samples_given = false;
  RegionVisibilityMethod region_method = RegionVisibilityOptions{}.method;
  std::uint32_t seed = RegionVisibilityOptions{}.seed;
  bool seed_given = false;  // (arealight refuses it with --sources: points are not jittered)
  std::optional<PixelRectangle> light, from_region, to_region;
  double light_height = RegionSampling{}.height;
  double from_height = RegionSampling{}.height, to_height = RegionSampling{}.height;
  std::string sources_file, masks_output, rays_output;
  std::string light_image;  // arealight --light-image: the light's colours
  bool decorrelate = false;
  // pvs (hfvis/pvs.hpp): the view cells (--view-cell C, --view-height H0[,H1], --view-mask FILE)
  // and tiles (--tile T); the sampler (--method agvs|sgvs|per-cell) and its budgets (--samples N,
  // --pixel-error E, --seconds S), --filter K, --bitset OUT.bin, --resume PREV.bin (an earlier
  // --bitset file to start from). (--seed sets `seed` above.)
  // --preview-view-cell COL,ROW: the preview draws that pixel's view cell's set.
  PvsGrid pvs_grid;
  std::string pvs_mask, pvs_resume;
  ReceiverPixel pvs_preview_cell;
  bool pvs_preview_cell_given = false;
  PvsOptions pvs;
  std::string bitset_output;
};

// What "hfvis sunpos" is asked.
struct SunArguments {
  double latitude_deg = 0.0, longitude_deg = 0.0;
  double utc_seconds = 0.0;
  bool apparent = false;  // add the atmosphere's refraction
};

struct CommandLine {
  Command command = Command::Help;
  // The command's name as typed (its canonical name or its alias), for messages.
  std::string name;
  // For Command::Help: the subcommand whose help was asked for, if any.
  std::optional<Command> help_topic;
  RunArguments run;
  SunArguments sun;  // Command::SunPosition
};

// For the commands' own checks (CommandSpec::check, cli/commands/):
// 'text', as the messages quote what was typed.
std::string inQuotes(const std::string& text);
// The same path once written plainly ("./b" is "b"; links are not followed, so a path with ".."
// is never the same here: the check of the files themselves, before the input is read, decides it).
bool samePath(const std::string& a, const std::string& b);
// `path` ends in `wanted` (".json"), in any case.
bool hasExtension(const std::string& path, const char* wanted);
// The name as an error about its extension gives it: quoted, and where the file name is an
// extension alone (".json": a hidden file without one) saying so.
std::string namedAs(const std::string& path);
// Runs the library's own checks of options (`check`), their InvalidArgument a UsageError.
template <typename Check>
void asUsageError(Check&& check) {
  try {
    check();
  } catch (const InvalidArgument& error) {
    throw UsageError(error.what());
  }
}

// Parses argv (without argv[0]). Throws UsageError naming the offending argument.
CommandLine parseCommandLine(const std::vector<std::string>& args);

// The library options and outputs a run asks for.
HorizonOptions horizonOptions(const RunArguments& run);
HorizonOutputs horizonOutputs(Command command, const RunArguments& run);
IntervisibilityOptions intervisibilityOptions(const RunArguments& run);
IntervisibilityOutputs intervisibilityOutputs(const RunArguments& run);
SweepOptions horizonListOptions(const RunArguments& run);
BounceOptions bounceOptions(const RunArguments& run);
InsolationOptions insolationOptions(const RunArguments& run);
ViewshedOptions viewshedOptions(const RunArguments& run);
RegionVisibilityOptions regionVisibilityOptions(const RunArguments& run);
HeightFieldReadOptions readOptions(const RunArguments& run);

}  // namespace hfvis::cli
