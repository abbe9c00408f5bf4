// environment_light.cpp: the irradiance from an HDR environment (hfvis/environment_light.hpp):
// the horizon operation with this output alone (its tables: src/core/environment_swaths.hpp), and
// with a maximum error its runs at K and K / 2 until their difference meets it.
#include "hfvis/environment_light.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include "hfvis/errors.hpp"
#include "core/horizon_common.hpp"
#include "ops/environment_light_result.hpp"

namespace hfvis {
namespace {

EnvironmentLightResult runAt(const ComputeContext& context, const HeightField& field,
                             const EnvironmentMap& map, const HorizonOptions& options) {
  HorizonOutputs outputs;
  outputs.environment = &map;
  return detail::environmentLightResult(computeHorizons(context, field, options, outputs), map);
}

// The estimate (EnvironmentLightResult::error_estimate) of `result` from `coarse`, runs at half its
// directions (the even ones and the odd ones): per pixel the larger difference.
void estimateFrom(EnvironmentLightResult& result, const std::vector<std::vector<float>>& coarse) {
  const std::size_t pixels = static_cast<std::size_t>(result.width) * result.height;
  const std::size_t channels = pixels ? result.irradiance.size() / pixels : 0;
  result.error_estimate.assign(pixels, 0.0f);
  for (std::size_t c = 0; c < channels; ++c) {
    const float* fine = &result.irradiance[c * pixels];
    double total = 0.0;
    std::size_t with_data = 0;
    for (std::size_t p = 0; p < pixels; ++p)
      if (!std::isnan(fine[p])) total += fine[p], ++with_data;
    const double mean = with_data ? total / with_data : 0.0;
    for (const std::vector<float>& half : coarse)
      for (std::size_t p = 0; p < pixels; ++p) {
        const double difference = std::abs(static_cast<double>(fine[p]) - half[c * pixels + p]);
        float& e = result.error_estimate[p];
        e = std::isnan(fine[p]) ? fine[p]
                                : std::max(e, static_cast<float>(mean > 0.0 ? difference / mean : 0.0));
      }
  }
  result.estimated_error = detail::estimatedError(result.error_estimate);
}

}  // namespace

EnvironmentLightResult computeEnvironmentLight(const ComputeContext& context, const HeightField& field,
                                               const EnvironmentMap& map, const HorizonOptions& options) {
  if (options.error_tile != 0)
    throw InvalidArgument("the environment light takes one K for the whole field: error_tile must be 0");
  if (options.max_error == 0.0) return runAt(context, field, map, options);
  if (!(options.max_error > 0.0 && options.max_error < 1.0))
    throw InvalidArgument("the maximum error must be in (0, 1): it is relative to the mean irradiance (got " +
                          std::to_string(options.max_error) + ")");
  HorizonOptions attempt = options;
  attempt.max_error = 0.0;
  return detail::runForMaxError<EnvironmentLightResult>(options.max_error, [&](int directions) {
    // At K / 2 twice: on K's even directions, and on its odd ones (turned by one step of K). A
    // source narrower than a swath (a sun) lights a pixel through the one direction whose swath
    // holds it, so its shadow's edge lies where the horizon in that direction crosses it. Where the
    // sun's nearest direction at K is one of the even ones, the run on them puts every shadow where
    // the run at K does, and their difference misses how far the shadows are from their place (on
    // a 64^2 city under a clear sky: 0.04 against 1.7, relative to the mean); the odd ones then put
    // them a step of K away.
    std::vector<std::vector<float>> coarse;
    attempt.directions = directions / 2;
    for (const int turn : {0, 1}) {
      attempt.azimuth_offset = options.azimuth_offset + turn * 2.0 * M_PI / directions;
      coarse.push_back(runAt(context, field, map, attempt).irradiance);
    }
    attempt.directions = directions;
    attempt.azimuth_offset = options.azimuth_offset;
    EnvironmentLightResult result = runAt(context, field, map, attempt);
    estimateFrom(result, coarse);
    return result;
  });
}

}  // namespace hfvis
