// bench/region_visibility.hpp: region visibility's backends (hfvis/region_visibility.hpp) timed
// against each other, interleaved, on one field: area lights against the number of samples, the
// light's size and its height; region pairs against the regions' size and distance; and the
// visible fraction's error against a Monte-Carlo reference with 16 times the samples.
#pragma once

#include <string>
#include <vector>

#include "hfvis/device.hpp"

namespace hfvis::bench {

// Markdown tables on stdout for the field at `path`, the sections named in `sections` (arealight,
// arealight-quick, pair, error); the pairs take the fastest of `reps` interleaved runs, the area lights one.
void regionVisibilityReport(const ComputeContext& context, const std::string& path,
                            const std::vector<std::string>& sections, int reps);

}  // namespace hfvis::bench
