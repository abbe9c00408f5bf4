// viewshed_pyramid.cpp: Stewart's culling pyramid (hfvis/viewshed.hpp). The horizons come from
// the sweep on the device; folding them into the finest nodes' occlusion regions and combining
// those up the quadtree is a preprocessing pass on the host, in double, every stored value
// rounded the conservative way. The query runs on the device (viewshed_cull in
// kernels/viewshed.cl, launched by src/ops/viewshed.cpp).
#include <algorithm>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <cstring>
#include <functional>
#include <limits>
#include <string>

#include "core/horizon_common.hpp"
#include "core/host_bands.hpp"
#include "core/lattice_geometry.hpp"
#include "core/sweep_framework.hpp"
#include "core/sweep_geometry.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/horizon.hpp"
#include "hfvis/viewshed.hpp"

namespace hfvis {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;
// The horizon planes one sweep call may hand back at once (three calls' blockers, twice as
// large, are held).
constexpr std::size_t kPlaneBytes = std::size_t(1) << 28;

// Rounded toward -inf / +inf: a stored bound never claims more than the double it came from.
float roundDown(double v) {
  const float f = static_cast<float>(v);
  return static_cast<double>(f) > v ? std::nextafter(f, -std::numeric_limits<float>::infinity()) : f;
}
float roundUp(double v) {
  const float f = static_cast<float>(v);
  return static_cast<double>(f) < v ? std::nextafter(f, std::numeric_limits<float>::infinity()) : f;
}

// A maximum pyramid over the cells' slope bounds (|grad h| anywhere in the cell, +inf at a
// nodata corner: kernels/viewshed.cl's viewshed_slopes, in double): the largest slope within
// a radius of a point.
class SlopePyramid {
 public:
  explicit SlopePyramid(const HeightField& f) {
    cells_x_ = std::max(f.width - 1, 1);
    cells_y_ = std::max(f.height - 1, 1);
    std::vector<float> level(static_cast<std::size_t>(cells_x_) * cells_y_);
    auto z = [&](int x, int y) { return static_cast<double>(f.at(x, y)) * f.z_scale; };
    for (int y = 0; y < cells_y_; ++y)
      for (int x = 0; x < cells_x_; ++x) {
        const int x1 = std::min(x + 1, f.width - 1), y1 = std::min(y + 1, f.height - 1);
        const double h00 = z(x, y), h10 = z(x1, y), h01 = z(x, y1), h11 = z(x1, y1);
        const double gx = std::max(std::fabs(h10 - h00), std::fabs(h11 - h01)) / f.cell_size_x;
        const double gy = std::max(std::fabs(h01 - h00), std::fabs(h11 - h10)) / f.cell_size_y;
        const double g = std::sqrt(gx * gx + gy * gy);
        level[static_cast<std::size_t>(y) * cells_x_ + x] = std::isfinite(g) ? roundUp(g) : INFINITY;
      }
    levels_.push_back(std::move(level));
    for (int w = cells_x_, h = cells_y_; w > 1 || h > 1;) {
      const int nw = (w + 1) / 2, nh = (h + 1) / 2;
      const std::vector<float>& below = levels_.back();
      std::vector<float> next(static_cast<std::size_t>(nw) * nh);
      for (int y = 0; y < nh; ++y)
        for (int x = 0; x < nw; ++x) {
          float m = 0.0f;
          for (int j = 2 * y; j <= std::min(2 * y + 1, h - 1); ++j)
            for (int i = 2 * x; i <= std::min(2 * x + 1, w - 1); ++i) m = std::max(m, below[std::size_t(j) * w + i]);
          next[std::size_t(y) * nw + x] = m;
        }
      levels_.push_back(std::move(next));
      w = nw;
      h = nh;
    }
  }

  // The largest slope bound over the cells meeting the square of half-side `radius` (pixels)
  // around (x, y) (pixels).
  float around(double x, double y, double radius) const {
    const int cx0 = std::clamp(static_cast<int>(std::floor(x - radius)), 0, cells_x_ - 1);
    const int cx1 = std::clamp(static_cast<int>(std::floor(x + radius)), 0, cells_x_ - 1);
    const int cy0 = std::clamp(static_cast<int>(std::floor(y - radius)), 0, cells_y_ - 1);
    const int cy1 = std::clamp(static_cast<int>(std::floor(y + radius)), 0, cells_y_ - 1);
    // The level whose blocks are longer than the radius: at most 3 blocks a side.
    const std::size_t k = std::min(levels_.size() - 1, radius < 1.0 ? std::size_t(0) : std::size_t(std::ilogb(radius) + 1));
    const int w = (cells_x_ + (1 << k) - 1) >> k;
    float m = 0.0f;
    for (int j = cy0 >> k; j <= cy1 >> k; ++j)
      for (int i = cx0 >> k; i <= cx1 >> k; ++i) m = std::max(m, levels_[k][std::size_t(j) * w + i]);
    return m;
  }

 private:
  int cells_x_ = 1, cells_y_ = 1;
  std::vector<std::vector<float>> levels_;  // level k: blocks of 2^k x 2^k cells
};

void validatePyramidOptions(const ViewshedPyramidOptions& o) {
  if (!(std::isfinite(o.target_height) && o.target_height >= 0.0))
    throw InvalidArgument("the pyramid's target height must be finite and >= 0");
  detail::validateCurvature(o.curvature, "the pyramid's curvature coefficient");
  if (o.sectors < 4 || o.sectors > 256) throw InvalidArgument("the pyramid takes 4 .. 256 sectors");
  if (o.directions_per_sector < 2 || o.directions_per_sector > 64)
    throw InvalidArgument("the pyramid takes 2 .. 64 directions per sector");
  if (o.finest_level < 1 || o.finest_level > 12) throw InvalidArgument("the pyramid's finest level must be 1 .. 12");
}

}  // namespace

std::size_t ViewshedPyramid::bytes() const {
  std::size_t b = valid_points.size() * sizeof(std::uint32_t);
  for (const Level& l : levels) b += l.regions.size() * sizeof(float);
  return b;
}

std::uint64_t heightsFingerprint(const HeightField& field) {
  std::uint64_t hash = 1469598103934665603ull;
  for (float h : field.heights) {
    std::uint32_t bits;
    std::memcpy(&bits, &h, sizeof bits);
    hash ^= bits;
    hash *= 1099511628211ull;
  }
  return hash;
}

namespace {

// The build of a culling pyramid in three pieces: plan (the pyramid's header, the finest
// nodes' accumulators, the sweep's calls within the budget and their azimuths), run (per call
// of the sweep, its directions' blockers folded into the finest nodes) and finish (the sectors
// and the levels above the finest).
class PyramidBuild {
 public:
  // The plan; throws MemoryBudgetError when the build would hold more than the budget.
  PyramidBuild(const HeightField& field, const ViewshedPyramidOptions& options)
      : field_(field),
        options_(options),
        sectors_(options.sectors),
        per_(options.directions_per_sector),
        directions_(sectors_ * per_),
        width_(field.width),
        height_(field.height),
        k0_(options.finest_level),
        cx_(field.cell_size_x),
        cy_(field.cell_size_y),
        least_cell_(std::min(cx_, cy_)),
        most_cell_(std::max(cx_, cy_)),
        target_(options.target_height),
        c_drop_(options.curvature),
        plane_(field.pixelCount()),
        nodes_x_((width_ + (1 << k0_) - 1) >> k0_),
        nodes_y_((height_ + (1 << k0_) - 1) >> k0_),
        threads_(detail::hostThreads()),
        slopes_(field) {
    describe();
    planNodes();
    planSweep();
  }

  // The sweep, call by call. Call c holds directions k * calls + c: the gaps run from call
  // c - 1 to call c, and from the last call to the first's next direction. The first call's
  // blockers are kept to the end.
  void run(const ComputeContext& context) {
    std::vector<Blockers> first, previous;
    for (int c = 0; c < calls_; ++c) {
      horizon_.azimuth_offset = kTwoPi * c / directions_;
      std::vector<Blockers> r = blockers(computeHorizons(context, field_, horizon_, outputs_), c);
      if (c > 0) foldGaps(c == 1 ? first : previous, c - 1, r, false);
      if (c == calls_ - 1) foldGaps(r, c, c == 0 ? r : first, true);
      if (c == 0)
        first = std::move(r);
      else
        previous = std::move(r);
      if (options_.progress) options_.progress((c + 1) * per_call_, directions_);
    }
  }

  ViewshedPyramid finish() {
    sectorSpans();
    buildLevels();
    return std::move(p_);
  }

 private:
  // Horizon points of one direction: per receiver, where its horizon point B lies from it
  // (pixels) and B's height (NaN: no horizon point, or a slope's own at the receiver).
  struct HorizonPoints {
    std::vector<float> ox, oy, zb;
    std::vector<float> zb_error;  // a bound on zb's error from the float angle and distance
  };
  // One direction's blockers per point (blockersOf).
  struct Blockers {
    double azimuth = 0.0;
    std::vector<float> half_sigma, half_d, whole_sigma, whole_d;
  };
  static constexpr int kFloats = ViewshedPyramid::kRegionFloats;

  // The pyramid's header: what it was built for.
  void describe() {
    p_.width = width_;
    p_.height = height_;
    p_.cell_size_x = cx_;
    p_.cell_size_y = cy_;
    p_.z_scale = field_.z_scale;
    p_.heights_fingerprint = heightsFingerprint(field_);
    p_.target_height = target_;
    p_.curvature = options_.curvature;
    p_.directions = directions_;
    p_.finest_level = k0_;
    p_.sectors = sectors_;
    p_.reach = 2.0 * std::hypot(width_ * cx_, height_ * cy_);
    for (int i = 0; i < ViewshedPyramid::kBreakpoints; ++i)
      breaks_[i] = p_.reach * ViewshedPyramid::breakFraction(i);
    double z_extent = 0.0;  // the largest |height|, for the rounding margin
    for (float h : field_.heights)
      if (std::isfinite(h)) z_extent = std::max(z_extent, std::fabs(h * field_.z_scale));
    z_margin_ = 1e-5 * (1.0 + z_extent + target_);
  }

  // The finest nodes' accumulators: per node and sector, d (largest) and the bound (least).
  void planNodes() {
    const std::size_t finest_nodes = static_cast<std::size_t>(nodes_x_) * nodes_y_;
    regions_.resize(finest_nodes * sectors_ * kFloats);
    for (std::size_t i = 0; i < regions_.size(); ++i) regions_[i] = i % kFloats == 0 ? 0.0f : FLT_MAX;
    p_.valid_points.assign(finest_nodes, 0);
    for (int y = 0; y < height_; ++y)
      for (int x = 0; x < width_; ++x)
        p_.valid_points[std::size_t(y >> k0_) * nodes_x_ + (x >> k0_)] += std::isfinite(field_.at(x, y));
  }

  // The sweep's calls, checked against the budget, and its azimuths.
  void planSweep() {
    // The sweep runs in calls of directions / calls directions each, evenly spread (azimuth offsets
    // 2 pi c / directions), as few calls as keep their planes within kPlaneBytes.
    calls_ = 1;
    while (calls_ < directions_ &&
           (directions_ % calls_ != 0 ||
            std::size_t(directions_ / calls_) * plane_ * 2 * sizeof(float) > kPlaneBytes))
      ++calls_;
    // What the build holds on the host at once: the finest regions (and a third more for the
    // levels above), three calls' blockers, one call's planes and horizon points, the slopes.
    per_call_ = directions_ / calls_;
    const std::size_t finest_nodes = static_cast<std::size_t>(nodes_x_) * nodes_y_;
    const double host_bytes = 4.0 / 3.0 * finest_nodes * sectors_ * kFloats * sizeof(float) +
                              double(plane_) * (3.0 * per_call_ * 16.0 + per_call_ * 8.0 + 16.0 + 6.0);
    const std::size_t budget =
        options_.memory_budget_bytes ? options_.memory_budget_bytes : detail::hostMemoryBudget();
    if (budget > 0 && host_bytes > budget)
      throw MemoryBudgetError("the culling pyramid would hold " +
                              detail::mebibytes(static_cast<std::size_t>(host_bytes)) +
                              " on the host, beyond the budget (" + detail::mebibytes(budget) +
                              "); keep fewer levels (a larger finest level) or crop the DEM");
    azimuth_.resize(directions_);
    horizon_.method = HorizonMethod::Sweep;
    horizon_.directions = per_call_;
    horizon_.samples_per_unit = 1.0;
    horizon_.curvature = options_.curvature;
    horizon_.memory_budget_bytes = options_.memory_budget_bytes;
    outputs_.horizon_angles = true;
    outputs_.horizon_distances = true;
    // The sweep's azimuths (its steps depend on the cell sizes alone, so they are known before it
    // runs; each call's are checked against them), and per direction the wider of its two gaps:
    // its blockers serve the gaps on both sides.
    for (int c = 0; c < calls_; ++c) {
      horizon_.azimuth_offset = kTwoPi * c / directions_;
      const std::vector<detail::LatticeDirection> steps =
          detail::latticeDirections(field_, horizon_, true, horizon_.azimuth_tolerance);
      for (int k = 0; k < per_call_; ++k) azimuth_[k * calls_ + c] = steps[k].azimuth;
    }
    std::vector<double> gap(directions_);  // gap[j]: from direction j to j + 1
    spread_.resize(directions_);
    for (int j = 0; j < directions_; ++j) {
      gap[j] = std::fmod(azimuth_[(j + 1) % directions_] - azimuth_[j], kTwoPi);
      if (gap[j] < 0.0) gap[j] += kTwoPi;
    }
    for (int j = 0; j < directions_; ++j)
      spread_[j] = std::max(gap[j], gap[(j + directions_ - 1) % directions_]) * (1.0 + 1e-9);
  }

  void horizonPoints(const HorizonResult& r, int k, HorizonPoints& hp) const {
    hp.ox.resize(plane_);
    hp.oy.resize(plane_);
    hp.zb.resize(plane_);
    hp.zb_error.resize(plane_);
    const double ux = std::cos(r.azimuths[k]) / cx_, uy = std::sin(r.azimuths[k]) / cy_;
    for (std::size_t at = 0; at < plane_; ++at) {
      const double dn = r.distances[k * plane_ + at], theta = r.angles[k * plane_ + at];
      const float h = field_.heights[at];
      const bool valid = dn > 0.0 && std::isfinite(theta) && std::fabs(theta) < 0.5 * M_PI && std::isfinite(h);
      hp.ox[at] = static_cast<float>(dn * ux);
      hp.oy[at] = static_cast<float>(dn * uy);
      const double t = valid ? std::tan(theta) : 0.0;
      hp.zb[at] = valid ? static_cast<float>(h * field_.z_scale + t * dn + c_drop_ * dn * dn) : NAN;
      hp.zb_error[at] = static_cast<float>(4e-7 * dn * (1.0 + t * t));
    }
  }

  // The blockers of one direction, per point P: for eyes within half of `gap` (the wider of the
  // direction's two gaps) of the direction and within all of it, the bound on their slope from P (-inf: none) and the distance they must
  // lie beyond. Candidates: the horizon points of P and of its 8 neighbours (any surface point
  // whose height is known blocks, and a neighbour's horizon point often stands where P's own
  // horizon is its own slope), each taken where it lies from P, its azimuth `off` from the
  // direction's. An eye within `spread` of B's azimuth at ground distance r > d, its slope from
  // P below slope(B) - L spread - margin / d, is hidden: the sight line passes within
  // d spread of B, where the surface lies at most L d spread lower. A blocker nearer than 2
  // pixels is too near the target for the exact test's rounding to show it reliably.
  void blockersOf(const HorizonPoints& hp, double azimuth, double gap, Blockers& out, int y0, int y1) const {
    const double ca = std::cos(azimuth), sa = std::sin(azimuth);
    for (int y = y0; y < y1; ++y)
      for (int x = 0; x < width_; ++x) {
        const std::size_t p = std::size_t(y) * width_ + x;
        double half = -INFINITY, half_d = 0.0, whole = -INFINITY, whole_d = 0.0;
        const double zp = field_.heights[p] * field_.z_scale + target_;
        if (std::isfinite(zp))
          for (int j = std::max(0, y - 1); j <= std::min(height_ - 1, y + 1); ++j)
            for (int i = std::max(0, x - 1); i <= std::min(width_ - 1, x + 1); ++i) {
              const std::size_t at = std::size_t(j) * width_ + i;
              const double zb = hp.zb[at];
              if (!std::isfinite(zb)) continue;
              const double bx = i + hp.ox[at], by = j + hp.oy[at];
              const double gx = (bx - x) * cx_, gy = (by - y) * cy_;
              const double d = std::sqrt(gx * gx + gy * gy);
              if (!(d >= 2.0 * most_cell_) || ca * gx + sa * gy <= 0.0) continue;
              const double slope = (zb - c_drop_ * d * d - zp) / d;
              if (slope <= whole) continue;  // its bounds lie below slope: it cannot do better
              const double sine = std::min(1.0, std::fabs(ca * gy - sa * gx) / d);
              const double off = sine <= 0.5 ? sine + 0.2 * sine * sine * sine : std::asin(sine);  // >= asin(sine)
              const double L = slopes_.around(bx, by, d * (gap + off) / least_cell_ + 1.0);
              if (!std::isfinite(L)) continue;
              // The margin: the heights' rounding, the exact test's (its vertex test skipped on
              // pieces under 1e-3 pixel) and zb's, from the receiver's float angle and distance.
              const double margin =
                  z_margin_ + 2e-3 * most_cell_ * (L + std::fabs(slope) + 1.0) + hp.zb_error[at];
              const double base = slope - margin / d - L * off;
              if (base - L * 0.5 * gap > half) half = base - L * 0.5 * gap, half_d = d + most_cell_;
              if (base - L * gap > whole) whole = base - L * gap, whole_d = d + most_cell_;
            }
        out.half_sigma[p] = roundDown(half);
        out.half_d[p] = roundUp(half_d);
        out.whole_sigma[p] = roundDown(whole);
        out.whole_d[p] = roundUp(whole_d);
      }
  }

  // Runs body(first, last) over bands of rows (or of the finest nodes' rows) on the threads.
  void parallel(int count, const std::function<void(int, int)>& body) const {
    detail::forEachBand(count, threads_, [&](int, int first, int last) { body(first, last); });
  }

  // The blockers of call c's directions.
  std::vector<Blockers> blockers(const HorizonResult& r, int c) const {
    std::vector<Blockers> out(per_call_);
    HorizonPoints hp;
    for (int k = 0; k < per_call_; ++k) {
      const int j = k * calls_ + c;
      if (std::fabs(r.azimuths[k] - azimuth_[j]) > 1e-12)
        throw InvalidArgument("the sweep's azimuths differ from its steps' (internal error)");
      horizonPoints(r, k, hp);
      Blockers& b = out[k];
      b.azimuth = r.azimuths[k];
      for (auto* v : {&b.half_sigma, &b.half_d, &b.whole_sigma, &b.whole_d}) v->resize(plane_);
      parallel(height_, [&](int y0, int y1) { blockersOf(hp, b.azimuth, spread_[j], b, y0, y1); });
    }
    return out;
  }

  // Folds the gaps from the directions of call ca (a) to their neighbours counter-clockwise (b;
  // next: b's direction k + 1 follows a's k) into the finest nodes. An eye in the gap is within
  // half of it of one of its two directions and within all of it of either: the gap's region
  // is the better of "both, half the gap each" and "one of them, the whole gap".
  void foldGaps(const std::vector<Blockers>& a, int ca, const std::vector<Blockers>& b, bool next) {
    parallel(nodes_y_, [&](int band_first, int band_last) {
      for (int k = 0; k < per_call_; ++k) {
        const int j = k * calls_ + ca, kb = next ? (k + 1) % per_call_ : k;
        const int s = j / per_;
        const Blockers &from_a = a[k], &from_b = b[kb];
        for (int y = band_first << k0_; y < std::min(height_, band_last << k0_); ++y)
          for (int x = 0; x < width_; ++x) {
            const std::size_t p = std::size_t(y) * width_ + x;
            const float h = field_.heights[p];
            if (!std::isfinite(h)) continue;
            const double zp = h * field_.z_scale + target_;
            float* region =
                &regions_[((std::size_t(y >> k0_) * nodes_x_ + (x >> k0_)) * sectors_ + s) * kFloats];
            region[1] = std::min(region[1], roundDown(zp));
            double sigma = std::min(from_a.half_sigma[p], from_b.half_sigma[p]);
            double d = std::max(from_a.half_d[p], from_b.half_d[p]);
            for (const Blockers* one : {&from_a, &from_b})
              if (one->whole_sigma[p] > sigma) sigma = one->whole_sigma[p], d = one->whole_d[p];
            if (std::isfinite(sigma)) region[0] = std::max(region[0], static_cast<float>(d));
            for (int i = 1; i < ViewshedPyramid::kBreakpoints; ++i)
              region[1 + i] = std::min(region[1 + i],
                                       std::isfinite(sigma) ? roundDown(zp + sigma * breaks_[i]) : -INFINITY);
          }
      }
    });
  }

  // The sectors: from the azimuth of their first direction to that of their last (the next
  // sector's first).
  void sectorSpans() {
    for (int s = 0; s < sectors_; ++s) {
      const double a0 = azimuth_[s * per_];
      double w = std::fmod(azimuth_[((s + 1) * per_) % directions_] - a0, kTwoPi);
      if (w < 0.0) w += kTwoPi;
      double start_az = std::fmod(a0, kTwoPi);
      if (start_az < 0.0) start_az += kTwoPi;
      // Stored in float: the query widens its azimuth range by far more than their rounding.
      p_.sector_start.push_back(static_cast<float>(start_az));
      p_.sector_width.push_back(static_cast<float>(w));
    }
  }

  // The levels: a parent's region per sector is the intersection of its children's, the
  // farthest d and the least bound at every breakpoint (each bound concave and piecewise linear
  // on the shared breakpoints, so the least of them interpolated lies below them all).
  void buildLevels() {
    p_.levels.push_back({k0_, nodes_x_, nodes_y_, std::move(regions_)});
    while (p_.levels.back().nodes_x > 1 || p_.levels.back().nodes_y > 1) {
      const ViewshedPyramid::Level& below = p_.levels.back();
      ViewshedPyramid::Level up;
      up.k = below.k + 1;
      up.nodes_x = (below.nodes_x + 1) / 2;
      up.nodes_y = (below.nodes_y + 1) / 2;
      up.regions.assign(std::size_t(up.nodes_x) * up.nodes_y * sectors_ * kFloats, 0.0f);
      for (int ny = 0; ny < up.nodes_y; ++ny)
        for (int nx = 0; nx < up.nodes_x; ++nx)
          for (int s = 0; s < sectors_; ++s) {
            float* out = &up.regions[((std::size_t(ny) * up.nodes_x + nx) * sectors_ + s) * kFloats];
            out[0] = 0.0f;
            for (int i = 1; i < kFloats; ++i) out[i] = FLT_MAX;
            for (int j = 2 * ny; j <= std::min(2 * ny + 1, below.nodes_y - 1); ++j)
              for (int i = 2 * nx; i <= std::min(2 * nx + 1, below.nodes_x - 1); ++i) {
                const float* in =
                    &below.regions[((std::size_t(j) * below.nodes_x + i) * sectors_ + s) * kFloats];
                out[0] = std::max(out[0], in[0]);
                for (int b = 1; b < kFloats; ++b) out[b] = std::min(out[b], in[b]);
              }
          }
      p_.levels.push_back(std::move(up));
    }
  }

  const HeightField& field_;
  const ViewshedPyramidOptions& options_;
  const int sectors_, per_, directions_;
  const int width_, height_, k0_;
  const double cx_, cy_, least_cell_, most_cell_;
  const double target_, c_drop_;
  const std::size_t plane_;
  const int nodes_x_, nodes_y_;  // the finest level's nodes
  const int threads_;
  const SlopePyramid slopes_;
  ViewshedPyramid p_;
  double breaks_[ViewshedPyramid::kBreakpoints] = {};
  double z_margin_ = 0.0;
  std::vector<float> regions_;  // the finest nodes' regions
  int calls_ = 1, per_call_ = 0;
  std::vector<double> azimuth_, spread_;  // per direction
  HorizonOptions horizon_;
  HorizonOutputs outputs_;
};

}  // namespace

ViewshedPyramid buildViewshedPyramid(const ComputeContext& context, const HeightField& field,
                                     const ViewshedPyramidOptions& options) {
  const auto start = std::chrono::steady_clock::now();
  validate(field);
  validatePyramidOptions(options);
  if (field.pixelCount() > static_cast<std::size_t>(std::numeric_limits<int>::max()))
    throw InvalidArgument("a culling pyramid takes fields of at most 2^31 - 1 points");
  if (detail::hasRowSpacing(field))
    throw InvalidArgument(
        "culling pyramids on latitude / longitude grids (per-row spacing) are not supported");
  PyramidBuild build(field, options);
  build.run(context);
  ViewshedPyramid p = build.finish();
  p.build_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return p;
}

}  // namespace hfvis
