// hfvis/insolation.hpp: sunshine hours and direct irradiation over a span of time at one place
// (GRASS r.sun's and WhiteboxTools' TimeInDaylight question): the sun's positions step by step,
// one horizon sweep per bucket of sun azimuths, the sun's disc seen above each pixel's horizon as
// computeSunShading sees it (hfvis/sun_shading.hpp).
#pragma once

#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/height_field.hpp"
#include "hfvis/sweep_options.hpp"

namespace hfvis {

// The least InsolationOptions::azimuth_bucket_deg taken: finer than the sun's own disc many times
// over, and a bucket's index (the azimuth over it) stays an integer.
constexpr double kLeastAzimuthBucketDeg = 0.001;

// Sunlight over a span of time at one place: GRASS r.sun's and WhiteboxTools' TimeInDaylight
// question. The span [from, to) is cut into steps of step_minutes (the last one shorter), each
// taken at its middle. The sun counts at a step while its centre is above the pixel's horizon in
// its azimuth and above the astronomical horizon (terrain beyond the field is taken as level at
// the pixel's height: the horizon is at least 0 there); steps with the whole disc below elevation
// 0 are skipped. Steps whose sun azimuths fall in one bucket of azimuth_bucket_deg share one
// horizon sweep, along the cheapest integer step within half a bucket of the bucket's centre (so
// within a bucket of every sun it lights; the closest step where none is that close), so a year
// costs a few hundred sweeps, not one per step.
struct InsolationOptions {
  double latitude_deg = 0.0, longitude_deg = 0.0;
  double from_utc = 0.0, to_utc = 0.0;  // seconds since 1970 (parseUtcTime), from < to
  double step_minutes = 10.0;           // (0, 1440]
  double size_deg = 0.53;               // the sun's disc, as SunLight
  double azimuth_bucket_deg = 0.25;     // [kLeastAzimuthBucketDeg, 10]
  bool apparent = false;                // refraction lifts the sun (sunPosition)
};

struct InsolationResult {
  int width = 0;
  int height = 0;
  // Hours with the sun's centre above the horizon; NaN at nodata.
  std::vector<float> sun_hours;
  // The direct irradiation from a sun of normal irradiance 1: the sum over steps of hours times
  // the disc's seen part times max(0, n . s), in hours (times the normal irradiance, W / m^2,
  // it is Wh / m^2); NaN at nodata.
  std::vector<float> direct;
  int steps = 0;   // steps with the sun up
  int sweeps = 0;  // horizon sweeps run (azimuth buckets)
};

// Throws InvalidArgument for options outside the ranges above, a span that does not run
// forward or holds over 10 million steps, or a place or time sunPosition refuses.
void validate(const InsolationOptions& options);

// Throws InvalidArgument for a bad field, options (validate) or sweep options, and what computeHorizons throws. `progress` of `sweep` counts
// buckets.
InsolationResult computeInsolation(const ComputeContext& context, const HeightField& field,
                                   const InsolationOptions& options, const SweepOptions& sweep = {});

}  // namespace hfvis
