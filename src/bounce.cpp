// bounce.cpp: the one-bounce operation on the device: per direction, one launch of the
// convex hull tree sweep on lattice lines with the gather, each receiver adding its
// irradiance straight into its pixel's sums.
#include <algorithm>
#include <cmath>

#include "bounce_internal.hpp"
#include "hfvis/errors.hpp"
#include "intervisibility_device.hpp"
#include "opencl_context.hpp"
#include "sweep_framework.hpp"

namespace hfvis {
namespace detail {
namespace {

TreeProgramFlags bounceFlags(const BounceInputs& inputs, const HullTreeTuning& tuning) {
  TreeProgramFlags flags;
  flags.tuning = tuning;
  flags.has_nodata = inputs.has_nodata;
  flags.count = false;
  flags.area = false;
  flags.stats = false;
  flags.bounce_channels = inputs.channels();
  return flags;
}

std::vector<float> joined(const std::vector<std::vector<float>>& planes) {
  std::vector<float> all;
  for (const auto& p : planes) all.insert(all.end(), p.begin(), p.end());
  return all;
}

BounceResult run(const ComputeContext& context, const HeightField& field, const ExitRadiance& radiance,
                 const BounceOptions& options) {
  ContextState& st = stateOf(context);
  const BounceInputs inputs = prepareBounce(field, radiance);
  const int channels = inputs.channels();
  const std::vector<TreeDirection> directions = treeDirections(field, options);
  checkTreeLimits(directions, inputs.heights);
  const TreeProgramFlags flags = bounceFlags(inputs, options.tree);
  cl::Program program = st.program("intervisibility.cl", treeProgramOptions(flags));
  const std::size_t plane = field.pixelCount();
  // Heights, normals, radiance and the irradiance sums.
  const std::size_t fixed = plane * sizeof(float) * (1 + 3 + 2 * channels);
  TreeBuffers b;
  allocateTreeScratch(st, flags, directions,
                      planTreeScratch(directions, fixed, treeEntryBytes(flags), options.memory_budget_bytes, st.info),
                      b);
  auto upload = [&](const std::vector<float>& values) {
    return cl::Buffer(st.context, CL_MEM_READ_ONLY | CL_MEM_COPY_HOST_PTR, values.size() * sizeof(float),
                      const_cast<float*>(values.data()));
  };
  b.heights = upload(inputs.heights);
  b.normals = upload(joined(inputs.normals));
  b.radiance = upload(joined(inputs.radiance));
  b.count_sum = b.area_sum = deviceBuffer(st, 0);
  b.irradiance = deviceBuffer(st, channels * plane * sizeof(float));
  const float zero = 0.0f;
  st.queue.enqueueFillBuffer(b.irradiance, zero, 0, channels * plane * sizeof(float));

  BounceResult result;
  result.width = field.width;
  result.height = field.height;
  result.directions = options.directions;
  for (int k = 0; k < options.directions; ++k) result.azimuths.push_back(directionAzimuth(k, options));
  for (std::size_t k = 0; k < directions.size(); ++k) {
    enqueueTreeDirection(st, program, directions[k], field.width, field.height, b);
    st.queue.finish();
    if (options.progress) options.progress(static_cast<int>(k + 1), static_cast<int>(directions.size()));
  }
  result.irradiance.assign(channels, std::vector<float>(plane));
  for (int c = 0; c < channels; ++c) {
    st.queue.enqueueReadBuffer(b.irradiance, CL_TRUE, c * plane * sizeof(float), plane * sizeof(float),
                               result.irradiance[c].data());
  }
  return result;
}

}  // namespace

BounceLineView bounceLinesOnDevice(const ComputeContext& context, const HeightField& field,
                                   const BounceInputs& inputs, const TreeDirection& d,
                                   const HullTreeTuning& tuning) {
  validate(tuning);
  return translateOpenClErrors([&] {
    BounceLineView view;
    std::vector<float> irradiance;
    view.lines = treeLinesOnDevice(stateOf(context), bounceFlags(inputs, tuning), field, inputs.heights, d, &inputs,
                                   &irradiance);
    // Each receiver entry takes its pixel's irradiance of this one direction.
    const int channels = inputs.channels();
    const std::size_t plane = field.pixelCount();
    view.bounce.channels = channels;
    view.bounce.half_sector = d.half_sector;
    view.bounce.wedge = d.wedge;
    view.bounce.step_ground = d.step_ground;
    const auto& g = view.lines.geometry;
    view.bounce.irradiance.assign(std::size_t(g.n_lines) * g.n_steps * channels, std::nanf(""));
    for (int j = 0; j < g.n_lines; ++j) {
      for (int i = view.lines.receiver_every - 1; i < g.n_steps; i += view.lines.receiver_every) {
        const std::size_t e = std::size_t(i) * g.n_lines + j;
        if (i >= d.lines[j].receivers * view.lines.receiver_every) break;
        const int receiver = i / view.lines.receiver_every;
        const std::size_t pixel = std::size_t(d.lines[j].row - receiver * d.lattice.b) * field.width +
                                  (d.lines[j].col - receiver * d.lattice.a);
        for (int c = 0; c < channels; ++c) view.bounce.irradiance[e * channels + c] = irradiance[c * plane + pixel];
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
