// hull_tree_device.hpp: the convex hull tree sweep on lattice lines on the device, which the
// intervisibility operation and the bounce share: its directions, program options, device
// buffers, scratch planning and the launch of one direction (kernel intervisibility_lattice in
// kernels/intervisibility.cl; the bounce's gather in kernels/bounce.cl).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "hfvis/intervisibility.hpp"
#include "core/hull_tree.hpp"
#include "core/opencl_context.hpp"
#include "core/sweep_framework.hpp"
#include "core/sweep_routine.hpp"

namespace hfvis::detail {

constexpr std::size_t kTreeNodeBytes = 4 * sizeof(int);  // tree node (int4)
constexpr std::size_t kTreePrefixBytes = sizeof(std::uint64_t);
constexpr std::size_t kTreePositionBytes = 2 * sizeof(std::int32_t);  // (position, unit sum), per-row spacing
constexpr std::size_t kTreeVisibleBytes = 2 * sizeof(float);  // (count, distance sum), per-entry tests only
constexpr std::size_t kTreeEntryStatsBytes = 4 * sizeof(std::uint32_t);
constexpr std::size_t kTreePeakInputBytes = 2 * sizeof(float);  // the prepass's, per slot (peakPrepass)
constexpr std::size_t kTreeLineTotals = 8;  // ulongs per line (HFVIS_LINE_TOTALS)
constexpr std::size_t kTreeLineStateBytes = 152;  // TreeLineState, per line in strips

// What the program computes besides the sweep itself (the HFVIS_WANT_* of the kernels).
struct TreeProgramFlags {
  bool has_nodata = true;
  bool curvature = false;  // HFVIS_CURVATURE
  // HFVIS_ROW_SPACING: the directions follow each row's spacing (TreeDirection::rowSpacing;
  // the safe zone is then off, and there is no bounce).
  bool row_spacing = false;
  bool strips = false;  // HFVIS_STRIPS: a field in strips of rows (not with the bounce)
  bool count = true;
  bool area = true;
  bool stats = true;
  bool entry_stats = false;
  int bounce_channels = 0;  // > 0: the bounce's gather, with that many channels
  HullTreeTuning tuning;
};

// Consecutive steps one work-item of the prepass takes (HFVIS_PEAK_STEPS): each sample's height is
// then computed once, not again as the next interval's far end.
constexpr std::size_t kTreePeakSteps = 4;

// Whether a program with these flags computes the samples' heights and the peaks between them
// in a prepass (kernel intervisibility_peaks, HFVIS_PEAK_PREPASS), launched before each chunk's
// sweep by enqueueTreeDirection: on uniform grids without strips.
bool peakPrepass(const TreeProgramFlags& flags);

// The -D options of kernels/intervisibility.cl with these flags on this context's device: its
// prepass runs simdLanes(st) lines per work-item (enqueueTreeDirection launches it so), and its
// kernels take the scratch's stride as 1 in the line-major layout (chunkLines gives them 1 there).
std::string treeProgramOptions(const TreeProgramFlags& flags, const ContextState& st);

// The device buffers a run binds; those its program does not use are minimal
// (deviceBuffer(st, 0)).
struct TreeBuffers {
  cl::Buffer heights;
  float height_base = 0.0f;  // PreparedHeights::base of `heights`
  cl::Buffer trees, prefix, positions, visible, entry_stats, peak_inputs;  // scratch, `scratch_entries` entries
  std::size_t scratch_entries = 0;
  cl::Buffer line_totals;          // kTreeLineTotals ulongs per line of the direction
  cl::Buffer count_sum, area_sum;  // per pixel
  cl::Buffer radiance, normals, irradiance;  // the bounce's planes
};

// Bytes of scratch per line entry for a program with these flags.
std::size_t treeEntryBytes(const TreeProgramFlags& flags);

// Scratch entries a run's directions need: all lines of the largest direction in one launch,
// and the longest line (a direction can always run one line at a time).
struct TreeScratchNeeds {
  std::size_t whole = 0, longest = 0;
};
TreeScratchNeeds treeScratchNeeds(const std::vector<TreeDirection>& directions, bool line_major);

// Scratch entries a run gets: all of its largest direction's lines in one launch when the
// budget allows, down to its longest line. Throws MemoryBudgetError when even that does not
// fit beside `fixed_bytes`.
std::size_t planTreeScratch(const std::vector<TreeDirection>& directions, std::size_t fixed_bytes,
                            std::size_t entry_bytes, std::size_t budget_bytes, const DeviceInfo& device,
                            bool line_major);

// Buffers of the scratch and line totals for `entries` entries (and the largest direction's
// lines when statistics are asked for).
void allocateTreeScratch(ContextState& st, const TreeProgramFlags& flags, const std::vector<TreeDirection>& all,
                         std::size_t entries, TreeBuffers& b);

// intervisibility_lattice set up for direction d over the buffers b, with the tables it reads
// (kept alive with it): every argument but the chunk's lines (lines, n_lines, stride,
// first_line); a strip sets row0, out_row0, strip_receivers and states, which are 0, 0 and
// empty buffers without strips.
struct TreeKernel {
  NamedKernel kernel;
  cl::Buffer samples, row_units, row_factors, pieces, interval_first, no_strips;
};
TreeKernel treeKernel(ContextState& st, cl::Program& program, const TreeDirection& d, int width, int height,
                      const TreeBuffers& b);

// Launches intervisibility_lattice for direction d, its lines in chunks whose scratch fits.
// With peakPrepass (a uniform grid), each chunk's prepass intervisibility_peaks first; with
// `sweep` false only that (the tests read its output).
void enqueueTreeDirection(ContextState& st, cl::Program& program, const TreeDirection& d, int width, int height,
                          const TreeBuffers& b, bool sweep = true);

// The prepass alone (kernel intervisibility_peaks) on direction d of a uniform grid (with its
// drop where d.drop is not 0), read back in the canonical step-major order of
// IntervisibilityLines: per entry the sample's height, the peak before it that the tree inserts
// (NaN for none) and that peak's position (in 2^-position_shift steps; unspecified where the peak
// is NaN). For the tests.
struct TreePeakInputs {
  std::vector<float> samples, peaks;
  std::vector<std::int32_t> positions;
};
TreePeakInputs treePeakInputsOnDevice(ContextState& st, const HeightField& field,
                                      const std::vector<float>& prepared_heights, const TreeDirection& d);

// The routine of an operation built on the tree sweep (visible counts and areas, the
// bounce): its program, its directions, its scratch, one launch per direction.
class TreeRoutine : public SweepRoutine {
 protected:
  TreeRoutine(ContextState& st, const HeightField& field, const SweepOptions& options, const TreeProgramFlags& flags)
      : SweepRoutine(st, field, options), flags_(flags) {}

  std::string programFile() const override { return "intervisibility.cl"; }
  std::string programOptions() const override;
  // The directions and the scratch, planned beside `fixed_bytes` of the operation's own
  // buffers (heights included).
  void allocateScratch(std::size_t fixed_bytes);
  int directionCount() const override { return static_cast<int>(directions_.size()); }
  void sweep(int direction, int slot) override;

  TreeProgramFlags flags_;  // has_nodata follows the prepared heights
  std::vector<TreeDirection> directions_;
  TreeBuffers buffers_;
};

// One direction's sweep with per-entry statistics (and with `bounce`, its gather: the
// per-pixel irradiance of that direction into `irradiance`, channel planes), read back as
// canonical lines (IntervisibilityLines, every sample's horizons read). `height_base`: the
// prepared heights' base (PreparedHeights::base), which the tie rule's rounding takes. For the
// tests' hooks.
IntervisibilityLines treeLinesOnDevice(ContextState& st, const TreeProgramFlags& flags,
                                       const HeightField& field, const std::vector<float>& prepared_heights,
                                       float height_base, const TreeDirection& d, const BounceInputs* bounce,
                                       std::vector<float>* irradiance);

}  // namespace hfvis::detail
