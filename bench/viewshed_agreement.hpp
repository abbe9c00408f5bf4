// bench/viewshed_agreement.hpp: how well viewshed rasters (hfvis's, gdal_viewshed's) agree with
// the exact sight-line test on the bilinear surface (hfvis_testing/viewshed_reference.hpp), on a random
// sample of targets.
#pragma once

#include <string>
#include <vector>

#include "hfvis/viewshed.hpp"

namespace hfvis::bench {

struct ViewshedAgreement {
  std::string raster;
  std::size_t targets = 0;            // sampled targets in range with data in both
  std::size_t reference_visible = 0;  // of them, visible by the exact test
  std::size_t raster_visible = 0;     // visible (> 0) in the raster
  std::size_t both = 0;               // visible in both
  std::size_t grazing = 0;            // disagreements where the exact test itself turns with the eye 1e-4 higher or lower
  double jaccard() const {
    const std::size_t either = reference_visible + raster_visible - both;
    return either ? double(both) / either : 1.0;
  }
};

// Each raster (one band; visible where > 0, NaN or nodata left out) against the exact test from
// `observer` at `samples` targets drawn uniformly (seeded) from the field.
std::vector<ViewshedAgreement> viewshedAgreement(const HeightField& field, const Observer& observer,
                                                 const ViewshedOptions& options, const std::vector<std::string>& rasters,
                                                 std::size_t samples, unsigned seed);

}  // namespace hfvis::bench
