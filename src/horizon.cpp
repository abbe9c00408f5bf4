// horizon.cpp: the horizon operation on the device: presample -> hull-stack sweep ->
// reduction (or the naive march) per batch of directions, downloading only the
// requested outputs.
#include "hfvis/horizon.hpp"

#include <algorithm>
#include <sstream>

#include "hfvis/errors.hpp"
#include "horizon_common.hpp"
#include "horizon_device.hpp"
#include "opencl_context.hpp"
#include "sweep_framework.hpp"

namespace hfvis {
namespace detail {
namespace {

constexpr std::size_t kLineEntryBytes = 2 * sizeof(float);  // (rise, occluder step) or stack (h, step)

std::string programOptions(const HorizonOptions& options, const HorizonOutputs& outputs, bool has_nodata) {
  std::ostringstream s;
  s << "-DHFVIS_HAS_NODATA=" << has_nodata << " -DHFVIS_WANT_ANGLES=" << outputs.horizon_angles
    << " -DHFVIS_WANT_DISTANCES=" << outputs.horizon_distances
    << " -DHFVIS_WANT_SVF=" << outputs.sky_view_factor << " -DHFVIS_WANT_AO=" << outputs.ambient_occlusion
    << " -DHFVIS_DIRECTIONS=" << options.directions << " -DHFVIS_NEAR_SAMPLES=" << options.near_field_samples;
  return s.str();
}

void enqueueHullSweep(ContextState& st, cl::Program& program, const cl::Buffer& directions,
                      const SweepBatch& batch, const cl::Buffer& lines, const cl::Buffer& stacks) {
  cl::Kernel hull(program, "horizon_sweep");
  hull.setArg(0, directions);
  hull.setArg(1, lines);
  hull.setArg(2, stacks);
  st.launch(hull, cl::NDRange(roundUp(batch.maxLines(), kLineGroup), batch.directions.size()),
            cl::NDRange(kLineGroup, 1));
}

HorizonResult run(const ComputeContext& context, const HeightField& field, const HorizonOptions& options,
                  const HorizonOutputs& outputs) {
  ContextState& st = context.state();
  const PreparedHeights prepared = prepareHeights(field);
  const bool sweep = options.method == HorizonMethod::Sweep;
  cl::Program program = st.program("horizon.cl", programOptions(options, outputs, prepared.has_nodata) + " " +
                                                     layoutProgramOption(st.info));
  const std::size_t plane = field.pixelCount();

  SweepMemory memory;
  memory.fixed_bytes = plane * sizeof(float) * (1 + outputs.sky_view_factor + outputs.ambient_occlusion);
  memory.bytes_per_entry = sweep ? 2 * kLineEntryBytes : 0;  // line buffer + hull stacks
  memory.largest_entry_bytes = kLineEntryBytes;
  memory.bytes_per_direction = plane * sizeof(float) * (outputs.horizon_angles + outputs.horizon_distances);
  const auto batches =
      planSweepBatches(runDirections(field, options), memory, options.memory_budget_bytes, st.info);
  std::size_t max_entries = 0, max_directions = 0;
  for (const auto& b : batches) {
    max_entries = std::max(max_entries, b.entries);
    max_directions = std::max(max_directions, b.directions.size());
  }

  HorizonResult result = allocateResult(field, options, outputs);
  cl::Buffer heights(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, plane * sizeof(float),
                     const_cast<float*>(prepared.heights.data()));
  cl::Buffer lines, stacks;
  if (sweep) {
    lines = deviceBuffer(st, max_entries * kLineEntryBytes);
    stacks = deviceBuffer(st, max_entries * kLineEntryBytes);
  }
  const std::size_t planes_bytes = max_directions * plane * sizeof(float);
  cl::Buffer angles = deviceBuffer(st, outputs.horizon_angles ? planes_bytes : 0);
  cl::Buffer distances = deviceBuffer(st, outputs.horizon_distances ? planes_bytes : 0);
  cl::Buffer svf = deviceBuffer(st, outputs.sky_view_factor ? plane * sizeof(float) : 0);
  cl::Buffer ao = deviceBuffer(st, outputs.ambient_occlusion ? plane * sizeof(float) : 0);
  const float zero = 0.0f;
  if (outputs.sky_view_factor) st.queue.enqueueFillBuffer(svf, zero, 0, plane * sizeof(float));
  if (outputs.ambient_occlusion) st.queue.enqueueFillBuffer(ao, zero, 0, plane * sizeof(float));

  const cl::NDRange pixels(roundUp(field.width, kTileX), roundUp(field.height, kTileY));
  int done = 0;
  for (const SweepBatch& batch : batches) {
    const cl::Buffer directions = uploadDirections(st, batch.directions);
    const int batch_size = static_cast<int>(batch.directions.size());
    if (sweep) {
      enqueuePresample(st, program, heights, field.width, field.height, directions, batch, lines);
      enqueueHullSweep(st, program, directions, batch, lines, stacks);
    }
    cl::Kernel reduce(program, sweep ? "horizon_reduce" : "horizon_naive");
    int arg = 0;
    reduce.setArg(arg++, heights);
    reduce.setArg(arg++, field.width);
    reduce.setArg(arg++, field.height);
    reduce.setArg(arg++, static_cast<float>(field.cell_size_x));
    reduce.setArg(arg++, static_cast<float>(field.cell_size_y));
    reduce.setArg(arg++, directions);
    reduce.setArg(arg++, batch_size);
    if (sweep) reduce.setArg(arg++, lines);
    reduce.setArg(arg++, angles);
    reduce.setArg(arg++, distances);
    reduce.setArg(arg++, svf);
    reduce.setArg(arg++, ao);
    st.launch(reduce, pixels, cl::NDRange(kTileX, kTileY));
    const std::size_t batch_bytes = batch_size * plane * sizeof(float);
    const std::size_t at = batch.first * plane;
    if (outputs.horizon_angles)
      st.queue.enqueueReadBuffer(angles, CL_TRUE, 0, batch_bytes, &result.angles[at]);
    if (outputs.horizon_distances)
      st.queue.enqueueReadBuffer(distances, CL_TRUE, 0, batch_bytes, &result.distances[at]);
    st.queue.finish();
    done += batch_size;
    if (options.progress) options.progress(done, options.directions);
  }
  if (outputs.sky_view_factor)
    st.queue.enqueueReadBuffer(svf, CL_TRUE, 0, plane * sizeof(float), result.sky_view_factor.data());
  if (outputs.ambient_occlusion)
    st.queue.enqueueReadBuffer(ao, CL_TRUE, 0, plane * sizeof(float), result.ambient_occlusion.data());
  finishReduction(options, result);
  return result;
}

}  // namespace

SweepLineBuffers sweepLinesOnDevice(const ComputeContext& context, const HeightField& field,
                                    const std::vector<float>& prepared_heights,
                                    const SweepDirection& direction) {
  return translateOpenClErrors([&] {
    ContextState& st = context.state();
    cl::Program program = st.program("horizon.cl", layoutProgramOption(st.info));
    const bool line_major = lineMajorLayout(st.info);
    SweepBatch batch;
    batch.directions = {direction};
    batch.directions[0].buffer_offset = 0;
    batch.entries = direction.entries();
    SweepLineBuffers out;
    out.geometry = batch.directions[0];
    cl::Buffer heights(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR,
                       prepared_heights.size() * sizeof(float), const_cast<float*>(prepared_heights.data()));
    const cl::Buffer directions = uploadDirections(st, batch.directions);
    cl::Buffer lines = deviceBuffer(st, batch.entries * kLineEntryBytes);
    cl::Buffer stacks = deviceBuffer(st, batch.entries * kLineEntryBytes);
    std::vector<float> pairs(batch.entries * 2);
    enqueuePresample(st, program, heights, field.width, field.height, directions, batch, lines);
    st.queue.enqueueReadBuffer(lines, CL_TRUE, 0, pairs.size() * sizeof(float), pairs.data());
    // Back to the canonical step-major order of SweepLineBuffers.
    const SweepDirection& d = out.geometry;
    out.samples.resize(batch.entries);
    out.occluder_rises.resize(batch.entries);
    out.occluder_steps.resize(batch.entries);
    for (int j = 0; j < d.n_lines; ++j)
      for (int i = 0; i < d.n_steps; ++i)
        out.samples[std::size_t(i) * d.n_lines + j] = pairs[2 * lineEntry(d, j, i, line_major)];
    enqueueHullSweep(st, program, directions, batch, lines, stacks);
    st.queue.enqueueReadBuffer(lines, CL_TRUE, 0, pairs.size() * sizeof(float), pairs.data());
    for (int j = 0; j < d.n_lines; ++j) {
      for (int i = 0; i < d.n_steps; ++i) {
        const std::size_t e = lineEntry(d, j, i, line_major), canonical = std::size_t(i) * d.n_lines + j;
        out.occluder_rises[canonical] = pairs[2 * e];
        out.occluder_steps[canonical] = pairs[2 * e + 1];
      }
    }
    return out;
  });
}

}  // namespace detail

HorizonResult computeHorizons(const ComputeContext& context, const HeightField& field,
                              const HorizonOptions& options, const HorizonOutputs& outputs) {
  validate(field);
  validate(options, outputs);
  return detail::translateOpenClErrors([&] { return detail::run(context, field, options, outputs); });
}

}  // namespace hfvis
