// hfvis/pvs.hpp: potentially visible sets (PVS) of a height field's view cells: for every region
// a viewer can stand in, the terrain tiles that can be seen from somewhere in it. After Bittner,
// Mattausch, Wonka, Havran & Wimmer (2009, "Adaptive global visibility sampling"): a
// visibility sample is a maximal free segment (a ray and its reverse from one point), whose end
// tiles are added to every view cell the segment passes through.
//
// Geometry. Positions are in pixels (x along columns, y along rows), heights z-scaled; the surface
// is the bilinear one of the viewshed (hfvis/viewshed.hpp), a cell being the square between four
// neighbouring grid points (W - 1 x H - 1 of them). View cell (a, b) is the square of C x C cells
// [a C, a C + C] x [b C, b C + C] (the last row and column of view cells fewer, clipped to the
// field), as a volume: the points whose height above the surface under them lies in the band
// [H0, H1] (H0 = H1: a sheet at eye height, a walker; a band for flight). Tile (a, b) is the
// surface over the T x T cells [a T, a T + T] x [b T, b T + T], likewise clipped. View cells and
// tiles are numbered row-major. A cell with a nodata corner has no surface and belongs to no view
// cell's volume.
//
// Visibility. Tile t is in view cell v's PVS when some point of v's volume sees some point of t's
// surface by the line-of-sight test of the region visibility (hfvis/region_visibility.hpp: no
// point of the surface strictly between them rises strictly above the segment). Sampling finds a
// subset: every entry it adds has a witness, an eye in v's volume and a surface point of t
// whose segment passes that test (checked when the entry is added: a sample whose witness fails
// through rounding adds nothing). The dense reference (computeDensePvs) decides the eyes on v's
// grid points at heights H0, (H0 + H1) / 2 and H1 (one height when H0 = H1) against the targets
// on t's grid points (its closed square: a grid point on a tile border counts for every tile
// around it) by exact viewsheds: tile visible when any of its grid points is visible from any
// of those eyes. With curvature c (PvsOptions::curvature, the viewshed's drop coefficient) every
// sight line is the straight one over a curved surface: the test takes the surface c d (D - d)
// higher relative to the segment, the rays are cast so (RayCastOptions::curvature), and the dense
// reference's viewsheds take c. With a maximum distance D (PvsOptions::max_distance) the eye and
// the point it sees lie at most D apart on the ground. Projected grids only.
#pragma once

#include <cstdint>
#include <functional>
#include <vector>

#include "hfvis/device.hpp"
#include "hfvis/height_field.hpp"

namespace hfvis {

// A ray o + t d, t in [0, t_max]: pixels and z-scaled heights (d need not be unit length).
struct HeightRay {
  float ox = 0, oy = 0, oz = 0;
  float dx = 0, dy = 0, dz = 0;
  float t_max = 0;
};

// The view cells and tiles.
struct PvsGrid {
  int view_cell = 32;                      // C, cells per view cell side, 1 .. max(W, H) - 1
  double band_low = 1.7, band_high = 1.7;  // H0 <= H1, z-scaled units above the surface, finite, >= 0
  int tile = 16;                           // T, cells per tile side, 1 .. max(W, H) - 1
  // One byte per view cell (row-major over the view-cell grid), non-zero = computed; empty = all.
  std::vector<std::uint8_t> mask;
};

// The sizes a grid takes on a field.
struct PvsLayout {
  int view_x = 0, view_y = 0;    // view cells across and down
  int tiles_x = 0, tiles_y = 0;  // tiles across and down
  int cells_x = 0, cells_y = 0;  // W - 1, H - 1
  int viewCells() const { return view_x * view_y; }
  int tiles() const { return tiles_x * tiles_y; }
  int tileOfCell(int cell) const;  // the tile holding cell cy * cells_x + cx
  int viewOfCell(int cell) const;  // the view cell holding it
  int view_cell = 1, tile = 1;
};

// Throws InvalidArgument for a field under 2 x 2 points, a latitude / longitude grid, C or T
// below 1 or past max(W, H) - 1, a band not finite, negative, with H1 < H0 or above 1e28, a mask
// of the wrong size or computing no view cell.
PvsLayout pvsLayout(const HeightField& field, const PvsGrid& grid);

// ---- The ray caster

struct RayCastOptions {
  // Also list the view cells of `grid` whose volume each ray passes through before its hit.
  bool view_cells = false;
  PvsGrid grid;
  // The drop coefficient c of hfvis/viewshed.hpp (earthCurvature() in hfvis/sweep_options.hpp;
  // 0 = flat, |c| <= 1 per ground unit): each ray is a straight line over a curved surface, a
  // point at ground distance d from its origin lying c d^2 lower relative to it, so that over
  // the grid the ray's height is oz + t dz + c g^2 t^2, g its ground length per unit of t.
  double curvature = 0.0;
  // Device memory for the rays and lists of the two launches in flight at a time (the host
  // packs one while the device casts the other); 0 = half the device's memory. Rays are cast in
  // launches that fit it (MemoryBudgetError when one ray in each does not).
  std::size_t memory_budget_bytes = 0;
};

struct RayCastResult {
  std::vector<float> t;   // per ray: the hit, or where the ray leaves the field's box or ends
  std::vector<int> cell;  // per ray: the hit cell (cy (W - 1) + cx), -1 for none
  // Ray r's view cells at first[r] .. first[r + 1] - 1 (rays + 1 offsets, all 0 without view
  // cells), in order along the ray, each with a t where the ray lies in its volume (to rounding).
  std::vector<std::size_t> first;
  std::vector<int> view_cell;
  std::vector<float> view_t;
  int count(std::size_t ray) const { return static_cast<int>(first[ray + 1] - first[ray]); }
};

// Casts the rays on the device: the first point where each passes strictly below the bilinear
// surface (a ray starting below it hits at t = 0; one only touching it goes on), exact to the
// float rounding of the per-cell quadratic's root. Throws InvalidArgument (bad field, a ray not
// finite, with `view_cells` a bad grid: without, the grid is not looked at), MemoryBudgetError,
// OpenClError, KernelBuildError.
RayCastResult castHeightFieldRays(const ComputeContext& context, const HeightField& field,
                                  const std::vector<HeightRay>& rays, const RayCastOptions& options = {});

// ---- Potentially visible sets

enum class PvsMethod {
  Agvs,     // adaptive global sampling: the mixture of distributions and mutations (see PvsOptions)
  Sgvs,     // stationary global sampling: view space-direction samples alone
  PerCell,  // per view cell random sampling (the paper's REF): rays from a view cell feed it alone
};

struct PvsResult;

struct PvsOptions {
  PvsMethod method = PvsMethod::Agvs;
  // Budgets: the run stops at the first one reached (0 = none; then the estimate may settle,
  // estimate_entries below), or at once when the sets are complete: every computed view cell that
  // holds a valid cell holds every tile that holds one, less than max_distance away (nodata pairs
  // with nothing; the estimate then 0; sets to resume from that are complete already cast
  // nothing); at least one must be set.
  std::uint64_t samples = 0;  // visibility samples (a global sample is two rays, a per-cell one one)
  double pixel_error = 0.0;   // the estimated pixel error (Sec. 4.5) at or below this
  double seconds = 0.0;       // wall time
  int batch = 1 << 16;        // samples per device launch (the mixture adapts once per batch)
  std::uint32_t seed = 1;     // a run is a function of the inputs and the seed
  // The Earth's curvature: the drop coefficient c of hfvis/viewshed.hpp (earthCurvature() in
  // hfvis/sweep_options.hpp, for ground units in metres; 0 = flat, |c| <= 1 per ground unit).
  double curvature = 0.0;
  // The largest ground distance between an eye and what it sees (ground units; 0 = none, else
  // at least kLeastMaxDistance of hfvis/region_visibility.hpp): farther pairs are not visible, as
  // in the viewshed and the region visibility, and no filter adds a tile beyond it.
  double max_distance = 0.0;
  // The pixel error's camera resolution (rays per camera; Sec. 4.5's `resolution`).
  double resolution = 1e6;
  // The visibility filter's k (Sec. 5's object-space filter, global extension; 0 = none): adds
  // every tile within k 2 d / sqrt(n) of a visible tile, d its distance from the view cell, n the
  // samples per view cell; counted in PvsResult::filtered, with no witness.
  double filter = 0.0;
  // Sec. 5's view-space filter (0 = none, at most 8): each computed view cell's set also takes the
  // sampled entries of the view_filter neighbouring computed view cells (of its 8) whose sampled
  // sets are the most like its own (Jaccard's index; ties to the lower index); counted in
  // PvsResult::filtered with the object-space filter's, with no witness.
  int view_filter = 0;
  // Settling the estimate: when a budget ends with fewer than this many entries found once by a
  // uniform view ray (the entries PvsResult::pixel_error counts), but one at least, view-direction
  // samples go on until that many carry it, at most as many samples as the run cast before them
  // (so a run casts up to twice its budget; under a seconds budget at most as many seconds again);
  // PvsResult::estimate_samples counts them, and their rows in the history say `settling`. A count
  // of a handful is off by more than 2x in about a quarter of runs (bench/report/pvs.md: ten DEM
  // runs within 2x in 6 of 10 unsettled, 9 of 10 settled). With none the estimate stays at its
  // floor (one entry over the uniform rays). A pixel-error budget the settled estimate no longer
  // meets goes on sampling, within the other budgets. 0: the estimate as the budget left it.
  std::size_t estimate_entries = 20;
  bool witnesses = false;               // keep each entry's witness (PvsResult::witnesses)
  std::size_t memory_budget_bytes = 0;  // as RayCastOptions::memory_budget_bytes
  // The sets to start from (empty: none), to resume a run: an earlier run's PvsResult::bits on the
  // same field and grid, whose view cells not computed now are empty (InvalidArgument otherwise),
  // computed with the same band, curvature and maximum distance (not checked: the bits do not say).
  // Its entries stay, and count as found by earlier samples, never as found once: the estimate is
  // of this run's uniform rays against the sets as a whole. Give a seed the earlier runs did not
  // use, or their samples are cast again.
  std::vector<std::uint32_t> start;
  // Called after each batch with the result so far (the sets, the samples and rays, the estimate,
  // the history; the visibility filter comes only at the end): the sets can be used or saved at
  // any point, and a later run resumed from them (`start`).
  std::function<void(const PvsResult&)> progress;
};

// Why an entry is in a PVS: an eye in the view cell's volume and a surface point of the tile
// that sees it.
struct PvsWitness {
  int view_cell = 0, tile = 0;
  float eye[3] = {0, 0, 0};
  float target[3] = {0, 0, 0};
};

// One row per batch: how the run went.
struct PvsProgress {
  std::uint64_t samples = 0, rays = 0, entries = 0;
  double seconds = 0.0;
  double pixel_error = 0.0;         // the estimate after the batch
  std::vector<double> probability;  // per distribution (kPvsDistributions), the mixture's
  bool settling = false;            // a batch settling the estimate (PvsOptions::estimate_entries):
                                    // view-direction samples alone, the mixture as it was
};

// The distributions of AGVS, in PvsProgress::probability's order.
constexpr int kPvsDistributions = 5;
const char* pvsDistributionName(int index);  // "view-direction", "object-direction", "two-point",
                                             // "two-point-mutation", "silhouette-mutation"

struct PvsResult {
  PvsLayout layout;
  int words = 0;                       // per view cell: ceil(tiles / 32)
  std::vector<std::uint32_t> bits;     // view cell v's tile j: bit j % 32 of word v * words + j / 32
  std::vector<std::uint8_t> computed;  // per view cell: the grid's mask (all 1 without one)
  std::uint64_t samples = 0, rays = 0;  // all of the run's, estimate_samples included
  std::uint64_t estimate_samples = 0;    // view-direction samples settling the estimate (PvsOptions::estimate_entries)
  std::uint64_t rejected = 0;  // candidate entries whose witness failed the line-of-sight test
  std::uint64_t filtered = 0;  // entries the visibility filter added (no witness)
  // Silhouette mutations drawn from a depth discontinuity (AGVS; Sec. 4.4): a silhouette ray that
  // passed its object's silhouette and hit a surface more than 3 tile radii beyond it.
  std::uint64_t discontinuities = 0;
  double pixel_error = 0.0;    // the estimate at the end (NaN before any estimate)
  // The uniform view rays the estimate rests on (view-direction and per-cell samples' rays): it is
  // pixel_error * uniform_rays / resolution of them that found an entry no other sample found
  // (never below 1: N rays do not tell an error below 1 / N from 0).
  std::uint64_t uniform_rays = 0;
  double seconds = 0.0;
  std::vector<PvsWitness> witnesses;  // with PvsOptions::witnesses: one per sampled entry
  std::vector<PvsProgress> history;
  bool visible(int view_cell, int tile) const {
    return (bits[std::size_t(view_cell) * words + tile / 32] >> (tile % 32)) & 1u;
  }
  std::size_t entries() const;  // set bits
};

// Throws InvalidArgument for no budget, a negative or non-finite budget, a batch below 1, a
// negative or non-finite filter, a view filter outside 0 .. 8 or resolution below 1.
void validate(const PvsOptions& options);

// The sampled PVS of every computed view cell. Throws InvalidArgument (bad field, grid or
// options), MemoryBudgetError, OpenClError, KernelBuildError.
PvsResult computePvs(const ComputeContext& context, const HeightField& field, const PvsGrid& grid,
                     const PvsOptions& options);

// Which of a tile's grid points the dense reference looks at: every one of its closed square (the
// definition above: a point on a tile's border is a point of it), or those strictly inside it.
// A tile seen only at its border (the far side of a ridge or roof edge that runs along it) is an
// entry of the first, of measure zero for sampling: the second leaves such entries out (and
// misses tiles seen only through slivers holding no inner grid point).
enum class DenseTargets { ClosedTiles, InsideTiles };

// The dense reference (see above): (C + 1)^2 x (1 or 3) viewsheds per view cell, for small
// fields, over a surface of `curvature` (PvsOptions::curvature), targets within `max_distance`
// of the eyes (PvsOptions::max_distance). Throws as computePvs, and InvalidArgument for
// InsideTiles with tiles below 2 cells.
PvsResult computeDensePvs(const ComputeContext& context, const HeightField& field, const PvsGrid& grid,
                          DenseTargets targets = DenseTargets::ClosedTiles, double curvature = 0.0,
                          double max_distance = 0.0);

// Entries of `got` that `want` holds, over `want`'s entries (1 when `want` has none).
double pvsRecall(const PvsResult& got, const PvsResult& want);

}  // namespace hfvis
