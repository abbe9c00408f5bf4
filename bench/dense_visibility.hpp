// bench/dense_visibility.hpp: the dense references of the visible counts (issue 8, target e;
// issue 25: also dense in azimuth) and the "city" surface model the intervisibility suite
// measures them on.
//
// What the library's count is (hfvis/intervisibility.hpp): per pixel, the visible samples
// summed over the K directions, at samples_per_unit S samples per pixel length along each
// ray; with S = 1 that is, per direction, about the visible length of the ray in pixel
// lengths. The reference measures that length densely: for each pixel p (height h0, its own)
// and each direction k (azimuth phi_k = 2 pi k / K + azimuth_offset, the library's
// directionAzimuth; on the ground (cos phi_k, sin phi_k) in (column, row) axes, i.e. in pixel
// axes (cos phi_k / cell_size_x, sin phi_k / cell_size_y), normalised to one pixel length, as
// the library's rays), it samples the bilinear surface at t = j / D pixel lengths, j = 1, 2,
// ..., while the point stays inside the bilinear domain [0, W-1] x [0, H-1]. A sample is
// visible when its slope (h(t) - h0) / t is >= the largest slope of every earlier sample
// (ties visible, the library's rule); the direction's reference count is (visible samples) / D,
// summed over the K directions. Heights are multiplied by the field's z_scale (the ordering of
// slopes along one ray does not depend on it, nor on the cell size: the ground distance is t
// times a constant of the ray, so t in pixel lengths is what the count is in).
//
// Exact ties matter: flat roofs and tilted planes make samples whose slopes are equal in exact
// arithmetic, and rounding noise would hide most of them. The reference computes in double,
// interpolates as a + (b - a) f (exact on flat cells) and counts a sample visible when its
// slope is within kDenseTieTolerance x (the field's height range, z-scaled) / t of the largest
// earlier slope: about 1e-9 of the relief, far above double rounding (1e-16) and far below
// any feature of a height field. Nodata is not handled (the suite's fields have none).
#pragma once

#include <cstdint>
#include <vector>

#include "hfvis/height_field.hpp"
#include "hfvis/sweep_options.hpp"

namespace hfvis::bench {

constexpr double kDenseTieTolerance = 1e-9;

// One direction of the reference: its ground azimuth (radians, the library's convention) and
// the weight its visible length is summed with.
struct DenseRay {
  double azimuth = 0.0;
  double weight = 1.0;
};

// Reference visible counts, width * height, in samples at one per pixel length: per pixel the
// sum over `rays` of weight x (visible length along the ray in pixel lengths), from a march of
// `per_unit` samples per pixel length (D). Multithreaded over rows (std::thread,
// hardware_concurrency threads). With per_unit = 1 it is a host unit march: the library's
// naive march's samples, decided in double with the tolerance above.
std::vector<double> denseVisibleCounts(const HeightField& field, const std::vector<DenseRay>& rays,
                                       int per_unit);

// The same per ray, unweighted: element [j][pixel] is ray j's visible length from that pixel.
std::vector<std::vector<double>> denseVisibleLengths(const HeightField& field,
                                                     const std::vector<DenseRay>& rays, int per_unit);

// The same over the K directions of `options` (phi_k = 2 pi k / K + azimuth_offset), weight 1
// each: what the naive march's count estimates.
std::vector<double> denseVisibleCounts(const HeightField& field, const SweepOptions& options, int per_unit);

// `n` directions evenly spaced from azimuth 0, each of weight 1 / n: dense in azimuth, their sum
// estimates the visible length's mean over the azimuth, 1 / (2 pi) times its integral. A
// K-direction count estimates K times that, whatever its directions.
std::vector<DenseRay> azimuthDenseRays(int n);

// A city-like surface model, width x height, cell size 1, z_scale 1, heights in pixel
// lengths: a street grid (streets 4-6 pixels wide, city blocks 30-60 pixels) on a gently
// tilted plane (rising 1/32 per pixel along the columns and 1/64 along the rows, exact in
// float), each city block filled with flat-roofed rectangular buildings (footprints 4-20
// pixels a side, 1-3 pixel alleys between them, roofs 5-40 in steps of 0.25 above the highest
// ground under the footprint).
// Deterministic for a seed (its own generator, no std distributions).
HeightField makeCityField(int width, int height, std::uint32_t seed);

}  // namespace hfvis::bench
