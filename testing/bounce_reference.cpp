// bounce_reference.cpp: the scalar reference of the one-bounce gather: the mirrors of
// bounce_presample, the gather inside the hull-tree sweep (src/scalar_hull_tree.cpp) and
// bounce_reduce.
#include "hfvis/bounce_reference.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "bounce_internal.hpp"
#include "hfvis/errors.hpp"
#include "horizon_common.hpp"

namespace hfvis {
namespace detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

}  // namespace

BounceLineView referenceBounceLines(const HeightField& field, const BounceInputs& inputs,
                                    const SweepDirection& d, int directions, const HullTreeTuning& tuning) {
  BounceLineView view;
  view.lines.geometry = d;
  const std::size_t entries = d.entries();
  const int channels = inputs.channels();
  const int stride = channels + kBounceNormalFloats;
  view.lines.samples.assign(entries, kNaN);
  view.bounce.channels = channels;
  bounceWedge(directions, &view.bounce.half_sector, &view.bounce.wedge);
  view.bounce.attributes.assign(entries * stride, kNaN);
  for (int j = 0; j < d.n_lines; ++j) {
    for (int i = 0; i < d.n_steps; ++i) {
      const Point2 p = sweepPosition(d, j, i);
      const std::size_t e = static_cast<std::size_t>(i) * d.n_lines + j;
      // As presample_lines and bounce_presample (attributes are sampled everywhere; only
      // those of present samples are read).
      if (insideField(p, field.width, field.height))
        view.lines.samples[e] = sampleHeight(inputs.heights, field.width, field.height, p);
      float* out = &view.bounce.attributes[e * stride];
      for (int c = 0; c < channels; ++c)
        out[c] = sampleHeight(inputs.radiance[c], field.width, field.height, p);
      const float nx = sampleHeight(inputs.normals[0], field.width, field.height, p);
      const float ny = sampleHeight(inputs.normals[1], field.width, field.height, p);
      const float nz = sampleHeight(inputs.normals[2], field.width, field.height, p);
      const float length = std::sqrt(nx * nx + ny * ny + nz * nz);
      out[channels] = nx / length;
      out[channels + 1] = ny / length;
      out[channels + 2] = nz / length;
    }
  }
  sweepPresampledLines(view.lines, tuning, false, &view.bounce);
  return view;
}

}  // namespace detail

BounceResult referenceBounce(const HeightField& field, const ExitRadiance& radiance,
                             const BounceOptions& options) {
  validate(field);
  validate(options);
  validate(field, radiance);
  const detail::BounceInputs inputs = detail::prepareBounce(field, radiance);
  const auto directions = detail::runDirections(field, options);
  IntervisibilityOutputs counts;
  counts.visible_count = true;
  detail::checkLineLimits(directions, inputs.heights, counts);
  const int channels = inputs.channels();
  const std::size_t plane = field.pixelCount();

  BounceResult result;
  result.width = field.width;
  result.height = field.height;
  result.directions = options.directions;
  for (int k = 0; k < options.directions; ++k) result.azimuths.push_back(directionAzimuth(k, options));
  result.irradiance.assign(channels, std::vector<float>(plane, 0.0f));
  for (const detail::SweepDirection& d : directions) {
    const detail::BounceLineView view =
        detail::referenceBounceLines(field, inputs, d, options.directions, options.tree);
    const std::vector<float>& gathered = view.bounce.irradiance;
    // Mirror of bounce_reduce, one direction at a time.
    for (int r = 0; r < field.height; ++r) {
      for (int c = 0; c < field.width; ++c) {
        float weight = 0.0f, acc[kMaxBounceChannels] = {};
        for (const detail::CellCorner& corner : detail::receiverCell(d, c, r)) {
          const float w = corner.weight;
          const std::size_t e = corner.entry;
          if (w <= 0.0f) continue;
          if (std::isnan(gathered[e * channels])) continue;
          weight += w;
          for (int ch = 0; ch < channels; ++ch) acc[ch] += w * gathered[e * channels + ch];
        }
        const bool renormalise = weight > 0.0f && weight != 1.0f;
        const std::size_t p = static_cast<std::size_t>(r) * field.width + c;
        for (int ch = 0; ch < channels; ++ch)
          result.irradiance[ch][p] += renormalise ? acc[ch] / weight : acc[ch];
      }
    }
  }
  for (std::size_t p = 0; p < plane; ++p)
    if (std::isnan(inputs.heights[p]))
      for (auto& channel : result.irradiance) channel[p] = std::numeric_limits<float>::quiet_NaN();
  return result;
}

}  // namespace hfvis
