// bounce.cpp: the one-bounce operation on the device: per direction, one launch of the
// convex hull tree sweep on lattice lines with the gather, each receiver adding its
// irradiance straight into its pixel's sums.
#include <algorithm>
#include <cmath>

#include "ops/bounce_internal.hpp"
#include "hfvis/errors.hpp"
#include "core/hull_tree_device.hpp"
#include "core/opencl_context.hpp"
#include "core/sweep_framework.hpp"

namespace hfvis {
namespace detail {
namespace {

// The tree program with the gather of `channels` radiance channels, nothing else.
TreeProgramFlags bounceFlags(int channels, const HullTreeTuning& tuning) {
  TreeProgramFlags flags;
  flags.tuning = tuning;
  flags.count = false;
  flags.area = false;
  flags.stats = false;
  flags.bounce_channels = channels;
  return flags;
}

std::vector<float> joined(const std::vector<std::vector<float>>& planes) {
  std::vector<float> all;
  for (const auto& p : planes) all.insert(all.end(), p.begin(), p.end());
  return all;
}

class BounceRoutine : public TreeRoutine {
 public:
  BounceRoutine(ContextState& st, const HeightField& field, const ExitRadiance& radiance, const BounceOptions& options)
      : TreeRoutine(st, field, options, bounceFlags(static_cast<int>(radiance.channels.size()), options.tree)),
        radiance_(radiance),
        bounce_(options) {}

  BounceResult take() { return std::move(result_); }

 private:
  PreparedHeights prepare() override {
    inputs_ = prepareBounce(field_, radiance_);
    PreparedHeights prepared{inputs_.heights, inputs_.has_nodata};
    prepared.base = inputs_.height_base;
    return prepared;
  }

  void allocate() override {
    const int channels = inputs_.channels();
    const std::size_t plane = field_.pixelCount();
    // Heights, normals, radiance and the irradiance sums.
    allocateScratch(plane * sizeof(float) * (1 + 3 + 2 * channels));
    buffers_.normals = upload(joined(inputs_.normals));
    buffers_.radiance = upload(joined(inputs_.radiance));
    buffers_.count_sum = buffers_.area_sum = deviceBuffer(st_, 0);
    buffers_.irradiance = zeros(channels * plane);
    result_.width = field_.width;
    result_.height = field_.height;
    result_.directions = bounce_.directions;
    for (int k = 0; k < bounce_.directions; ++k) result_.azimuths.push_back(directionAzimuth(k, bounce_));
  }

  void finish() override {
    const std::size_t plane = field_.pixelCount();
    result_.irradiance.assign(inputs_.channels(), std::vector<float>(plane));
    for (int c = 0; c < inputs_.channels(); ++c) {
      st_.queue.enqueueReadBuffer(buffers_.irradiance, CL_TRUE, c * plane * sizeof(float), plane * sizeof(float),
                                  result_.irradiance[c].data());
    }
  }

  const ExitRadiance& radiance_;
  const BounceOptions& bounce_;
  BounceInputs inputs_;
  BounceResult result_;
};

}  // namespace

BounceLineView bounceLinesOnDevice(const ComputeContext& context, const HeightField& field,
                                   const BounceInputs& inputs, const TreeDirection& d,
                                   const HullTreeTuning& tuning) {
  validate(tuning);
  return translateOpenClErrors([&] {
    BounceLineView view;
    std::vector<float> irradiance;
    TreeProgramFlags flags = bounceFlags(inputs.channels(), tuning);
    flags.has_nodata = inputs.has_nodata;
    view.lines = treeLinesOnDevice(stateOf(context), flags, field, inputs.heights, inputs.height_base, d,
                                   &inputs, &irradiance);
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
  // The radiance, irradiance and normal planes are indexed across one buffer each.
  detail::checkPixelIndexing(field, std::max<int>(3, static_cast<int>(radiance.channels.size())));
  return detail::translateOpenClErrors([&] {
    detail::BounceRoutine routine(detail::stateOf(context), field, radiance, options);
    routine.run();
    return routine.take();
  });
}

}  // namespace hfvis
