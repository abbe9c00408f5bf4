// horizon_reference.cpp: scalar mirrors of kernels/horizon.cl (the lattice sweep with its
// per-receiver outputs, and the naive march); the per-direction terms are the kernels' own
// (src/core/direction_terms.hpp). Keep every expression in the kernels' order: the build disables
// FP contraction on both sides so the predicates decide identically.
#include <algorithm>
#include <cmath>
#include <limits>

#include "core/direction_terms.hpp"
#include "core/environment_swaths.hpp"
#include "ops/environment_light_terms.hpp"
#include "core/fast_math.hpp"
#include "hfvis_testing/horizon_reference.hpp"
#include "core/horizon_common.hpp"
#include "core/lattice_geometry.hpp"
#include "hfvis/errors.hpp"
#include "core/surface_normal.hpp"
#include "reference_internal.hpp"

namespace hfvis {
namespace detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();

// A normal as its slopes: (x, y, 1) / |(x, y, 1)| (surface_slopes in the kernel).
struct Slopes {
  float x = 0.0f, y = 0.0f;
};

Slopes surfaceSlopes(const std::vector<float>& h, int width, int height, int c, int r, float hp, float cell_x,
                     float cell_y) {
  float sum[3];
  surface_normal_sum(h.data(), width, height, 0, c, r, hp, cell_x, cell_y, sum);
  if (!(sum[2] > 0.0f)) return {};
  return {sum[0] / sum[2], sum[1] / sum[2]};
}

// Every pixel's normal, as the kernels compute it (only needed for ambient occlusion), with
// each row's own cell sizes where the field has them.
std::vector<Slopes> pixelNormals(const HeightField& field, const std::vector<float>& h, bool wanted) {
  std::vector<Slopes> normals(field.pixelCount());
  if (!wanted) return normals;
  for (int r = 0; r < field.height; ++r) {
    const bool rows = hasRowSpacing(field);
    const auto cell_x = static_cast<float>(rows ? field.row_cell_size_x[r] : field.cell_size_x);
    const auto cell_y = static_cast<float>(rows ? field.row_cell_size_y[r] : field.cell_size_y);
    for (int c = 0; c < field.width; ++c) {
      const std::size_t pixel = static_cast<std::size_t>(r) * field.width + c;
      if (!std::isnan(h[pixel]))
        normals[pixel] = surfaceSlopes(h, field.width, field.height, c, r, h[pixel], cell_x, cell_y);
    }
  }
  return normals;
}

// The environment's tables (environment_tables in kernels/environment_light.cl) computed here on
// their own, in double: per direction, band and channel (KA, LA, KB, LB, KC, LC).
std::vector<float> environmentTables(const EnvironmentMap& map, const std::vector<LatticeDirection>& directions) {
  const EnvironmentSwaths swaths = environmentSwaths(map, directions);
  const int rows = tableRows(map), C = map.channels, W = map.width, H = map.height;
  const double column = 2.0 * M_PI / W;
  std::vector<float> tables;
  for (std::size_t k = 0; k < directions.size(); ++k) {
    std::vector<double> cum(3 * C, 0.0);
    for (int i = 0; i < rows; ++i) {
      const double t0 = i * M_PI / rows, t1 = (i + 1) * M_PI / rows;
      std::vector<double> s(3 * C, 0.0);  // the band's (A, B, C) radiance integrals over azimuth
      for (int j = 0; j < H; ++j) {
        const double a = std::max(t0, j * M_PI / H), b = std::min(t1, (j + 1) * M_PI / H);
        if (!(b > a)) continue;
        const double share = (std::cos(a) - std::cos(b)) / (std::cos(t0) - std::cos(t1));
        const auto [first, count] = swaths.spans[k];
        for (int q = first; q < first + count; ++q) {
          const auto& bin = swaths.bins[q];
          for (int col = 0; col < W; ++col) {  // every column, each at its turns around the bin
            for (int turn = -2; turn <= 2; ++turn) {
              const double left = bin[2] + (col - bin[3] + turn * W) * column;
              const double lo = std::max<double>(left, bin[0]), hi = std::min<double>(left + column, bin[1]);
              if (!(hi > lo)) continue;
              for (int c = 0; c < C; ++c) {
                const double L = share * map.radiance[(static_cast<std::size_t>(c) * H + j) * W + col];
                s[3 * c] += L * (hi - lo);
                s[3 * c + 1] += L * (std::sin(hi) - std::sin(lo));
                s[3 * c + 2] += L * (std::cos(lo) - std::cos(hi));
              }
            }
          }
        }
      }
      auto q1 = [](double t) { return 0.5 * std::sin(t) * std::sin(t); };
      auto q2 = [](double t) { return 0.5 * (t - std::sin(t) * std::cos(t)); };
      for (int c = 0; c < C; ++c) {
        const double sa = s[3 * c], sb = s[3 * c + 1], sc = s[3 * c + 2];
        for (double v : {cum[3 * c] - sa * q1(t0), sa, cum[3 * c + 1] - sb * q2(t0), sb, cum[3 * c + 2] - sc * q2(t0), sc})
          tables.push_back(static_cast<float>(v));
        cum[3 * c] += sa * (q1(t1) - q1(t0));
        cum[3 * c + 1] += sb * (q2(t1) - q2(t0));
        cum[3 * c + 2] += sc * (q2(t1) - q2(t0));
      }
    }
  }
  return tables;
}

// What one direction contributes at one receiver, as emit_direction / emit_lanes in the kernel.
struct DirectionOutputs {
  float cos_azimuth, sin_azimuth, weight;
  int k;  // the direction's plane
  float swath() const { return swathFactor(weight); }
  const float* environment = nullptr;  // the direction's table, if the environment is asked for
  int table_rows = 0, channels = 0;
};

void emitDirection(HorizonResult& result, std::size_t pixel, bool nodata, bool found, float rise, float run,
                   float distance, const DirectionOutputs& o, const std::vector<Slopes>& normals) {
  const std::size_t plane = static_cast<std::size_t>(result.width) * result.height;
  const float elevation = nodata ? kNaN : elevation_term(found, rise, run);
  if (!result.angles.empty()) result.angles[o.k * plane + pixel] = elevation;
  if (!result.distances.empty()) result.distances[o.k * plane + pixel] = nodata ? kNaN : distance;
  if (!result.sky_view_factor.empty()) {
    const float sky = sky_term(found, rise, run);
    float& sum = result.sky_view_factor[pixel];
    sum = nodata ? kNaN : sum + o.weight * sky;
  }
  if (!result.ambient_occlusion.empty()) {
    float& sum = result.ambient_occlusion[pixel];
    const Slopes& n = normals[pixel];
    const float term =
        ambient_term(found, rise, run, n.x, n.y, 1.0f, o.cos_azimuth, o.sin_azimuth, o.weight, o.swath());
    sum = nodata ? kNaN : sum + term;
  }
  if (o.environment) {
    const Slopes& n = normals[pixel];
    const float x = lower_limit(found, rise, run, n.x * o.cos_azimuth + n.y * o.sin_azimuth, 1.0f);
    environment_add(&result.irradiance[pixel], static_cast<unsigned int>(plane), o.channels, nodata, x, n.x, n.y,
                    1.0f, o.cos_azimuth, o.sin_azimuth, o.environment, o.table_rows);
  }
}

// occlusion_scale in the kernel: the sums of normals (x, y, 1) made those of unit normals.
void scaleOcclusion(HorizonResult& result, const std::vector<Slopes>& normals) {
  for (std::size_t p = 0; p < result.ambient_occlusion.size(); ++p) {
    const Slopes& n = normals[p];
    result.ambient_occlusion[p] = result.ambient_occlusion[p] / std::sqrt(n.x * n.x + n.y * n.y + 1.0f);
  }
  for (std::size_t i = 0; i < result.irradiance.size(); ++i) {
    const Slopes& n = normals[i % normals.size()];
    result.irradiance[i] = result.irradiance[i] / std::sqrt(n.x * n.x + n.y * n.y + 1.0f);
  }
}

// The direction's outputs with its environment table, from `tables` (environmentTables).
DirectionOutputs withEnvironment(DirectionOutputs out, const HorizonOutputs& outputs, const std::vector<float>& tables) {
  if (!outputs.environment) return out;
  out.table_rows = tableRows(*outputs.environment);
  out.channels = outputs.environment->channels;
  out.environment = tables.data() + static_cast<std::size_t>(out.k) * out.table_rows * out.channels * kEnvTerms;
  return out;
}

DirectionOutputs outputsOf(const LatticeDirection& d, int k) {
  return {static_cast<float>(std::cos(d.azimuth)), static_cast<float>(std::sin(d.azimuth)),
          static_cast<float>(d.weight), k};
}

}  // namespace

float latticeHeight(const std::vector<float>& h, std::size_t at, std::size_t right, std::size_t down,
                    const LatticeSample& s) {
  const float h00 = h[at], h10 = h[at + right], h01 = h[at + down], h11 = h[at + down + right];
  const float plain = cornerBilinear(h00, h10, h01, h11, s.w10, s.w01, s.w11);
  return std::isnan(plain) ? bilinearBesideNodata(h00, h10, h01, h11, s.w00, s.w10, s.w01, s.w11) : plain;
}

namespace {

// near_rise in the kernel.
float nearRise(const std::vector<float>& h, int width, int height, int c, int r, float hp, int a, int b) {
  const int sx = (a > 0) - (a < 0), sy = (b > 0) - (b < 0);
  if (c + sx < 0 || c + sx >= width || r + sy < 0 || r + sy >= height) return kNaN;
  const float hx = h[static_cast<std::size_t>(r) * width + (c + sx)];
  const float hy = h[static_cast<std::size_t>(r + sy) * width + c];
  // (the first cell, or on an axis its first edge, with a nodata corner has no surface)
  if (std::isnan(h[static_cast<std::size_t>(r + sy) * width + (c + sx)])) return kNaN;
  return (hx - hp) * static_cast<float>(std::abs(a)) + (hy - hp) * static_cast<float>(std::abs(b));
}

// Directions of `parity` only (k mod 2; -1: all), for the error estimate's halves.
void sweepReference(const HeightField& field, const PreparedHeights& prepared, const HorizonOptions& options,
                    const HorizonOutputs& outputs, HorizonResult& result, int parity) {
  const int width = field.width, height = field.height;
  const auto& h = prepared.heights;
  const auto normals = pixelNormals(field, h, outputs.ambient_occlusion || outputs.environment);
  const auto directions = horizonDirections(field, options, outputs);
  const std::vector<float> env_tables =
      outputs.environment ? environmentTables(*outputs.environment, directions) : std::vector<float>{};
  // Positions in pixels of the direction's ground length, or (per-row spacing) units of sweepUnit.
  const bool rows = hasRowSpacing(field);
  const std::vector<RowTable> tables =
      rows ? latticeRowTables(field, directions, !exactAzimuths(outputs), outputs.error_estimate) : std::vector<RowTable>{};
  for (int k = 0; k < options.directions; ++k) {
    const LatticeDirection& d = directions[k];
    if (d.weight == 0.0 && result.angles.empty() && result.distances.empty()) continue;  // merged step
    if (parity >= 0 && k % 2 != parity) continue;
    DirectionOutputs out = withEnvironment(outputsOf(d, k), outputs, env_tables);
    const double unit = rows ? sweepUnit(field) : d.ground_per_pixel;
    const RowTable* table = rows ? &tables[k] : nullptr;
    const float gpp = static_cast<float>(unit);
    const float drop = static_cast<float>(options.curvature * unit * unit);
    float period_ground = static_cast<float>(d.period * d.ground_per_pixel);
    const LatticeWindow window = latticeWindow(field, d, options.max_distance);
    for (const LatticeLine& line : latticeLines(d, width, height)) {
      for (const LatticeLineSample& s :
           latticeLineSamples(field, h, d, options.samples_per_unit, line, drop, window, table)) {
        if (s.receiver < 0) continue;
        const std::size_t pixel = static_cast<std::size_t>(s.receiver);
        if (std::isnan(s.height)) {
          emitDirection(result, pixel, true, false, 0.0f, 1.0f, 0.0f, out, normals);
          continue;
        }
        const int c = static_cast<int>(pixel % width), r = static_cast<int>(pixel / width);
        if (table) {  // the receiver's period: its ground length and terms
          period_ground = table->length[r] * gpp;
          out.cos_azimuth = table->terms[4 * r];
          out.sin_azimuth = table->terms[4 * r + 1];
          out.weight = table->terms[4 * r + 2];
        }
        float rise = s.occluder_rise, run = s.occluder_run;
        if (!table && window.window > 0.0f) {  // the window's far end (horizon_lattice's end_h)
          const float reach = window.window / static_cast<float>(d.period);
          const int oc = field.origin.col, orow = field.origin.row;
          const Point2 p{
              (static_cast<float>(c + oc) + static_cast<float>(d.a) * reach) - static_cast<float>(oc),
              (static_cast<float>(r + orow) + static_cast<float>(d.b) * reach) - static_cast<float>(orow)};
          if (p.x >= 0.0f && p.x <= static_cast<float>(width - 1) && p.y >= 0.0f &&
              p.y <= static_cast<float>(height - 1)) {  // (inside exactly, as horizon_lattice)
            const float end = s.position - window.window;
            const float end_rise = (sampleHeight(h, width, height, p) - drop * end * end) -
                                   (s.height - drop * s.position * s.position);
            if (!std::isnan(end_rise) && (run <= 0.0f || end_rise * run >= rise * window.window))
              rise = end_rise, run = window.window;
          }
        }
        const float near = nearRise(h, width, height, c, r, s.height, d.a, d.b);
        const bool has_far = run > 0.0f, has_near = !std::isnan(near);
        const float ground = has_far ? run * gpp : 0.0f;
        // The kernel's far_rise (its curvature correction is an exact 0 without curvature).
        const float far_rise = rise - 2.0f * drop * s.position * run;
        const bool use_near = has_near && (!has_far || near * ground > far_rise * period_ground);
        const float distance = has_far && !use_near ? ground : 0.0f;
        emitDirection(result, pixel, false, has_far || has_near, use_near ? near : far_rise,
                      use_near ? period_ground : ground, distance, out, normals);
      }
    }
  }
  scaleOcclusion(result, normals);
}

// Directions of `parity` only (k mod 2; -1: all), for the error estimate's halves.
void naiveReference(const HeightField& field, const PreparedHeights& prepared, const HorizonOptions& options,
                    const HorizonOutputs& outputs, HorizonResult& result, int parity) {
  const int width = field.width, height = field.height;
  const auto& h = prepared.heights;
  const auto normals = pixelNormals(field, h, outputs.ambient_occlusion || outputs.environment);
  const auto directions = runDirections(field, options);
  std::vector<LatticeDirection> env_directions(options.directions);
  for (int k = 0; k < options.directions; ++k) {
    env_directions[k].azimuth = directionAzimuth(k, options);
    env_directions[k].weight = 1.0 / options.directions;
  }
  const std::vector<float> env_tables =
      outputs.environment ? environmentTables(*outputs.environment, env_directions) : std::vector<float>{};
  const std::vector<RowTable> tables =
      hasRowSpacing(field) ? rayRowTables(field, directions) : std::vector<RowTable>(1);
  for (int k = 0; k < options.directions; ++k) {
    if (parity >= 0 && k % 2 != parity) continue;
    const SweepDirection& d = directions[k];
    DirectionOutputs out = withEnvironment(
        {d.cos_azimuth, d.sin_azimuth, static_cast<float>(1.0 / options.directions), k}, outputs, env_tables);
    // Per-row spacing: the ray's ground length summed step by step (horizon_naive's row_ground_at).
    const bool rows = hasRowSpacing(field);
    const RowTable& table = tables[rows ? k : 0];
    auto groundAt = [&](float y) {
      const float clamped = std::clamp(y, 0.0f, static_cast<float>(height - 1));
      const int r0 = static_cast<int>(clamped), r1 = std::min(r0 + 1, height - 1);
      const float w = clamped - static_cast<float>(r0);
      return (1.0f - w) * table.length[r0] + w * table.length[r1];
    };
    const double unit = rows ? 1.0 : double(d.ground_per_pixel);
    const float drop = static_cast<float>(options.curvature * unit * unit);
    // With per-row spacing the march cuts at the ground length itself (horizon_naive's max_ground).
    const int max_steps =
        rows ? kAllSteps : stepsWithin(options.max_distance, double(d.step_length) * d.ground_per_pixel);
    const float max_ground = rows && options.max_distance > 0.0 ? static_cast<float>(options.max_distance)
                                                                 : std::numeric_limits<float>::infinity();
    // Without per-row spacing the march also takes the surface at the maximum distance itself
    // (horizon_naive's max_reach), where it lies past the last step within it.
    const float max_reach = !rows && options.max_distance > 0.0
                                ? static_cast<float>(options.max_distance / d.ground_per_pixel)
                                : std::numeric_limits<float>::infinity();
    for (int r = 0; r < height; ++r) {
      for (int c = 0; c < width; ++c) {
        const std::size_t pixel = static_cast<std::size_t>(r) * width + c;
        const float hp = h[pixel];
        float best_rise = 0.0f, along = 0.0f, best_along = 0.0f;
        int best_step = 0;
        // March until the ray has left the field for good (the kernel's trip count may be
        // longer; the extra samples are outside and masked).
        for (int i = 1; i <= max_steps; ++i) {
          const float t = static_cast<float>(i) * d.step_length;
          const Point2 p{static_cast<float>(c) + t * d.dir_x, static_cast<float>(r) + t * d.dir_y};
          if (!insideField(p, width, height)) break;
          const float q = sampleHeight(h, width, height, p);
          if (rows) {
            along += d.step_length *
                     groundAt(static_cast<float>(r) + (static_cast<float>(i) - 0.5f) * d.step_length * d.dir_y);
          }
          const float g = rows ? along : t;
          if (g > max_ground) break;  // the ground length only grows
          const float rise = q - hp - drop * g * g;
          const bool steeper = rows ? rise * best_along >= best_rise * along
                                    : rise * static_cast<float>(best_step) >= best_rise * static_cast<float>(i);
          if (!std::isnan(q) && (best_step == 0 || steeper)) {
            best_rise = rise;
            best_step = i;
            best_along = along;
          }
        }
        float best_t = static_cast<float>(best_step) * d.step_length;
        if (max_reach < std::numeric_limits<float>::infinity() &&
            max_reach > static_cast<float>(max_steps) * d.step_length) {
          const float px = static_cast<float>(c) + max_reach * d.dir_x;
          const float py = static_cast<float>(r) + max_reach * d.dir_y;
          if (px >= 0.0f && px <= static_cast<float>(width - 1) && py >= 0.0f &&
              py <= static_cast<float>(height - 1)) {
            const float rise = sampleHeight(h, width, height, {px, py}) - hp - drop * max_reach * max_reach;
            if (!std::isnan(rise) && (best_step == 0 || rise * best_t >= best_rise * max_reach)) {
              best_rise = rise, best_t = max_reach;
              best_step = std::max(best_step, 1);
            }
          }
        }
        const float ground = rows ? best_along : best_t * d.ground_per_pixel;
        const float distance = best_step > 0 ? ground : 0.0f;
        if (rows) {
          out.cos_azimuth = table.terms[4 * r];
          out.sin_azimuth = table.terms[4 * r + 1];
          out.weight = table.terms[4 * r + 2];
        }
        emitDirection(result, pixel, std::isnan(hp), best_step > 0, best_rise, ground, distance, out,
                      normals);
      }
    }
  }
  scaleOcclusion(result, normals);
}

}  // namespace

std::vector<LatticeLineSample> latticeLineSamples(const HeightField& field, const std::vector<float>& h,
                                                  const LatticeDirection& d, double samples_per_unit,
                                                  const LatticeLine& line, float drop, const LatticeWindow& window,
                                                  const RowTable* rows) {
  const int width = field.width, height = field.height;
  const std::vector<LatticeSample> samples = latticeSamples(d, samples_per_unit);
  const std::vector<CellSegment> segments = cellSegments(d, samples_per_unit);
  const float period = static_cast<float>(d.period);
  const float inv_period = 1.0f / period;
  float row_base = 0.0f;  // per-row spacing: the receiver's position, in units
  const bool windowed = window.window > 0.0f;
  // Every sample of the line in sweep order (height NaN where it is absent: outside the field
  // or without height), with its block (horizon_lattice's window_pass) and its height as the
  // stack holds it (the kernel's curvature transform, an exact no-op at drop 0). Before each
  // sample the peak inside the segment that ends at it (segment_peak), present where the
  // kernel takes one.
  struct Raw {
    LatticeLineSample sample;
    int block = 0;
    float stacked = 0.0f;
    bool is_receiver = false;
    // A present peak: -(B / 2 + C), its rise over (1 - u) span seen from the sample after it
    // (horizon_lattice's on-hull test), and the span.
    float peak_rise = 0.0f, span = 0.0f;
  };
  std::vector<Raw> raw;
  int c = line.col, r = line.row;
  float here_before = 0.0f;
  // Positions count from the far end of the line through the larger field (HeightField::origin;
  // without one, this field's: 0), as horizon_lattice with HFVIS_ORIGIN counts them.
  const int first = rows ? 0 : receiverIndex(field, d.a, d.b, line.col, line.row);
  if (rows) row_base = lineStartPosition(field, *rows, d.a, d.b, line.col, line.row);
  for (int i = 0; i < line.receivers; ++i, c -= d.a, r -= d.b) {
    float base = static_cast<float>(first + i) * period, tau_scale = 1.0f;
    if (rows) {  // horizon_lattice with HFVIS_ROW_SPACING
      const float length = rows->length[r];
      if (i > 0) row_base += length;
      base = row_base;
      tau_scale = length * inv_period;
    }
    for (std::size_t q = 0; q < samples.size(); ++q) {
      const LatticeSample& s = samples[q];
      const float here = rows ? base - s.tau * tau_scale : base - s.tau;
      const CellSegment& g = segments[q];
      if (g.curved) {
        Raw e;
        e.sample.peak = true;
        e.sample.height = kNaN;
        const int x0 = c + g.ox, y0 = r + g.oy;
        if (x0 >= 0 && x0 + 1 <= width - 1 && y0 >= 0 && y0 + 1 <= height - 1) {
          const std::size_t at = static_cast<std::size_t>(y0) * width + x0;
          const float h00 = h[at], h10 = h[at + 1], h01 = h[at + width], h11 = h[at + width + 1];
          const float fx = g.fx, fy = g.fy, dx = g.dx, dy = g.dy;
          const float gx = h10 - h00, gy = h01 - h00;
          const float twist = (h11 - h01) - gx;
          const float A = h00 + gx * fx + gy * fy + twist * (fx * fy);
          const float B = gx * dx + gy * dy + twist * (fx * dy + fy * dx);
          const float C = twist * (dx * dy);
          const float u = B / (-2.0f * C);
          const float tau = g.tau_far - u * (g.tau_far - g.tau_near);
          const float position = rows ? base - tau * tau_scale : base - tau;
          // (horizon_lattice's at_receiver: the segment ending at the period's receiver)
          const float limit = q + 1 == samples.size() ? -1.998f : -2.0f;
          if (C < 0.0f && B > 0.0f && B < limit * C && std::isfinite(A) && position > here_before &&
              position < here) {
            e.sample.height = A + 0.5f * B * u;
            e.sample.position = position;
            e.span = rows ? (g.tau_far - g.tau_near) * tau_scale : g.tau_far - g.tau_near;
            e.peak_rise = -(0.5f * B + C);
            if (drop != 0.0f) e.peak_rise = e.peak_rise + drop * (here + (here - (1.0f - u) * e.span)) * e.span;
          }
        }
        e.block = windowed && !std::isnan(e.sample.height)
                      ? static_cast<int>(std::floor(e.sample.position * window.inv_window))
                      : 0;
        e.stacked = e.sample.height - drop * e.sample.position * e.sample.position;
        raw.push_back(e);
      }
      here_before = here;
      Raw e;
      e.sample.position = here;
      e.sample.height = kNaN;
      e.block = windowed ? static_cast<int>(std::floor(e.sample.position * window.inv_window)) : 0;
      e.is_receiver = q + 1 == samples.size();
      const int x0 = c + s.ox, y0 = r + s.oy;
      if (x0 >= 0 && x0 + s.ex <= width - 1 && y0 >= 0 && y0 + s.ey <= height - 1) {
        const std::size_t at = static_cast<std::size_t>(y0) * width + x0;
        e.sample.height = latticeHeight(h, at, s.ex, static_cast<std::size_t>(s.ey) * width, s);
        e.sample.receiver = e.is_receiver ? static_cast<long>(at) : -1;
      }
      e.stacked = e.sample.height - drop * e.sample.position * e.sample.position;
      raw.push_back(e);
    }
  }
  using Entry = std::pair<float, float>;  // (stacked height, position)
  // Algorithm 1 of Timonen & Westerholm 2010, one sample arriving beyond every entry of the
  // stack (toward +1: positions grow; -1: they shrink), as hull_step: returns (rise, run) of
  // the occluder and its depth (-1: none), then pushes the sample.
  auto hullStep = [](std::vector<Entry>& stack, float hs, float here, float toward, float* rise, float* run) {
    long depth = -1;
    if (!stack.empty()) {
      auto top = stack.back();
      float v1h = top.first - hs, v1d = toward > 0.0f ? here - top.second : top.second - here;
      while (stack.size() > 1) {
        const auto below = stack[stack.size() - 2];
        const float v2h = below.first - hs, v2d = toward > 0.0f ? here - below.second : below.second - here;
        if (v2h * v1d >= v1h * v2d) {
          top = below, v1h = v2h, v1d = v2d;
          stack.pop_back();
        } else {
          break;
        }
      }
      depth = static_cast<long>(stack.size()) - 1;
      *rise = v1h;
      *run = v1d;
    }
    stack.emplace_back(hs, here);
    return depth;
  };
  // The forward sweep, restarted at every block (at samples: a peak goes with the sample before
  // it, and is taken only where it lies in that sample's block).
  std::vector<Entry> stack;
  std::vector<Entry> far(raw.size(), Entry(0.0f, 0.0f));  // window_pass's (rise, run) per receiver
  int block = 0;
  for (const Raw& e : raw) {
    if (!e.sample.peak) {
      block = e.block;
      break;
    }
  }
  for (std::size_t t = 0; t < raw.size(); ++t) {
    if (raw[t].sample.peak) continue;  // taken with the sample after it, below
    if (raw[t].block != block) {
      // window_pass for the new block: its receivers nearest first, the block before's samples
      // pushed backwards once within the window (a peak with the sample before it, under that
      // sample's test), the tangent by binary search.
      const int k = raw[t].block;
      std::size_t end = t;
      while (end < raw.size() && (raw[end].sample.peak || raw[end].block == k)) ++end;
      std::vector<Entry> back;
      std::size_t cursor = t;  // samples [0, cursor) not pushed yet
      float unused_rise = 0.0f, unused_run = 0.0f;
      auto push = [&](const Raw& e) {
        if (!std::isnan(e.sample.height)) hullStep(back, e.stacked, e.sample.position, -1.0f, &unused_rise, &unused_run);
      };
      for (std::size_t j = end; j-- > t;) {
        if (!raw[j].is_receiver) continue;
        const float x = raw[j].sample.position;
        for (;;) {
          if (cursor == 0 || (cursor == 1 && raw[0].sample.peak)) break;  // (the line's first peak is never present)
          const std::size_t next = raw[cursor - 1].sample.peak ? cursor - 2 : cursor - 1;  // the sample tested
          if (raw[next].block != k - 1 || x - raw[next].sample.position > window.window) {
            // (its segment's peak within reach before it: the segment straddles the window's far
            // end or the block's, as window_pass takes it)
            const Raw& p = raw[cursor - 1];
            if (p.sample.peak && !std::isnan(p.sample.height) && p.block == k - 1 &&
                x - p.sample.position <= window.window) {
              push(p);
              --cursor;
            }
            break;
          }
          if (raw[cursor - 1].sample.peak) {
            const Raw& p = raw[cursor - 1];
            if (p.block == k - 1) push(p);
            --cursor;
          }
          push(raw[--cursor]);
        }
        const float hs = raw[j].stacked;
        std::size_t lo = 0, hi = back.empty() ? 0 : back.size() - 1;
        while (lo < hi) {
          const std::size_t mid = (lo + hi) >> 1;
          const Entry e0 = back[mid], e1 = back[mid + 1];
          if ((e1.first - hs) * (x - e0.second) >= (e0.first - hs) * (x - e1.second)) {
            lo = mid + 1;
          } else {
            hi = mid;
          }
        }
        if (!back.empty()) far[j] = Entry(back[lo].first - hs, x - back[lo].second);
      }
      block = k;
      stack.clear();
    }
    Raw& e = raw[t];
    if (std::isnan(e.sample.height)) continue;
    e.sample.occluder = hullStep(stack, e.stacked, e.sample.position, 1.0f, &e.sample.occluder_rise,
                                 &e.sample.occluder_run);
    // The peak before the sample (horizon_lattice): on the hull where it is steeper from the
    // sample than the sample's occluder (by -(B/2 + C)/span, as horizon_lattice decides it
    // between the halves of the sample's step); then the sample's push is undone, the peak
    // pushed and the sample pushed again.
    // Only a peak in the sample's block (one before a sample that starts a block may lie in the
    // block before: window_pass takes it).
    if (t > 0 && raw[t - 1].sample.peak && !std::isnan(raw[t - 1].sample.height) && raw[t - 1].block == block) {
      Raw& p = raw[t - 1];
      const bool on_hull =
          e.sample.occluder < 0 || p.peak_rise * e.sample.occluder_run > e.sample.occluder_rise * p.span;
      if (on_hull) {
        stack.pop_back();
        p.sample.occluder = hullStep(stack, p.stacked, p.sample.position, 1.0f, &p.sample.occluder_rise,
                                     &p.sample.occluder_run);
        e.sample.occluder = hullStep(stack, e.stacked, e.sample.position, 1.0f, &e.sample.occluder_rise,
                                     &e.sample.occluder_run);
      }
    }
    // The steeper of the block's own occluder and the block before's (which wins ties).
    const auto [rise2, run2] = far[t];
    if (run2 > 0.0f && (e.sample.occluder_run <= 0.0f || rise2 * e.sample.occluder_run >= e.sample.occluder_rise * run2)) {
      e.sample.occluder = 0;
      e.sample.occluder_rise = rise2;
      e.sample.occluder_run = run2;
    }
  }
  std::vector<LatticeLineSample> out;
  for (const Raw& e : raw) {
    if (!std::isnan(e.sample.height) || e.sample.receiver >= 0) out.push_back(e.sample);
  }
  return out;
}

}  // namespace detail

HorizonResult referenceHorizons(const HeightField& field, const HorizonOptions& options,
                                const HorizonOutputs& outputs) {
  validate(field);
  validate(options, outputs);
  const detail::PreparedHeights prepared = detail::prepareHeights(field);
  if (options.max_error != 0.0)
    throw InvalidArgument("the reference takes K; HorizonOptions::max_error chooses it on the device alone");
  const bool sweep = options.method == HorizonMethod::Sweep;
  std::vector<double> weights(options.directions, 1.0 / options.directions);
  HorizonResult result = detail::allocateResult(field, options, outputs);
  if (sweep) {
    const auto directions = detail::horizonDirections(field, options, outputs);
    for (int k = 0; k < options.directions; ++k) {
      result.azimuths[k] = directions[k].azimuth;
      weights[k] = directions[k].weight;
    }
  }
  const auto run = [&](HorizonResult& into, int parity) {
    if (sweep)
      detail::sweepReference(field, prepared, options, outputs, into, parity);
    else
      detail::naiveReference(field, prepared, options, outputs, into, parity);
  };
  if (outputs.error_estimate) {
    // The even directions' sums in `result`, the odd ones' apart, as the device keeps them.
    HorizonResult odd = detail::allocateResult(field, options, outputs);
    run(result, 0);
    run(odd, 1);
    double even_weight = 0.0, odd_weight = 0.0, cubes = 0.0;
    for (int k = 0; k < options.directions; ++k) {
      (k % 2 ? odd_weight : even_weight) += weights[k];
      cubes += weights[k] * weights[k] * weights[k];
    }
    detail::splitErrorHalves(result, odd.sky_view_factor, odd.ambient_occlusion, even_weight, odd_weight,
                             field, prepared.heights, cubes / (even_weight + odd_weight));
  } else {
    run(result, -1);
  }
  detail::finishReduction(result);
  return result;
}

}  // namespace hfvis
