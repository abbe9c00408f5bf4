// bench/lighting.hpp: environment lighting's benchmark pieces (bench/lighting.cpp).
#pragma once

#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/environment_light.hpp"
#include "hfvis/height_field.hpp"

namespace hfvis::bench {

// The Monte-Carlo reference's irradiance per channel plane, and its own noise (half the difference
// of its two halves) per value.
struct LightingReference {
  int channels = 0;
  int samples = 0;        // random directions per pixel (both halves)
  int bright_pixels = 0;  // map pixels integrated on a grid instead
  std::vector<double> irradiance, noise;
};

// About `samples` directions per pixel (bench/lighting.cpp has the method).
LightingReference monteCarloIrradiance(const HeightField& field, const EnvironmentMap& map, int samples);

// The fastest of `reps` computeHorizons calls lighting `field` with `map` from K directions, s.
double timeEnvironmentLighting(const ComputeContext& context, const HeightField& field, const EnvironmentMap& map,
                               int directions, int reps);

}  // namespace hfvis::bench
