// cli/help.cpp: the help texts. The conventions here are the contract of ../shared/DESIGN.md
// stated for users; keep them in step with include/hfvis/horizon.hpp.
#include "help.hpp"

namespace hfvis::cli {
namespace {

const char* const kUsage = R"(Usage:
  hfvis horizon IN -o OUT.exr [-k K] [--distance-out DIST.exr] [options]
  hfvis svf     IN -o OUT.exr [-k K] [options]
  hfvis ao      IN -o OUT.exr [-k K] [options]
  hfvis devices
  hfvis --help | hfvis COMMAND --help
)";

const char* const kCommands = R"(
Commands:
  horizon   K float32 channels h000..h(K-1): horizon elevation angle per direction, radians
  svf       one float32 channel "svf": sky-view factor, 0..1
  ao        one float32 channel "ao": ambient occlusion, 0..1 (1 = unoccluded flat ground)
  devices   list the OpenCL devices and mark the one automatic selection picks
)";

const char* const kOptions = R"(
Options:
  -o, --output FILE        output image, float32 EXR (required)
  -k, --directions K       number of azimuth directions, K >= 1 (default 64)
  --method sweep|naive     sweep: convex-hull-stack sweep, linear time per direction;
                           naive: per-pixel ray march, slow reference (default sweep)
  --azimuth-offset DEG     added to every direction's azimuth, degrees (default 0)
  --samples-per-unit S     height samples per pixel length along a line or ray (default 1)
  --lines-per-unit L       sweep lines per pixel length across a direction (default 1)
  --cell-size X[,Y]        ground units per pixel along columns (X) and rows (Y)
                           (default: from the file (hfvis:cell_size_x/y attributes,
                           GeoTIFF pixel scale), else 1)
  --z-scale Z              multiplies every height, e.g. 0.3048 for feet over metre cells (default 1)
  --channel NAME|INDEX     input channel to read; needed for multi-channel images
  --device SEL             device index, "gpu", "cpu" or part of a device/platform name
                           (default: env HFVIS_DEVICE, else a GPU, else the first CPU)
  --memory-budget MB       device memory for one batch of directions, MiB (default: from the device)
  --preview PNG            also write an 8-bit PNG preview
  -q, --quiet              print neither progress nor the summary line
  -h, --help               show help
)";

const char* const kHorizonOnly = R"(
Horizon only:
  --distance-out FILE      also write K channels d000.. of ground distance to the
                           horizon point (ground units), computed in the same run
  Its preview shows the mean horizon elevation over the directions whose ray stays in
  the field (low = dark, high = bright), stretched from its minimum to its maximum; the
  svf and ao previews map 0..1 to black..white. Nodata is black in every preview.
)";

const char* const kConventions = R"(
Conventions and units:
  Input      one height channel of any image OpenImageIO reads (EXR, TIFF/GeoTIFF, PNG, ...),
             row-major, row 0 first as stored. Pixel (col, row) lies at ground position
             (col*X, row*Y); the surface is bilinear between pixels; height = value * Z.
             Integer pixels are read as their stored values (16-bit PNG: 0..65535).
  Directions direction k of K has azimuth phi_k = 360*k/K deg + offset, measured on the
             ground from the +column axis toward +row. When row 0 is north (most DEMs),
             compass azimuth = 90 + phi_k deg: k = 0 looks east, then south, west, north.
  Horizon    the largest elevation angle atan2(dz, ground distance) of the surface along
             the ray from a pixel in direction k, in radians (-pi/2..pi/2; 0 = level);
             -pi/2 where the ray leaves the field at once (at the border).
             Horizon distance: ground distance to the point casting it, ground units
             (0 where no point casts a horizon).
  SVF        1 - mean_k sin(max(0, elevation_k)): the fraction of the sky hemisphere
             visible from a pixel (level horizon = 1, fully enclosed = 0).
  AO         outgoing radiance of a white Lambertian surface under a uniform sky of
             radiance 1, from its horizons and its surface normal (Timonen & Westerholm
             2010, Eq. 5), normalised so that a flat plane gives 1.
  Nodata     non-finite heights (NaN, +-inf) are nodata: they neither cast nor receive;
             every output is NaN there, and holes do not spread into valid neighbours.
  Outputs    float32 EXR (any float format OpenImageIO writes, by extension), with the
             run described in string attributes hfvis:*. Files are written to a temporary
             name and renamed only once every output of the run is complete, so a failed
             run leaves no partial or mismatched output behind.
)";

const char* const kExitStatus = R"(
Progress ("hfvis: 16/64 directions") goes to stderr when it is a terminal; a one-line
summary goes to stdout.

Exit status: 0 success, 1 runtime error (unreadable input, device or write failure),
2 usage error (unknown option or command, missing or invalid value).
)";

}  // namespace

std::string generalHelp() {
  return std::string("hfvis: horizons, sky-view factor and ambient occlusion on height fields (OpenCL)\n\n") +
         kUsage + kCommands + kOptions + kHorizonOnly + kConventions + kExitStatus;
}

std::string commandHelp(Command command) {
  switch (command) {
    case Command::Horizon:
      return std::string(
                 "hfvis horizon IN -o OUT.exr [-k K] [--distance-out DIST.exr] [options]\n\n"
                 "Writes K float32 channels h000..h(K-1) (zero-padded, so sorted order = direction order;\n"
                 "select channels by name): channel k = horizon elevation angle in direction k, radians.\n") +
             kOptions + kHorizonOnly + kConventions + kExitStatus;
    case Command::SkyViewFactor:
      return std::string(
                 "hfvis svf IN -o OUT.exr [-k K] [options]\n\n"
                 "Writes one float32 channel \"svf\": sky-view factor 1 - mean_k sin(max(0, elevation_k)),\n"
                 "the fraction of the sky visible from each pixel (a flat plane gives 1).\n"
                 "The preview (--preview) maps svf 0..1 to black..white; NaN (nodata) is black.\n") +
             kOptions + kConventions + kExitStatus;
    case Command::AmbientOcclusion:
      return std::string(
                 "hfvis ao IN -o OUT.exr [-k K] [options]\n\n"
                 "Writes one float32 channel \"ao\": ambient occlusion under a uniform sky of radiance 1,\n"
                 "normalised so a flat plane gives 1 (0 = fully occluded).\n"
                 "The preview (--preview) maps ao 0..1 to black..white; NaN (nodata) is black.\n") +
             kOptions + kConventions + kExitStatus;
    case Command::Devices:
      return "hfvis devices\n\n"
             "Lists every OpenCL device of every platform: index, type, name, platform, driver\n"
             "version and global memory. '*' marks the device automatic selection picks (the\n"
             "HFVIS_DEVICE environment variable if set, else a GPU, else the first CPU). Use the\n"
             "index, a type (gpu, cpu) or part of the name with --device or HFVIS_DEVICE.\n";
    case Command::Help:
      break;
  }
  return generalHelp();
}

}  // namespace hfvis::cli
