// horizon_lists.cpp: the visibility horizons of chosen receivers: each receiver's ray is
// sampled as the naive method samples it, the peaks between its samples added as occluders
// (kernels/shared/tree_peaks.cl), and swept, receiver last, by the scalar hull-tree sweep (the
// mirror of kernels/intervisibility.cl), which keeps every horizon and the end of its visible run.
#include "hfvis/horizon_lists.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>

#include "core/horizon_common.hpp"
#include "core/hull_tree.hpp"
#include "core/lattice_geometry.hpp"
#include "core/tree_peaks.hpp"
#include "hfvis/errors.hpp"
#include "ops/horizon_lists_ray.hpp"

namespace hfvis {
namespace detail {

std::size_t longestHorizonRay(const HeightField& field, const SweepOptions& options) {
  return static_cast<std::size_t>((field.width + field.height) * options.samples_per_unit) + 2;
}

int horizonRayShift(const HeightField& field, const SweepOptions& options) {
  if (hasRowSpacing(field) || field.width < 2 || field.height < 2) return 0;
  return treePositionShift(longestHorizonRay(field, options));
}

HorizonRay horizonRay(const HeightField& field, const std::vector<float>& heights, const SweepDirection& d,
                      int c, int r, double curvature, const std::int32_t* units, double unit, int shift) {
  const float step_ground = d.step_length * d.ground_per_pixel;
  const float drop = units ? static_cast<float>(curvature * unit * unit)
                           : static_cast<float>(curvature) * step_ground * step_ground;
  const float step_y = d.step_length * d.dir_y;
  HorizonRay ray;
  std::int32_t position = 0;
  for (int i = 1;; ++i) {
    const float t = static_cast<float>(i) * d.step_length;
    const Point2 p{static_cast<float>(c) + t * d.dir_x, static_cast<float>(r) + t * d.dir_y};
    if (!insideField(p, field.width, field.height)) break;
    float at = static_cast<float>(i);
    if (units) {
      const std::int32_t ring = rayStepUnits(units, field.height, r, i, step_y);
      position += ring;
      ray.positions.push_back(position);
      ray.rings.push_back(ring);
      at = static_cast<float>(position);
    }
    const float q = sampleHeightFrom(heights, field.width, field.height, c, r, t * d.dir_x, t * d.dir_y);
    ray.points.push_back(p);
    ray.surface.push_back(q);
    ray.heights.push_back(curvature != 0.0 ? q - drop * at * at : q);
  }
  ray.shift = units ? 0 : shift;
  // The peaks, as intervisibility_lattice takes them on its lines: of each interval's crossings
  // and concave pieces, the point farthest above the chord of its two samples, at one of the
  // interval's whole positions (2^shift a step, or with per-row spacing the step's units of
  // ground length). With curvature the candidates and the chord are the surface's before the
  // drop; the peak then takes the drop at its own distance (in steps or units: exact in float,
  // positions stay below 2^23). None on a field narrower than a cell.
  if (units ? field.width < 2 || field.height < 2 : ray.shift == 0) return ray;
  const int n = static_cast<int>(ray.heights.size()), w = field.width;
  const float inv_scale = units ? 1.0f : 1.0f / static_cast<float>(1 << ray.shift);  // positions to steps
  ray.peaks.assign(n, std::numeric_limits<float>::quiet_NaN());
  ray.peak_offsets.assign(n, 0);
  auto clamped = [&](Point2 p) {  // a sample within the edge's slack lies on the edge
    return Point2{std::clamp(p.x, 0.0f, static_cast<float>(field.width - 1)),
                  std::clamp(p.y, 0.0f, static_cast<float>(field.height - 1))};
  };
  for (int i = 0; i < n; ++i) {
    // Interval i: from sample i + 1 (the farther, at far_position) to sample i, `scale` positions.
    const std::int32_t far_position = units ? ray.positions[i] : (i + 1) << ray.shift;
    const int scale = units ? ray.rings[i] : 1 << ray.shift;
    const float h_far = ray.surface[i];
    const float h_near = i > 0 ? ray.surface[i - 1] : heights[static_cast<std::size_t>(r) * w + c];
    if (scale < 2 || std::isnan(h_far) || std::isnan(h_near)) continue;  // a peak lies strictly inside
    const Point2 far = clamped(ray.points[i]);
    const Point2 near =
        i > 0 ? clamped(ray.points[i - 1]) : Point2{static_cast<float>(c), static_cast<float>(r)};
    float best_h = -INFINITY, best_excess = 0.0f;
    int offset = 0;
    TreePieceCurve curve{};
    for (const TreePiece& g : segmentTreePieces(far.x, far.y, near.x, near.y, field.width, field.height)) {
      const std::size_t at = static_cast<std::size_t>(g.oy) * w + g.ox;
      tree_piece_peak(heights[at], heights[at + 1], heights[at + w], heights[at + w + 1], g.fx, g.fy, g.dx,
                      g.dy, g.t_far, g.t_near, g.inv_span, g.far_crossing, h_far, h_near - h_far, scale,
                      &curve, &best_h, &offset, &best_excess);
    }
    if (!(best_h > -INFINITY)) continue;  // none, or NaN (a corner at nodata)
    const float distance = static_cast<float>(far_position - offset) * inv_scale;
    ray.peaks[i] = curvature != 0.0 ? best_h - drop * distance * distance : best_h;
    ray.peak_offsets[i] = offset;
  }
  return ray;
}

}  // namespace detail

namespace {

DirectionHorizons listDirection(const HeightField& field, const detail::PreparedHeights& prepared,
                                const detail::SweepDirection& d, int k, double azimuth, int c, int r,
                                double curvature, const std::int32_t* units, double unit, int shift) {
  const std::vector<float>& heights = prepared.heights;
  DirectionHorizons out;
  out.direction = k;
  out.azimuth = azimuth;
  const detail::HorizonRay samples =
      detail::horizonRay(field, heights, d, c, r, curvature, units, unit, shift);
  const std::vector<float>& ray = samples.heights;
  const int n = static_cast<int>(ray.size());
  // Ground distance of sample i: i steps, or its position in units with per-row spacing.
  auto distance = [&](int i) { return units ? samples.positions[i - 1] * unit : i * out.sample_spacing; };
  out.sample_spacing = units ? (n > 0 ? samples.rings[0] * unit : 0.0)
                             : static_cast<double>(d.step_length) * d.ground_per_pixel;
  out.ray_samples = n;
  const float h = heights[static_cast<std::size_t>(r) * field.width + c];
  if (std::isnan(h) || n == 0) return out;

  // One line, swept from the far end: step s holds sample n - s, the receiver is step n; with
  // peaks, the peak before step s is that of interval n - s (between samples n - s + 1 and n - s).
  detail::IntervisibilityLines line;
  line.geometry = d;
  line.geometry.n_lines = 1;
  line.geometry.n_steps = n + 1;
  line.geometry.buffer_offset = 0;
  line.height_base = prepared.base;
  line.samples.resize(static_cast<std::size_t>(n) + 1);
  for (int s = 0; s < n; ++s) line.samples[s] = ray[n - 1 - s];
  line.samples[n] = h;
  if (!samples.peaks.empty()) {
    line.position_shift = samples.shift;
    line.peaks.assign(line.samples.size(), std::numeric_limits<float>::quiet_NaN());
    line.peak_offsets.assign(line.samples.size(), 0);
    for (int s = 1; s <= n; ++s) {
      line.peaks[s] = samples.peaks[n - s];
      line.peak_offsets[s] = samples.peak_offsets[n - s];
    }
  }
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

  // The horizons and their runs are tree slots (with peaks, 2 s + 1 for step s's sample and 2 s
  // for the peak before it): a run [start, end) holds the samples of steps [start >> 1, end >> 1).
  // A run starts at its horizon, or farther out where the horizon hides samples only within the
  // heights' rounding (the tie rule forgives it); the segment is then listed by the farthest of
  // those, which may stand a hair lower than the next nearer horizon.
  const int slot_shift = samples.peaks.empty() ? 0 : 1;
  const std::vector<int>& slots = line.horizon_steps[n];  // farthest first
  const std::vector<int>& starts = line.horizon_run_starts[n];
  const std::vector<int>& ends = line.horizon_run_ends[n];
  for (std::size_t idx = slots.size(); idx-- > 0;) {  // nearest first
    const int first_step = starts[idx] >> slot_shift, end_step = ends[idx] >> slot_shift;
    // A peak is no sample: its segment is the samples nearer than it up to the first hidden one
    // (the sample right after it, a present one, when any), listed by the farthest of them;
    // where even that one is hidden, the peak bounds no segment.
    if (first_step >= end_step) continue;
    VisibilityHorizon horizon;
    horizon.sample = n - first_step;
    horizon.segment_end = horizon.sample + 1;
    // Steps [first_step, end_step) hold the run; its nearest present sample begins the segment.
    horizon.segment_begin = n - end_step + 1;
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
    throw InvalidArgument(
        "a maximum distance is not supported for horizon lists yet (visible counts take it)");
  validateReceivers(field, receivers);
  const detail::PreparedHeights prepared = detail::prepareHeights(field);
  const auto directions = detail::runDirections(field, options);
  // A ray (and its receiver) has at most width + height samples per unit step; with peaks, its
  // positions are in fixed point.
  const int shift = detail::horizonRayShift(field, options);
  detail::checkStepLimits(detail::longestHorizonRay(field, options) << shift, prepared.heights);

  // Per-row spacing: positions in units along each ray, as the naive visibility march's.
  const bool row_spacing = detail::hasRowSpacing(field);
  const double unit = row_spacing ? detail::groundUnit(field) : 0.0;
  const detail::NaiveRowTables rows =
      row_spacing ? detail::naiveRowTables(field, directions, unit) : detail::NaiveRowTables{};
  std::vector<ReceiverHorizons> lists;
  lists.reserve(receivers.size());
  for (const ReceiverPixel& p : receivers) {
    ReceiverHorizons receiver;
    receiver.pixel = p;
    receiver.height = field.at(p.col, p.row);
    receiver.nodata = std::isnan(prepared.heights[static_cast<std::size_t>(p.row) * field.width + p.col]);
    if (receiver.nodata) receiver.height = std::numeric_limits<float>::quiet_NaN();
    for (int k = 0; k < options.directions; ++k) {
      const std::int32_t* units =
          row_spacing ? &rows.units[k * (2 * static_cast<std::size_t>(field.height) - 1)] : nullptr;
      receiver.directions.push_back(listDirection(field, prepared, directions[k], k,
                                                  directionAzimuth(k, options), p.col, p.row,
                                                  options.curvature, units, unit, shift));
    }
    lists.push_back(std::move(receiver));
  }
  return lists;
}

}  // namespace hfvis
