// horizon_common.cpp: pieces shared by the horizon device path and its reference.
#include "core/horizon_common.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>

#include "core/fast_math.hpp"
#include "core/surface_normal.hpp"
#include "hfvis/errors.hpp"

namespace hfvis {

void validate(const HorizonOptions& options, const HorizonOutputs& outputs) {
  validate(static_cast<const SweepOptions&>(options));
  // (an enum value cast from a bad integer failed later as an OpenCL error)
  if (options.method != HorizonMethod::Sweep && options.method != HorizonMethod::Naive)
    throw InvalidArgument("unknown horizon method " + std::to_string(static_cast<int>(options.method)));
  if (!(options.azimuth_tolerance > 0.0) || !(options.azimuth_tolerance <= 0.1)) {
    throw InvalidArgument("the azimuth tolerance must be in (0, 0.1] radians, (0, 5.73] degrees (got " +
                          std::to_string(options.azimuth_tolerance * 180.0 / M_PI) + " degrees)");
  }
  if (!outputs.horizon_angles && !outputs.horizon_distances && !outputs.sky_view_factor &&
      !outputs.ambient_occlusion && !outputs.environment) {
    throw InvalidArgument("no output requested");
  }
  detail::validateStripRows(options.strip_rows, options.method == HorizonMethod::Naive);
  if (options.error_tile < 0 || (options.error_tile > 0 && options.error_tile < kMinErrorTile))
    throw InvalidArgument(
        "the error tile must be 0 (the whole field) or at least " + std::to_string(kMinErrorTile) +
        " pixels (got " + std::to_string(options.error_tile) +
        "): a smaller tile stops on a few pixels' estimates, low by chance, and misses the error "
        "asked for");
  if (options.error_tile > 0 && options.max_error == 0.0)
    throw InvalidArgument("the error tile refines toward max_error: give max_error with it");
  const bool angles_alone = outputs.horizon_angles && !outputs.sky_view_factor && !outputs.ambient_occlusion &&
                            !outputs.environment;
  if ((options.max_error != 0.0 || outputs.error_estimate) && angles_alone) {
    // The horizon angles' own error (core/horizon_angle_error.hpp), in radians.
    if (options.error_tile > 0)
      throw InvalidArgument(
          "the error tile refines the sky-view factor and occlusion; horizon planes take one K for the whole "
          "field");
    if (!(options.max_error >= 0.0 && options.max_error < M_PI / 2.0))
      throw InvalidArgument(
          "the maximum error of the horizon angles must be in (0, pi/2) radians, (0, 90) degrees: the mean "
          "error of an angle in -90 .. 90 degrees (got " +
          std::to_string(options.max_error * 180.0 / M_PI) + " degrees)");
    if (options.max_error == 0.0 && options.directions < 5)
      throw InvalidArgument(
          "an error estimate of the horizon angles needs K >= 5 (it interpolates each direction from its "
          "neighbours one and two places away)");
  } else if (options.max_error != 0.0 || outputs.error_estimate) {
    if (outputs.horizon_angles || outputs.horizon_distances || outputs.environment ||
        (!outputs.sky_view_factor && !outputs.ambient_occlusion))
      throw InvalidArgument(
          "an error estimate and a maximum error apply to the sky-view factor and ambient occlusion alone, or to "
          "the horizon angles alone (with their distances)");
    if (!(options.max_error >= 0.0 && options.max_error < 1.0))
      throw InvalidArgument("the maximum error must be in (0, 1): the sky-view factor and occlusion lie in 0..1 (got " +
                            std::to_string(options.max_error) + ")");
    if (options.max_error == 0.0 && options.directions < 2)
      throw InvalidArgument("an error estimate needs K >= 2 (it compares the even and the odd directions)");
  }
  if (outputs.environment) validate(*outputs.environment);
}

std::vector<int> directionLadder() {
  std::vector<int> ladder;
  for (int step = 8, k = 8; k <= kMaxAutoDirections; k += step) {
    ladder.push_back(k);
    if (k >= 8 * step) step *= 2;
  }
  return ladder;
}

namespace detail {

bool hasRowSpacing(const HeightField& field) { return !field.row_cell_size_x.empty(); }

namespace {

// One row of a table: the ground length, and the terms of ground azimuth `azimuth` and weight.
void appendRow(RowTable& t, double length, double azimuth, double weight) {
  const float w = static_cast<float>(weight);
  t.length.push_back(static_cast<float>(length));
  t.terms.insert(t.terms.end(),
                 {static_cast<float>(std::cos(azimuth)), static_cast<float>(std::sin(azimuth)), w, swathFactor(w)});
}

}  // namespace

std::vector<RowTable> latticeRowTables(const HeightField& field, const std::vector<LatticeDirection>& directions,
                                       bool quadrature, bool parity_apart) {
  // A field cut from a larger one takes the larger field's rows (cellSizeAtRow interpolates
  // across this field's edges there) and keeps its own [first, first + height) of them.
  const FieldOrigin& o = field.origin;
  HeightField larger;  // only its rows are read
  larger.height = o.whole_height;
  larger.row_cell_size_x = o.row_cell_size_x;
  larger.row_cell_size_y = o.row_cell_size_y;
  const HeightField& rows_of = o.present() ? larger : field;
  const int first = o.present() ? o.row : 0;
  const double unit = sweepUnit(field);
  const std::size_t K = directions.size();
  std::vector<RowTable> whole(K);
  std::vector<LatticeDirection> at_row = directions;
  for (int r = 0; r < rows_of.height; ++r) {
    std::vector<double> lengths(K);
    for (std::size_t k = 0; k < K; ++k) {
      const LatticeDirection& d = directions[k];
      double cell_x = 0.0, cell_y = 0.0;
      cellSizeAtRow(rows_of, r + 0.5 * d.b, &cell_x, &cell_y);
      const double gx = d.a * cell_x, gy = d.b * cell_y;
      lengths[k] = static_cast<double>(std::max(1LL, std::llround(std::hypot(gx, gy) / unit)));
      // The step's ground azimuth here, next to the one it has at the centre latitude.
      at_row[k].azimuth = d.azimuth + angleDifference(std::atan2(gy, gx), d.azimuth);
      at_row[k].weight = d.weight;
    }
    if (quadrature && K > 1) setQuadratureWeights(at_row, parity_apart);
    for (std::size_t k = 0; k < K; ++k) appendRow(whole[k], lengths[k], at_row[k].azimuth, at_row[k].weight);
  }
  std::vector<RowTable> tables(K);
  for (std::size_t k = 0; k < K; ++k) {
    const int b = directions[k].b, H = rows_of.height;
    if (b != 0) {  // summed from the far edge, row R's after row R + b's (modulo 2^32)
      whole[k].beyond.assign(H, 0);
      for (int i = 0; i < H; ++i) {
        const int R = b > 0 ? H - 1 - i : i;
        whole[k].beyond[R] = static_cast<std::uint32_t>(whole[k].length[R]) +
                             (R + b >= 0 && R + b < H ? whole[k].beyond[R + b] : 0u);
      }
    }
    tables[k].length.assign(whole[k].length.begin() + first, whole[k].length.begin() + first + field.height);
    tables[k].terms.assign(whole[k].terms.begin() + 4 * first,
                           whole[k].terms.begin() + 4 * (first + field.height));
    tables[k].beyond = std::move(whole[k].beyond);
  }
  return tables;
}

float lineStartPosition(const HeightField& field, const RowTable& table, int a, int b, int col, int row) {
  if (!field.origin.present()) return 0.0f;
  const int m = receiverIndex(field, a, b, col, row);
  if (b == 0) return static_cast<float>(m * static_cast<std::int32_t>(table.length[row]));
  const int R = row + field.origin.row;
  return static_cast<float>(table.beyond[R] - table.beyond[R + m * b]);  // below 2^24: exact
}

std::vector<RowTable> rayRowTables(const HeightField& field, const std::vector<SweepDirection>& rays) {
  const std::size_t K = rays.size();
  std::vector<RowTable> tables(K);
  for (int r = 0; r < field.height; ++r) {
    std::vector<double> lengths(K), azimuths(K);
    for (std::size_t k = 0; k < K; ++k) {
      const double gx = rays[k].dir_x * field.row_cell_size_x[r], gy = rays[k].dir_y * field.row_cell_size_y[r];
      lengths[k] = std::hypot(gx, gy);
      azimuths[k] = std::atan2(gy, gx);
    }
    const std::vector<double> weights = halfGapWeights(azimuths);
    for (std::size_t k = 0; k < K; ++k) appendRow(tables[k], lengths[k], azimuths[k], weights[k]);
  }
  return tables;
}

HorizonResult allocateResult(const HeightField& field, const HorizonOptions& options,
                             const HorizonOutputs& outputs) {
  HorizonResult result;
  result.width = field.width;
  result.height = field.height;
  result.directions = options.directions;
  for (int k = 0; k < options.directions; ++k) result.azimuths.push_back(directionAzimuth(k, options));
  const std::size_t plane = field.pixelCount();
  const float nan = std::numeric_limits<float>::quiet_NaN();
  if (outputs.horizon_angles) result.angles.assign(plane * options.directions, nan);
  if (outputs.horizon_distances) result.distances.assign(plane * options.directions, nan);
  if (outputs.sky_view_factor) result.sky_view_factor.assign(plane, 0.0f);
  if (outputs.ambient_occlusion) result.ambient_occlusion.assign(plane, 0.0f);
  if (outputs.environment) result.irradiance.assign(plane * outputs.environment->channels, 0.0f);
  return result;
}

bool exactAzimuths(const HorizonOutputs& outputs) { return outputs.horizon_angles || outputs.horizon_distances; }

std::vector<LatticeDirection> horizonDirections(const HeightField& field, const HorizonOptions& options,
                                                const HorizonOutputs& outputs) {
  return latticeDirections(field, options, exactAzimuths(outputs), options.azimuth_tolerance, outputs.error_estimate);
}

void pixelNormal(const std::vector<float>& h, int width, int height, int c, int r, float cell_x, float cell_y,
                 float* n) {
  float sum[3];
  surface_normal_sum(h.data(), width, height, 0, c, r, h[static_cast<std::size_t>(r) * width + c], cell_x,
                     cell_y, sum);
  if (!(sum[2] > 0.0f)) {
    n[0] = 0.0f, n[1] = 0.0f, n[2] = 1.0f;
    return;
  }
  const float length = std::sqrt(sum[0] * sum[0] + sum[1] * sum[1] + sum[2] * sum[2]);
  n[0] = sum[0] / length, n[1] = sum[1] / length, n[2] = sum[2] / length;
}

float swathFactor(float weight) { return hfSin(kPiF * weight) / kPiF; }

void finishReduction(HorizonResult& result) {
  // Both are shares of the sky, within 0 .. 1 (NaN kept); the azimuthal quadrature can pass an end
  // by its error (ambient occlusion up to 1.006 on steep noise at K = 16), and the integral it
  // approximates lies inside: clamping only brings a value nearer it.
  const auto share = [](float v) { return v > 1.0f ? 1.0f : (v < 0.0f ? 0.0f : v); };
  for (float& v : result.sky_view_factor) v = share(1.0f - v);
  for (float& v : result.ambient_occlusion) v = share(v);
}

double swathBias(double sin2_tilt, double square_weight) {
  constexpr double kPi = 3.14159265358979323846;
  return 1.15 * (kPi * kPi / 6.0) * square_weight * sin2_tilt;
}

void splitErrorHalves(HorizonResult& result, const std::vector<float>& odd_svf,
                      const std::vector<float>& odd_ao, double even_weight, double odd_weight,
                      const HeightField& field, const std::vector<float>& prepared, double square_weight) {
  std::vector<float>& estimate = result.error_estimate;
  estimate.assign(static_cast<std::size_t>(result.width) * result.height, 0.0f);
  const bool rows = hasRowSpacing(field);
  const auto split = [&](std::vector<float>& sum, const std::vector<float>& odd, bool occlusion) {
    for (std::size_t p = 0; p < sum.size(); ++p) {
      if (std::isnan(sum[p])) {
        estimate[p] = sum[p];
        continue;
      }
      // SVF = 1 - sum and AO = sum: either way half the halves' difference of the sums.
      double half_difference = 0.5 * std::abs(sum[p] / even_weight - odd[p] / odd_weight);
      if (occlusion) {  // and its swaths' own bias, from the pixel's tilt (nx^2 + ny^2 of its normal)
        const int c = static_cast<int>(p % field.width), r = static_cast<int>(p / field.width);
        float n[3];
        pixelNormal(prepared, field.width, field.height, c, r,
                    static_cast<float>(rows ? field.row_cell_size_x[r] : field.cell_size_x),
                    static_cast<float>(rows ? field.row_cell_size_y[r] : field.cell_size_y), n);
        half_difference += swathBias(n[0] * n[0] + n[1] * n[1], square_weight);
      }
      estimate[p] = std::max(estimate[p], static_cast<float>(half_difference));
      sum[p] += odd[p];
    }
  };
  split(result.sky_view_factor, odd_svf, false);
  split(result.ambient_occlusion, odd_ao, true);
  result.estimated_error = estimatedError(estimate);
}

double estimatedError(const std::vector<float>& estimate) {
  std::vector<float> values;
  for (float v : estimate)
    if (!std::isnan(v)) values.push_back(v);
  if (values.empty()) return 0.0;
  const std::size_t at = std::min(values.size() - 1, static_cast<std::size_t>(0.99 * values.size()));
  std::nth_element(values.begin(), values.begin() + at, values.end());
  return values[at];
}

int directionsForError(int directions, double estimated, int earlier, double earlier_estimate, double max_error) {
  double order = 1.0, factor = 0.0;
  if (earlier > 0 && earlier_estimate > estimated && estimated > 0.0)
    order = std::clamp(std::log(earlier_estimate / estimated) / std::log(double(directions) / earlier), 0.5, 3.0);
  factor = std::pow(estimated / max_error, 1.0 / order) * 1.05;
  if (earlier == 0) factor = std::min(factor, 4.0);
  const double wanted = std::ceil(directions * factor / 8.0) * 8.0;
  // Beyond kMaxAutoDirections, capped where an int holds it: the caller refuses it.
  return static_cast<int>(
      std::max<double>(directions + 8, std::min<double>(wanted, 2.0 * kMaxAutoDirections)));
}

double estimateOrder(const std::vector<EstimateRun>& runs) {
  if (runs.size() < 2) return 1.0;
  const EstimateRun& last = runs.back();
  for (auto it = runs.rbegin() + 1; it != runs.rend(); ++it) {
    if (2 * it->directions > last.directions) continue;
    if (!(it->raw > 0.0 && last.raw > 0.0)) return 1.0;
    const double order = std::log(it->raw / last.raw) / std::log(double(last.directions) / it->directions);
    return std::clamp(order, 1.0, kMaxRichardsonOrder);
  }
  return 1.0;  // no run at half its K or fewer: nothing measured
}

double richardsonDivisor(double order) { return std::pow(2.0, order) - 1.0; }

NextErrorRun nextDirectionsForError(const std::vector<EstimateRun>& runs, double max_error) {
  const EstimateRun& last = runs.back();
  // The fall of the raw estimate: from the last two runs, however near (within 1 .. 2); from one
  // run K^-1 for the run, K^-2 (the fastest it assumes) for the bound.
  double order = 1.0;
  if (runs.size() >= 2) {
    const EstimateRun& before = runs[runs.size() - 2];
    if (before.raw > last.raw && last.raw > 0.0)
      order = std::clamp(std::log(before.raw / last.raw) / std::log(double(last.directions) / before.directions),
                         1.0, 2.0);
  }
  // K where the error estimate, raw (K / K')^order / divisor at K', meets `error`; beyond
  // kMaxAutoDirections capped where an int holds it (the caller refuses it).
  const auto meeting = [&](double fall, double error) {
    const double divisor = richardsonDivisor(std::min(fall, kMaxRichardsonOrder));
    return std::min(last.directions * std::pow(last.raw / divisor / error, 1.0 / fall), 2.0 * kMaxAutoDirections);
  };
  const auto multipleOf8 = [&](double K) {
    return static_cast<int>(std::max<double>(last.directions + 8, std::ceil(K / 8.0) * 8.0));
  };
  NextErrorRun next;
  next.predicted = multipleOf8(meeting(runs.size() >= 2 ? order : 2.0, max_error));
  double wanted = meeting(order, kErrorAim * max_error);
  // Far beyond the last K, a probe: twice it, or a sixth of the way when that is more.
  if (wanted > 4.0 * last.directions) wanted = std::min(wanted, std::max(2.0 * last.directions, wanted / 6.0));
  next.directions = std::min(multipleOf8(wanted), std::max(kMaxAutoDirections, last.directions + 8));
  return next;
}

InvalidArgument beyondAutoDirections(double max_error, int next, int directions, double estimated,
                                     const std::string& where) {
  std::ostringstream message;
  // (directionsForError caps its answer at twice the most: beyond that, a bound)
  message << "a maximum error of " << max_error << " needs "
          << (next >= 2 * kMaxAutoDirections ? "at least " : "about ") << next
          << " directions (the estimate at K = " << directions << " is " << estimated << where << "), beyond the "
          << kMaxAutoDirections << " a run may choose: ask for a larger error, or give K";
  return InvalidArgument(message.str());
}

}  // namespace detail
}  // namespace hfvis
