// intervisibility_common.cpp: option validation, the tree sweep's directions and the limits
// that the intervisibility and bounce device paths and their scalar references share.
#include <algorithm>
#include <cmath>
#include <limits>
#include <string>

#include "hfvis/errors.hpp"
#include "intervisibility_internal.hpp"

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

void validate(const IntervisibilityOptions& options, const IntervisibilityOutputs& outputs) {
  validate(static_cast<const SweepOptions&>(options));
  validate(options.tree);
  if (!outputs.visible_count && !outputs.visible_area && !outputs.statistics) {
    throw InvalidArgument("no output requested");
  }
  if (outputs.statistics && options.method != IntervisibilityMethod::HullTree) {
    throw InvalidArgument("statistics (horizons and iterations) exist only for the hull-tree method");
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
  return d;
}

std::vector<TreeDirection> treeDirections(const HeightField& field, const SweepOptions& options) {
  std::vector<TreeDirection> out;
  for (const LatticeDirection& lattice : latticeDirections(field, options, false, 0.0)) {
    if (lattice.weight == 0.0) continue;  // merged into an equal step
    out.push_back(makeTreeDirection(field, lattice, options.samples_per_unit, options.directions, options.curvature,
                                    options.max_distance));
  }
  return out;
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
  horizon_steps.assign(keep_horizons ? entries : 0, {});
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
  return out;
}

void checkTreeLimits(const std::vector<TreeDirection>& directions, const std::vector<float>& prepared_heights) {
  std::size_t longest = 0;
  for (const auto& d : directions) longest = std::max(longest, d.longestLine());
  checkStepLimits(longest, prepared_heights);
}

void checkStepLimits(std::size_t longest, const std::vector<float>& prepared_heights) {
  if (longest >= (std::size_t(1) << 24)) {
    throw InvalidArgument("a sweep line would have " + std::to_string(longest) +
                          " samples; at most 2^24 are supported: lower the samples per unit");
  }
  float highest = 0.0f;  // prepared heights are >= 0 (offset by the lowest one)
  for (float h : prepared_heights)
    if (!std::isnan(h)) highest = std::max(highest, std::fabs(h));
  if (!(static_cast<double>(highest) * 4.0 * static_cast<double>(longest) < 1e37)) {
    throw InvalidArgument("the height range times the z-scale is too large for single precision (" +
                          std::to_string(highest) + "): lower the z-scale");
  }
}

}  // namespace detail
}  // namespace hfvis
