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
// border of the box analysed (the field clipped to the maximum distance), each keeping, per
// distance, lower and upper bounds on the largest elevation slope met so far, widened by a
// bound on the surface's slope times the angle to the next ray, so that they bound the slope
// met by every sight line between the two rays (rigorous while that angle spans at most a
// pixel). A target whose slope lies below the lower bound of a ray around its sight line is
// hidden; the others are marched exactly over their last pixels, and over the rest of the line
// (skipping the blocks of a maximum pyramid that lie below it) unless the upper bounds settle
// them. The kernels decide in single precision: sight lines that graze the surface within its
// rounding may go either way, and pieces of a line shorter than 1e-3 pixel skip their vertex
// test.
#pragma once

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
  // Device memory for the rays' bounds; 0 = half the device memory. When the rays' bounds at
  // every 2 pixels do not fit, they are kept farther apart (more of every sight line is marched).
  std::size_t memory_budget = 0;
  // Cumulative viewsheds: called after each observer with (done, total).
  std::function<void(int, int)> progress;
};

struct ViewshedOutputs {
  bool visible = true;  // 1 / 0, NaN at nodata
  bool angle = false;   // the target's elevation angle from the eye, radians (NaN at nodata)
  // The height above the surface a target needs to be seen (0 where one on the surface is; NaN
  // at nodata and out of range). Every target's whole sight line is marched (through the
  // maximum pyramid): much slower than `visible`.
  bool needed_height = false;
};

struct ViewshedResult {
  int width = 0, height = 0;
  std::vector<float> visible;  // width * height when asked
  std::vector<float> angle;    // width * height when asked
  std::vector<float> needed_height;  // width * height when asked
  // Targets the classification left to be marched (the rest were settled by the range, nodata
  // or the rays' lower bounds).
  std::size_t marched = 0;
};

struct CumulativeViewshed {
  int width = 0, height = 0;
  int observers = 0;
  std::vector<float> count;  // observers that see each grid point; NaN at nodata
};

// Throws InvalidArgument for a negative or non-finite target height or maximum distance, a
// non-finite curvature, azimuths outside [0, 360], or elevation limits outside [-90, 90] or
// crossed.
void validate(const ViewshedOptions& options);

// Throws InvalidArgument for an observer outside the field, on nodata, or with a non-finite
// height.
void validate(const HeightField& field, const Observer& observer);

// The viewshed of one observer. Throws InvalidArgument (bad field, observer or options, a
// latitude / longitude grid, a field of 2^31 points or more), MemoryBudgetError, OpenClError,
// KernelBuildError.
ViewshedResult computeViewshed(const ComputeContext& context, const HeightField& field, const Observer& observer,
                               const ViewshedOptions& options, const ViewshedOutputs& outputs = {});

// How many of the observers see each grid point (a cumulative viewshed): one viewshed per
// observer, summed on the device. Throws as computeViewshed, and for an empty list.
CumulativeViewshed computeCumulativeViewshed(const ComputeContext& context, const HeightField& field,
                                             const std::vector<Observer>& observers, const ViewshedOptions& options);

}  // namespace hfvis
