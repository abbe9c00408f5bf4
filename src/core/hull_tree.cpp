// hull_tree.cpp: what every operation on the convex hull tree sweep (intervisibility, the
// bounce, the horizon lists) and their scalar references share: the tree's tunings, its
// directions and lines, and the limits of its exact arithmetic.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "hfvis/errors.hpp"
#include "core/horizon_common.hpp"
#include "core/hull_tree.hpp"

namespace hfvis {

std::optional<HullTreeTuning> hullTreeTuningNamed(const std::string& name) {
  HullTreeTuning t;
  if (name == "plain") {
    t.deferred_writes = t.replacement_check = false;
  } else if (name == "deferred") {
    t.replacement_check = false;
  } else if (name == "zone") {
    t.safe_zone = true;
  } else if (name != "default") {
    return std::nullopt;
  }
  return t;
}

void validate(const HullTreeTuning& tuning) {
  if (tuning.replacement_check && !tuning.deferred_writes) {
    throw InvalidArgument("the replacement check needs the deferred-writes walk (it works inside it)");
  }
  if (tuning.safe_zone && !tuning.replacement_check) {
    throw InvalidArgument("the safe zone needs the replacement check");
  }
  const int z = tuning.safe_zone_steps;
  if (z < 1 || z > 4096 || (z & (z - 1)) != 0) {
    throw InvalidArgument("the safe zone's steps must be a power of two in 1 .. 4096, not " + std::to_string(z));
  }
}

namespace detail {

float intervisibilitySector(const IntervisibilityOptions& options) {
  return static_cast<float>(2.0 * M_PI / options.directions);
}

std::size_t TreeDirection::longestLine() const {
  std::size_t longest = 0;
  for (const LatticeLine& line : lines) longest = std::max(longest, lineCapacity(line, samples.size()));
  return longest;
}

TreeDirection makeTreeDirection(const HeightField& field, const LatticeDirection& lattice, double samples_per_unit,
                                int directions, double curvature, double max_distance) {
  TreeDirection d;
  d.lattice = lattice;
  d.per_period = samplesPerPeriod(lattice, samples_per_unit);
  d.samples = uniformLatticeSamples(lattice, d.per_period);
  d.lines = latticeLines(lattice, field.width, field.height);
  const double step = lattice.period / d.per_period, ground = step * lattice.ground_per_pixel;
  d.step_length = static_cast<float>(step);
  d.step_ground = static_cast<float>(ground);
  d.count_factor = static_cast<float>(directions * lattice.weight * step * samples_per_unit);
  d.area_factor = static_cast<float>(2.0 * M_PI * lattice.weight * ground * ground);
  d.drop = static_cast<float>(curvature * ground * ground);
  d.max_steps = stepsWithin(max_distance, ground);
  d.half_sector = static_cast<float>(M_PI * lattice.weight);
  d.wedge = static_cast<float>(2.0 * std::sin(M_PI * lattice.weight));
  d.cos_azimuth = static_cast<float>(std::cos(lattice.azimuth));
  d.sin_azimuth = static_cast<float>(std::sin(lattice.azimuth));
  d.intervals = treeIntervals(lattice, d.per_period);
  d.position_shift = treePositionShift(d.longestLine());
  return d;
}

int treePositionShift(std::size_t steps) {
  int bits = 0;
  while ((std::size_t(1) << bits) <= steps) ++bits;
  return std::clamp(23 - bits, 1, 8);
}

std::int32_t stepUnits(const HeightField& field, double y, double dx, double dy, double unit) {
  double cell_x = 0.0, cell_y = 0.0;
  cellSizeAtRow(field, y, &cell_x, &cell_y);
  return static_cast<std::int32_t>(std::max<long long>(1, std::llround(std::hypot(dx * cell_x, dy * cell_y) / unit)));
}

NaiveRowTables naiveRowTables(const HeightField& field, const std::vector<SweepDirection>& rays, double unit) {
  NaiveRowTables t;
  const std::vector<RowTable> rows = rayRowTables(field, rays);
  const double K = static_cast<double>(rays.size());
  for (std::size_t k = 0; k < rays.size(); ++k) {
    const SweepDirection& d = rays[k];
    for (int half = 0; half < 2 * field.height - 1; ++half)
      t.units.push_back(stepUnits(field, 0.5 * half, double(d.step_length) * d.dir_x, double(d.step_length) * d.dir_y,
                                  unit));
    for (int r = 0; r < field.height; ++r) {
      const double weight = rows[k].terms[4 * static_cast<std::size_t>(r) + 2];
      t.factors.push_back(static_cast<float>(K * weight));
      t.factors.push_back(static_cast<float>(2.0 * M_PI * weight * unit * unit));
    }
  }
  return t;
}

void followRows(TreeDirection& d, const HeightField& field, const RowTable& rows, double unit,
                double samples_per_unit, int directions, double curvature, double max_distance) {
  const double n = d.per_period, step = d.lattice.period / n;
  for (int r = 0; r < field.height; ++r) {
    d.row_units.push_back(stepUnits(field, r + 0.5 * d.lattice.b, d.lattice.a / n, d.lattice.b / n, unit));
    const double weight = rows.terms[4 * static_cast<std::size_t>(r) + 2];
    d.row_factors.push_back(static_cast<float>(directions * weight * step * samples_per_unit));
    d.row_factors.push_back(static_cast<float>(2.0 * M_PI * weight * unit * unit));
  }
  d.drop = static_cast<float>(curvature * unit * unit);
  d.max_steps = stepsWithin(max_distance, unit);
  d.position_shift = 0;  // positions are whole units (a peak's too: a step has thousands)
}

std::vector<TreeDirection> treeDirections(const HeightField& field, const SweepOptions& options,
                                          bool follow_rows, bool parity_apart) {
  std::vector<LatticeDirection> lattice = latticeDirections(field, options, false, 0.0, parity_apart);
  // Each step stands for the wedge of its phi_k, 1 / K of the circle (a merged step for each
  // phi_k it took), not for the half gaps to its neighbours' azimuths: see treeDirections' note.
  const int K = options.directions;
  std::vector<double> wedges(lattice.size(), 0.0);
  for (std::size_t k = 0; k < lattice.size(); ++k) {
    // The step that sweeps for phi_k: the first equal one (setQuadratureWeights), of k's parity
    // with parity_apart.
    std::size_t m = parity_apart ? k % 2 : 0;
    while (lattice[m].a != lattice[k].a || lattice[m].b != lattice[k].b || lattice[m].weight == 0.0)
      m += parity_apart ? 2 : 1;
    wedges[m] += 1.0 / K;
  }
  for (std::size_t k = 0; k < lattice.size(); ++k) lattice[k].weight = wedges[k];
  std::vector<RowTable> rows;
  double unit = 0.0;
  if (follow_rows && hasRowSpacing(field)) {
    rows = latticeRowTables(field, lattice, false);
    unit = groundUnit(field);
  }
  std::vector<TreeDirection> out;
  for (std::size_t k = 0; k < lattice.size(); ++k) {
    if (lattice[k].weight == 0.0) continue;  // merged into an equal step
    out.push_back(makeTreeDirection(field, lattice[k], options.samples_per_unit, options.directions,
                                    options.curvature, options.max_distance));
    out.back().index = static_cast<int>(k);
    if (!rows.empty())
      followRows(out.back(), field, rows[k], unit, options.samples_per_unit, options.directions,
                 options.curvature, options.max_distance);
  }
  return out;
}

void splitVisibilityHalves(IntervisibilityResult& result, const std::vector<float>& odd_count,
                           const std::vector<float>& odd_area, double even_weight, double odd_weight) {
  std::vector<float>& count = result.visible_count;
  std::vector<float>& estimate = result.error_estimate;
  estimate.resize(count.size());
  double total = 0.0;
  std::size_t with_data = 0;
  for (std::size_t p = 0; p < count.size(); ++p) {
    // Each half's sum over its own wedges estimates the whole count: their whole difference
    // (see IntervisibilityResult::error_estimate for why not half of it, as the sky-view factor).
    estimate[p] = static_cast<float>(std::abs(count[p] / even_weight - odd_count[p] / odd_weight));
    count[p] += odd_count[p];
    if (std::isnan(count[p])) continue;
    total += count[p];
    ++with_data;
  }
  // Relative to the field's mean count, not the pixel's own (near 0 in a pit or a street, where
  // one far sample more would swamp the field's error).
  const double mean = with_data ? total / with_data : 0.0;
  for (std::size_t p = 0; p < count.size(); ++p)
    estimate[p] = std::isnan(count[p]) ? count[p]
                  : mean > 0.0         ? static_cast<float>(estimate[p] / mean)
                                       : 0.0f;
  for (std::size_t p = 0; p < result.visible_area.size(); ++p) result.visible_area[p] += odd_area[p];
  result.estimated_error = estimatedError(estimate);
}

void IntervisibilityLines::resetResults(bool keep_horizons) {
  const std::size_t entries = samples.size();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  counts.assign(entries, nan);
  distance_sums.assign(entries, nan);
  horizons.assign(entries, 0);
  iterations.assign(entries, 0);
  horizon_hashes.assign(entries, 0);
  walks_skipped.assign(entries, 0);
  peak_horizons.assign(peaks.empty() ? 0 : entries, 0);
  horizon_steps.assign(keep_horizons ? entries : 0, {});
  horizon_run_starts.assign(keep_horizons ? entries : 0, {});
  horizon_run_ends.assign(keep_horizons ? entries : 0, {});
}

IntervisibilityLines canonicalTreeLines(const TreeDirection& d) {
  IntervisibilityLines out;
  const std::size_t longest = d.longestLine();
  out.geometry.n_lines = static_cast<int>(d.lines.size());
  out.geometry.n_steps = static_cast<int>(longest);
  out.geometry.step_length = d.step_length;
  out.geometry.ground_per_pixel = static_cast<float>(d.lattice.ground_per_pixel);
  out.geometry.cos_azimuth = d.cos_azimuth;
  out.geometry.sin_azimuth = d.sin_azimuth;
  out.receiver_every = static_cast<int>(d.samples.size());
  out.max_steps = d.max_steps;
  out.samples.assign(longest * d.lines.size(), std::numeric_limits<float>::quiet_NaN());
  out.position_shift = d.position_shift;
  out.peaks.assign(out.samples.size(), std::numeric_limits<float>::quiet_NaN());
  out.peak_offsets.assign(out.samples.size(), 0);
  if (d.rowSpacing()) {
    // As the kernel sums them: step 0 at 0, then each step of period i the units of the row
    // of receiver i (the first period's: receiver 0's). A sample's ring units are those of
    // its step toward the receivers (the next one). Padding entries keep the last.
    const std::size_t n_lines = d.lines.size(), per_period = d.samples.size();
    out.positions.assign(out.samples.size(), 0);
    out.step_units.assign(out.samples.size(), 0);
    for (std::size_t j = 0; j < n_lines; ++j) {
      const LatticeLine& line = d.lines[j];
      const std::size_t steps = lineCapacity(line, per_period);
      auto units_of = [&](std::size_t s) {  // of the step into s (s < steps)
        return d.row_units[line.row - static_cast<int>(s / per_period) * d.lattice.b];
      };
      std::int32_t position = 0;
      for (std::size_t s = 0; s < longest; ++s) {
        if (s > 0 && s < steps) position += units_of(s);
        out.positions[s * n_lines + j] = position;
        out.step_units[s * n_lines + j] = units_of(std::min(s + 1, steps - 1));
      }
    }
  }
  return out;
}

void checkTreeLimits(const std::vector<TreeDirection>& directions, const std::vector<float>& prepared_heights) {
  std::size_t longest = 0;
  for (const auto& d : directions) {
    // With peaks, positions in fixed point: the line's steps << position_shift (at least 1).
    longest = std::max(longest, d.longestLine() << d.position_shift);
    if (!d.rowSpacing()) continue;
    // Positions in units: the line's steps times the most units a step has.
    const std::size_t most = *std::max_element(d.row_units.begin(), d.row_units.end());
    longest = std::max(longest, d.longestLine() * most);
  }
  checkStepLimits(longest, prepared_heights);
}

void checkStepLimits(std::size_t longest, const std::vector<float>& prepared_heights) {
  if (longest >= (std::size_t(1) << 24)) {
    throw InvalidArgument("a sweep line would have " + std::to_string(longest) +
                          " samples; at most 2^24 are supported: lower the samples per unit");
  }
  float highest = 0.0f;  // the largest |prepared height| (counted from the base: either sign)
  for (float h : prepared_heights)
    if (!std::isnan(h)) highest = std::max(highest, std::fabs(h));
  if (!(static_cast<double>(highest) * 4.0 * static_cast<double>(longest) < 1e37)) {
    throw InvalidArgument("the height range times the z-scale is too large for single precision (" +
                          std::to_string(highest) + "): lower the z-scale");
  }
}

}  // namespace detail
}  // namespace hfvis
