// intervisibility_reference.cpp: the scalar reference of the intervisibility operation:
// the lattice lines sampled as the kernel samples them, the hull tree sweep
// (src/core/scalar_hull_tree.cpp, the mirror of the kernel's), each receiver's results added to
// its pixel, and the naive visibility march, in the kernels' order, so every per-sample
// result matches exactly.
#include "hfvis_testing/intervisibility_reference.hpp"

#include <cmath>
#include <cstdint>
#include <limits>

#include "core/chord_side.hpp"
#include "core/horizon_common.hpp"
#include "core/hull_tree.hpp"
#include "core/tree_peaks.hpp"
#include "hfvis/errors.hpp"
#include "reference_internal.hpp"

namespace hfvis {
namespace detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// Per-pixel sums of one direction, as add_direction / accumulate_visible.
struct PixelSums {
  float count = 0.0f, area = 0.0f;
  void add(const SweepDirection& d, float sector, float c, float distance_steps) {
    const float ground = d.step_length * d.ground_per_pixel;
    count += c;
    area += sector * ground * ground * distance_steps;
  }
};

// The position of entry e's step along its line, as intervisibility_lattice counts it: the
// step << position_shift, or with per-row spacing its units; and the positions of the step
// into it (a peak's offset lies strictly inside).
std::int32_t stepPosition(const TreeDirection& d, const IntervisibilityLines& lines, std::size_t e) {
  return lines.positions.empty() ? static_cast<std::int32_t>(e / d.lines.size()) << d.position_shift
                                 : lines.positions[e];
}
int stepScale(const TreeDirection& d, const IntervisibilityLines& lines, std::size_t e) {
  return stepPosition(d, lines, e) - stepPosition(d, lines, e - d.lines.size());
}

void finish(IntervisibilityResult& result, const std::vector<PixelSums>& sums,
            const std::vector<float>& heights) {
  for (std::size_t p = 0; p < sums.size(); ++p) {
    const bool nodata = std::isnan(heights[p]);
    if (!result.visible_count.empty()) result.visible_count[p] = nodata ? kNaN : sums[p].count;
    if (!result.visible_area.empty()) result.visible_area[p] = nodata ? kNaN : sums[p].area;
  }
}

// With `halves` (the error estimate) the odd-numbered directions' sums apart, split as the
// device path splits them.
void sweepReference(const HeightField& field, const std::vector<float>& h, float height_base,
                    const IntervisibilityOptions& options, bool statistics, bool halves,
                    IntervisibilityResult& result) {
  std::vector<PixelSums> halves_sums[2] = {std::vector<PixelSums>(field.pixelCount()),
                                           std::vector<PixelSums>(halves ? field.pixelCount() : 0)};
  double weights[2] = {0.0, 0.0};
  auto& stats = result.statistics;
  for (const TreeDirection& d : treeDirections(field, options, true, halves)) {
    const int half = halves ? d.index % 2 : 0;
    std::vector<PixelSums>& sums = halves_sums[half];
    weights[half] += d.lattice.weight;
    IntervisibilityLines lines = latticeTreeLines(field, h, d, options.curvature != 0.0);
    lines.height_base = height_base;
    lines.horizons_at_every_sample = statistics;  // as the kernel without statistics
    sweepPresampledLines(lines, options.tree, false);
    const auto& g = lines.geometry;
    for (int j = 0; j < g.n_lines; ++j) {
      std::uint64_t n = 0, m = 0, t = 0, peaks = 0;
      for (int i = 0; i < g.n_steps; ++i) {
        const std::size_t e = static_cast<std::size_t>(i) * g.n_lines + j;
        if (i > 0 &&  // inserted where it rises above the chord of the samples
            tree_peak_inserted(lines.samples[e - g.n_lines], lines.peaks[e], lines.samples[e],
                               lines.peak_offsets[e], stepScale(d, lines, e))) {
          ++peaks;
          m += lines.peak_horizons[e];
        }
        if (std::isnan(lines.samples[e])) continue;
        stats.naive_iterations += n;
        ++n;
        m += lines.horizons[e];
        t += lines.iterations[e];
        stats.safe_zone_skips += lines.walks_skipped[e];
        if (statistics) stats.visible_samples += static_cast<std::uint64_t>(lines.counts[e]);
      }
      stats.receivers += n;
      stats.horizons += m;
      stats.iterations += t;
      stats.lines += n > 0;
      stats.lines_over_bound += t > 2 * m + n + peaks;  // nodes: samples and peaks
      // Receivers add their counts to their pixels, as intervisibility_lattice.
      for (int i = lines.receiver_every - 1; i < d.lines[j].receivers * lines.receiver_every;
           i += lines.receiver_every) {
        const std::size_t e = static_cast<std::size_t>(i) * g.n_lines + j;
        if (std::isnan(lines.samples[e])) continue;
        const std::size_t pixel = receiverPixel(d, field.width, j, i);
        const std::size_t row = pixel / static_cast<std::size_t>(field.width);
        const float count_factor = d.rowSpacing() ? d.row_factors[2 * row] : d.count_factor;
        const float area_factor = d.rowSpacing() ? d.row_factors[2 * row + 1] : d.area_factor;
        sums[pixel].count += count_factor * lines.counts[e];
        sums[pixel].area += area_factor * lines.distance_sums[e];
      }
    }
  }
  finish(result, halves_sums[0], h);
  if (!halves) return;
  std::vector<float> odd_count, odd_area;
  for (const PixelSums& p : halves_sums[1]) odd_count.push_back(p.count), odd_area.push_back(p.area);
  splitVisibilityHalves(result, odd_count, odd_area, weights[0], weights[1]);
}

void naiveReference(const HeightField& field, const std::vector<float>& h, float height_base,
                    const IntervisibilityOptions& options, IntervisibilityResult& result) {
  const int width = field.width, height = field.height;
  const auto directions = runDirections(field, options);
  const float sector = intervisibilitySector(options);
  // Per-row spacing: positions in units, as intervisibility_naive with HFVIS_ROW_SPACING.
  const bool row_spacing = hasRowSpacing(field);
  const double unit = row_spacing ? groundUnit(field) : 0.0;
  const NaiveRowTables rows = row_spacing ? naiveRowTables(field, directions, unit) : NaiveRowTables{};
  std::vector<PixelSums> sums(field.pixelCount());
  for (int r = 0; r < height; ++r) {
    for (int c = 0; c < width; ++c) {
      const std::size_t pixel = static_cast<std::size_t>(r) * width + c;
      const float hp = h[pixel];
      for (std::size_t k = 0; k < directions.size(); ++k) {
        const SweepDirection& d = directions[k];
        const float step_ground = d.step_length * d.ground_per_pixel;
        const float drop = row_spacing ? static_cast<float>(options.curvature * unit * unit)
                                       : static_cast<float>(options.curvature) * step_ground * step_ground;
        const int counted_steps =
            stepsWithin(options.max_distance, row_spacing ? unit : double(d.step_length) * d.ground_per_pixel);
        const std::int32_t* units = row_spacing ? &rows.units[k * (2 * static_cast<std::size_t>(height) - 1)] : nullptr;
        const float step_y = d.step_length * d.dir_y;
        float best_h = 0.0f, weighted = 0.0f;
        int best_step = 0, count = 0, position = 0;
        bool forgiving = false;  // every hidden sample since the latest visible one was forgiven
        std::uint32_t distance_sum = 0;
        // March until the ray has left the field for good (the kernel may march further;
        // those samples are outside and masked).
        for (int i = 1;; ++i) {
          const float t = static_cast<float>(i) * d.step_length;
          const Point2 p{static_cast<float>(c) + t * d.dir_x, static_cast<float>(r) + t * d.dir_y};
          if (!insideField(p, width, height)) break;
          int ring = 0, at = i;
          if (row_spacing) {
            ring = rayStepUnits(units, height, r, i, step_y);
            position += ring;
            at = position;
          }
          const float q =
              sampleHeightFrom(h, width, height, c, r, t * d.dir_x, t * d.dir_y) -
              (options.curvature != 0.0 ? drop * static_cast<float>(at) * static_cast<float>(at) : 0.0f);
          if (std::isnan(q)) continue;
          // Visible, or hidden only within the heights' rounding after a visible sample (as
          // every hidden one since it).
          const float dab = static_cast<float>(at - best_step), dbc = static_cast<float>(best_step);
          const bool hidden = best_step > 0 && chordSide(q, best_h, hp, dab, dbc) > 0;
          if (hidden) forgiving = forgiving && seen_within_rounding(q, best_h, hp, dab, dbc, height_base);
          if (!hidden || forgiving) {
            if (at <= counted_steps) {
              ++count;
              if (row_spacing)
                weighted += static_cast<float>(at) * static_cast<float>(ring);
              else
                distance_sum += static_cast<std::uint32_t>(i);
            }
          }
          if (!hidden) {
            forgiving = true;
            best_h = q;
            best_step = at;
          }
        }
        if (row_spacing) {
          const float* factors = &rows.factors[(k * height + r) * 2];
          sums[pixel].count += factors[0] * static_cast<float>(count);
          sums[pixel].area += factors[1] * weighted;
        } else {
          sums[pixel].add(d, sector, static_cast<float>(count), static_cast<float>(distance_sum));
        }
      }
    }
  }
  finish(result, sums, h);
}

}  // namespace

IntervisibilityLines latticeTreeLines(const HeightField& field, const std::vector<float>& prepared_heights,
                                      const TreeDirection& d, bool curvature) {
  const int width = field.width, height = field.height;
  const std::size_t per_period = d.samples.size();
  IntervisibilityLines out = canonicalTreeLines(d);
  for (std::size_t j = 0; j < d.lines.size(); ++j) {
    const LatticeLine& line = d.lines[j];
    int c = line.col, r = line.row;
    std::size_t step = 0;
    for (int i = 0; i < line.receivers; ++i, c -= d.lattice.a, r -= d.lattice.b) {
      for (std::size_t q = 0; q < per_period; ++q, ++step) {
        const LatticeSample& s = d.samples[q];
        const int x0 = c + s.ox, y0 = r + s.oy;
        if (i == 0 && (x0 < 0 || x0 + s.ex > width - 1 || y0 < 0 || y0 + s.ey > height - 1)) continue;
        const std::size_t at = static_cast<std::size_t>(y0) * width + x0;
        out.samples[step * d.lines.size() + j] =
            s.ex + s.ey == 0 ? prepared_heights[at]
                             : latticeHeight(prepared_heights, at, s.ex, static_cast<std::size_t>(s.ey) * width, s);
      }
    }
  }
  // The kernel's curvature transform: every sample lowered by drop * position^2 (the step,
  // or its units with per-row spacing).
  if (curvature) {
    for (std::size_t e = 0; e < out.samples.size(); ++e) {
      const float p = out.positions.empty() ? static_cast<float>(e / d.lines.size())
                                            : static_cast<float>(out.positions[e]);
      out.samples[e] = out.samples[e] - d.drop * p * p;
    }
  }
  addTreePeaks(field, prepared_heights, d, curvature, out);
  return out;
}

void addTreePeaks(const HeightField& field, const std::vector<float>& heights, const TreeDirection& d,
                  bool curvature, IntervisibilityLines& lines) {
  const int width = field.width, height = field.height;
  const std::size_t per_period = d.samples.size();
  const float inv_scale = 1.0f / static_cast<float>(1 << d.position_shift);  // positions to steps (or units)
  for (std::size_t j = 0; j < d.lines.size(); ++j) {
    const LatticeLine& line = d.lines[j];
    int c = line.col, r = line.row;
    std::size_t step = 0;
    for (int i = 0; i < line.receivers; ++i, c -= d.lattice.a, r -= d.lattice.b) {
      for (std::size_t q = 0; q < per_period; ++q, ++step) {
        const std::size_t e = step * d.lines.size() + j;
        if (step == 0) continue;  // no step before it
        // As intervisibility_lattice: of the interval's crossings and concave pieces, the point
        // farthest above the chord of its samples.
        const float far = lines.samples[e - d.lines.size()], near = lines.samples[e];
        if (std::isnan(far) || std::isnan(near)) continue;
        // A peak's offset: whole positions of the step (2^shift, or its units), strictly inside.
        const int scale = stepScale(d, lines, e);
        if (scale < 2) continue;
        // With curvature, against the samples' chord before the drop, as the kernel (positions:
        // steps, or units, in which the drop is given).
        const float far_position = static_cast<float>(stepPosition(d, lines, e - d.lines.size()));
        float chord_far = far, rise = near - far;
        if (curvature) {
          const float q_far = far_position * inv_scale,
                      q_near = static_cast<float>(stepPosition(d, lines, e)) * inv_scale;
          chord_far = far + d.drop * q_far * q_far;
          rise = (near + d.drop * q_near * q_near) - chord_far;
        }
        float best_h = -INFINITY, best_excess = 0.0f;
        int offset = 0;
        TreePieceCurve curve{};
        for (int k = d.intervals.first[q]; k < d.intervals.first[q + 1]; ++k) {
          const TreePiece& g = d.intervals.pieces[k];
          const int x0 = c + g.ox, y0 = r + g.oy;
          if (i == 0 && (x0 < 0 || x0 + 1 > width - 1 || y0 < 0 || y0 + 1 > height - 1)) {
            best_h = NAN;
            break;
          }
          const std::size_t at = static_cast<std::size_t>(y0) * width + x0;
          tree_piece_peak(heights[at], heights[at + 1], heights[at + width], heights[at + width + 1], g.fx,
                          g.fy, g.dx, g.dy, g.t_far, g.t_near, g.inv_span, g.far_crossing, chord_far, rise,
                          scale, &curve, &best_h, &offset, &best_excess);
        }
        if (!(best_h > -INFINITY)) continue;  // none, or NaN
        lines.peak_offsets[e] = offset;
        lines.peaks[e] = best_h;
        if (curvature) {  // at its own position, in steps (or units)
          const float q = (far_position + static_cast<float>(offset)) * inv_scale;
          lines.peaks[e] = best_h - d.drop * q * q;
        }
      }
    }
  }
}

std::size_t receiverPixel(const TreeDirection& d, int width, int j, int i) {
  const int receiver = i / static_cast<int>(d.samples.size());
  const LatticeLine& line = d.lines[j];
  return static_cast<std::size_t>(line.row - receiver * d.lattice.b) * width + (line.col - receiver * d.lattice.a);
}

}  // namespace detail

IntervisibilityResult referenceIntervisibility(const HeightField& field,
                                               const IntervisibilityOptions& options,
                                               const IntervisibilityOutputs& outputs) {
  validate(field);
  validate(options, outputs);
  const detail::PreparedHeights prepared = detail::prepareHeights(field);
  if (options.method == IntervisibilityMethod::HullTree)
    detail::checkTreeLimits(detail::treeDirections(field, options), prepared.heights);
  IntervisibilityResult result;
  result.width = field.width;
  result.height = field.height;
  result.directions = options.directions;
  for (int k = 0; k < options.directions; ++k) result.azimuths.push_back(directionAzimuth(k, options));
  const float nan = std::numeric_limits<float>::quiet_NaN();
  if (outputs.visible_count || outputs.error_estimate) result.visible_count.assign(field.pixelCount(), nan);
  if (outputs.visible_area) result.visible_area.assign(field.pixelCount(), nan);
  if (options.method == IntervisibilityMethod::HullTree) {
    detail::sweepReference(field, prepared.heights, prepared.base, options, outputs.statistics,
                           outputs.error_estimate, result);
    if (!outputs.visible_count) result.visible_count.clear();
  } else {
    detail::naiveReference(field, prepared.heights, prepared.base, options, result);
  }
  if (!outputs.statistics) result.statistics = {};
  return result;
}

double countErrorP99(const IntervisibilityResult& result, const IntervisibilityResult& truth) {
  double mean = 0.0;
  std::size_t with_data = 0;
  for (float c : truth.visible_count)
    if (!std::isnan(c)) mean += double(c) / truth.directions, ++with_data;
  mean /= double(with_data);
  std::vector<float> errors(result.visible_count.size());
  for (std::size_t p = 0; p < errors.size(); ++p)
    errors[p] = static_cast<float>(std::abs(double(result.visible_count[p]) / result.directions -
                                            double(truth.visible_count[p]) / truth.directions) /
                                   mean);  // NaN at nodata
  return detail::estimatedError(errors);
}

}  // namespace hfvis
