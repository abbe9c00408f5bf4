// hfvis/sweep_options.hpp: the options every sweep operation shares: directions, sampling
// density along the sweep lines and rays, device memory budget and progress. (The sweeps run
// one line through every pixel centre per direction: there is no density across lines.)
//
// Direction k of K has azimuth phi_k = 2*pi*k/K + azimuth_offset, measured on the ground
// in the (column, row) axes, so the ground direction is (cos phi_k, sin phi_k); with square
// cells this is the pixel-axes direction itself (docs/CONVENTIONS.md). Compass azimuth
// (clockwise from north = row -1) is 90 deg + phi in degrees when rows run south.
#pragma once

#include <cstddef>
#include <functional>

namespace hfvis {

// Earth curvature and atmospheric refraction, as GRASS r.viewshed and gdal_viewshed take them:
// a point at ground distance d from the receiver lies drop = d^2 (1 - K) / (2 R) lower, K the
// refraction coefficient and R the Earth's radius, in metres (so the ground units must be
// metres). SweepOptions::curvature is the coefficient (1 - K) / (2 R) of d^2.
constexpr double kEarthRadius = 6370997.0;       // metres, GRASS's and GDAL's sphere
constexpr double kDefaultRefraction = 1.0 / 7.0;  // GRASS's and GDAL's default K
constexpr double earthCurvature(double refraction = kDefaultRefraction, double radius = kEarthRadius) {
  return (1.0 - refraction) / (2.0 * radius);
}

// The most directions a run takes: 0.0055 degrees apart, far finer than a height field
// resolves, and a bound that keeps a mistyped K from running for hours.
constexpr int kMaxDirections = 65536;

struct SweepOptions {
  int directions = 64;                  // K, 1 .. kMaxDirections
  double azimuth_offset = 0.0;          // radians added to every phi_k
  double samples_per_unit = 1.0;        // height samples per pixel length along a line or ray, (0, 64]
  // Drop coefficient c: a point at ground distance d from the receiver counts c d^2 lower
  // (earthCurvature() for the Earth with refraction, ground units metres); 0 = flat.
  // Every operation takes it but the bounce, which refuses it.
  double curvature = 0.0;
  // Only terrain within this ground distance of the receiver counts (ground units; 0 = the
  // whole field): horizons, sky-view factor, occlusion and intervisibility take it (exact, the
  // cut decided in float arithmetic); the horizon lists and the bounce refuse it.
  double max_distance = 0.0;
  // Device memory for one batch; 0 = half the device memory (a CPU device: half the host's).
  // The horizon operation runs a field beyond it in strips of rows (HorizonOptions::strip_rows).
  std::size_t memory_budget_bytes = 0;
  // Called after each batch of directions with (directions done, directions in all).
  std::function<void(int, int)> progress;
  // When a field runs in strips (HorizonOptions::strip_rows): called after each strip of the
  // direction under way with (strips done, strips in all).
  std::function<void(int, int)> strip_progress;
};

// Azimuth of direction k, in radians: 2 pi k / K + azimuth_offset, k / K taken in lowest terms, so
// that a direction two K share (every m-th of m K's is one of K's) has one azimuth, to the bit.
double directionAzimuth(int k, const SweepOptions& options);

// Throws InvalidArgument for K < 1, a sampling density outside (0, 64], an azimuth offset not
// finite or beyond two turns, a curvature not finite or beyond -1 .. 1 per ground unit, or a
// negative or non-finite maximum distance.
void validate(const SweepOptions& options);

}  // namespace hfvis
