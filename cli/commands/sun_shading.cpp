// cli/commands/sun_shading.cpp: the sun's light in "hfvis shade": the part of the sun's disc above
// each pixel's horizon and the direct irradiance (hfvis/sun_shading.hpp).
#include <cmath>

#include "hfvis/sun.hpp"
#include "light_parts.hpp"

namespace hfvis::cli {

SunShading::SunShading(const RunArguments& run) {
  if (!run.sun && !run.sun_time) return;
  sun_.emplace();
  sun_->size_deg = run.sun_size_deg;
  sun_->position = run.sun ? SunPosition{run.sun->first, run.sun->second}
                           : sunPosition(*run.sun_time, *run.latitude, *run.longitude);
}

void SunShading::compute(Job& job, const NorthUp& lit, const HorizonOptions& options) {
  const HeightField& field = lit.field();
  result_ = job.progress.run([&] { return computeSunShading(*job.context, field, *sun_, options); });
  requireSize(result_.sun, field.pixelCount(), "sun fractions");
  requireSize(result_.direct, field.pixelCount(), "direct irradiances");
  requireFiniteResult(result_.direct, field, "direct irradiance");
  lit.restore(result_.sun);
  lit.restore(result_.direct);
}

void SunShading::describe(LitOutput& output) const {
  output.attributes.emplace_back("hfvis:sun_azimuth_deg", formatNumber(sun_->position.azimuth_deg));
  output.attributes.emplace_back("hfvis:sun_elevation_deg", formatNumber(sun_->position.elevation_deg));
  output.attributes.emplace_back("hfvis:sun_size_deg", formatNumber(sun_->size_deg));
  output.attributes.emplace_back("hfvis:swept_azimuth_deg", formatNumber(result_.azimuth * 180.0 / M_PI));
  output.names.insert(output.names.end(), {"direct", "sun"});
  output.planes.insert(output.planes.end(), {result_.direct, result_.sun});
  output.quantity +=
      "sun: the fraction of the sun's disc above the pixel's horizon in the sun's azimuth; direct: sun * "
      "max(0, n . s), the irradiance from a sun of normal irradiance 1 (row 0 taken as north); ";
  output.units += "sun: 0..1; direct: the sun's normal irradiance; ";
  output.note += "; sun at " + formatFixed(sun_->position.azimuth_deg, 2) + " deg, " +
                 formatFixed(sun_->position.elevation_deg, 2) + " deg up; mean sun " +
                 formatFixed(finiteMean(result_.sun), 3);
}

}  // namespace hfvis::cli
