// sweep_framework.hpp: host side of the sweep framework every sweep kernel shares
// (kernels/shared/sweep_framework.cl): the scratch layout of a context, memory budgets,
// buffers, the naive marches' direction uploads, and launch shapes.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "core/lattice_geometry.hpp"
#include "core/opencl_context.hpp"
#include "core/sweep_geometry.hpp"

namespace hfvis::detail {

constexpr std::size_t kLineGroup = 64;          // work-items per group along lines
constexpr std::size_t kTileX = 16, kTileY = 4;  // pixel tile of per-pixel kernels
constexpr int kMaxDirectionsPerBatch = 32;      // bounds kernel time, paces progress

inline std::size_t roundUp(std::size_t n, std::size_t m) { return (n + m - 1) / m * m; }

// Scratch layout of a context's lattice sweeps (chunkLines): its options' line_layout,
// automatically line-major on CPUs and step-major elsewhere.
bool lineMajorLayout(const ContextState& st);

// Lines (or rays) one work-item runs side by side (HFVIS_LANES, kernels/shared/lanes.cl): SIMD lanes
// where a work-item runs on a CPU core in the line-major layout; one per work-item on GPUs
// (whatever the layout: a lane-wide work-item would run alone in its group there) and in the
// step-major layout, whose neighbouring work-items read neighbouring entries.
int simdLanes(const ContextState& st);

// The device memory an operation may plan with: the caller's `budget_bytes`, or when that is 0
// half the device memory (for a CPU device, whose memory is the host's, half the host's
// physical memory).
std::size_t memoryBudget(std::size_t budget_bytes, const DeviceInfo& device);

// Half the host's physical memory (or of its cgroup's limit, where lower); 0 when unknown.
std::size_t hostMemoryBudget();

// A byte count as messages show it: MiB with one decimal, KiB or bytes below a tenth of a MiB.
std::string mebibytes(std::size_t bytes);

// A read-write buffer of at least `bytes` (never zero-sized, so it can always be bound).
cl::Buffer deviceBuffer(ContextState& st, std::size_t bytes);

cl::Buffer uploadDirections(ContextState& st, const std::vector<SweepDirection>& directions);

// Runs a lattice sweep kernel (its other arguments set) over the lines of one direction, in
// chunks whose scratch fits `scratch_entries` (chunkLines, in the context's layout): per
// chunk it sets the kernel's arguments `lines` (a copy of the chunk's line table: sub-buffer
// offsets must be aligned on some devices), `n_lines`, `stride` and, where the kernel takes
// it, `first_line`, and launches ceil(count / lanes) work-items in groups of `group`. With
// `lanes_together`, a work-item's lanes are lines [k lanes, (k + 1) lanes) of `lines` (chunks
// start at multiples of `lanes`).
void launchLineChunks(ContextState& st, NamedKernel& kernel, std::vector<LatticeLine> lines,
                      std::size_t samples_per_period, std::size_t scratch_entries, int lanes,
                      std::size_t group, bool lanes_together = false);

}  // namespace hfvis::detail
