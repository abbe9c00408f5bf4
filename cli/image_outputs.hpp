// cli/image_outputs.hpp: how the CLI names and previews what it writes. Not the library's (a
// library user names channels and draws previews as they like); the tests include it from cli/.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "hfvis/height_field.hpp"

namespace hfvis::cli {

// Zero-padded channel names whose sorted order is the direction order: h000, h001, ...
// Throws InvalidArgument for a negative count.
std::vector<std::string> directionChannelNames(const std::string& prefix, int count);

// The q-quantiles of a plane's finite values for q = lo_q and hi_q (nearest rank), to stretch a
// preview's contrast over the values most pixels hold: a sky-view factor of 0.85 .. 1 over most
// of a DEM reads as grey on 0 .. 1. (0, 0) when no value is finite.
std::pair<float, float> quantileRange(const std::vector<float>& plane, double lo_q = 0.01,
                                      double hi_q = 0.99);

// A hillshade in 0 .. 1 (light from the north-west, 45 degrees up), under the previews of what
// an observer sees (viewshed, pvs).
std::vector<float> hillshade(const HeightField& field);

}  // namespace hfvis::cli
