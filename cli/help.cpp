// cli/help.cpp: the help texts. The conventions here are the contract of docs/CONVENTIONS.md
// stated for users; keep them in step with include/hfvis/horizon.hpp, intervisibility.hpp,
// horizon_lists.hpp and bounce.hpp.
#include "help.hpp"

namespace hfvis::cli {
namespace {

const char* const kUsage = R"(Usage:
  hfvis horizon   IN -o OUT.exr [-k K] [--distance-out DIST.exr] [options]
  hfvis svf       IN -o OUT.exr [-k K] [options]
  hfvis ao        IN -o OUT.exr [-k K] [options]
  hfvis viewcount IN -o OUT.exr [-k K] [--method tree|naive] [--stats] [options]
  hfvis horizons  IN --at COL,ROW [--at COL,ROW ...] -o OUT.json|OUT.csv [-k K] [options]
  hfvis bounce    IN --radiance RAD.exr -o OUT.exr [-k K] [options]
  hfvis shade     IN -o OUT.exr [--env ENV.exr [-k K]] [--sun AZ,EL | --at TIME --lat LAT --lon LON]
                  [--albedo A|FILE] [options]
  hfvis insolation IN -o OUT.exr --lat LAT --lon LON --from TIME --to TIME [--step MINUTES] [options]
  hfvis viewshed  IN -o OUT.exr --observer COL,ROW [--observer COL,ROW ...] [--observers FILE.csv]
                  [--observer-height H] [--target-height T] [--absolute] [options]
  hfvis sunpos    --lat LAT --lon LON --at TIME [--apparent]
  hfvis devices
  hfvis --help | hfvis COMMAND --help
)";

const char* const kCommands = R"(
Commands:
  horizon   K float32 channels h000..h(K-1): horizon elevation angle per direction, radians
  svf       one float32 channel "svf": sky-view factor, 0..1
  ao        one float32 channel "ao": ambient occlusion, 0..1 (1 = unoccluded flat ground)
  viewcount channel 0 "count": visible surface samples summed over the K directions;
            channel 1 "visible_area": the visible ground area (total viewshed), ground units^2
  horizons  the visibility horizons of chosen receivers per direction, as JSON or CSV
  bounce    incident indirect irradiance of one diffuse bounce of a given exit radiance
  shade     --env: "R", "G", "B" (or "Y"), the irradiance from an HDR environment through the
            horizons; the sun: "sun", the part of its disc above the horizon (0..1), and
            "direct", sun * max(0, n . s); --albedo: "radiance[.R/G/B]", what the surface sends out
  insolation "sun_hours" (hours of sun) and "direct" (irradiation of a unit sun, hours) over a span
  viewshed  "visible" (1 / 0): what one observer sees; with several observers "count"
  sunpos    the sun's compass azimuth and elevation at a time and place
  devices   list the OpenCL devices and mark the one automatic selection picks
)";

const char* const kOptions = R"(
Options:
  -o, --output FILE        output image (required): float32 EXR, or a float32 GeoTIFF when the
                           name ends in .tif or .tiff (the input's georeference kept; see
                           Conventions, GIS)
  -k, --directions K       number of azimuth directions, K >= 1 (default 64)
  --method sweep|naive     horizon, svf, ao: sweep = convex-hull-stack sweep along lines through
                           every pixel centre, linear time per direction, exact over the samples
                           of each receiver's own ray; naive = per-pixel ray march, slow
                           reference (default sweep).
                           The sweep's directions are integer pixel steps: within 0.25 deg of
                           phi_k for horizon, within half the spacing (weighted) for svf and ao;
                           the hfvis:azimuths_deg attribute lists those used
  --method tree|naive      viewcount: tree = convex hull tree sweep (Timonen 2013); naive =
                           per-pixel visibility march, slow reference (default tree)
  --azimuth-offset DEG     added to every direction's azimuth, degrees (default 0)
  --curvature              all but bounce: lower every point at ground distance d by
                           the Earth's drop d^2 (1 - K) / (2 R), R = 6370997 m, K = 1/7 (GRASS and
                           GDAL's convention; cell sizes must be in metres)
  --refraction K           the same with refraction coefficient K in -1 .. 1 (implies --curvature)
  --max-distance D         horizon, svf, ao, viewcount, shade, viewshed: only terrain within D
                           ground units of the receiver counts (farther terrain neither casts a
                           horizon nor hides anything nearer; r.horizon's maxdistance, RVT's
                           svf_r_max); viewshed: only targets within D
  --samples-per-unit S     naive, viewcount, bounce: height samples per pixel length along a
                           line or ray; sweep: every grid-line crossing of the ray (exact heights)
                           and, for S > 1, about S points per pixel length between crossings
                           (default 1: the crossings alone)
  --cell-size X[,Y]        ground units per pixel along columns (X) and rows (Y)
                           (default: from the file (a raster's geotransform, the
                           hfvis:cell_size_x/y attributes), else 1)
  --z-scale Z              multiplies every height, e.g. 0.3048 for feet over metre cells (default 1)
  --channel NAME|INDEX     input channel (a raster's band: its description or zero-based index)
                           to read; needed for multi-channel images
  --nodata VALUE           GeoTIFF outputs: write VALUE (a finite float32 number, or nan) in
                           nodata cells and declare it as every band's nodata value (default
                           nan); EXR outputs keep NaN. Needs a .tif/.tiff output
  --device SEL             device index, "gpu", "cpu" or part of a device/platform name
                           (default: env HFVIS_DEVICE, else a GPU, else the first CPU)
  --memory-budget MB       device memory for one batch of directions, MiB (default: half the
                           device's memory; on a CPU device half the host's); horizon, svf and
                           ao run a field beyond it in strips of rows, with the same result
  --preview PNG            also write an 8-bit PNG preview
  -q, --quiet              print neither progress nor the summary line
  -h, --help               show help
  (horizons takes only -o, -k, --azimuth-offset, --samples-per-unit, --cell-size, --z-scale,
  --channel, --curvature, --refraction and --quiet: it runs on the host, one ray per receiver
  and direction, and writes text. viewshed and insolation take none of -k, --azimuth-offset,
  --samples-per-unit or --method sweep|naive (viewshed's --method is exact|culled); shade takes
  -k, --method and --azimuth-offset with --env only.)
)";

const char* const kHorizonOnly = R"(
Horizon only:
  --distance-out FILE      also write K channels d000.. of ground distance to the
                           horizon point (ground units), computed in the same run
  --azimuth-tolerance DEG  the sweep's direction k is the cheapest integer pixel step within
                           DEG of phi_k (default 0.25; at most 5.72958, 0.1 radian). Smaller
                           is closer to phi_k and slower: steps with more grid crossings per
                           pixel
  Its preview shows the mean horizon elevation over the directions whose ray stays in
  the field (low = dark, high = bright), stretched from its minimum to its maximum; the
  svf and ao previews stretch their 1st to 99th percentile over black..white (the summary
  line prints both ends). Nodata is black in every preview.
)";

const char* const kViewCount = R"(
Viewcount:
  --stats                  also print, for the tree method, the statistics of Timonen (2013)'s
                           Table 2 per point and direction: m_a (visibility horizons), t_a
                           (convexity checks made), visible samples and naive iterations (the
                           samples the naive method tests); also stored as hfvis:stats_* EXR
                           attributes. Printed even with --quiet. Table 2's t_a is Algorithm
                           1's: add --hull-tree plain.
  --hull-tree T            (viewcount and bounce) how the convex hull tree does its work; the
                           results are the same for every T: plain = Algorithm 1 as written,
                           deferred = link writes only where a link changes (Algorithm 2's
                           aim), default = deferred + the old root's last child checked
                           first, zone = default + the safe zone (Algorithm 3) (default:
                           default)
  Tie rule   along direction k a pixel sees the samples q_i = p + i/S * d_k (S samples per
             unit, bilinear heights, inside the field); q is visible when its slope from p is
             >= the slope of every sample between them (grazing samples are visible: on a flat
             plane every sample is), decided exactly. Count: the visible samples summed over
             the K directions, each counting its step times S; an N x M flat plane gives
             N + M - 2 at K = 4. The tree method runs on lines through the pixel centres along
             integer steps (a, b) close to d_k, each pixel the receiver of its own line, its
             steps |(a, b)| / ceil(|(a, b)| S); the naive method marches each pixel's own ray.
  Area       each visible sample at ground distance rho stands for its direction's share of
             the circle (2*pi/K for the naive march, the quadrature weight of the tree's
             step) times rho * drho, drho the ground step: ground units squared; it tends to
             the area seen as K grows.
  The preview stretches the count from its minimum to its maximum.
)";

const char* const kHorizonLists = R"(
Horizons:
  --at COL,ROW             a receiver pixel (zero-based column, row); repeat for more. A pixel
                           outside the field is a usage error (status 2).
  -o OUT.json|OUT.csv      JSON: every receiver, direction and horizon, with the conventions
                           spelled out; CSV: one row per horizon with the columns
                           col,row,direction,azimuth_rad,horizon,sample,distance,elevation_rad,
                           segment_begin,segment_end,near_distance,visible_samples,nodata
                           (a direction without horizons: one row with the horizon fields empty;
                           nodata 1 where the receiver's height is nodata).
  Along direction k the receiver's own ray is sampled at i = 1, 2, ... (i/S pixel lengths,
  the naive method's samples; tie rule as viewcount). Horizons are listed nearest first: each
  is the farthest visible sample of its segment (distance in ground units, elevation in
  radians); its visible segment is the samples [segment_begin, segment_end) toward the
  receiver, from near_distance up to distance. The segments hold every visible sample once.
)";

const char* const kBounce = R"(
Bounce:
  --radiance RAD.exr       exit radiance of every surface point: an image of the input's size
                           with 1 to 4 channels (grey, RGB, ...), finite and >= 0 where the
                           height is valid. The output has the same channel names.
  For every pixel, direction and visible sample along its sweep line, the sample's radiance
  times the projected solid angle of its elevation band (from the visible segments: bands
  split at mean elevations between adjacent visible samples; across hidden samples the band
  goes to the farther sample), for a Lambertian receiver whose normal comes from the four
  quads around it, each direction standing for its wedge of azimuth (the quadrature weight of
  its lattice step times 2*pi, about 2*pi/K); surface behind
  the receiver's tangent plane adds nothing. The sum is the incident indirect irradiance, in
  radiance units times steradians (W/m^2 for W m^-2 sr^-1); a surface of albedo rho re-emits
  rho * E / pi, the next bounce's radiance. A flat plane receives 0. The preview stretches
  the mean over the channels from its minimum to its maximum.
)";

const char* const kConventions = R"(
Conventions and units:
  Input      one band of a raster GDAL reads (GeoTIFF/COG .tif/.tiff, .hgt, .asc, .vrt, .img,
             .bil, .dem, .grd, .adf) or one channel of an EXR (OpenEXR) or of another image
             OpenImageIO reads (PNG, ...), row-major, row 0 first as stored. Pixel (col, row) lies at ground position
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
  Outputs    float32 EXR (ZIP-compressed, through OpenEXR), with the run described in
             string attributes hfvis:*; GeoTIFF for .tif/.tiff (horizons: JSON
             or CSV text). Files are written to a temporary name and renamed only once every
             output of the run is complete, so a failed run leaves no partial or mismatched
             output behind.
  GIS        A georeferenced input keeps its CRS (projected or geographic, copied as it is)
             and geotransform in GeoTIFF outputs, so they overlay it. Cell sizes come from
             the geotransform in the CRS's units; geographic degrees become metres (WGS84,
             at each row's latitude: every command follows each row's spacing but bounce, which
             takes the centre latitude's); rotated geotransforms are refused. A band's
             nodata value reads as nodata. GeoTIFF outputs: one float32 band per channel,
             named by its description (h000.., svf, ao, count, visible_area), nodata declared
             on every band (NaN, or --nodata VALUE written in those cells), DEFLATE with the
             floating-point predictor, 256x256 tiles, BigTIFF when needed; the hfvis:*
             attributes become metadata items hfvis_* (GDAL splits names at ':'). EXR
             outputs keep the cell size (hfvis:cell_size_x/y) but no georeference.
)";

const char* const kExitStatus = R"(
Progress ("hfvis: 16/64 directions") goes to stderr when it is a terminal; a one-line
summary goes to stdout.

Exit status: 0 success, 1 runtime error (unreadable input, device or write failure),
2 usage error (unknown option or command, missing or invalid value).
)";

}  // namespace

std::string generalHelp() {
  return std::string(
             "hfvis: horizons, sky-view factor, ambient occlusion, intervisibility, one-bounce light, and lighting by "
             "HDR environments and the sun on "
             "height fields (OpenCL)\n\n") +
         kUsage + kCommands + kOptions + kHorizonOnly + kViewCount + kHorizonLists + kBounce + kConventions +
         kExitStatus;
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
    case Command::ViewCount:
      return std::string(
                 "hfvis viewcount IN -o OUT.exr [-k K] [--method tree|naive] [--stats] [options]\n\n"
                 "Writes two float32 channels: channel 0 \"count\" = the number of visible surface samples\n"
                 "summed over the K directions (one sample per 1/S pixel lengths along each direction, S =\n"
                 "--samples-per-unit, default 1); channel 1 \"visible_area\" = the visible ground area, "
                 "ground\n"
                 "units squared. NaN at nodata pixels.\n") +
             kOptions + kViewCount + kConventions + kExitStatus;
    case Command::HorizonLists:
      return std::string(
                 "hfvis horizons IN --at COL,ROW [--at COL,ROW ...] -o OUT.json|OUT.csv [-k K] [options]\n\n"
                 "Writes, for each receiver and direction, the visibility horizons along the receiver's ray\n"
                 "and the visible segments they bound, as JSON or CSV (by the extension of -o).\n") +
             kOptions + kHorizonLists + kConventions + kExitStatus;
    case Command::Bounce:
      return std::string(
                 "hfvis bounce IN --radiance RAD.exr -o OUT.exr [-k K] [options]\n\n"
                 "Writes the incident indirect irradiance of one diffuse bounce of the exit radiance RAD,\n"
                 "one float32 channel per radiance channel (same names). NaN at nodata pixels.\n") +
             kOptions + kBounce + kConventions + kExitStatus;
    case Command::Devices:
      return "hfvis devices\n\n"
             "Lists every OpenCL device of every platform: index, type, name, platform, driver\n"
             "version and global memory. '*' marks the device automatic selection picks (the\n"
             "HFVIS_DEVICE environment variable if set, else a GPU, else the first CPU). Use the\n"
             "index, a type (gpu, cpu) or part of the name with --device or HFVIS_DEVICE.\n";
    case Command::Shade:
      return std::string(
                 "hfvis shade IN -o OUT.exr [--env ENV.exr [--env-rotate DEG] [--env-rows N] [-k K]]\n"
                 "            [--sun AZ,EL | --at TIME --lat LAT --lon LON] [--sun-size DEG]\n"
                 "            [--albedo A|FILE [--sun-irradiance E]] [options]\n\n"
                 "Lights the surface; give --env, the sun, or both.\n"
                 "--env ENV.exr: an HDR environment, equirectangular (latitude / longitude, 2:1): row 0 at\n"
                 "  the zenith, the last row at the nadir; the column at fraction u of the width looks toward\n"
                 "  compass azimuth 360 u + DEG (--env-rotate; left edge north, a quarter east, the middle\n"
                 "  south). One channel or R, G, B (an alpha channel is ignored). Channels R, G, B (or Y): the\n"
                 "  irradiance at each point from the part of the environment above its horizons, for its\n"
                 "  normal, in the environment's radiance times steradians (uniform radiance 1 gives pi on\n"
                 "  open flat ground, pi times 'hfvis ao' everywhere). -k directions (default 64) and\n"
                 "  --method as for ao; --env-rows N bands of zenith angle in the tables (default the map's\n"
                 "  rows, exact for a map constant over each pixel; fewer are faster to build, not to light).\n"
                 "The sun: channel \"sun\" is the fraction of the sun's disc (--sun-size degrees across,\n"
                 "  default 0.53; 0 = a point sun, hard shadows) above each pixel's horizon in the sun's\n"
                 "  azimuth and above elevation 0 (level ground beyond the field); \"direct\" is sun * max(0,\n"
                 "  n . s), the irradiance from a sun of normal irradiance 1. --sun AZ,EL (compass azimuth,\n"
                 "  degrees clockwise from north; elevation, degrees), or where it stands at --at TIME seen\n"
                 "  from --lat, --lon (as 'hfvis sunpos', geometric). Only the sun's azimuth is swept, along\n"
                 "  the cheapest integer step within 0.02 degree of it (near the axes up to 1415 pixels\n"
                 "  long, and as slow).\n"
                 "--albedo A|FILE (a number in 0..1, or an image of the field's size, 1 or 3 channels): also\n"
                 "  \"radiance\" (or radiance.R/G/B), albedo / pi times the irradiance: the environment's plus\n"
                 "  the direct light times --sun-irradiance E (default 1; only with --albedo), a Lambertian\n"
                 "  surface's radiance. An RGB GeoTIFF's bands (colour interpretation) read as R, G, B.\n"
                 "Row 0 is taken as north (a south-up GeoTIFF is lit flipped north-up). The preview is the\n"
                 "radiance or the irradiance tonemapped (ACES filmic, sRGB), or with the sun alone a\n"
                 "hillshade with cast shadows: direct from 0 (black) to its largest value (white). NaN at\n"
                 "nodata pixels.\n") +
             kOptions + kConventions + kExitStatus;
    case Command::Insolation:
      return std::string(
                 "hfvis insolation IN -o OUT.exr --lat LAT --lon LON --from TIME --to TIME [--step MINUTES]\n"
                 "                 [--sun-size DEG] [--azimuth-bucket DEG] [--apparent] [options]\n\n"
                 "Sunlight from TIME to TIME (ISO 8601 with a zone) at latitude LAT, longitude LON, in steps\n"
                 "of MINUTES (default 10; the last one shorter), each taken at its middle. Channel\n"
                 "\"sun_hours\": hours with the sun's centre above the pixel's horizon and above elevation 0\n"
                 "(terrain beyond the field taken as level); \"direct\": the sum over the steps of hours *\n"
                 "the disc's part seen * max(0, n . s), the irradiation from a sun of normal irradiance 1 in\n"
                 "hours (times a normal irradiance in W/m^2 it is Wh/m^2). Steps whose sun azimuths fall in\n"
                 "one bucket of DEG (default 0.25) share one horizon sweep, so a year costs a few hundred\n"
                 "sweeps. --apparent lifts the sun by the atmosphere's refraction. Row 0 is taken as north (a\n"
                 "south-up GeoTIFF is lit flipped north-up). The preview stretches direct over its 1st to\n"
                 "99th percentile. NaN at nodata pixels.\n") +
             kOptions + kConventions + kExitStatus;
    case Command::Viewshed:
      return std::string(
                 "hfvis viewshed IN -o OUT.exr --observer COL,ROW [--observer COL,ROW ...] [--observers FILE.csv]\n"
                 "               [--observer-height H] [--target-height T] [--absolute] [--max-distance D]\n"
                 "               [--curvature] [--refraction K] [--fov FROM,TO] [--elevation-range LO,HI]\n"
                 "               [--angle] [--needed-height] [--method exact|culled] [--cull-level K] [options]\n\n"
                 "What an observer standing on grid point COL,ROW (zero-based) sees: channel \"visible\" is 1\n"
                 "where a target standing T (default 0) above the surface is seen from the eye H (default 2)\n"
                 "above the surface (--absolute: at height H), 0 where it is hidden or out of range, NaN at\n"
                 "nodata. Seen means no point of the bilinear surface strictly between eye and target rises\n"
                 "above the straight sight line (grazing sees); cells with a nodata corner hide nothing.\n"
                 "Decided exactly for every target, up to single-precision rounding of sight lines that\n"
                 "graze. --max-distance D: targets within D ground units; --fov FROM,TO: targets whose\n"
                 "compass azimuth lies clockwise from FROM to TO; --elevation-range LO,HI: targets seen\n"
                 "between LO and HI degrees above the eye's horizontal; --curvature and --refraction lower\n"
                 "every point, targets too, by the Earth's drop. --angle adds channel \"angle\", the target's\n"
                 "elevation angle from the eye in degrees; --needed-height channel \"needed_height\", the height\n"
                 "above the surface a target there needs to be seen (0 where one on the surface is; NaN out of\n"
                 "range; every sight line is marched in full, much slower).\n"
                 "Several observers (--observer repeated, and / or --observers FILE.csv with columns\n"
                 "col,row[,height], a header line allowed): channel \"count\", how many of them see each\n"
                 "point (a cumulative viewshed); a row's height replaces --observer-height. An observer\n"
                 "outside the field or on nodata is an error.\n"
                 "--method culled first builds Stewart's culling pyramid (horizons swept in 128 directions,\n"
                 "occlusion regions per point and sector combined up a quadtree, nodes of 2^K x 2^K points\n"
                 "from --cull-level K, default 2) and skips the targets of every node it shows hidden: the\n"
                 "same result as --method exact; worth it for many observers, where one pyramid serves all.\n"
                 "The preview shows the visible points (or the count) bright over a dimmed hillshade.\n") +
             kOptions + kConventions + kExitStatus;
    case Command::SunPosition:
      return "hfvis sunpos --lat LAT --lon LON --at TIME [--apparent]\n\n"
             "Prints 'azimuth=<deg> elevation=<deg>': where the sun stands seen from latitude LAT and\n"
             "longitude LON (degrees, north and east positive) at TIME (ISO 8601 with a zone, e.g.\n"
             "2026-06-21T12:00:00Z or 2026-06-21T14:00:00+02:00). The azimuth is the compass azimuth,\n"
             "degrees clockwise from north; the elevation is geometric (the sun's centre, no\n"
             "atmosphere; geocentric), or with --apparent raised by the refraction of a standard\n"
             "atmosphere (1010 hPa, 10 C). The algorithm is Meeus's (1998, ch. 25) with Smart's\n"
             "equation of time, as NOAA's solar calculator: within 0.003 degree of NREL's SPA on\n"
             "its worked example; years 1800 - 2200 (the range it accepts).\n";
    case Command::Help:
      break;
  }
  return generalHelp();
}

}  // namespace hfvis::cli
