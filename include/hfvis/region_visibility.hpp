// hfvis/region_visibility.hpp: visibility between regions: per receiver, which samples of a
// source region (an area light, a wind farm, an antenna site) it sees, as a bitmask, and the
// fraction seen. After Eisemann & Décoret (2007, "Visibility sampling on GPU and
// applications"), who sample a source region and keep, per receiver sample, a bitmask of the
// visible source samples (soft shadows, region-to-region visibility).
//
// Sources: S samples of a rectangle of grid points (inclusive corners, in any order: the region
// spanned by their pixel centres, so a one-pixel rectangle is a point), each `height` above the
// bilinear surface under it, or at that absolute (z-scaled) height (an area light in a
// horizontal plane); or an explicit list of points. A rectangle's samples are stratified: rows of
// about sqrt(S * width / height) strata, so that they are about square (all in one row or column
// for a rectangle one point thick; the last row holds the rest, its strata wider), each sample
// jittered uniformly inside its stratum by a hash of (seed, the rectangle's corners, stream,
// sample), so results are deterministic, a rectangle draws the same samples as sources or as
// receivers, and two rectangles of one size draw unrelated jitters. With `decorrelate`, each receiver draws
// its own jitter of the sources (stream receiver + 1), trading the banding of shared samples for noise; else
// every receiver sees the same samples (stream 0).
//
// Receivers: every grid point, `target_height` above the surface (a pixel's height: nodata
// pixels receive nothing, their fraction NaN); or a second rectangle, sampled the same way with
// its own stream 0 (a region pair).
//
// A pair is visible as in the viewshed (hfvis/viewshed.hpp): the segment between the two points
// sees when no point of the bilinear surface strictly between them rises strictly above it (a
// segment that only touches the surface sees; an end below the surface is hidden, the surface
// rising above the segment beside it, except from a point straight above or below it: a vertical
// segment has no surface strictly between its ends and sees); a cell with a nodata corner has no surface
// inside and hides nothing, though an edge between two valid heights is surface. With curvature c, the
// surface at ground distance d from one end and D - d from the other lies c d (D - d) higher
// relative to the straight segment (the viewshed's c d^2 drop from an eye, the target lowered
// c D^2, written symmetrically). Pairs farther apart than max_distance are not visible. The test
// runs in single precision, the pair in a canonical order (so that A sees B exactly when B sees
// A), and forgives the heights' rounding as the viewshed's does: a segment is hidden only where
// the surface rises above it by more than 2^-21 of |its ends' heights| + |the curvature's c D^2|,
// and at a grid crossing also the surface's slope along that grid line times 2^-21 of (the ends'
// largest |column| + largest |row| + 2), what the crossing's position rounds by.
//
// Methods: the exact one, one line-of-sight march per (receiver, source sample) pair on the
// device (kernels/region_visibility.cl): O(receivers * S * (W + H)); the same march culled by a
// max pyramid (the same bits, sooner); one viewshed per source sample, for sources
// on grid points (RegionVisibilityMethod::Viewsheds); Eisemann & Décoret's bitmask scatter for
// a planar light (RegionVisibilityMethod::Bitmask: the cells back-projected onto the light's
// plane through a table of edge bitmasks, a conservative pair per cell, the samples between the
// pair decided by the culled march, so the bits are the exact method's); and the default,
// RegionVisibilityMethod::Auto, which takes the bitmask scatter or the culled march by the light
// and S. bench/report/region_visibility.md compares their speed.
#pragma once

#include <cstdint>
#include <functional>
#include <memory>
#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/height_field.hpp"

namespace hfvis {

// The most samples on either side of a region visibility (the bitmasks' bits).
constexpr int kMaxRegionSamples = 4096;
// The most source samples of the bitmask method (a work-item's masks in private memory).
constexpr int kMaxBitmaskSamples = 1024;
// From this many source samples on, RegionVisibilityMethod::Auto takes the bitmask method where
// it takes the light: on the 512^2 and 1024^2 fractal (bench/report/region_visibility.md, "Which
// method the default takes") it took 0.14 - 0.75 of the culled march's time at every S >= 64
// measured, for lights of 16 and 64 pixels 20 and 400 above the top; at S = 32 under the
// 64-pixel light the two were even (1.03 - 1.07), its cost per receiver shrinking less with S.
constexpr int kBitmaskFromSamples = 64;
// The least RegionVisibilityOptions::max_distance taken (its square, in float32, must not vanish).
constexpr double kLeastMaxDistance = 1e-18;

// A rectangle of grid points, corners included, in any order.
struct PixelRectangle {
  int col0 = 0, row0 = 0, col1 = 0, row1 = 0;
};

// A sample: pixel position (column, row; fractional between pixel centres) and height.
struct RegionPoint {
  double col = 0.0, row = 0.0;
  double height = 0.0;
};

struct RegionSampling {
  PixelRectangle rectangle;
  int samples = 16;       // S, 1 .. kMaxRegionSamples
  double height = 2.0;    // above the surface under each sample, or absolute (z-scaled units)
  bool absolute = false;  // `height` (and the points' heights) absolute
  // When not empty: these points are the samples (col, row inside the field; height as
  // `height` above, per point), and rectangle and samples are ignored.
  std::vector<RegionPoint> points;
};

enum class RegionVisibilityMethod {
  Exact,  // one line-of-sight march per pair (the reference of the other methods)
  // One viewshed per source sample (computeViewshed, hfvis/viewshed.hpp), its visible targets
  // gathered into the bits. Only for sources on grid points (a one-point rectangle, or points at
  // whole columns and rows), shared samples and every-pixel receivers (InvalidArgument
  // otherwise). The viewshed walks the same sight lines in its own float operations, from the
  // source's end: it decides some grazing lines the other way (not bit for bit: up to about
  // 0.1 % of the pairs on the hard cases, every one grazing).
  Viewsheds,
  // The exact march, culled: it leaps over every block of cells (a max pyramid, blocks of
  // 2^k x 2^k cells) whose highest point lies below the segment by more than the march's
  // rounding, resuming where the segment leaves the block in the march's own state, so its bits
  // are the exact method's, bit for bit, at a fraction of the steps.
  Culled,
  // The bitmask scatter of Eisemann & Décoret (2007) for a planar light (a rectangle at an
  // absolute height, or points all at one absolute height; shared samples, at most
  // kMaxBitmaskSamples, every-pixel receivers, no curvature, a field of cells (at least 2 x 2
  // points): InvalidArgument otherwise): per receiver, every cell that may reach the shaft to the light (a
  // max pyramid's blocks below it left out) is back-projected from the receiver onto the light's plane, and
  // the samples inside come from a table of edge bitmasks (RegionVisibilityOptions::
  // bitmask_table), ANDed per edge and ORed over the cells. The bilinear cell's back-projection
  // has curved edges, so each cell gives two pairs of polygons: the prisms under the
  // triangulation above the surface (raised by the march's rounding) hold every sample the cell
  // may hide, those under the one below it (lowered) only samples it surely hides; triangles the
  // receiver lies above are culled under a light above the whole surface (the terrain is closed
  // from above); the receiver's own four cells are decided per sample along the line. The
  // samples between (and within the table's resolution of an edge) are decided by the culled
  // march: the bits are the exact method's, bit for bit; RegionVisibilityResult::exact_tested
  // counts them.
  Bitmask,
  // The default: the bitmask method where it takes the light (as Bitmask says) and the light has
  // at least kBitmaskFromSamples samples, else the culled march (a region pair: always). Both
  // give the exact bits, so the choice changes the time alone; the result names the one taken.
  Auto,
};

// The method's name as the command line takes it: "exact", "viewsheds", "culled", "bitmask", "auto".
const char* regionVisibilityMethodName(RegionVisibilityMethod method);

// A textured light (Eisemann & Décoret 2007, Sec. 8: colours over the source): an RGB image
// stretched over the source rectangle's extent [C0, C1] x [R0, R1] (lowest column and row first:
// image row 0 along the rectangle's lowest row, as an image lies over the field), its texels'
// edges on the rectangle's, texel (i, j) centred at C0 + (i + 0.5) (C1 - C0) / width (a rectangle
// one point thick: the image's middle along that axis). A sample's colour is the image's bilinear
// lookup at the sample's own jittered position (between the centres of the four nearest texels,
// clamped to the edge texels: a renderer's filtered texture lookup), so a light of one colour
// gives that colour whatever its image's size.
struct LightImage {
  int width = 0, height = 0;  // 0: no light image
  std::vector<float> rgb;     // planar: the R, G, B planes, each row-major; finite, >= 0
};

struct RegionVisibilityOptions {
  RegionVisibilityMethod method = RegionVisibilityMethod::Auto;
  double target_height = 0.0;  // every-pixel receivers stand this high above the surface
  // Ground units; 0 = no limit, else at least kLeastMaxDistance. Farther pairs are not visible.
  double max_distance = 0.0;
  double curvature = 0.0;      // drop coefficient c (earthCurvature() in hfvis/sweep_options.hpp); 0 = flat
  std::uint32_t seed = 1;      // the jitter's
  bool decorrelate = false;    // each receiver its own jitter of the sources
  // Hears (done, in all) after each launch of receivers (with the viewsheds method: after each
  // source sample's viewshed); may be empty. An exception thrown from it stops the run.
  std::function<void(int, int)> progress;
  // With an image: the result's red, green, blue (rectangle sources and every-pixel receivers).
  LightImage light_image;
  // The bitmask method's table: edge angles and offsets each (8 .. 1024); finer, fewer samples
  // left to the march, a larger table (angles * (offsets + 1) * ceil(S / 32) words).
  int bitmask_table = 64;
};

// Per receiver a bitmask of the source samples it sees: bit s % 32 of word s / 32 (words per
// receiver: ceil(S / 32), the bits past S zero).
struct RegionVisibilityResult {
  int width = 0, height = 0;        // the field: receivers are its grid points, row-major
  int samples = 0;                  // S
  int words = 0;                    // per receiver
  std::vector<std::uint32_t> bits;  // width * height * words
  std::vector<float> fraction;      // visible samples / S per receiver; NaN at nodata
  // With options.light_image (else empty): per receiver, the sum over its visible samples of
  // each sample's colour (LightImage), divided by S (its irradiance from the coloured light, the
  // light's mean colour where it sees every sample); NaN at nodata. Decorrelated, each
  // receiver's samples lie where its own jitter put them, and so do their colours.
  std::vector<float> red, green, blue;
  // The bitmask method's (else 0): the bits its table left undecided, decided by the culled
  // march, and how many of those it found visible (a table alone would get one or the other of
  // the two counts wrong, by its choice of side).
  std::uint64_t exact_tested = 0, exact_tested_visible = 0;
  RegionVisibilityMethod method = RegionVisibilityMethod::Auto;  // the one that ran (never Auto)
  // Receiver p's sample s is visible.
  bool visible(std::size_t p, int s) const { return (bits[p * words + s / 32] >> (s % 32)) & 1u; }
};

struct RegionPairVisibilityResult {
  int source_samples = 0, receiver_samples = 0;
  int words = 0;  // per receiver sample: ceil(source_samples / 32)
  // The samples, heights absolute (z-scaled); the sources are stream 0's (decorrelated, each
  // receiver sample drew its own).
  std::vector<RegionPoint> sources, receivers;
  std::vector<std::uint32_t> bits;  // receiver_samples * words
  std::uint64_t clear_pairs = 0, pairs = 0;
  std::vector<float> source_fraction;    // per source sample: the receiver samples it sees / their count
  std::vector<float> receiver_fraction;  // per receiver sample: the source samples it sees / S
  bool visible(int receiver, int source) const {
    return (bits[std::size_t(receiver) * words + source / 32] >> (source % 32)) & 1u;
  }
};

// Throws InvalidArgument for a negative or non-finite target height or maximum distance, a
// curvature not finite or beyond -1 .. 1 per ground unit, a light image not of 3 * width * height
// values or holding a negative or non-finite one (naming the first).
void validate(const RegionVisibilityOptions& options);

// Throws InvalidArgument for a rectangle outside the field, S outside 1 .. kMaxRegionSamples, a
// non-finite height, a rectangle holding a nodata point (or a relative height over one), or a
// point outside the field or over a cell whose surface there takes a nodata height.
void validate(const HeightField& field, const RegionSampling& sampling);

// The samples of a region (stream 0 of `seed`), heights absolute (z-scaled), as the kernels
// place them. Throws as validate.
std::vector<RegionPoint> regionSamplePoints(const HeightField& field, const RegionSampling& sampling,
                                            std::uint32_t seed);

// A field prepared once for many region visibility calls (a renderer's frames under a moving
// light, a GIS loop over project sites or antenna areas): validated as the calls validate it, its
// heights prepared as the kernels take them (z-scaled), the culling pyramid (the culled march's
// and the bitmask method's) built, both uploaded to the context's device, once. Each call on it
// then costs only its own samples, tables, marches and results (the viewsheds method excepted: it
// runs the library's viewshed per source sample, which prepares the field itself); the one-shot
// calls below do the same preparation every call (about 9 ms of CPU on a 1024^2 field on a
// 2-core CPU, a fifth to a quarter of a hidden region pair's: bench/report/region_visibility.md),
// about 18 ms of a 115 ms call where 54 % of the lines are clear (97 ms prepared). The bits and fractions
// are the one-shot calls', bit for bit (the one-shot calls prepare the same way and run the same
// code).
//
// It holds a copy of the field (its heights: later changes to the caller's field are not seen) and
// of the context (a shared handle: the device buffers live as long as the prepared field); copies
// of a RegionField share the prepared state. Its device memory (the heights and the pyramid, about
// 2.3 floats a point: 9.3 MiB for 1024^2) stays held while it lives, besides each call's memory
// budget; on the host it keeps the field's copy, its z-scaled heights and the pyramid (which the
// host's probes read), about 3.3 floats a point (13 MiB for 1024^2). Calls on it run on its
// context, one at a time as every call on a context (hfvis/device.hpp): copies share the context,
// so two copies are not called from two threads at once, and a program with one context per
// thread prepares one RegionField per context (the constructor is a call on the context too). A
// moved-from RegionField may only be assigned or destroyed; a call on it throws InvalidArgument.
class RegionField {
 public:
  // Throws InvalidArgument (an empty or inconsistent field, a latitude / longitude grid, a field
  // of 2^31 points or more), OpenClError.
  explicit RegionField(const ComputeContext& context, const HeightField& field);

  const HeightField& field() const;
  const ComputeContext& context() const;

 private:
  // The prepared state, opaque here: the library defines it (src/ops/region_visibility.cpp) and
  // reaches it through RegionFieldAccess.
  struct State;
  friend class RegionFieldAccess;
  std::shared_ptr<const State> state_;
};

// Which source samples every grid point sees. Throws InvalidArgument (bad field, sources or
// options, a light image over explicit points, a latitude / longitude grid, a field of 2^31 points or more),
// MemoryBudgetError (bitmasks beyond half the device's memory), OpenClError, KernelBuildError.
RegionVisibilityResult computeRegionVisibility(const ComputeContext& context, const HeightField& field,
                                               const RegionSampling& sources,
                                               const RegionVisibilityOptions& options);

// Which source samples every receiver sample sees, between two regions (options.target_height is
// not used: the receivers' own height is; a light image is refused). Throws as
// computeRegionVisibility.
RegionPairVisibilityResult computeRegionPairVisibility(const ComputeContext& context,
                                                       const HeightField& field,
                                                       const RegionSampling& sources,
                                                       const RegionSampling& receivers,
                                                       const RegionVisibilityOptions& options);

// The same calls on a prepared field (RegionField): the same results, without the per-call
// preparation of the field. Throw as the calls above, less the field's own checks (done once).
RegionVisibilityResult computeRegionVisibility(const RegionField& field, const RegionSampling& sources,
                                               const RegionVisibilityOptions& options);
RegionPairVisibilityResult computeRegionPairVisibility(const RegionField& field,
                                                       const RegionSampling& sources,
                                                       const RegionSampling& receivers,
                                                       const RegionVisibilityOptions& options);

}  // namespace hfvis
