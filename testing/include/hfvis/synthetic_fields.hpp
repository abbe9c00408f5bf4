// hfvis/synthetic_fields.hpp: the hard cases (README, Tests) as generated height fields,
// shared by the tests and the benchmark so both exercise the same inputs (test support
// library hfvis_testing; not installed).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hfvis/height_field.hpp"

namespace hfvis {

// Names: flat, tilted_plane (8848 + 0.001 x), terraces, cliff (1e6 high), spikes, sine,
// bowl, dome, noise, nan_holes, infinities, denormals, negative. Deterministic for a seed.
HeightField makeSyntheticField(const std::string& name, int width, int height, std::uint32_t seed = 1);

// Every name makeSyntheticField accepts.
const std::vector<std::string>& syntheticFieldNames();

}  // namespace hfvis
