// intervisibility_device.hpp: the device plumbing of the convex hull tree sweep that the
// intervisibility operation and the bounce share: program options, the sweep's buffers and
// its launch (kernels/intervisibility.cl, included by kernels/bounce.cl).
#pragma once

#include <cstddef>
#include <cstdint>
#include <string>

#include "hfvis/intervisibility.hpp"
#include "opencl_context.hpp"
#include "sweep_framework.hpp"

namespace hfvis::detail {

constexpr std::size_t kTreeLineBytes = 2 * sizeof(float);     // (height, rank)
constexpr std::size_t kTreeNodeBytes = 4 * sizeof(int);       // tree node
constexpr std::size_t kTreeVisibleBytes = 2 * sizeof(float);  // (count, distance sum)
constexpr std::size_t kTreePrefixBytes = sizeof(std::uint32_t);
constexpr std::size_t kTreeEntryStatsBytes = 4 * sizeof(std::uint32_t);
constexpr std::size_t kTreeLineTotals = 8;  // ulongs per line (HFVIS_LINE_TOTALS)

// What the program computes besides the sweep itself (the HFVIS_WANT_* of the kernels).
struct TreeProgramFlags {
  bool has_nodata = true;
  bool area = true;
  bool stats = true;
  bool entry_stats = false;
  int bounce_channels = 0;  // > 0: the bounce program (bounce.cl) with that many channels
  HullTreeTuning tuning;
};

// The kernel file and the -D options of a program with these flags, for `device`.
const char* treeProgramFile(const TreeProgramFlags& flags);
std::string treeProgramOptions(const TreeProgramFlags& flags, const ContextState& st);

// The device buffers of one batch's sweep (sized for the largest batch); those a program
// does not use may be minimal (deviceBuffer(st, 0)).
struct TreeSweepBuffers {
  cl::Buffer lines, trees, visible, prefix, entry_stats, line_totals;
  int totals_stride = 0;
  cl::Buffer bounce_lines, bounce_out;  // the bounce's attributes and gathered irradiance
  float half_sector = 0.0f, wedge = 0.0f;
};

// Launches intervisibility_sweep over the batch (lines presampled).
void enqueueTreeSweep(ContextState& st, cl::Program& program, const cl::Buffer& directions,
                      const SweepBatch& batch, const TreeSweepBuffers& buffers);

}  // namespace hfvis::detail
