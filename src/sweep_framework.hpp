// sweep_framework.hpp: host side of the sweep framework every sweep kernel shares
// (kernels/sweep_framework.cl): batching directions under a memory budget, uploading
// their geometry, presampling the line buffers, and launch shapes.
#pragma once

#include <cstddef>
#include <string>
#include <vector>

#include "opencl_context.hpp"
#include "sweep_geometry.hpp"

namespace hfvis::detail {

constexpr std::size_t kLineGroup = 64;          // work-items per group along lines
constexpr std::size_t kPresampleRows = 4;       // rows of a presampling work-group
constexpr std::size_t kTileX = 16, kTileY = 4;  // pixel tile of per-pixel kernels
constexpr int kMaxDirectionsPerBatch = 32;      // bounds kernel time, paces progress

inline std::size_t roundUp(std::size_t n, std::size_t m) { return (n + m - 1) / m * m; }

// Directions [first, first + directions.size()) of a run, with buffer offsets set.
struct SweepBatch {
  int first = 0;
  std::vector<SweepDirection> directions;
  std::size_t entries = 0;  // line-buffer entries of the whole batch
  int maxLines() const;
  int maxSteps() const;
};

// What one run needs on the device, for planning batches.
struct SweepMemory {
  std::size_t fixed_bytes = 0;          // for the whole run (heights, accumulators)
  std::size_t bytes_per_entry = 0;      // per line-buffer entry, all buffers together
  std::size_t largest_entry_bytes = 0;  // per entry in the largest single buffer
  std::size_t bytes_per_direction = 0;  // per direction besides its entries (output planes)
};

// Line-buffer layout of a context (HFVIS_LINE_MAJOR in kernels/sweep_framework.cl): its
// options' line_layout, automatically line-major on CPUs and step-major elsewhere.
bool lineMajorLayout(const ContextState& st);
// "-DHFVIS_LINE_MAJOR=0|1" for a context.
std::string layoutProgramOption(const ContextState& st);

// Index of entry (line, step) of d, as line_entry() in the kernels.
inline std::size_t lineEntry(const SweepDirection& d, int line, int step, bool line_major) {
  return d.buffer_offset +
         (line_major ? std::size_t(line) * d.n_steps + step : std::size_t(step) * d.n_lines + line);
}

// The budget when the caller gives none: half the device memory, at most 1 GiB.
std::size_t defaultMemoryBudget(const DeviceInfo& device);

// Splits `all` into batches that fit `budget_bytes` (0 = default). Throws
// MemoryBudgetError, saying what one direction needs, when even one does not fit.
std::vector<SweepBatch> planSweepBatches(const std::vector<SweepDirection>& all, const SweepMemory& memory,
                                         std::size_t budget_bytes, const DeviceInfo& device);

std::string mebibytes(std::size_t bytes);

// A read-write buffer of at least `bytes` (never zero-sized, so it can always be bound).
cl::Buffer deviceBuffer(ContextState& st, std::size_t bytes);

cl::Buffer uploadDirections(ContextState& st, const std::vector<SweepDirection>& directions);

// Launches presample_lines of `program` (any program including sweep_framework.cl) over
// the batch: every (step, line) of every direction gets its height, NaN where absent.
void enqueuePresample(ContextState& st, cl::Program& program, const cl::Buffer& heights, int width,
                      int height, const cl::Buffer& directions, const SweepBatch& batch,
                      const cl::Buffer& lines);

}  // namespace hfvis::detail
