// horizon_lists.cpp: the visibility horizons of chosen receivers: each receiver's ray is
// sampled as the naive method samples it and swept, receiver last, by the scalar hull-tree
// sweep (the mirror of kernels/intervisibility.cl), which keeps every horizon and the end
// of its visible run.
#include "hfvis/horizon_lists.hpp"

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "hfvis/errors.hpp"
#include "core/horizon_common.hpp"
#include "core/hull_tree.hpp"

namespace hfvis {
namespace {

// The ray from pixel (c, r) along d, as the naive visibility march samples it: sample i
// (1 = nearest) at index i - 1, NaN where absent, up to the last sample inside the field, each
// lowered by the Earth's drop at its distance (c times its step's ground length squared, times
// i^2, in float). With per-row spacing (units: the ray's half-row table of step units,
// naiveRowTables) sample i lies at `positions[i - 1]` whole units of `unit` ground length, its
// step toward the receiver `rings[i - 1]` units long, and the drop is c unit^2 position^2.
struct Ray {
  std::vector<float> heights;
  std::vector<std::int32_t> positions, rings;
};

Ray raySamples(const HeightField& field, const std::vector<float>& heights, const detail::SweepDirection& d, int c,
               int r, double curvature, const std::int32_t* units, double unit) {
  const float step_ground = d.step_length * d.ground_per_pixel;
  const float drop = units ? static_cast<float>(curvature * unit * unit)
                           : static_cast<float>(curvature) * step_ground * step_ground;
  const float step_y = d.step_length * d.dir_y;
  Ray ray;
  std::int32_t position = 0;
  for (int i = 1;; ++i) {
    const float t = static_cast<float>(i) * d.step_length;
    const detail::Point2 p{static_cast<float>(c) + t * d.dir_x, static_cast<float>(r) + t * d.dir_y};
    if (!detail::insideField(p, field.width, field.height)) break;
    float at = static_cast<float>(i);
    if (units) {
      const std::int32_t ring = detail::rayStepUnits(units, field.height, r, i, step_y);
      position += ring;
      ray.positions.push_back(position);
      ray.rings.push_back(ring);
      at = static_cast<float>(position);
    }
    const float q = detail::sampleHeight(heights, field.width, field.height, p);
    ray.heights.push_back(curvature != 0.0 ? q - drop * at * at : q);
  }
  return ray;
}

DirectionHorizons listDirection(const HeightField& field, const std::vector<float>& heights,
                                const detail::SweepDirection& d, int k, double azimuth, int c, int r,
                                double curvature, const std::int32_t* units, double unit) {
  DirectionHorizons out;
  out.direction = k;
  out.azimuth = azimuth;
  const Ray samples = raySamples(field, heights, d, c, r, curvature, units, unit);
  const std::vector<float>& ray = samples.heights;
  const int n = static_cast<int>(ray.size());
  // Ground distance of sample i: i steps, or its position in units with per-row spacing.
  auto distance = [&](int i) {
    return units ? samples.positions[i - 1] * unit : i * out.sample_spacing;
  };
  out.sample_spacing = units ? (n > 0 ? samples.rings[0] * unit : 0.0)
                             : static_cast<double>(d.step_length) * d.ground_per_pixel;
  out.ray_samples = n;
  const float h = heights[static_cast<std::size_t>(r) * field.width + c];
  if (std::isnan(h) || n == 0) return out;

  // One line, swept from the far end: step s holds sample n - s, the receiver is step n.
  detail::IntervisibilityLines line;
  line.geometry = d;
  line.geometry.n_lines = 1;
  line.geometry.n_steps = n + 1;
  line.geometry.buffer_offset = 0;
  line.samples.resize(static_cast<std::size_t>(n) + 1);
  for (int s = 0; s < n; ++s) line.samples[s] = ray[n - 1 - s];
  line.samples[n] = h;
  if (units) {  // positions rise toward the receiver, at the farthest sample's distance
    const std::int32_t far = samples.positions[n - 1];
    line.positions.resize(line.samples.size());
    line.step_units.resize(line.samples.size());
    for (int s = 0; s < n; ++s) {
      line.positions[s] = far - samples.positions[n - 1 - s];
      line.step_units[s] = samples.rings[n - 1 - s];
    }
    line.positions[n] = far;
    line.step_units[n] = 0;  // the receiver is no one's farther sample
  }
  detail::sweepPresampledLines(line, HullTreeTuning{}, true);

  const std::vector<int>& steps = line.horizon_steps[n];  // farthest first
  const std::vector<int>& ends = line.horizon_run_ends[n];
  for (std::size_t idx = steps.size(); idx-- > 0;) {  // nearest first
    VisibilityHorizon horizon;
    horizon.sample = n - steps[idx];
    horizon.segment_end = horizon.sample + 1;
    // Steps [h, end) hold the run; its nearest present sample begins the segment.
    horizon.segment_begin = n - ends[idx] + 1;
    while (std::isnan(ray[horizon.segment_begin - 1])) ++horizon.segment_begin;
    horizon.distance = distance(horizon.sample);
    horizon.near_distance = distance(horizon.segment_begin);
    horizon.elevation = std::atan2(static_cast<double>(ray[horizon.sample - 1]) - h, horizon.distance);
    for (int i = horizon.segment_begin; i < horizon.segment_end; ++i)
      horizon.visible_samples += !std::isnan(ray[i - 1]);
    out.visible_samples += horizon.visible_samples;
    out.horizons.push_back(horizon);
  }
  if (out.visible_samples != static_cast<int>(line.counts[n])) {
    throw Error("internal error: the horizon segments hold " + std::to_string(out.visible_samples) +
                " samples, the sweep counted " + std::to_string(line.counts[n]));
  }
  return out;
}

}  // namespace

void validateReceivers(const HeightField& field, const std::vector<ReceiverPixel>& receivers) {
  for (const ReceiverPixel& p : receivers) {
    if (p.col < 0 || p.col >= field.width || p.row < 0 || p.row >= field.height) {
      throw InvalidArgument("receiver (" + std::to_string(p.col) + ", " + std::to_string(p.row) +
                            ") is outside the field, which is " + std::to_string(field.width) + " x " +
                            std::to_string(field.height) + " pixels (columns 0.." +
                            std::to_string(field.width - 1) + ", rows 0.." +
                            std::to_string(field.height - 1) + ")");
    }
  }
}

std::vector<ReceiverHorizons> computeHorizonLists(const HeightField& field, const SweepOptions& options,
                                                  const std::vector<ReceiverPixel>& receivers) {
  validate(field);
  validate(options);
  if (options.max_distance != 0.0)
    throw InvalidArgument("a maximum distance is not supported for horizon lists yet (visible counts take it)");
  validateReceivers(field, receivers);
  const detail::PreparedHeights prepared = detail::prepareHeights(field);
  const auto directions = detail::runDirections(field, options);
  // A ray (and its receiver) has at most width + height samples per unit step.
  detail::checkStepLimits(static_cast<std::size_t>((field.width + field.height) * options.samples_per_unit) + 2,
                          prepared.heights);

  // Per-row spacing: positions in units along each ray, as the naive visibility march's.
  const bool row_spacing = detail::hasRowSpacing(field);
  const double unit = row_spacing ? detail::groundUnit(field) : 0.0;
  const detail::NaiveRowTables rows = row_spacing ? detail::naiveRowTables(field, directions, unit) : detail::NaiveRowTables{};
  std::vector<ReceiverHorizons> lists;
  lists.reserve(receivers.size());
  for (const ReceiverPixel& p : receivers) {
    ReceiverHorizons receiver;
    receiver.pixel = p;
    receiver.height = field.at(p.col, p.row);
    receiver.nodata = std::isnan(prepared.heights[static_cast<std::size_t>(p.row) * field.width + p.col]);
    if (receiver.nodata) receiver.height = std::numeric_limits<float>::quiet_NaN();
    for (int k = 0; k < options.directions; ++k) {
      const std::int32_t* units = row_spacing ? &rows.units[k * (2 * static_cast<std::size_t>(field.height) - 1)] : nullptr;
      receiver.directions.push_back(listDirection(field, prepared.heights, directions[k], k,
                                                  directionAzimuth(k, options), p.col, p.row, options.curvature,
                                                  units, unit));
    }
    lists.push_back(std::move(receiver));
  }
  return lists;
}

}  // namespace hfvis
