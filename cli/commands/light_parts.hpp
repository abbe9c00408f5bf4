// cli/commands/light_parts.hpp: the two lights "hfvis shade" composes in one pass and one output:
// an HDR environment's (environment_light.cpp, hfvis/environment_light.hpp) and the sun's
// (sun_shading.cpp, hfvis/sun_shading.hpp). Each is computed on the north-up field and brought
// back to the input's order, and adds its channels, attributes and summary note to the output.
#pragma once

#include <optional>
#include <string>
#include <vector>

#include "../pipeline.hpp"
#include "hfvis/environment_light.hpp"
#include "hfvis/environment_map.hpp"
#include "hfvis/horizon.hpp"
#include "hfvis/sun_shading.hpp"

namespace hfvis::cli {

// The channels of shade's output, as its parts add them.
struct LitOutput {
  Attributes attributes;
  std::vector<std::string> names;
  std::vector<std::vector<float>> planes;
  std::string quantity, units, note;
};

// --env ENV.exr: the irradiance from the environment above each point's horizons.
class EnvironmentLight {
 public:
  explicit EnvironmentLight(const RunArguments& run) : run_(run) {}
  bool given() const { return !run_.environment.empty(); }
  void read();  // the map, rotated and banded as asked
  void compute(Job& job, const NorthUp& lit, const HorizonOptions& options);
  void describe(LitOutput& output, std::size_t pixels) const;
  int channels() const { return map_.channels; }
  // Channel c's irradiance (width * height values from c * pixels on).
  const std::vector<float>& irradiance() const { return result_.irradiance; }
  // The K run (--max-error chooses it) and, with --max-error, the estimate (else empty).
  int directions() const { return result_.directions; }
  const std::vector<float>& errorEstimate() const { return result_.error_estimate; }

 private:
  const RunArguments& run_;
  EnvironmentMap map_;
  EnvironmentLightResult result_;
};

// The sun, --sun AZ,EL or where it stands at --at TIME from --lat, --lon: the part of its disc
// above each pixel's horizon and the direct irradiance.
class SunShading {
 public:
  explicit SunShading(const RunArguments& run);
  bool given() const { return sun_.has_value(); }
  void compute(Job& job, const NorthUp& lit, const HorizonOptions& options);
  void describe(LitOutput& output) const;
  const std::vector<float>& direct() const { return result_.direct; }

 private:
  std::optional<SunLight> sun_;
  SunShadingResult result_;
};

}  // namespace hfvis::cli
