// reference_internal.hpp: line-level pieces of the scalar horizon reference, for tests
// that compare a sweep line by line.
#pragma once

#include <vector>

#include "hfvis/height_field.hpp"
#include "sweep_geometry.hpp"

namespace hfvis::detail {

// Presampled heights and hull-stack occluders of every line of one direction, laid out as
// the kernels' line buffer (entry (step i, line j) at i * n_lines + j): the occluder's
// height above the sample (rise) and its step (-1 = none).
struct LineOccluders {
  std::vector<float> samples;
  std::vector<float> rises;
  std::vector<float> steps;
};

LineOccluders referenceSweepLines(const HeightField& field, const std::vector<float>& prepared_heights,
                                  const SweepDirection& direction);

}  // namespace hfvis::detail
