// bounce.cpp: the one-bounce operation on the device: per batch of directions, presample
// heights, radiance and normals -> convex hull tree sweep with the gather -> reduction into
// the irradiance sums.
#include <algorithm>

#include "bounce_internal.hpp"
#include "hfvis/errors.hpp"
#include "intervisibility_device.hpp"
#include "opencl_context.hpp"
#include "sweep_framework.hpp"

namespace hfvis {
namespace detail {
namespace {

std::size_t attributeBytes(int channels) { return (channels + kBounceNormalFloats) * sizeof(float); }

TreeProgramFlags bounceFlags(const BounceInputs& inputs, const HullTreeTuning& tuning) {
  TreeProgramFlags flags;
  flags.tuning = tuning;
  flags.has_nodata = inputs.has_nodata;
  flags.area = false;
  flags.stats = false;
  flags.bounce_channels = inputs.channels();
  return flags;
}

// The inputs' planes, uploaded once per run.
struct BouncePlanes {
  cl::Buffer heights, normals, radiance;
};

BouncePlanes uploadPlanes(ContextState& st, const BounceInputs& inputs) {
  auto upload = [&](const std::vector<std::vector<float>>& planes) {
    std::vector<float> joined;
    for (const auto& p : planes) joined.insert(joined.end(), p.begin(), p.end());
    return cl::Buffer(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, joined.size() * sizeof(float),
                      joined.data());
  };
  BouncePlanes planes;
  planes.heights =
      cl::Buffer(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, inputs.heights.size() * sizeof(float),
                 const_cast<float*>(inputs.heights.data()));
  planes.normals = upload(inputs.normals);
  planes.radiance = upload(inputs.radiance);
  return planes;
}

// The sweep's buffers for `entries` line entries (the bounce needs no area, statistics or
// per-entry statistics).
TreeSweepBuffers sweepBuffers(ContextState& st, std::size_t entries, int channels, int directions) {
  TreeSweepBuffers b;
  b.lines = deviceBuffer(st, entries * kTreeLineBytes);
  b.trees = deviceBuffer(st, entries * kTreeNodeBytes);
  b.visible = deviceBuffer(st, entries * kTreeVisibleBytes);
  b.prefix = deviceBuffer(st, 0);
  b.entry_stats = deviceBuffer(st, 0);
  b.line_totals = deviceBuffer(st, 0);
  b.bounce_lines = deviceBuffer(st, entries * attributeBytes(channels));
  b.bounce_out = deviceBuffer(st, entries * channels * sizeof(float));
  bounceWedge(directions, &b.half_sector, &b.wedge);
  return b;
}

// Presampling of heights (presample_lines) and of radiance and normals (bounce_presample).
void enqueueBouncePresample(ContextState& st, cl::Program& program, const BouncePlanes& planes, int width,
                            int height, const cl::Buffer& directions, const SweepBatch& batch,
                            const TreeSweepBuffers& b) {
  enqueuePresample(st, program, planes.heights, width, height, directions, batch, b.lines);
  cl::Kernel presample(program, "bounce_presample");
  presample.setArg(0, planes.radiance);
  presample.setArg(1, planes.normals);
  presample.setArg(2, width);
  presample.setArg(3, height);
  presample.setArg(4, directions);
  presample.setArg(5, b.bounce_lines);
  const std::size_t lines = batch.maxLines(), steps = batch.maxSteps();
  const bool line_major = lineMajorLayout(st);
  st.launch(presample,
            cl::NDRange(roundUp(line_major ? steps : lines, kLineGroup),
                        roundUp(line_major ? lines : steps, kPresampleRows), batch.directions.size()),
            cl::NDRange(kLineGroup, kPresampleRows, 1));
}

BounceResult run(const ComputeContext& context, const HeightField& field, const ExitRadiance& radiance,
                 const BounceOptions& options) {
  ContextState& st = stateOf(context);
  const BounceInputs inputs = prepareBounce(field, radiance);
  const int channels = inputs.channels();
  const auto all = runDirections(field, options);
  IntervisibilityOutputs counts;
  counts.visible_count = true;
  checkLineLimits(all, inputs.heights, counts);
  const TreeProgramFlags flags = bounceFlags(inputs, options.tree);
  cl::Program program = st.program(treeProgramFile(flags), treeProgramOptions(flags, st));
  const std::size_t plane = field.pixelCount();

  SweepMemory memory;
  // Heights, normals, radiance and the irradiance sums.
  memory.fixed_bytes = plane * sizeof(float) * (1 + 3 + 2 * channels);
  memory.bytes_per_entry = kTreeLineBytes + kTreeNodeBytes + kTreeVisibleBytes + attributeBytes(channels) +
                           channels * sizeof(float);
  memory.largest_entry_bytes = std::max(kTreeNodeBytes, attributeBytes(channels));
  const auto batches = planSweepBatches(all, memory, options.memory_budget_bytes, st.info);
  std::size_t max_entries = 0;
  for (const auto& b : batches) max_entries = std::max(max_entries, b.entries);

  BounceResult result;
  result.width = field.width;
  result.height = field.height;
  result.directions = options.directions;
  for (int k = 0; k < options.directions; ++k) result.azimuths.push_back(directionAzimuth(k, options));

  const BouncePlanes planes = uploadPlanes(st, inputs);
  const TreeSweepBuffers buffers = sweepBuffers(st, max_entries, channels, options.directions);
  cl::Buffer sums = deviceBuffer(st, channels * plane * sizeof(float));
  const float zero = 0.0f;
  st.queue.enqueueFillBuffer(sums, zero, 0, channels * plane * sizeof(float));

  const cl::NDRange pixels(roundUp(field.width, kTileX), roundUp(field.height, kTileY));
  int done = 0;
  for (const SweepBatch& batch : batches) {
    const cl::Buffer directions = uploadDirections(st, batch.directions);
    const int batch_size = static_cast<int>(batch.directions.size());
    enqueueBouncePresample(st, program, planes, field.width, field.height, directions, batch, buffers);
    enqueueTreeSweep(st, program, directions, batch, buffers);
    cl::Kernel reduce(program, "bounce_reduce");
    reduce.setArg(0, planes.heights);
    reduce.setArg(1, field.width);
    reduce.setArg(2, field.height);
    reduce.setArg(3, directions);
    reduce.setArg(4, batch_size);
    reduce.setArg(5, buffers.bounce_out);
    reduce.setArg(6, sums);
    st.launch(reduce, pixels, cl::NDRange(kTileX, kTileY));
    st.queue.finish();
    done += batch_size;
    if (options.progress) options.progress(done, options.directions);
  }
  result.irradiance.assign(channels, std::vector<float>(plane));
  for (int c = 0; c < channels; ++c) {
    st.queue.enqueueReadBuffer(sums, CL_TRUE, c * plane * sizeof(float), plane * sizeof(float),
                               result.irradiance[c].data());
  }
  return result;
}

}  // namespace

BounceLineView bounceLinesOnDevice(const ComputeContext& context, const HeightField& field,
                                   const BounceInputs& inputs, const SweepDirection& direction,
                                   int directions, const HullTreeTuning& tuning) {
  validate(tuning);
  return translateOpenClErrors([&] {
    ContextState& st = stateOf(context);
    const TreeProgramFlags flags = bounceFlags(inputs, tuning);
    cl::Program program = st.program(treeProgramFile(flags), treeProgramOptions(flags, st));
    const bool line_major = lineMajorLayout(st);
    const int channels = inputs.channels();
    const int stride = channels + kBounceNormalFloats;
    SweepBatch batch;
    batch.directions = {direction};
    batch.directions[0].buffer_offset = 0;
    batch.entries = direction.entries();
    const std::size_t entries = batch.entries;
    const BouncePlanes planes = uploadPlanes(st, inputs);
    const cl::Buffer directions_buffer = uploadDirections(st, batch.directions);
    const TreeSweepBuffers buffers = sweepBuffers(st, entries, channels, directions);
    enqueueBouncePresample(st, program, planes, field.width, field.height, directions_buffer, batch, buffers);
    enqueueTreeSweep(st, program, directions_buffer, batch, buffers);
    std::vector<float> pairs(entries * 2), visible(entries * 2), attributes(entries * stride),
        gathered(entries * channels);
    st.queue.enqueueReadBuffer(buffers.lines, CL_TRUE, 0, pairs.size() * sizeof(float), pairs.data());
    st.queue.enqueueReadBuffer(buffers.visible, CL_TRUE, 0, visible.size() * sizeof(float), visible.data());
    st.queue.enqueueReadBuffer(buffers.bounce_lines, CL_TRUE, 0, attributes.size() * sizeof(float),
                               attributes.data());
    st.queue.enqueueReadBuffer(buffers.bounce_out, CL_TRUE, 0, gathered.size() * sizeof(float),
                               gathered.data());

    // Back to the canonical step-major order.
    BounceLineView view;
    const SweepDirection& d = batch.directions[0];
    view.lines.geometry = d;
    view.lines.samples.resize(entries);
    view.lines.counts.resize(entries);
    view.bounce.channels = channels;
    bounceWedge(directions, &view.bounce.half_sector, &view.bounce.wedge);
    view.bounce.attributes.resize(entries * stride);
    view.bounce.irradiance.resize(entries * channels);
    for (int j = 0; j < d.n_lines; ++j) {
      for (int i = 0; i < d.n_steps; ++i) {
        const std::size_t e = lineEntry(d, j, i, line_major), canonical = std::size_t(i) * d.n_lines + j;
        view.lines.samples[canonical] = pairs[2 * e];
        view.lines.counts[canonical] = visible[2 * e];
        for (int a = 0; a < stride; ++a)
          view.bounce.attributes[canonical * stride + a] = attributes[e * stride + a];
        for (int c = 0; c < channels; ++c)
          view.bounce.irradiance[canonical * channels + c] = gathered[e * channels + c];
      }
    }
    return view;
  });
}

}  // namespace detail

BounceResult computeBounce(const ComputeContext& context, const HeightField& field,
                           const ExitRadiance& radiance, const BounceOptions& options) {
  validate(field);
  validate(options);
  validate(field, radiance);
  return detail::translateOpenClErrors([&] { return detail::run(context, field, radiance, options); });
}

}  // namespace hfvis
