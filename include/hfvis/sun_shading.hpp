// hfvis/sun_shading.hpp: a height field lit by the sun: how much of the sun's disc each point
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

struct SunShadingResult {
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
SunShadingResult computeSunShading(const ComputeContext& context, const HeightField& field, const SunLight& sun,
                                   const SweepOptions& options = {});

}  // namespace hfvis
