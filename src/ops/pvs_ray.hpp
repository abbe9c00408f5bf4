// pvs_ray.hpp: the height-field ray caster for C++ (the host and the scalar reference):
// kernels/shared/heightfield_ray.cl itself, the source the kernel compiles, included here so the
// two cannot drift; the maximum pyramid it skips empty space with; and what the samplers share.
#pragma once

#include <cmath>
#include <functional>
#include <vector>

#include "hfvis/height_field.hpp"
#include "hfvis/pvs.hpp"
#include "core/opencl_builtins.hpp"

namespace hfvis::detail {

#include "../../kernels/shared/heightfield_ray.cl"

// The maximum pyramid of heightfield_ray.cl over the (z-scaled) heights: levels 1 .. top, up to
// one block over the field; `levels` 4 ints per level (blocks across, down, first value, 0),
// level 0 unused.
struct RayPyramid {
  std::vector<float> values;
  std::vector<int> levels;
  int top = 0;
};
RayPyramid buildRayPyramid(const std::vector<float>& heights, int width, int height);

// The grid a cast checks and takes: `options.grid`, or without the lists (which alone use it) one
// any field of 2 x 2 points holds (its default view cells of 32 refused every field under 33 x 33,
// naming an option the caller had not given).
inline PvsGrid castGrid(const RayCastOptions& options) {
  if (options.view_cells) return options.grid;
  PvsGrid grid;
  grid.view_cell = grid.tile = 1;
  grid.band_low = grid.band_high = 0.0;
  return grid;
}

// The heights the ray caster reads: z-scaled, from zero (the viewshed's and the region
// visibility's, so the witnesses' line-of-sight test sees the same surface).
std::vector<float> rayHeights(const HeightField& field);

}  // namespace hfvis::detail

namespace hfvis::detail {

// A view cell a ray passes through, with a t where the ray lies in its volume (to rounding).
struct ViewCellPoint {
  int view_cell;
  float t;
};

// What the caster gives the samplers: RayCastResult's hits, and each ray's view cells where the
// caster put them (launch after launch, in the order it cast the rays), found from the ray:
// putting a million rays' lists into the callers' order took about 0.1 s of the host's on the
// 2-core CPU (bench/report/pvs.md).
struct RayCasts {
  std::vector<float> t;   // per ray, as RayCastResult::t
  std::vector<int> cell;  // per ray, as RayCastResult::cell
  // Ray r's view cells: view_cells[list_first[r] .. list_first[r] + list_count[r]), in order
  // along the ray (both empty without view cells).
  std::vector<std::size_t> list_first;
  std::vector<int> list_count;
  std::vector<ViewCellPoint> view_cells;
  // Launches whose lists did not all come with the hits: a work-group listed more pairs than the
  // first read took, and the rest was read after (a statistic, for the tests to see that it ran).
  int lists_read_again = 0;
};

// The device ray caster, set up once (heights and pyramid uploaded, program built) for many
// batches: a sampler's whole run.
class RayCaster {
 public:
  virtual ~RayCaster() = default;
  // Casts `rays` (view cells listed when `view_cells`), in launches that fit the memory budget.
  virtual RayCasts cast(const std::vector<HeightRay>& rays, bool view_cells) = 0;
};

// Runs `body` with a caster of `field` and `grid` (validated) on the device, its rays over a
// surface of `curvature` (validated; RayCastOptions::curvature), its launches within
// `memory_budget_bytes` (0: the default budget).
void withRayCaster(const ComputeContext& context, const HeightField& field, const PvsGrid& grid,
                   double curvature, std::size_t memory_budget_bytes,
                   const std::function<void(RayCaster&)>& body);

}  // namespace hfvis::detail
