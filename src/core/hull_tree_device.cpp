// hull_tree_device.cpp: the convex hull tree sweep on the device (see hull_tree_device.hpp):
// program options, scratch planning, the kernel's arguments for a direction, its launch in
// chunks of lines, the routine the tree's operations derive from, and the line views the tests
// compare with the scalar sweep.
#include "core/hull_tree_device.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <sstream>

#include "hfvis/errors.hpp"
#include "core/horizon_common.hpp"
#include "core/hull_tree.hpp"
#include "core/opencl_context.hpp"
#include "core/sweep_framework.hpp"

namespace hfvis {
namespace detail {

bool peakPrepass(const TreeProgramFlags& f) { return !f.row_spacing && !f.strips; }

std::string treeProgramOptions(const TreeProgramFlags& f, const ContextState& st) {
  std::ostringstream s;
  s << "-DHFVIS_LANES=" << simdLanes(st) << " -DHFVIS_PEAK_STEPS=" << kTreePeakSteps
    << " -DHFVIS_LINE_MAJOR=" << lineMajorLayout(st) << " ";
  s << "-DHFVIS_HAS_NODATA=" << f.has_nodata << " -DHFVIS_WANT_COUNT=" << f.count
    << " -DHFVIS_WANT_AREA=" << f.area
    << " -DHFVIS_WANT_STATS=" << f.stats << " -DHFVIS_WANT_ENTRY_STATS=" << f.entry_stats;
  s << " -DHFVIS_CURVATURE=" << f.curvature << " -DHFVIS_ROW_SPACING=" << f.row_spacing
    << " -DHFVIS_STRIPS=" << f.strips << " -DHFVIS_PEAK_PREPASS=" << peakPrepass(f);
  const HullTreeTuning tuning = tuningFor(f.tuning, f.row_spacing);
  s << " -DHFVIS_DEFERRED_WRITES=" << tuning.deferred_writes
    << " -DHFVIS_REPLACEMENT_CHECK=" << tuning.replacement_check
    << " -DHFVIS_SAFE_ZONE=" << tuning.safe_zone << " -DHFVIS_SAFE_ZONE_STEPS=" << tuning.safe_zone_steps;
  if (f.bounce_channels > 0) s << " -DHFVIS_WANT_BOUNCE=1 -DHFVIS_CHANNELS=" << f.bounce_channels;
  return s.str();
}

namespace {
bool needsPrefix(const TreeProgramFlags& f) { return f.area && (f.has_nodata || f.row_spacing); }
}  // namespace

std::size_t treeEntryBytes(const TreeProgramFlags& f) {
  return kTreeNodeBytes + (needsPrefix(f) ? kTreePrefixBytes : 0) + (f.row_spacing ? kTreePositionBytes : 0) +
         (f.entry_stats ? kTreeVisibleBytes + kTreeEntryStatsBytes : 0) + (peakPrepass(f) ? kTreePeakInputBytes : 0);
}

TreeScratchNeeds treeScratchNeeds(const std::vector<TreeDirection>& directions, bool line_major) {
  TreeScratchNeeds needs;
  for (const TreeDirection& d : directions) {
    std::size_t total = 0, direction_longest = 0;
    for (const LatticeLine& line : d.lines) {
      const std::size_t capacity = lineCapacity(line, d.slotsPerPeriod());
      total += capacity;
      direction_longest = std::max(direction_longest, capacity);
    }
    // Step-major chunks pad every line to the chunk's longest (chunkLines).
    if (!line_major) total = std::max(total, direction_longest * d.lines.size());
    needs.whole = std::max(needs.whole, total);
    needs.longest = std::max(needs.longest, direction_longest);
  }
  return needs;
}

std::size_t planTreeScratch(const std::vector<TreeDirection>& directions, std::size_t fixed_bytes,
                            std::size_t entry_bytes, std::size_t budget_bytes, const DeviceInfo& device,
                            bool line_major) {
  const std::size_t budget = memoryBudget(budget_bytes, device);
  const std::size_t max_alloc = device.max_allocation_bytes ? device.max_allocation_bytes : budget;
  const TreeScratchNeeds needs = treeScratchNeeds(directions, line_major);
  const std::size_t least = fixed_bytes + needs.longest * entry_bytes;
  if (least > budget || needs.longest * kTreeNodeBytes > max_alloc) {
    throw MemoryBudgetError("one direction needs " + mebibytes(least) + " of device memory but the budget is " +
                            mebibytes(budget) + " (largest single buffer " + mebibytes(max_alloc) +
                            "); raise the memory budget or use a smaller field");
  }
  return std::min({needs.whole, (budget - fixed_bytes) / entry_bytes, max_alloc / kTreeNodeBytes});
}

void allocateTreeScratch(ContextState& st, const TreeProgramFlags& flags, const std::vector<TreeDirection>& all,
                         std::size_t entries, TreeBuffers& b) {
  b.scratch_entries = entries;
  b.trees = st.reusableBuffer("tree nodes", entries * kTreeNodeBytes);
  b.prefix = deviceBuffer(st, needsPrefix(flags) ? entries * kTreePrefixBytes : 0);
  b.positions = deviceBuffer(st, flags.row_spacing ? entries * kTreePositionBytes : 0);
  b.peak_inputs = deviceBuffer(st, peakPrepass(flags) ? entries * kTreePeakInputBytes : 0);
  b.visible = deviceBuffer(st, flags.entry_stats ? entries * kTreeVisibleBytes : 0);
  b.entry_stats = deviceBuffer(st, flags.entry_stats ? entries * kTreeEntryStatsBytes : 0);
  std::size_t max_lines = 0;
  for (const TreeDirection& d : all) max_lines = std::max(max_lines, d.lines.size());
  b.line_totals = deviceBuffer(st, flags.stats ? max_lines * kTreeLineTotals * sizeof(cl_ulong) : 0);
}

namespace {

// The arguments intervisibility_lattice and its prepass intervisibility_peaks share: the field,
// the direction's lattice samples and interval pieces, and the prepass's buffer.
void setLineSamplingArguments(NamedKernel& kernel, const TreeKernel& k, const TreeDirection& d, int width, int height,
                              const TreeBuffers& b) {
  kernel.set("heights", b.heights);
  kernel.set("width", width);
  kernel.set("height", height);
  kernel.set("samples", k.samples);
  kernel.set("n_samples", static_cast<int>(d.samples.size()));
  kernel.set("a", d.lattice.a);
  kernel.set("b", d.lattice.b);
  kernel.set("drop", d.drop);
  kernel.set("pieces", k.pieces);
  kernel.set("interval_first", k.interval_first);
  kernel.set("position_shift", d.position_shift);
  kernel.set("peak_inputs", b.peak_inputs);
}

}  // namespace

TreeKernel treeKernel(ContextState& st, cl::Program& program, const TreeDirection& d, int width, int height,
                      const TreeBuffers& b) {
  auto table = [&](const void* data, std::size_t bytes) {
    if (!bytes) return deviceBuffer(st, 0);
    return cl::Buffer(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, bytes, const_cast<void*>(data));
  };
  TreeKernel k;
  k.samples = table(d.samples.data(), d.samples.size() * sizeof(LatticeSample));
  k.row_units = table(d.row_units.data(), d.row_units.size() * sizeof(std::int32_t));
  k.row_factors = table(d.row_factors.data(), d.row_factors.size() * sizeof(float));
  k.pieces = table(d.intervals.pieces.data(), d.intervals.pieces.size() * sizeof(TreePiece));
  k.interval_first = table(d.intervals.first.data(), d.intervals.first.size() * sizeof(std::int32_t));
  k.no_strips = deviceBuffer(st, 0);
  k.kernel = NamedKernel(st, program, "intervisibility_lattice");  // the chunk's lines set per chunk
  NamedKernel& kernel = k.kernel;
  setLineSamplingArguments(kernel, k, d, width, height, b);
  kernel.set("height_base", b.height_base);
  kernel.set("count_factor", d.count_factor);
  kernel.set("area_factor", d.area_factor);
  kernel.set("max_steps", d.max_steps);
  kernel.set("row_units", k.row_units);
  kernel.set("row_factors", k.row_factors);
  kernel.set("trees", b.trees);
  kernel.set("prefix", b.prefix);
  kernel.set("positions", b.positions);
  kernel.set("visible", b.visible);
  kernel.set("entry_stats", b.entry_stats);
  kernel.set("line_totals", b.line_totals);
  kernel.set("count_sum", b.count_sum);
  kernel.set("area_sum", b.area_sum);
  kernel.set("radiance", b.radiance);
  kernel.set("normals", b.normals);
  kernel.set("cos_azimuth", d.cos_azimuth);
  kernel.set("sin_azimuth", d.sin_azimuth);
  kernel.set("step_ground", d.step_ground);
  kernel.set("half_sector", d.half_sector);
  kernel.set("wedge", d.wedge);
  kernel.set("irradiance", b.irradiance);
  kernel.set("row0", 0);
  kernel.set("out_row0", 0);
  kernel.set("strip_receivers", k.no_strips);
  kernel.set("states", k.no_strips);
  return k;
}

void enqueueTreeDirection(ContextState& st, cl::Program& program, const TreeDirection& d, int width, int height,
                          const TreeBuffers& b, bool sweep) {
  TreeKernel k = treeKernel(st, program, d, width, height, b);
  // Per-row spacing computes its peaks in the sweep (peakPrepass: so was its program built).
  if (d.rowSpacing()) {
    launchLineChunks(st, k.kernel, d.lines, d.slotsPerPeriod(), b.scratch_entries, 1, kLineGroup);
    return;
  }
  NamedKernel peaks(st, program, "intervisibility_peaks");
  setLineSamplingArguments(peaks, k, d, width, height, b);
  // A prepass work-item takes `lanes` lines over kTreePeakSteps steps (HFVIS_LANES and
  // HFVIS_PEAK_STEPS, as the program was built: treeProgramOptions). Work-groups along the steps
  // of one work-item's lines where a line's slots lie together (line-major), across lines where a
  // step's do (step-major). Each chunk's sweep reads what its prepass wrote, and the next chunk's
  // prepass overwrites it: both rely on the context's one in-order queue (ContextState), which
  // runs each launch after the one before.
  const bool line_major = lineMajorLayout(st);
  const std::size_t lanes = static_cast<std::size_t>(simdLanes(st));
  const std::size_t group_lines = line_major ? 1 : kLineGroup, group_steps = line_major ? kLineGroup : 1;
  std::vector<LatticeLine> lines = d.lines;
  for (const LineChunk& chunk : chunkLines(lines, d.slotsPerPeriod(), b.scratch_entries, line_major)) {
    const cl::Buffer chunk_lines(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                                 chunk.count * sizeof(LatticeLine), lines.data() + chunk.first);
    std::size_t steps = 0;
    for (std::size_t j = chunk.first; j < chunk.first + chunk.count; ++j)
      steps = std::max(steps, static_cast<std::size_t>(lines[j].receivers) * d.samples.size());
    for (NamedKernel* kernel : {&peaks, &k.kernel}) {
      kernel->set("lines", chunk_lines);
      kernel->set("n_lines", static_cast<int>(chunk.count));
      kernel->set("stride", static_cast<cl_uint>(chunk.stride));
    }
    k.kernel.set("first_line", static_cast<int>(chunk.first));
    st.launch(peaks,
              cl::NDRange(roundUp((chunk.count + lanes - 1) / lanes, group_lines),
                          roundUp((steps + kTreePeakSteps - 1) / kTreePeakSteps, group_steps)),
              cl::NDRange(group_lines, group_steps));
    if (sweep) st.launch(k.kernel, cl::NDRange(roundUp(chunk.count, kLineGroup)), cl::NDRange(kLineGroup));
  }
}

std::string TreeRoutine::programOptions() const {
  TreeProgramFlags flags = flags_;
  flags.has_nodata = prepared_.has_nodata;
  return treeProgramOptions(flags, st_);
}

void TreeRoutine::allocateScratch(std::size_t fixed_bytes) {
  flags_.has_nodata = prepared_.has_nodata;
  directions_ = treeDirections(field_, options_, flags_.row_spacing);
  checkTreeLimits(directions_, prepared_.heights);
  // The per-line totals of the statistics count beside the operation's own buffers.
  std::size_t max_lines = 0;
  for (const TreeDirection& d : directions_) max_lines = std::max(max_lines, d.lines.size());
  if (flags_.stats) fixed_bytes += max_lines * kTreeLineTotals * sizeof(cl_ulong);
  allocateTreeScratch(st_, flags_, directions_,
                      planTreeScratch(directions_, fixed_bytes, treeEntryBytes(flags_), options_.memory_budget_bytes,
                                      st_.info, lineMajorLayout(st_)),
                      buffers_);
  buffers_.heights = heights_;
  buffers_.height_base = prepared_.base;
}

void TreeRoutine::sweep(int direction, int) {
  enqueueTreeDirection(st_, program_, directions_[direction], field_.width, field_.height, buffers_);
}

IntervisibilityLines treeLinesOnDevice(ContextState& st, const TreeProgramFlags& program_flags,
                                       const HeightField& field, const std::vector<float>& prepared_heights,
                                       float height_base, const TreeDirection& d, const BounceInputs* bounce,
                                       std::vector<float>* irradiance) {
  TreeProgramFlags flags = program_flags;
  flags.entry_stats = true;
  flags.row_spacing = d.rowSpacing();
  cl::Program program = st.program("intervisibility.cl", treeProgramOptions(flags, st));
  const std::size_t plane = field.pixelCount();
  // Scratch entries are tree slots: two per step (the peak's, then the sample's).
  const std::size_t slots_per_period = d.slotsPerPeriod(), slots_per_step = 2;
  std::size_t entries = 0;
  for (const LatticeLine& line : d.lines) entries += lineCapacity(line, slots_per_period);
  // Scratch for all lines in one launch; the step-major layout pads every line to the longest.
  entries = std::max(entries, d.longestLine() * slots_per_step * d.lines.size());
  TreeBuffers b;
  allocateTreeScratch(st, flags, {d}, entries, b);
  auto upload = [&](const std::vector<float>& values) {
    return cl::Buffer(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, values.size() * sizeof(float),
                      const_cast<float*>(values.data()));
  };
  auto joined = [](const std::vector<std::vector<float>>& planes) {
    std::vector<float> all;
    for (const auto& p : planes) all.insert(all.end(), p.begin(), p.end());
    return all;
  };
  const int channels = bounce ? bounce->channels() : 0;
  b.heights = upload(prepared_heights);
  b.height_base = height_base;
  b.count_sum = deviceBuffer(st, plane * sizeof(float));
  b.area_sum = deviceBuffer(st, plane * sizeof(float));
  b.radiance = bounce ? upload(joined(bounce->radiance)) : deviceBuffer(st, 0);
  b.normals = bounce ? upload(joined(bounce->normals)) : deviceBuffer(st, 0);
  b.irradiance = deviceBuffer(st, channels * plane * sizeof(float));
  const float zero = 0.0f;
  st.queue.enqueueFillBuffer(b.count_sum, zero, 0, plane * sizeof(float));
  st.queue.enqueueFillBuffer(b.area_sum, zero, 0, plane * sizeof(float));
  if (channels) st.queue.enqueueFillBuffer(b.irradiance, zero, 0, channels * plane * sizeof(float));
  enqueueTreeDirection(st, program, d, field.width, field.height, b);
  std::vector<cl_int> nodes(entries * 4);
  std::vector<float> visible(entries * 2);
  std::vector<std::uint32_t> stats(entries * 4);
  st.queue.enqueueReadBuffer(b.trees, CL_TRUE, 0, nodes.size() * sizeof(cl_int), nodes.data());
  st.queue.enqueueReadBuffer(b.visible, CL_TRUE, 0, visible.size() * sizeof(float), visible.data());
  st.queue.enqueueReadBuffer(b.entry_stats, CL_TRUE, 0, stats.size() * sizeof(std::uint32_t), stats.data());
  if (irradiance) {
    irradiance->resize(channels * plane);
    st.queue.enqueueReadBuffer(b.irradiance, CL_TRUE, 0, irradiance->size() * sizeof(float), irradiance->data());
  }

  // Back to the canonical step-major order, as the launch laid the lines out.
  std::vector<LatticeLine> lines = d.lines;
  const auto chunks = chunkLines(lines, slots_per_period, entries, lineMajorLayout(st));
  IntervisibilityLines out = canonicalTreeLines(d);
  out.resetResults();
  out.height_base = b.height_base;
  for (const LineChunk& chunk : chunks) {
    for (std::size_t j = chunk.first; j < chunk.first + chunk.count; ++j) {
      const std::size_t steps = lineCapacity(lines[j], d.samples.size());
      for (std::size_t i = 0; i < steps; ++i) {
        const std::size_t slot = i * slots_per_step + slots_per_step - 1;
        const std::size_t e = static_cast<std::size_t>(lines[j].stack) + slot * chunk.stride;
        const std::size_t c = i * lines.size() + j;
        std::memcpy(&out.samples[c], &nodes[4 * e], sizeof(float));
        out.counts[c] = visible[2 * e];
        out.distance_sums[c] = visible[2 * e + 1];
        out.horizons[c] = stats[4 * e];
        out.iterations[c] = stats[4 * e + 1];
        out.horizon_hashes[c] = stats[4 * e + 2];
        out.walks_skipped[c] = stats[4 * e + 3];
      }
    }
  }
  return out;
}

TreePeakInputs treePeakInputsOnDevice(ContextState& st, const HeightField& field,
                                      const std::vector<float>& prepared_heights, const TreeDirection& d) {
  TreeProgramFlags flags;
  flags.curvature = d.drop != 0.0f;
  flags.stats = false;
  if (d.rowSpacing() || !peakPrepass(flags)) throw InvalidArgument("the peaks' prepass takes uniform grids only");
  cl::Program program = st.program("intervisibility.cl", treeProgramOptions(flags, st));
  const std::size_t plane = field.pixelCount();
  std::size_t entries = 0;
  for (const LatticeLine& line : d.lines) entries += lineCapacity(line, d.slotsPerPeriod());
  entries = std::max(entries, d.longestLine() * 2 * d.lines.size());  // (step-major: every line the longest)
  TreeBuffers b;
  allocateTreeScratch(st, flags, {d}, entries, b);
  b.heights = cl::Buffer(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, prepared_heights.size() * sizeof(float),
                         const_cast<float*>(prepared_heights.data()));
  b.count_sum = b.area_sum = deviceBuffer(st, plane * sizeof(float));
  b.radiance = b.normals = b.irradiance = deviceBuffer(st, 0);
  // NaN everywhere first: an entry the prepass leaves unwritten reads as a wrong sample.
  const float nan = std::numeric_limits<float>::quiet_NaN();
  cl_int2 nan2;
  std::memcpy(&nan2.s[0], &nan, sizeof(float));
  std::memcpy(&nan2.s[1], &nan, sizeof(float));
  st.queue.enqueueFillBuffer(b.peak_inputs, nan2, 0, entries * kTreePeakInputBytes);
  enqueueTreeDirection(st, program, d, field.width, field.height, b, false);
  std::vector<cl_int2> inputs(entries);
  st.queue.enqueueReadBuffer(b.peak_inputs, CL_TRUE, 0, entries * kTreePeakInputBytes, inputs.data());

  // Back to the canonical step-major order, as the launch laid the lines out.
  std::vector<LatticeLine> lines = d.lines;
  const auto chunks = chunkLines(lines, d.slotsPerPeriod(), entries, lineMajorLayout(st));
  const std::size_t n_steps = d.longestLine(), canonical = n_steps * lines.size();
  TreePeakInputs out;
  out.samples.assign(canonical, std::numeric_limits<float>::quiet_NaN());
  out.peaks.assign(canonical, std::numeric_limits<float>::quiet_NaN());
  out.positions.assign(canonical, 0);
  for (const LineChunk& chunk : chunks) {
    for (std::size_t j = chunk.first; j < chunk.first + chunk.count; ++j) {
      const std::size_t steps = lineCapacity(lines[j], d.samples.size());
      for (std::size_t i = 0; i < steps; ++i) {
        const std::size_t base = static_cast<std::size_t>(lines[j].stack), c = i * lines.size() + j;
        const cl_int2 sample = inputs[base + (2 * i + 1) * chunk.stride], peak = inputs[base + 2 * i * chunk.stride];
        std::memcpy(&out.samples[c], &sample.s[0], sizeof(float));
        std::memcpy(&out.peaks[c], &peak.s[0], sizeof(float));
        out.positions[c] = peak.s[1];
      }
    }
  }
  return out;
}

IntervisibilityLines intervisibilityLinesOnDevice(const ComputeContext& context, const HeightField& field,
                                                  const PreparedHeights& prepared, const TreeDirection& d,
                                                  const HullTreeTuning& tuning) {
  validate(tuning);
  return translateOpenClErrors([&] {
    TreeProgramFlags flags;
    flags.tuning = tuning;
    return treeLinesOnDevice(stateOf(context), flags, field, prepared.heights, prepared.base, d, nullptr,
                             nullptr);
  });
}

}  // namespace detail
}  // namespace hfvis
