// cli/commands/environment_light.cpp: the environment's light in "hfvis shade --env": the
// irradiance from an HDR environment above each point's horizons (hfvis/environment_light.hpp).
#include "light_parts.hpp"

namespace hfvis::cli {

void EnvironmentLight::read() {
  map_ = readEnvironmentMap(run_.environment);
  map_.rotation_deg = run_.environment_rotation_deg;
  map_.table_rows = run_.environment_rows;
}

void EnvironmentLight::compute(Job& job, const NorthUp& lit, const HorizonOptions& options) {
  const HeightField& field = lit.field();
  result_ = job.progress.run([&] { return computeEnvironmentLight(*job.context, field, map_, options); });
  requireSize(result_.irradiance, field.pixelCount() * map_.channels, "irradiances");
  requireFiniteResult(result_.irradiance, field, "irradiance");
  lit.restore(result_.irradiance);
  if (!result_.error_estimate.empty()) lit.restore(result_.error_estimate);
}

void EnvironmentLight::describe(LitOutput& output, std::size_t pixels) const {
  output.attributes.emplace_back("hfvis:environment", run_.environment);
  output.attributes.emplace_back("hfvis:environment_rotation_deg",
                                 formatNumber(run_.environment_rotation_deg));
  output.attributes.emplace_back("hfvis:environment_table_rows", std::to_string(tableRows(map_)));
  output.names = map_.names;
  output.planes = splitPlanes(result_.irradiance, pixels, map_.channels);
  output.quantity = map_.names.size() == 1 ? "Y" : "R, G, B";
  output.quantity += ": the irradiance from the environment above each point's horizons, for its normal; ";
  output.units =
      "the environment's radiance times steradians (a uniform radiance of 1 gives pi on open flat ground); ";
  output.note += "; mean irradiance " + formatFixed(finiteMean(result_.irradiance), 4);
  // The K run, which --max-error chooses, and the error estimate when there is one.
  for (auto& [name, value] : output.attributes)
    if (name == "hfvis:directions") value = std::to_string(result_.directions);
  if (run_.max_error > 0.0) {
    output.attributes.emplace_back("hfvis:max_error", formatNumber(run_.max_error));
    output.attributes.emplace_back("hfvis:estimated_error", formatNumber(result_.estimated_error));
    output.note += "; estimated error (99th percentile, relative to the mean irradiance) " +
                   formatFixed(result_.estimated_error, 4) + " for --max-error " +
                   formatNumber(run_.max_error);
  }
}

}  // namespace hfvis::cli
