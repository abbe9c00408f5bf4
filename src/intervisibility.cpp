// intervisibility.cpp: the intervisibility operation on the device: presample -> convex
// hull tree sweep -> reduction (or the naive march) per batch of directions, downloading
// only the requested outputs.
#include "hfvis/intervisibility.hpp"

#include <algorithm>
#include <sstream>

#include "hfvis/errors.hpp"
#include "horizon_common.hpp"
#include "intervisibility_device.hpp"
#include "intervisibility_internal.hpp"
#include "opencl_context.hpp"
#include "sweep_framework.hpp"

namespace hfvis {
namespace detail {

const char* treeProgramFile(const TreeProgramFlags& flags) {
  return flags.bounce_channels > 0 ? "bounce.cl" : "intervisibility.cl";
}

std::string treeProgramOptions(const TreeProgramFlags& f, const ContextState& st) {
  std::ostringstream s;
  s << "-DHFVIS_HAS_NODATA=" << f.has_nodata << " -DHFVIS_WANT_AREA=" << f.area
    << " -DHFVIS_WANT_STATS=" << f.stats << " -DHFVIS_WANT_ENTRY_STATS=" << f.entry_stats << " "
    << layoutProgramOption(st);
  s << " -DHFVIS_DEFERRED_WRITES=" << f.tuning.deferred_writes
    << " -DHFVIS_REPLACEMENT_CHECK=" << f.tuning.replacement_check
    << " -DHFVIS_SAFE_ZONE=" << f.tuning.safe_zone << " -DHFVIS_SAFE_ZONE_STEPS=" << f.tuning.safe_zone_steps;
  if (f.bounce_channels > 0) s << " -DHFVIS_WANT_BOUNCE=1 -DHFVIS_CHANNELS=" << f.bounce_channels;
  return s.str();
}

void enqueueTreeSweep(ContextState& st, cl::Program& program, const cl::Buffer& directions,
                      const SweepBatch& batch, const TreeSweepBuffers& b) {
  cl::Kernel sweep(program, "intervisibility_sweep");
  int arg = 0;
  sweep.setArg(arg++, directions);
  sweep.setArg(arg++, b.lines);
  sweep.setArg(arg++, b.trees);
  sweep.setArg(arg++, b.visible);
  sweep.setArg(arg++, b.prefix);
  sweep.setArg(arg++, b.entry_stats);
  sweep.setArg(arg++, b.line_totals);
  sweep.setArg(arg++, b.totals_stride);
  sweep.setArg(arg++, b.bounce_lines);
  sweep.setArg(arg++, b.bounce_out);
  sweep.setArg(arg++, b.half_sector);
  sweep.setArg(arg++, b.wedge);
  st.launch(sweep, cl::NDRange(roundUp(batch.maxLines(), kLineGroup), batch.directions.size()),
            cl::NDRange(kLineGroup, 1));
}

namespace {

// Buffers a program without the bounce still binds.
void bindNoBounce(ContextState& st, TreeSweepBuffers& b) {
  b.bounce_lines = deviceBuffer(st, 0);
  b.bounce_out = deviceBuffer(st, 0);
}

// Adds one batch's per-line totals (receivers, m, t, naive, visible, skips) to the statistics.
void addLineTotals(const std::vector<cl_ulong>& totals, const SweepBatch& batch, int stride,
                   IntervisibilityStatistics& s) {
  for (std::size_t b = 0; b < batch.directions.size(); ++b) {
    for (int j = 0; j < batch.directions[b].n_lines; ++j) {
      const cl_ulong* t = &totals[(b * stride + j) * kTreeLineTotals];
      s.receivers += t[0];
      s.lines += t[0] > 0;
      s.horizons += t[1];
      s.iterations += t[2];
      s.naive_iterations += t[3];
      s.visible_samples += t[4];
      s.safe_zone_skips += t[5];
      s.lines_over_bound += t[2] > 2 * t[1] + t[0];
    }
  }
}

IntervisibilityResult run(const ComputeContext& context, const HeightField& field,
                          const IntervisibilityOptions& options, const IntervisibilityOutputs& outputs) {
  ContextState& st = stateOf(context);
  const PreparedHeights prepared = prepareHeights(field);
  const auto all = runDirections(field, options);
  checkLineLimits(all, prepared.heights, outputs);
  const bool tree = options.method == IntervisibilityMethod::HullTree;
  TreeProgramFlags flags;
  flags.has_nodata = prepared.has_nodata;
  flags.area = outputs.visible_area;
  flags.stats = outputs.statistics;
  flags.tuning = options.tree;
  cl::Program program = st.program(treeProgramFile(flags), treeProgramOptions(flags, st));
  const std::size_t plane = field.pixelCount();
  int max_lines = 0;
  for (const auto& d : all) max_lines = std::max(max_lines, d.n_lines);

  const bool want_pixels = outputs.visible_count || outputs.visible_area;
  // Step sums for the area across holes, which only nodata makes.
  const bool want_prefix = outputs.visible_area && prepared.has_nodata;
  SweepMemory memory;
  // Heights, and the accumulators: the count (also when only the area is asked for: the
  // reduction writes both) and the area.
  memory.fixed_bytes = plane * sizeof(float) * (1 + want_pixels + outputs.visible_area);
  if (tree) {
    memory.bytes_per_entry =
        kTreeLineBytes + kTreeNodeBytes + kTreeVisibleBytes + (want_prefix ? kTreePrefixBytes : 0);
    memory.largest_entry_bytes = kTreeNodeBytes;
    memory.bytes_per_direction = outputs.statistics ? max_lines * kTreeLineTotals * sizeof(cl_ulong) : 0;
  }
  const auto batches = planSweepBatches(all, memory, options.memory_budget_bytes, st.info);
  std::size_t max_entries = 0, max_directions = 0;
  for (const auto& b : batches) {
    max_entries = std::max(max_entries, b.entries);
    max_directions = std::max(max_directions, b.directions.size());
  }

  IntervisibilityResult result;
  result.width = field.width;
  result.height = field.height;
  result.directions = options.directions;
  for (int k = 0; k < options.directions; ++k) result.azimuths.push_back(directionAzimuth(k, options));

  cl::Buffer heights(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, plane * sizeof(float),
                     const_cast<float*>(prepared.heights.data()));
  TreeSweepBuffers buffers;
  if (tree) {
    bindNoBounce(st, buffers);
    buffers.lines = deviceBuffer(st, max_entries * kTreeLineBytes);
    buffers.trees = deviceBuffer(st, max_entries * kTreeNodeBytes);
    buffers.visible = deviceBuffer(st, max_entries * kTreeVisibleBytes);
    buffers.prefix = deviceBuffer(st, want_prefix ? max_entries * kTreePrefixBytes : 0);
    buffers.entry_stats = deviceBuffer(st, 0);
    buffers.totals_stride = max_lines;
    buffers.line_totals = deviceBuffer(
        st, outputs.statistics ? max_directions * max_lines * kTreeLineTotals * sizeof(cl_ulong) : 0);
  }
  cl::Buffer count_sum = deviceBuffer(st, want_pixels ? plane * sizeof(float) : 0);
  cl::Buffer area_sum = deviceBuffer(st, outputs.visible_area ? plane * sizeof(float) : 0);
  const float zero = 0.0f;
  if (want_pixels) st.queue.enqueueFillBuffer(count_sum, zero, 0, plane * sizeof(float));
  if (outputs.visible_area) st.queue.enqueueFillBuffer(area_sum, zero, 0, plane * sizeof(float));

  const float sector = intervisibilitySector(options);
  const cl::NDRange pixels(roundUp(field.width, kTileX), roundUp(field.height, kTileY));
  std::vector<cl_ulong> totals;
  int done = 0;
  for (const SweepBatch& batch : batches) {
    const cl::Buffer directions = uploadDirections(st, batch.directions);
    const int batch_size = static_cast<int>(batch.directions.size());
    if (tree) {
      enqueuePresample(st, program, heights, field.width, field.height, directions, batch, buffers.lines);
      enqueueTreeSweep(st, program, directions, batch, buffers);
    }
    if (want_pixels) {
      cl::Kernel reduce(program, tree ? "intervisibility_reduce" : "intervisibility_naive");
      int arg = 0;
      reduce.setArg(arg++, heights);
      reduce.setArg(arg++, field.width);
      reduce.setArg(arg++, field.height);
      reduce.setArg(arg++, directions);
      reduce.setArg(arg++, batch_size);
      reduce.setArg(arg++, sector);
      if (tree) reduce.setArg(arg++, buffers.visible);
      reduce.setArg(arg++, count_sum);
      reduce.setArg(arg++, area_sum);
      st.launch(reduce, pixels, cl::NDRange(kTileX, kTileY));
    }
    if (outputs.statistics) {
      totals.resize(batch.directions.size() * max_lines * kTreeLineTotals);
      st.queue.enqueueReadBuffer(buffers.line_totals, CL_TRUE, 0, totals.size() * sizeof(cl_ulong),
                                 totals.data());
      addLineTotals(totals, batch, max_lines, result.statistics);
    }
    st.queue.finish();
    done += batch_size;
    if (options.progress) options.progress(done, options.directions);
  }
  if (outputs.visible_count) {
    result.visible_count.resize(plane);
    st.queue.enqueueReadBuffer(count_sum, CL_TRUE, 0, plane * sizeof(float), result.visible_count.data());
  }
  if (outputs.visible_area) {
    result.visible_area.resize(plane);
    st.queue.enqueueReadBuffer(area_sum, CL_TRUE, 0, plane * sizeof(float), result.visible_area.data());
  }
  return result;
}

}  // namespace

IntervisibilityLines intervisibilityLinesOnDevice(const ComputeContext& context, const HeightField& field,
                                                  const std::vector<float>& prepared_heights,
                                                  const SweepDirection& direction,
                                                  const HullTreeTuning& tuning) {
  validate(tuning);
  return translateOpenClErrors([&] {
    ContextState& st = stateOf(context);
    TreeProgramFlags flags;
    flags.entry_stats = true;
    flags.tuning = tuning;
    cl::Program program = st.program(treeProgramFile(flags), treeProgramOptions(flags, st));
    const bool line_major = lineMajorLayout(st);
    SweepBatch batch;
    batch.directions = {direction};
    batch.directions[0].buffer_offset = 0;
    batch.entries = direction.entries();
    const std::size_t entries = batch.entries;
    IntervisibilityLines out;
    out.geometry = batch.directions[0];
    cl::Buffer heights(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                       prepared_heights.size() * sizeof(float), const_cast<float*>(prepared_heights.data()));
    const cl::Buffer directions = uploadDirections(st, batch.directions);
    TreeSweepBuffers buffers;
    bindNoBounce(st, buffers);
    buffers.lines = deviceBuffer(st, entries * kTreeLineBytes);
    buffers.trees = deviceBuffer(st, entries * kTreeNodeBytes);
    buffers.visible = deviceBuffer(st, entries * kTreeVisibleBytes);
    buffers.prefix = deviceBuffer(st, entries * kTreePrefixBytes);
    buffers.entry_stats = deviceBuffer(st, entries * kTreeEntryStatsBytes);
    buffers.totals_stride = direction.n_lines;
    buffers.line_totals = deviceBuffer(st, direction.n_lines * kTreeLineTotals * sizeof(cl_ulong));
    enqueuePresample(st, program, heights, field.width, field.height, directions, batch, buffers.lines);
    enqueueTreeSweep(st, program, directions, batch, buffers);
    std::vector<float> pairs(entries * 2), visible(entries * 2);
    std::vector<std::uint32_t> stats(entries * 4);
    st.queue.enqueueReadBuffer(buffers.lines, CL_TRUE, 0, pairs.size() * sizeof(float), pairs.data());
    st.queue.enqueueReadBuffer(buffers.visible, CL_TRUE, 0, visible.size() * sizeof(float), visible.data());
    st.queue.enqueueReadBuffer(buffers.entry_stats, CL_TRUE, 0, stats.size() * sizeof(std::uint32_t),
                               stats.data());
    // Back to the canonical step-major order of IntervisibilityLines.
    const SweepDirection& d = out.geometry;
    out.samples.resize(entries);
    out.counts.resize(entries);
    out.distance_sums.resize(entries);
    out.horizons.resize(entries);
    out.iterations.resize(entries);
    out.horizon_hashes.resize(entries);
    out.walks_skipped.resize(entries);
    for (int j = 0; j < d.n_lines; ++j) {
      for (int i = 0; i < d.n_steps; ++i) {
        const std::size_t e = lineEntry(d, j, i, line_major), canonical = std::size_t(i) * d.n_lines + j;
        out.samples[canonical] = pairs[2 * e];
        out.counts[canonical] = visible[2 * e];
        out.distance_sums[canonical] = visible[2 * e + 1];
        out.horizons[canonical] = stats[4 * e];
        out.iterations[canonical] = stats[4 * e + 1];
        out.horizon_hashes[canonical] = stats[4 * e + 2];
        out.walks_skipped[canonical] = stats[4 * e + 3];
      }
    }
    return out;
  });
}

}  // namespace detail

IntervisibilityResult computeIntervisibility(const ComputeContext& context, const HeightField& field,
                                             const IntervisibilityOptions& options,
                                             const IntervisibilityOutputs& outputs) {
  validate(field);
  validate(options, outputs);
  return detail::translateOpenClErrors([&] { return detail::run(context, field, options, outputs); });
}

}  // namespace hfvis
