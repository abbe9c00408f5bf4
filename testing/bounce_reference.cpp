// bounce_reference.cpp: the scalar reference of the one-bounce gather: the lattice lines
// and their exit radiance sampled as intervisibility_lattice samples them, the gather inside
// the hull-tree sweep (src/core/scalar_hull_tree.cpp), and each receiver's irradiance added to
// its pixel.
#include "hfvis_testing/bounce_reference.hpp"

#include <cmath>
#include <limits>
#include <string>

#include "ops/bounce_internal.hpp"
#include "hfvis/errors.hpp"
#include "core/horizon_common.hpp"
#include "reference_internal.hpp"

namespace hfvis {
namespace detail {

BounceLineView referenceBounceLines(const HeightField& field, const BounceInputs& inputs, const TreeDirection& d,
                                    const HullTreeTuning& tuning, bool all_horizons) {
  BounceLineView view;
  view.lines = latticeTreeLines(field, inputs.heights, d);
  view.lines.height_base = inputs.height_base;
  view.lines.horizons_at_every_sample = all_horizons;
  const int channels = inputs.channels();
  const int stride = channels + kBounceNormalFloats;
  const std::size_t entries = view.lines.samples.size();
  view.bounce.channels = channels;
  view.bounce.half_sector = d.half_sector;
  view.bounce.wedge = d.wedge;
  view.bounce.step_ground = d.step_ground;
  view.bounce.attributes.assign(entries * stride, std::numeric_limits<float>::quiet_NaN());
  // Radiance sampled like the heights (lattice_radiance); the receivers' normals are their pixels'.
  for (int c = 0; c < channels; ++c) {
    const IntervisibilityLines radiance = latticeTreeLines(field, inputs.radiance[c], d);
    for (std::size_t e = 0; e < entries; ++e) view.bounce.attributes[e * stride + c] = radiance.samples[e];
  }
  const auto& g = view.lines.geometry;
  for (int j = 0; j < g.n_lines; ++j) {
    for (int i = view.lines.receiver_every - 1; i < d.lines[j].receivers * view.lines.receiver_every;
         i += view.lines.receiver_every) {
      const std::size_t e = static_cast<std::size_t>(i) * g.n_lines + j, pixel = receiverPixel(d, field.width, j, i);
      for (int a = 0; a < kBounceNormalFloats; ++a) view.bounce.attributes[e * stride + channels + a] = inputs.normals[a][pixel];
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
  const auto directions = detail::treeDirections(field, options);
  detail::checkTreeLimits(directions, inputs.heights);
  const int channels = inputs.channels();
  const std::size_t plane = field.pixelCount();

  BounceResult result;
  result.width = field.width;
  result.height = field.height;
  result.directions = options.directions;
  for (int k = 0; k < options.directions; ++k) result.azimuths.push_back(directionAzimuth(k, options));
  result.irradiance.assign(channels, std::vector<float>(plane, 0.0f));
  for (const detail::TreeDirection& d : directions) {
    const detail::BounceLineView view = detail::referenceBounceLines(field, inputs, d, options.tree, false);
    const auto& g = view.lines.geometry;
    const int every = view.lines.receiver_every;
    for (int j = 0; j < g.n_lines; ++j) {
      for (int i = every - 1; i < d.lines[j].receivers * every; i += every) {
        const std::size_t e = static_cast<std::size_t>(i) * g.n_lines + j;
        const std::size_t p = detail::receiverPixel(d, field.width, j, i);
        for (int ch = 0; ch < channels; ++ch) result.irradiance[ch][p] += view.bounce.irradiance[e * channels + ch];
      }
    }
  }
  for (std::size_t p = 0; p < plane; ++p)
    if (std::isnan(inputs.heights[p]))
      for (auto& channel : result.irradiance) channel[p] = std::numeric_limits<float>::quiet_NaN();
  return result;
}

}  // namespace hfvis
