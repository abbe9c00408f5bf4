// hfvis/shading.hpp: a height field lit by the sun: how much of the sun's disc each point
// sees above its own horizon, and the direct irradiance that brings.
//
// The sun is a disc of angular diameter `size_deg` (0.53 degree by default) at compass azimuth
// and elevation (hfvis/sun.hpp; over a field whose row 0 is north, hfvis azimuth = compass
// azimuth - 90 degrees). Only the sun's azimuth is swept: the horizon of every pixel in that
// one direction, along the sweep's cheapest integer step within 0.02 degree of it (far inside the
// disc's 0.265 degree radius; next to the axes a step of up to 1415 pixels, which costs as many
// samples per pixel; the swept azimuth is returned), and the part of the disc above that
// horizon, taken as a straight line across the disc (the horizon's slope across a disc's width
// is left out).
#pragma once

#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/height_field.hpp"
#include "hfvis/sun.hpp"
#include "hfvis/sweep_options.hpp"

namespace hfvis {

struct SunLight {
  SunPosition position;   // compass azimuth and elevation, degrees
  double size_deg = 0.53;  // the disc's angular diameter, degrees, 0 (a point: hard shadows) to 10
};

struct SunShading {
  int width = 0;
  int height = 0;
  double azimuth = 0.0;      // the swept direction's hfvis azimuth, radians
  std::vector<float> sun;     // the fraction of the disc above the horizon, 0 .. 1; NaN at nodata
  std::vector<float> direct;  // sun * max(0, n . s): the irradiance from a sun of normal irradiance 1
};

// The fraction of a disc of angular radius `radius` whose centre stands `above` (radians)
// above a straight horizon line: 1 - (acos(t) - t sqrt(1 - t^2)) / pi, t = above / radius
// clamped to [-1, 1]. A point sun (radius 0): 1 above, 0 below, 1/2 on the line.
double discAboveHorizon(double above, double radius);

// Sweeps the sun's azimuth over `field` (options: samples_per_unit, curvature, max_distance,
// memory budget and progress; directions and azimuth_offset are set by the sun). Normals are
// those of ambient occlusion (each row's cell sizes on latitude / longitude grids). The disc is
// seen above the pixel's horizon and above elevation 0 (terrain beyond the field taken as level,
// as computeInsolation takes it), so a sun below the astronomical horizon lights nothing. Throws
// InvalidArgument for a bad field, options or sun (size outside [0, 10] degrees, a non-finite
// position), and what computeHorizons throws.
SunShading computeSunShading(const ComputeContext& context, const HeightField& field, const SunLight& sun,
                             const SweepOptions& options = {});

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
  double azimuth_bucket_deg = 0.25;     // (0, 10]
  bool apparent = false;                // refraction lifts the sun (sunPosition)
};

struct Insolation {
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
Insolation computeInsolation(const ComputeContext& context, const HeightField& field,
                             const InsolationOptions& options, const SweepOptions& sweep = {});

}  // namespace hfvis
