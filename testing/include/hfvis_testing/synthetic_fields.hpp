// hfvis_testing/synthetic_fields.hpp: the hard cases (docs/TESTING.md) as generated height fields,
// shared by the tests and the benchmark so both exercise the same inputs (test support
// library hfvis_testing; not installed).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hfvis/height_field.hpp"

namespace hfvis {

// Names: city (a city DSM: flat ground, flat roofs of many heights, one-pixel streets and
// walls, buildings touching only at a corner, courtyards, towers, a street grid along the axes
// and one rotated off them), flat, tilted_plane (8848 + 0.001 x), terraces, cliff (1e6 high),
// spikes, sine, bowl, dome, noise, nan_holes, infinities, denormals, negative. Deterministic
// for a seed.
HeightField makeSyntheticField(const std::string& name, int width, int height, std::uint32_t seed = 1);

// Every name makeSyntheticField accepts.
const std::vector<std::string>& syntheticFieldNames();

}  // namespace hfvis
