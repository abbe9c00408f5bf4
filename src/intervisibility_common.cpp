// intervisibility_common.cpp: option validation, direction geometry and the limits that
// the intervisibility device path and its scalar reference share.
#include <algorithm>
#include <cmath>
#include <string>

#include "hfvis/errors.hpp"
#include "intervisibility_internal.hpp"

namespace hfvis {

std::optional<HullTreeTuning> hullTreeTuningNamed(const std::string& name) {
  HullTreeTuning t;
  if (name == "plain") {
    t.deferred_writes = t.replacement_check = false;
  } else if (name == "deferred") {
    t.replacement_check = false;
  } else if (name == "zone") {
    t.safe_zone = true;
  } else if (name != "default") {
    return std::nullopt;
  }
  return t;
}

void validate(const HullTreeTuning& tuning) {
  if (tuning.replacement_check && !tuning.deferred_writes) {
    throw InvalidArgument("the replacement check needs the deferred-writes walk (it works inside it)");
  }
  if (tuning.safe_zone && !tuning.replacement_check) {
    throw InvalidArgument("the safe zone needs the replacement check");
  }
  const int z = tuning.safe_zone_steps;
  if (z < 1 || z > 4096 || (z & (z - 1)) != 0) {
    throw InvalidArgument("the safe zone's steps must be a power of two in 1 .. 4096, not " + std::to_string(z));
  }
}

void validate(const IntervisibilityOptions& options, const IntervisibilityOutputs& outputs) {
  validate(static_cast<const SweepOptions&>(options));
  validate(options.tree);
  if (!outputs.visible_count && !outputs.visible_area && !outputs.statistics) {
    throw InvalidArgument("no output requested");
  }
  if (outputs.statistics && options.method != IntervisibilityMethod::HullTree) {
    throw InvalidArgument("statistics (horizons and iterations) exist only for the hull-tree method");
  }
}

namespace detail {

float intervisibilitySector(const IntervisibilityOptions& options) {
  return static_cast<float>(2.0 * M_PI / options.directions);
}

void checkLineLimits(const std::vector<SweepDirection>& directions,
                     const std::vector<float>& prepared_heights, const IntervisibilityOutputs& outputs) {
  int longest = 0;
  for (const auto& d : directions) longest = std::max(longest, d.n_steps);
  if (longest >= (1 << 24)) {
    throw InvalidArgument("a sweep line would have " + std::to_string(longest) +
                          " samples; at most 2^24 are supported: lower the samples per unit");
  }
  // Distance sums of one receiver: at most longest^2 / 2 steps, kept in 32 bits.
  if (outputs.visible_area && static_cast<double>(longest) * longest / 2.0 >= 4294967295.0) {
    throw InvalidArgument(
        "a sweep line would have " + std::to_string(longest) +
        " samples, too many for the visible area (at most 92681): lower the samples per unit");
  }
  float highest = 0.0f;  // prepared heights are >= 0 (offset by the lowest one)
  for (float h : prepared_heights)
    if (!std::isnan(h)) highest = std::max(highest, std::fabs(h));
  if (!(static_cast<double>(highest) * 4.0 * longest < 1e37)) {
    throw InvalidArgument("the height range times the z-scale is too large for single precision (" +
                          std::to_string(highest) + "): lower the z-scale");
  }
}

}  // namespace detail
}  // namespace hfvis
