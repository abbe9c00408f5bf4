// bench/methods.hpp: every horizon method the benchmark runs, behind one call: the
// library's sweep and naive kernels (through computeHorizons; the library's naive march is
// the report's naive baseline) and the approximations and floor of
// bench/kernels/horizon_baselines.cl (launched here on the library's context and queue).
#pragma once

#include <map>
#include <string>
#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/height_field.hpp"

namespace hfvis::detail {
// The benchmark's own kernels (bench/kernels/*.cl) by file name, embedded into hfvis_bench at
// build time (cmake/EmbedKernels.cmake), not into the library.
const std::map<std::string, std::string>& benchKernelSources();
}  // namespace hfvis::detail

namespace hfvis::bench {

enum class MethodKind {
  Sweep,    // library: receiver-exact lattice sweep (HorizonMethod::Sweep)
  Naive,    // library: naive march (HorizonMethod::Naive, kernel horizon_naive)
  Radius,   // baselines: naive march limited to `parameter` pixels (kernel radius_march)
  Pyramid,  // baselines: max-pyramid march, `parameter` unit steps then parameter/2 per octave
  Floor,    // baselines: read heights, write one value per pixel and direction
};

struct MethodSpec {
  MethodKind kind = MethodKind::Sweep;
  int directions = 64;
  // S: the marches step 1/S pixel; the sweep adds about S samples per pixel between crossings.
  double samples_per_unit = 1.0;
  int parameter = 0;  // radius (Radius) or near steps (Pyramid)
  // true: K horizon planes downloaded to the host (the `hfvis horizon` job). false: the
  // library computes the sky-view factor only; the floor writes its planes on the device only.
  bool angles = true;
  // Library methods without angles: ambient occlusion instead of the sky-view factor (the
  // `hfvis ao` job, for the comparison with heman).
  bool ambient_occlusion = false;
  // Library methods: only terrain within this ground distance counts (0 = the whole field).
  double max_distance = 0.0;

  std::string name() const;     // "sweep", "naive", "radius_16", "pyramid_16", "floor"
  std::string outputs() const;  // "angles", "svf", "ao" or "device"
};

struct MethodOutput {
  std::vector<float> angles;     // K planes of width * height when spec.angles
  std::vector<float> svf;        // library methods without angles (or ao, with ambient_occlusion)
  std::vector<double> azimuths;  // library methods: the azimuths computed (HorizonResult::azimuths)
};

// Runs the method once on `field` (no nodata; width and height >= 2 for the baselines).
MethodOutput runMethod(const ComputeContext& context, const HeightField& field, const MethodSpec& spec);

// The library with sky-view factor and ambient occlusion outputs (no angles): the
// azimuthal discretisation study compares these across K.
struct ShadingOutput {
  std::vector<float> svf, ao;
};
ShadingOutput runShading(const ComputeContext& context, const HeightField& field, MethodKind kind,
                         int directions);

// Ray steps a per-pixel march takes over the whole field for K directions (azimuths
// 2 pi k / K) at `samples_per_unit`, at most `max_steps` per ray (0 = no limit): `executed`
// as the kernels run them (the library's horizon_naive and the baselines' radius_march: every
// lane of a tile_x x tile_y work-group runs the tile's longest ray), `inside` those that
// sample inside the field.
struct MarchSteps {
  double executed = 0.0, inside = 0.0;
};
MarchSteps naiveMarchSteps(const HeightField& field, int directions, double samples_per_unit, int tile_x,
                           int tile_y, int max_steps = 0);

// The per-pixel tile (work-group) shape of the library's naive kernel and of the
// baselines: the library's kTileX x kTileY (16 x 4).
int baselineTileX();
int baselineTileY();

}  // namespace hfvis::bench
