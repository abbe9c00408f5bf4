// hfvis/viewshed.hpp: what an observer sees: for every grid point of the field, whether a
// target standing there is visible from the observer's eye, on the bilinear surface.
//
// The observer stands on a grid point (col, row), the eye `height` above the surface there (or
// at that absolute height, z-scaled units, with `absolute`); a target stands on every grid
// point, `target_height` above the surface. The sight line is the straight segment between
// eye and target; the target is visible when no point of the surface strictly between them
// rises strictly above it (a sight line that only touches the surface sees). The surface is the
// bilinear interpolation of the heights; a cell with a nodata corner has no surface inside and
// hides nothing there, though an edge between two valid heights is surface (nodata targets are
// NaN). With curvature, a point at ground distance d from the eye
// counts c d^2 lower (SweepOptions::curvature's convention), the target too.
//
// How it is computed (kernels/viewshed.cl): the surface along a sight line is a quadratic
// within each cell, so one sight line is decided exactly by marching it cell by cell. Marching
// every target is O(N^3), so rays are first marched from the eye to every grid point on the
// border of the box analysed (the field clipped to the maximum distance). Each ray keeps lower
// and upper bounds on the largest elevation slope met so far, widened by a bound on the
// surface's slope times the angle to the next ray, so that they bound the slope met by every
// sight line of its wedge (the directions from its border point up to the next one; rigorous
// while that angle spans at most a pixel). For an eye inside the box the wedges partition the
// directions around it exactly (integer cross products), and each ray settles its wedge's
// targets as it passes them: a target whose slope lies below the lower bound is hidden; the
// others keep an upper bound at their own angle from the ray and are marched exactly over their
// last 2.5 pixels, and over the rest of the line (skipping the blocks of a maximum pyramid that
// lie below it) unless that bound settles them. The few targets no ray settles (beside the eye,
// along the border through an eye on it) are marched whole. The kernels
// decide in single precision and forgive the heights' rounding: a target is hidden only where the
// surface rises above its sight line by more than 2^-21 of |eye height| + |target height| + |the
// Earth's drop| (about 8 units in the last place; so an eye on a tilted plane sees all of it), and
// pieces of a line shorter than 1e-3 pixel skip their vertex test.
//
// A culling pyramid (ViewshedPyramid, after Stewart 1997, "Hierarchical visibility in
// terrains") lets a viewshed skip whole blocks of targets hidden from the eye: built once per
// field and target height from horizons swept in many directions, it is queried per observer
// and never changes a result (see buildViewshedPyramid).
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/height_field.hpp"

namespace hfvis {

struct Observer {
  int col = 0;
  int row = 0;
  double height = 2.0;  // the eye above the surface (or absolute, ViewshedOptions::absolute)
};

struct ViewshedPyramid;

struct ViewshedOptions {
  bool absolute = false;       // Observer::height is an absolute (z-scaled) height
  double target_height = 0.0;  // targets stand this high above the surface
  double max_distance = 0.0;   // ground units; 0 = the whole field. Farther targets are not visible.
  double curvature = 0.0;      // drop coefficient c (earthCurvature() in hfvis/sweep_options.hpp); 0 = flat
  // Horizontal field of view: targets whose compass azimuth from the observer (degrees
  // clockwise from north, north toward row 0) lies clockwise from azimuth_from to azimuth_to;
  // the whole circle when the two are equal or 360 apart.
  double azimuth_from_deg = 0.0, azimuth_to_deg = 0.0;
  // Vertical field of view: targets whose elevation angle from the eye lies within these
  // limits (degrees, -90 .. 90).
  double elevation_min_deg = -90.0, elevation_max_deg = 90.0;
  // Decide every target by marching its whole sight line (through the maximum pyramid) instead
  // of deciding most from the rays' bounds: the same decisions, more slowly (tests and the
  // benchmark compare the two).
  bool march_every_target = false;
  // Device memory for the rays' upper bounds (a float per grid point); 0 = half the device
  // memory. When they take more than half of it, every target is marched (the same decisions,
  // more slowly).
  std::size_t memory_budget_bytes = 0;
  // Cumulative viewsheds: called after each observer with (done, total).
  std::function<void(int, int)> progress;
  // A culling pyramid built for this field, target height and curvature (buildViewshedPyramid),
  // or null: the targets of the blocks it shows hidden are hidden without further work. The same
  // results either way. Must outlive the call.
  const ViewshedPyramid* pyramid = nullptr;
};

struct ViewshedOutputs {
  bool visible = true;  // 1 / 0, NaN at nodata
  bool angle = false;   // the target's elevation angle from the eye, radians (NaN at nodata)
  // The height above the surface a target needs to be seen (0 where one on the surface is; NaN
  // at nodata and out of range). Every target's whole sight line is marched (through the
  // maximum pyramid): much slower than `visible`.
  bool needed_height = false;
  // 1 where the culling pyramid (ViewshedOptions::pyramid, required) culled the point, else 0;
  // NaN at nodata.
  bool culled_mask = false;
};

struct ViewshedResult {
  int width = 0, height = 0;
  std::vector<float> visible;  // width * height when asked
  std::vector<float> angle;    // width * height when asked
  std::vector<float> needed_height;  // width * height when asked
  std::vector<float> culled_mask;    // width * height when asked
  // Targets the classification left to be marched (the rest were settled by the range, nodata,
  // the culling pyramid or the rays' lower bounds).
  std::size_t marched = 0;
  // Valid targets in the blocks the culling pyramid culled (0 without one).
  std::size_t culled = 0;
};

struct CumulativeViewshed {
  int width = 0, height = 0;
  int observers = 0;
  std::vector<float> count;  // observers that see each grid point; NaN at nodata
};

// Stewart's culling pyramid. For every grid point P (a target standing target_height above the
// surface there) and every sector of azimuths, an occlusion region: eyes that P's horizon in
// that sector hides it from. The horizons come from the sweep (computeHorizons) in
// `sectors * directions_per_sector` directions, each giving a surface point B at ground distance
// d and slope s (curvature taken) from P. An eye at ground distance r > d in a direction within
// angle delta of B's, whose slope from P, (z_eye - c r^2 - z_P) / r, is below
// s - L delta - margin / d, is hidden from P: the sight line passes under the surface near B
// (L bounds the surface's slope within d delta of B; the margin keeps the exact test's rounding
// clear of the decision). Horizons nearer than 2 pixels (a slope's own) give no region. Between
// two neighbouring directions an eye lies within half the gap of one and within the whole gap
// of either: the better of the two regions stands for the gap, and a sector's region is the
// intersection of its gaps' (the farthest d, the least bound).
//
// The regions of the points of a quadtree node (2^k x 2^k grid points) are intersected: the
// node keeps, per sector, the farthest d and a lower bound on min_P (z_P + s_P r) as a concave
// piecewise-linear function of r (kBreakpoints vertices at fixed distances shared by every
// node), so that a parent's region is the intersection of its children's with the same bounded
// vertex count. A query culls a node when, for every sector its points can see the eye in, the
// eye lies farther than d from all of them and below the bound over the range of their
// distances; a node holding the eye never passes. Levels finest_level .. the one node over the
// field are kept; the query walks them from the coarsest down.
//
// The regions are conservative: a node is culled only when every point of it is, so rough
// terrain, whose hidden points are interleaved with points on convex slopes (their horizons are
// their own slope), culls few coarse nodes (docs/ALGORITHMS.md gives the fractions measured).
struct ViewshedPyramidOptions {
  double target_height = 0.0;  // the height above the surface of the targets it culls
  double curvature = 0.0;      // as ViewshedOptions::curvature; queries must use the same
  int sectors = 16;            // sectors of azimuth, 4 .. 256
  int directions_per_sector = 8;  // horizon directions per sector (2 .. 64; shared at the sectors' edges)
  int finest_level = 2;        // the finest nodes kept: 2^finest_level points a side, 1 .. 12
  // Bytes the build may use: on the device for the horizon sweeps (SweepOptions::
  // memory_budget_bytes) and on the host for its planes and regions; 0 = half the device's
  // memory and half the host's.
  std::size_t memory_budget_bytes = 0;
  std::function<void(int, int)> progress;  // (directions done, directions in all)
};

struct ViewshedPyramid {
  static constexpr int kBreakpoints = 5;  // the bound's vertices, at reach * {0, 1/64, 1/16, 1/4, 1}
  static constexpr int kRegionFloats = 1 + kBreakpoints;  // per node and sector: d, then the bound
  static constexpr double breakFraction(int i) {
    return i == 0 ? 0.0 : i == 1 ? 1.0 / 64.0 : i == 2 ? 1.0 / 16.0 : i == 3 ? 0.25 : 1.0;
  }
  // What it was built for: queries check these.
  int width = 0, height = 0;
  double cell_size_x = 1.0, cell_size_y = 1.0, z_scale = 1.0;
  std::uint64_t heights_fingerprint = 0;
  double target_height = 0.0, curvature = 0.0;
  int directions = 0;        // horizon directions swept
  int finest_level = 0;
  int sectors = 0;
  // Sector s covers the ground azimuths (SweepOptions's convention, radians) from
  // sector_start[s] over sector_width[s], counter-clockwise in (column, row) axes.
  std::vector<float> sector_start, sector_width;
  double reach = 0.0;  // ground distance of the last breakpoint; farther eyes are never culled
  struct Level {
    int k = 0;  // nodes of 2^k x 2^k grid points
    int nodes_x = 0, nodes_y = 0;
    // Per node (row-major), per sector: kRegionFloats floats. An empty node (only nodata) has
    // d = 0 and the bound FLT_MAX.
    std::vector<float> regions;
  };
  std::vector<Level> levels;                // finest_level first, up to one node
  std::vector<std::uint32_t> valid_points;  // per node of the finest level: its valid grid points
  double build_seconds = 0.0;               // wall time of buildViewshedPyramid
  std::size_t bytes() const;                // the regions' memory
};

// Builds the pyramid. Throws InvalidArgument (bad field or options, a latitude / longitude
// grid, a field of 2^31 points or more), MemoryBudgetError (also when the build would hold more
// on the host than the budget), OpenClError, KernelBuildError.
ViewshedPyramid buildViewshedPyramid(const ComputeContext& context, const HeightField& field,
                                     const ViewshedPyramidOptions& options);

// The fingerprint queries compare: FNV-1a over the heights, 32 bits at a time.
std::uint64_t heightsFingerprint(const HeightField& field);

// Throws InvalidArgument for a negative or non-finite target height or maximum distance, a
// curvature not finite or beyond -1 .. 1 per ground unit, azimuths outside [0, 360], or
// elevation limits outside [-90, 90] or crossed.
void validate(const ViewshedOptions& options);

// Throws InvalidArgument for an observer outside the field, on nodata, or with a non-finite
// height.
void validate(const HeightField& field, const Observer& observer);

// The viewshed of one observer. Throws InvalidArgument (bad field, observer or options, a
// latitude / longitude grid, a field of 2^31 points or more, a pyramid built for another field,
// target height or curvature, or malformed), OpenClError, KernelBuildError.
ViewshedResult computeViewshed(const ComputeContext& context, const HeightField& field, const Observer& observer,
                               const ViewshedOptions& options, const ViewshedOutputs& outputs = {});

// How many of the observers see each grid point (a cumulative viewshed): one viewshed per
// observer, summed on the device. Throws as computeViewshed, and for an empty list.
CumulativeViewshed computeCumulativeViewshed(const ComputeContext& context, const HeightField& field,
                                             const std::vector<Observer>& observers, const ViewshedOptions& options);

}  // namespace hfvis
