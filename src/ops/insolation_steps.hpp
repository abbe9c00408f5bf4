// insolation_steps.hpp: the sun's steps over a span of time, grouped into buckets of azimuth,
// and the horizon sweep each bucket runs (hfvis/insolation.hpp). Shared by computeInsolation
// and its scalar reference (testing/insolation_reference.cpp), so both take the same steps and
// sweep the same directions.
#pragma once

#include <map>
#include <vector>

#include "hfvis/horizon.hpp"
#include "hfvis/insolation.hpp"

namespace hfvis::detail {

// One step with the sun up: its unit vector over the field (x, y, z), its elevation in radians
// and its duration in hours (the span's last step may be shorter).
struct SunStep {
  float x = 0.0f, y = 0.0f, z = 0.0f, elevation = 0.0f;
  float hours = 0.0f;
};

// The sun's disc radius in radians; a point sun (size 0) as a disc far below a float's
// resolution of the elevations, so that disc_above never divides by 0.
double sunDiscRadius(const InsolationOptions& options);

// The steps with some of the disc above elevation 0, keyed by azimuth bucket (the bucket's
// centre is key * azimuth_bucket_deg, compass degrees). options must be valid.
std::map<long, std::vector<SunStep>> sunStepsByBucket(const InsolationOptions& options);

// The one-direction horizon sweep of a bucket: its centre azimuth, along a step within half a
// bucket of it, with `sweep`'s sampling, curvature, distance and budget (no progress).
HorizonOptions bucketSweep(long bucket, const InsolationOptions& options, const SweepOptions& sweep);

}  // namespace hfvis::detail
