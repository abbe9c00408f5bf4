// horizon_device.hpp: internal entry points of the horizon device path that tests use to
// look inside a sweep (the line buffers of one direction).
#pragma once

#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/height_field.hpp"
#include "sweep_geometry.hpp"

namespace hfvis::detail {

// One direction's line buffers as the kernels left them, in step-major order whatever the
// device's layout: entry (step i, line j) at i * geometry.n_lines + j. `samples` are the presampled heights (NaN = no sample);
// `occluder_rises` (occluder height - sample height) and `occluder_steps` what the
// hull-stack sweep recorded (step -1 = none).
struct SweepLineBuffers {
  SweepDirection geometry;
  std::vector<float> samples;
  std::vector<float> occluder_rises;
  std::vector<float> occluder_steps;
};

// Runs the presampling and hull-stack sweep kernels for one direction on prepared
// heights (see prepareHeights) and downloads both stages.
SweepLineBuffers sweepLinesOnDevice(const ComputeContext& context, const HeightField& field,
                                    const std::vector<float>& prepared_heights, const SweepDirection& direction);

}  // namespace hfvis::detail
