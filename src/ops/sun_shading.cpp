// sun_shading.cpp: the sun's light on a height field (see hfvis/sun_shading.hpp): one horizon sweep in
// the sun's azimuth, then per pixel the visible part of the disc and the direct irradiance.
#include "hfvis/sun_shading.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "hfvis/errors.hpp"
#include "hfvis/horizon.hpp"
#include "core/horizon_common.hpp"
#include "core/unit_normals.hpp"
#include "ops/sun_shading_pixels.hpp"

namespace hfvis {

double discAboveHorizon(double above, double radius) {
  if (radius <= 0.0) return above > 0.0 ? 1.0 : above < 0.0 ? 0.0 : 0.5;  // a point sun
  const double t = std::clamp(above / radius, -1.0, 1.0);
  return 1.0 - (std::acos(t) - t * std::sqrt(1.0 - t * t)) / M_PI;
}

namespace detail {

HorizonOptions sunSweep(const SunLight& sun, const SweepOptions& options) {
  constexpr double kDegree = M_PI / 180.0;
  // The sun's azimuth alone, at an exact step: hfvis azimuth = compass - 90 degrees.
  HorizonOptions horizon;
  static_cast<SweepOptions&>(horizon) = options;
  horizon.directions = 1;
  horizon.azimuth_offset = std::remainder((sun.position.azimuth_deg - 90.0) * kDegree, 2.0 * M_PI);
  horizon.azimuth_tolerance = 0.02 * kDegree;
  return horizon;
}

SunShadingResult sunShadingFromHorizons(const HeightField& field, const SunLight& sun, const std::vector<float>& angles,
                                        double azimuth) {
  constexpr double kDegree = M_PI / 180.0;
  SunShadingResult out;
  out.width = field.width;
  out.height = field.height;
  out.azimuth = azimuth;
  const std::size_t plane = field.pixelCount();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  out.sun.assign(plane, nan);
  out.direct.assign(plane, nan);
  const double elevation = sun.position.elevation_deg * kDegree, radius = 0.5 * sun.size_deg * kDegree;
  const glm::dvec3 s = sunDirection(sun.position);
  const std::vector<float> normals = detail::unitNormals(field);
  for (std::size_t p = 0; p < plane; ++p) {
    const float* n = &normals[4 * p];
    if (std::isnan(n[0])) continue;
    // Terrain beyond the field is taken as level, as computeInsolation takes it: a sun below
    // elevation 0 lights nothing, not even a pixel whose own horizon lies lower.
    const double seen = discAboveHorizon(elevation - std::max(0.0, double(angles[p])), radius);
    const double cosine = n[0] * s.x + n[1] * s.y + n[2] * s.z;
    out.sun[p] = static_cast<float>(seen);
    out.direct[p] = static_cast<float>(seen * std::max(0.0, cosine));
  }
  return out;
}

}  // namespace detail

SunShadingResult computeSunShading(const ComputeContext& context, const HeightField& field, const SunLight& sun,
                                   const SweepOptions& options) {
  validate(field);
  if (!(sun.size_deg >= 0.0 && sun.size_deg <= 10.0))
    throw InvalidArgument("the sun's size must be in [0, 10] degrees (got " + std::to_string(sun.size_deg) +
                          ")");
  // (two turns at most, as the azimuth offset: 1e20 degrees kept no fraction of a turn, and lit
  // as another azimuth, exit 0)
  if (!(std::fabs(sun.position.azimuth_deg) <= 720.0) || !(std::fabs(sun.position.elevation_deg) <= 90.0))
    throw InvalidArgument("the sun's azimuth must lie in -720 .. 720 degrees and its elevation in -90 .. 90");
  HorizonOutputs outputs;
  outputs.horizon_angles = true;
  const HorizonResult horizons = computeHorizons(context, field, detail::sunSweep(sun, options), outputs);
  return detail::sunShadingFromHorizons(field, sun, horizons.angles, horizons.azimuths.at(0));
}

}  // namespace hfvis
