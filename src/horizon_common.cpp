// horizon_common.cpp: pieces shared by the horizon device path and its reference.
#include "horizon_common.hpp"

#include <cmath>
#include <limits>

#include "fast_math.hpp"
#include "hfvis/errors.hpp"

namespace hfvis {

void validate(const HorizonOptions& options, const HorizonOutputs& outputs) {
  validate(static_cast<const SweepOptions&>(options));
  if (!(options.azimuth_tolerance > 0.0) || !(options.azimuth_tolerance <= 0.1)) {
    throw InvalidArgument("the azimuth tolerance must be in (0, 0.1] radians, (0, 5.73] degrees (got " +
                          std::to_string(options.azimuth_tolerance * 180.0 / M_PI) + " degrees)");
  }
  if (!outputs.horizon_angles && !outputs.horizon_distances && !outputs.sky_view_factor &&
      !outputs.ambient_occlusion) {
    throw InvalidArgument("no output requested");
  }
}

namespace detail {

bool hasRowSpacing(const HeightField& field) { return !field.row_cell_size_x.empty(); }

void requireSupported(const HeightField& field, const HorizonOptions& options) {
  if (hasRowSpacing(field) && options.max_distance > 0.0)
    throw InvalidArgument("a maximum distance is not supported on a field with per-row spacing (a latitude / "
                          "longitude grid) yet: reproject it, or leave out the maximum distance");
}

HorizonResult allocateResult(const HeightField& field, const HorizonOptions& options,
                             const HorizonOutputs& outputs) {
  HorizonResult result;
  result.width = field.width;
  result.height = field.height;
  result.directions = options.directions;
  for (int k = 0; k < options.directions; ++k) result.azimuths.push_back(directionAzimuth(k, options));
  const std::size_t plane = field.pixelCount();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  if (outputs.horizon_angles) result.angles.assign(plane * options.directions, nan);
  if (outputs.horizon_distances) result.distances.assign(plane * options.directions, nan);
  if (outputs.sky_view_factor) result.sky_view_factor.assign(plane, 0.0f);
  if (outputs.ambient_occlusion) result.ambient_occlusion.assign(plane, 0.0f);
  return result;
}

std::vector<LatticeDirection> horizonDirections(const HeightField& field, const HorizonOptions& options,
                                                const HorizonOutputs& outputs) {
  const bool exact = outputs.horizon_angles || outputs.horizon_distances;
  return latticeDirections(field, options, exact, options.azimuth_tolerance);
}

float swathFactor(float weight) { return hfSin(kPiF * weight) / kPiF; }

void finishReduction(HorizonResult& result) {
  for (float& v : result.sky_view_factor) v = 1.0f - v;
}

}  // namespace detail
}  // namespace hfvis
