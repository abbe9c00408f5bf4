// bounce_internal.hpp: what the bounce's device path, its scalar reference and the tests
// share: the prepared inputs (heights, pixel normals, radiance planes) and the line-level
// view of one direction's gather, to compare the kernel with the reference line by line.
#pragma once

#include <vector>

#include "hfvis/bounce.hpp"
#include "core/hull_tree.hpp"

namespace hfvis::detail {

// The inputs as both paths see them (BounceInputs in core/hull_tree.hpp).
BounceInputs prepareBounce(const HeightField& field, const ExitRadiance& radiance);

// One direction's sweep and gather: `lines` as the intervisibility line view (samples,
// counts, ...), `bounce` with the attributes (radiance per entry, the receivers' normals)
// and the gathered irradiance per receiver entry, all in canonical step-major order.
struct BounceLineView {
  IntervisibilityLines lines;
  BounceLines bounce;
};

// The kernel's view (attributes left empty: the kernel samples them itself).
BounceLineView bounceLinesOnDevice(const ComputeContext& context, const HeightField& field,
                                   const BounceInputs& inputs, const TreeDirection& direction,
                                   const HullTreeTuning& tuning = {});

// The scalar reference's; `all_horizons`: every sample reads its horizons (as the kernel
// with per-entry statistics), else receivers only.
BounceLineView referenceBounceLines(const HeightField& field, const BounceInputs& inputs,
                                    const TreeDirection& direction, const HullTreeTuning& tuning = {},
                                    bool all_horizons = true);

}  // namespace hfvis::detail
