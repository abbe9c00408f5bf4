// bounce_inputs.cpp: what the bounce's device run and its scalar reference share: the
// validation of a run's inputs and the prepared inputs (heights, normals, radiance).
#include <cmath>
#include <limits>
#include <string>

#include "ops/bounce_internal.hpp"
#include "hfvis/errors.hpp"
#include "core/horizon_common.hpp"

namespace hfvis {
namespace detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

}  // namespace

BounceInputs prepareBounce(const HeightField& field, const ExitRadiance& radiance) {
  BounceInputs in;
  PreparedHeights prepared = prepareHeights(field);
  in.heights = std::move(prepared.heights);
  in.height_base = prepared.base;
  in.has_nodata = prepared.has_nodata;
  const std::size_t plane = field.pixelCount();
  in.normals.assign(3, std::vector<float>(plane, kNaN));
  const auto cell_x = static_cast<float>(field.cell_size_x), cell_y = static_cast<float>(field.cell_size_y);
  for (int r = 0; r < field.height; ++r) {
    for (int c = 0; c < field.width; ++c) {
      const std::size_t p = static_cast<std::size_t>(r) * field.width + c;
      if (std::isnan(in.heights[p])) continue;
      float n[3];
      pixelNormal(in.heights, field.width, field.height, c, r, cell_x, cell_y, n);
      for (int i = 0; i < 3; ++i) in.normals[i][p] = n[i];
    }
  }
  for (const auto& channel : radiance.channels) {
    in.radiance.push_back(channel);
    for (std::size_t p = 0; p < plane; ++p)
      if (std::isnan(in.heights[p])) in.radiance.back()[p] = kNaN;
  }
  return in;
}

}  // namespace detail

void validate(const BounceOptions& options) {
  validate(static_cast<const SweepOptions&>(options));
  validate(options.tree);
  if (options.curvature != 0.0) throw InvalidArgument("Earth curvature is not supported for the bounce");
  if (options.max_distance != 0.0) throw InvalidArgument("a maximum distance is not supported for the bounce");
}

void validate(const HeightField& field, const ExitRadiance& radiance) {
  if (radiance.width != field.width || radiance.height != field.height) {
    throw InvalidArgument("the exit radiance is " + std::to_string(radiance.width) + " x " +
                          std::to_string(radiance.height) + " pixels, the height field " +
                          std::to_string(field.width) + " x " + std::to_string(field.height) +
                          ": it needs one value per height");
  }
  const int channels = static_cast<int>(radiance.channels.size());
  if (channels < 1 || channels > kMaxBounceChannels) {
    throw InvalidArgument("the exit radiance has " + std::to_string(channels) + " channels; 1 to " +
                          std::to_string(kMaxBounceChannels) + " are gathered in one run");
  }
  for (int c = 0; c < channels; ++c) {
    const auto& plane = radiance.channels[c];
    if (plane.size() != field.pixelCount()) {
      throw InvalidArgument("exit radiance channel " + std::to_string(c) + " holds " +
                            std::to_string(plane.size()) + " values for " +
                            std::to_string(field.pixelCount()) + " pixels");
    }
    for (std::size_t p = 0; p < plane.size(); ++p) {
      if (!std::isfinite(field.heights[p])) continue;  // nodata: ignored
      // (the gather sums radiance times weights over whole lines in float: 1e30 leaves room, as
      // for an environment's; 3e38 overflowed there, and the message blamed the heights)
      if (!(std::isfinite(plane[p]) && plane[p] >= 0.0f && plane[p] <= 1e30f)) {
        throw InvalidArgument(
            "the exit radiance must be finite, >= 0 and at most 1e30 where the height is valid; channel " +
            std::to_string(c) + " at pixel (" + std::to_string(p % field.width) + ", " +
            std::to_string(p / field.width) + ") is " + std::to_string(plane[p]));
      }
    }
  }
}

}  // namespace hfvis
