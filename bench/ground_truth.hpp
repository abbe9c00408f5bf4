// bench/ground_truth.hpp: the oracle every method's error is measured against: the exact
// horizon of the bilinear surface (README's conventions: the supremum over all t > 0, not
// over samples), in double precision, in the exact direction from the exact pixel, for a
// random subset of receivers; computed on all cores and cached on disk.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "hfvis/height_field.hpp"

namespace hfvis::bench {

// Horizon angles (radians) of `receivers` (pixel indices row * width + col, ascending) in
// directions phi_k = 2 pi k / directions; angle of receiver n, direction k at
// angles[n * directions + k].
struct GroundTruth {
  int width = 0;
  int height = 0;
  int directions = 0;
  std::vector<std::int32_t> receivers;
  std::vector<double> angles;
  double seconds = 0.0;  // time it took to compute (0 when read from the cache)
  bool from_cache = false;

  double angle(std::size_t receiver, int k) const { return angles[receiver * directions + k]; }
};

// A ray from pixel (c, r) in ground azimuth `azimuth`: its direction in pixel axes and the
// ground length of one pixel-axis unit along it (as makeSweepDirection in the library).
struct Ray {
  double dx = 0.0, dy = 0.0;
  double ground_per_unit = 1.0;
};
Ray rayForAzimuth(const HeightField& field, double azimuth);

// Exact horizon (radians) of the bilinear surface seen from pixel (c, r) along `ray`: the
// ray is cut at every grid line it crosses; on each cell the surface is a quadratic in t,
// so the largest elevation over the piece is at an end or where d/dt (h(t) - h0) / t = 0.
// Near the receiver this is the surface's slope, the limit t -> 0. -pi/2 when the ray
// leaves the field at once, NaN from a nodata receiver. Heights are used times z_scale; nodata
// (every non-finite height) as the surface model has it: a cell with a nodata corner has no
// surface inside, an edge with a nodata end none along it, a valid grid point is surface.
double exactHorizon(const HeightField& field, int c, int r, const Ray& ray);

// The same by dense sampling (every `step` pixels, plus the exit point): the check that
// exactHorizon is the limit of a dense march (fields without nodata).
double denseHorizon(const HeightField& field, int c, int r, const Ray& ray, double step);

// `receiver_count` receivers drawn uniformly without replacement among the pixels with a height
// (all of them when there are fewer), fixed seed; `threads` workers.
GroundTruth computeGroundTruth(const HeightField& field, int directions, int receiver_count, int threads);

// computeGroundTruth, cached in `cache_dir` under a name made of `label` and a hash of the
// field's heights, cell sizes and z-scale, the direction and receiver counts.
GroundTruth cachedGroundTruth(const HeightField& field, const std::string& label, int directions,
                              int receiver_count, int threads, const std::string& cache_dir);

// Self-checks of the oracle: analytic cases (plane, tilted plane, wall, spike) and the dense
// march on random fields. Returns the failures (empty when all pass) and fills `summary`
// with the largest differences seen, for the report.
std::vector<std::string> checkGroundTruth(std::string* summary);

}  // namespace hfvis::bench
