// pvs_sampling.cpp: the samplers of the potentially visible sets (hfvis/pvs.hpp): per view cell
// random sampling, stationary global sampling and adaptive global visibility sampling (Bittner
// et al. 2009, Sec. 4), the pixel-error estimate (Sec. 4.5) and the object-space visibility
// filter (Sec. 5). Samples are drawn on the host in batches from one seeded generator, cast on
// the device (pvs.cpp's ray caster) and folded in in sample order, so a run is a function of its
// inputs and seed. Geometry here is in ground units (x cell_x, y cell_y, z), rays in pixels.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <deque>
#include <limits>
#include <sstream>
#include <string>
#include <unordered_map>

#include "core/number_text.hpp"
#include "core/sweep_geometry.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/pvs.hpp"
#include "hfvis/region_visibility.hpp"
#include "ops/pvs_ray.hpp"

namespace hfvis {
namespace {

constexpr double kPi = 3.14159265358979323846;
// Every distribution keeps at least this probability (Sec. 4.2 recalibrates now and then;
// this keeps a distribution that was poor early from never being tried again).
constexpr double kMinProbability = 0.02;
// Mutation candidates kept (Sec. 4.4: the highest mutation count is dropped when full).
constexpr std::size_t kMutationCandidates = 1 << 16;
// The silhouette mutation's search along the perpendicular (Sec. 4.4): rounds of discovery rays,
// each splitting the interval that holds the silhouette in kDiscoveryRays ("packets of 4 rays").
// Two rounds, not the paper's quaternary search of depth 3: against one round, two and three both
// raised recall per sample on the city and the DEM (by about 0.5 - 2 points at 1M - 3M samples),
// but three lowered it on rough terrain where two did not (bench/report/pvs.md, "The silhouette
// search").
constexpr int kDiscoveryRays = 4;
constexpr int kSearchRounds = 2;
// A silhouette ray whose hit lies beyond its end by more than this many object radii reports a
// depth discontinuity (Sec. 4.4, after Wonka et al. 2006's reverse sampling; the paper's k = 3).
constexpr double kDiscontinuityRadii = 3.0;
// The most uniform rays a pixel-error budget alone may ask for (at 5M rays a second, days).
constexpr double kMaxPixelErrorRays = 1e12;
// The view space-direction samples' least probability in the mixture: the pixel error is
// estimated from them alone (Sec. 4.5), and at the common floor (kMinProbability) so few are
// cast late in a run that an error of a few per million rests on no contributing ray at all.
constexpr double kMinViewDirection = 0.1;

enum Distribution { kViewDirection, kObjectDirection, kTwoPoint, kTwoPointMutation, kSilhouetteMutation };

struct Vec {
  double x = 0, y = 0, z = 0;
};
Vec operator+(Vec a, Vec b) { return {a.x + b.x, a.y + b.y, a.z + b.z}; }
Vec operator-(Vec a, Vec b) { return {a.x - b.x, a.y - b.y, a.z - b.z}; }
Vec operator*(double s, Vec a) { return {s * a.x, s * a.y, s * a.z}; }
double dot(Vec a, Vec b) { return a.x * b.x + a.y * b.y + a.z * b.z; }
Vec cross(Vec a, Vec b) { return {a.y * b.z - a.z * b.y, a.z * b.x - a.x * b.z, a.x * b.y - a.y * b.x}; }
Vec unit(Vec a) { return (1.0 / std::sqrt(dot(a, a))) * a; }

// SplitMix64: small, fast, and the same sequence on every platform.
class Random {
 public:
  // The stream starts at the seed's hash: a start linear in the seed (seed times the step) made
  // seed s + 1's stream seed s's shifted by one number, so runs with neighbouring seeds cast
  // nearly the same samples.
  explicit Random(std::uint64_t seed) : state_(mix(seed ^ 0x632be59bd9b4e019ULL)) {}
  std::uint64_t next() { return mix(state_ += 0x9e3779b97f4a7c15ULL); }
  double uniform() { return double(next() >> 11) * 0x1p-53; }  // [0, 1)
  std::size_t below(std::size_t n) { return std::size_t(uniform() * double(n)) % n; }
  double gaussian() {  // Box-Muller, one of the pair
    const double u = 1.0 - uniform(), v = uniform();
    return std::sqrt(-2.0 * std::log(u)) * std::cos(2.0 * kPi * v);
  }
  Vec sphere() {  // uniform direction: phi = 2 pi psi1, theta = acos(1 - 2 psi2)
    const double phi = 2.0 * kPi * uniform(), c = 1.0 - 2.0 * uniform(),
                 s = std::sqrt(std::max(0.0, 1.0 - c * c));
    return {s * std::cos(phi), s * std::sin(phi), c};
  }

 private:
  // SplitMix64's output function (Steele, Lea & Flood 2014).
  static std::uint64_t mix(std::uint64_t z) {
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }
  std::uint64_t state_;
};

// A point of a sample: ground position, and what it is (a tile hit, or a point in view space).
struct MutationCandidate {
  Vec origin, target;  // s_o, s_t
  double origin_radius = 0, target_radius = 0;
  int tile = 0;               // the object at s_t
  std::uint64_t lineage = 0;  // the sample it descends from (Sampler::lineage)
};

// Candidates by mutation count: the least mutated first (Sec. 4.4).
class MutationBuffer {
 public:
  bool empty() const { return size_ == 0; }
  void add(const MutationCandidate& c) {
    if (size_ == kMutationCandidates) drop();
    if (buckets_.empty()) buckets_.emplace_back();
    buckets_[0].push_back(c);
    ++size_;
  }
  // The least mutated candidate, its count raised by one.
  MutationCandidate take() {
    std::size_t b = 0;
    while (buckets_[b].empty()) ++b;
    MutationCandidate c = buckets_[b].front();
    buckets_[b].pop_front();
    if (b + 1 == buckets_.size()) buckets_.emplace_back();
    buckets_[b + 1].push_back(c);
    return c;
  }

 private:
  void drop() {
    std::size_t b = buckets_.size();
    while (buckets_[b - 1].empty()) --b;
    buckets_[b - 1].pop_back();
    --size_;
  }
  std::vector<std::deque<MutationCandidate>> buckets_;
  std::size_t size_ = 0;
};

// One visibility sample to cast: a ray (both ways when global), its distribution.
struct Sample {
  Vec origin, direction;  // ground units
  int distribution = kViewDirection;
  int view_cell = -1;  // per-cell samples: the view cell fed
  // The first sample of its line of mutations (itself when not a mutation): the pixel error's
  // leave-one-out does not count a sample's own mutations as finding its entry again.
  std::uint64_t lineage = 0;
  // A silhouette mutation drawn from a depth discontinuity (Sec. 4.4): it reports none itself.
  bool follow_up = false;
};

class Sampler {
 public:
  Sampler(const HeightField& field, const PvsGrid& grid, const PvsOptions& options, PvsResult& out)
      : field_(field), grid_(grid), options_(options), out_(out), random_(options.seed) {
    out_.layout = pvsLayout(field, grid);
    const PvsLayout& l = out_.layout;
    out_.words = (l.tiles() + 31) / 32;
    out_.bits.assign(std::size_t(l.viewCells()) * out_.words, 0u);
    only_finder_ = out_.bits;
    out_.computed = grid.mask.empty() ? std::vector<std::uint8_t>(l.viewCells(), 1) : grid.mask;
    if (!options.start.empty()) {
      // (the entries to resume from: found by earlier samples, so never in only_finder_)
      if (options.filter > 0.0)
        throw InvalidArgument(
            "the visibility filter takes its width from a run's samples, which a resumed "
            "run knows only in part: no filter with sets to resume from");
      if (options.start.size() != out_.bits.size())
        throw InvalidArgument("the sets to resume from hold " + std::to_string(options.start.size()) +
                              " words, the grid's " + std::to_string(out_.bits.size()) + " (" +
                              std::to_string(l.viewCells()) + " view cells of " + std::to_string(out_.words) +
                              " words): another field or grid");
      const std::uint32_t last = l.tiles() % 32 ? (1u << (l.tiles() % 32)) - 1u : ~0u;
      for (int v = 0; v < l.viewCells(); ++v)
        for (int w = 0; w < out_.words; ++w) {
          const std::uint32_t word = options.start[std::size_t(v) * out_.words + w];
          if (word && !out_.computed[v])
            throw InvalidArgument("the sets to resume from hold entries of view cell " + std::to_string(v) +
                                  ", which this run does not compute (another view mask)");
          if (w == out_.words - 1 && (word & ~last))
            throw InvalidArgument("the sets to resume from have bits past the last tile in view cell " +
                                  std::to_string(v));
        }
      out_.bits = options.start;
    }
    out_.pixel_error = std::numeric_limits<double>::quiet_NaN();
    heights_ = detail::rayHeights(field);
    cx_ = field.cell_size_x;
    cy_ = field.cell_size_y;
    curvature_ = options.curvature;
    // Valid cells by view cell (view space) and by tile (objects).
    view_cells_.resize(l.viewCells());
    tile_cells_.resize(l.tiles());
    for (int cy = 0; cy < l.cells_y; ++cy)
      for (int cx = 0; cx < l.cells_x; ++cx) {
        const std::size_t p = std::size_t(cy) * field.width + cx;
        if (!std::isfinite(heights_[p]) || !std::isfinite(heights_[p + 1]) ||
            !std::isfinite(heights_[p + field.width]) || !std::isfinite(heights_[p + field.width + 1]))
          continue;
        const int cell = cy * l.cells_x + cx, v = l.viewOfCell(cell);
        if (out_.computed[v]) view_cells_[v].push_back(cell), view_space_.push_back(cell);
        tile_cells_[l.tileOfCell(cell)].push_back(cell);
      }
    for (int v = 0; v < l.viewCells(); ++v)
      if (!view_cells_[v].empty()) sampled_views_.push_back(v);
    for (int t = 0; t < l.tiles(); ++t)
      if (!tile_cells_[t].empty()) objects_.push_back(t);
    max_d2_ = options.max_distance > 0.0 ? float(options.max_distance * options.max_distance) : 0.0f;
    reachIn(options.max_distance);
    // The entries a sample can find: an eye stands on a valid cell of its view cell and a hit is on
    // a valid cell of its tile, so view cells and tiles all nodata never pair; nor do those farther
    // apart than the maximum distance.
    reachable_tiles_.assign(out_.words, 0u);
    for (int t : objects_) reachable_tiles_[t / 32] |= 1u << (t % 32);
    reachable_ = reachable_found_ = 0;
    for (int v : sampled_views_)
      for (int w = 0; w < out_.words; ++w) {
        const std::uint32_t can = reach(v, w) & reachable_tiles_[w];
        reachable_ += std::size_t(__builtin_popcount(can));
        reachable_found_ += std::size_t(__builtin_popcount(out_.bits[std::size_t(v) * out_.words + w] & can));
      }
    if (view_space_.empty()) throw InvalidArgument("the computed view cells hold no valid cell (all nodata)");
    tile_radius_ = 0.5 * l.tile * std::hypot(cx_, cy_);
    view_radius_ = 0.5 * l.view_cell * std::hypot(cx_, cy_);
    probability_.assign(kPvsDistributions, 0.0);
    if (options.method == PvsMethod::Agvs)
      for (int d = 0; d < 3; ++d) probability_[d] = 1.0 / 3.0;  // mutations join once seeded
    else
      probability_[kViewDirection] = 1.0;
  }

  void run(detail::RayCaster& caster) {
    const auto start = std::chrono::steady_clock::now();
    if (complete()) {  // (sets to resume from that are complete already: nothing to cast)
      out_.pixel_error = 0.0;
      if (options_.filter > 0.0 || options_.view_filter > 0) filters();
      return;
    }
    for (;;) {
      if (sample(caster, start)) break;
      settle(caster, start);
      if (complete()) break;
      // A pixel-error budget the settled estimate no longer meets goes on, within the others.
      const bool budget_left = (!options_.samples || out_.samples < options_.samples) &&
                               (options_.seconds <= 0.0 || out_.seconds < options_.seconds);
      if (!(options_.pixel_error > 0.0 && out_.pixel_error > options_.pixel_error && budget_left)) break;
    }
    if (options_.filter > 0.0 || options_.view_filter > 0) filters();
  }

 private:
  // The sampler's batches until a budget is reached or the sets are complete (then true).
  bool sample(detail::RayCaster& caster, std::chrono::steady_clock::time_point start) {
    for (;;) {
      std::uint64_t n = std::uint64_t(options_.batch);
      if (options_.samples) n = std::min(n, options_.samples - std::min(options_.samples, out_.samples));
      if (n == 0) return false;
      batch(caster, static_cast<int>(n));
      record(start);
      if (complete()) return true;
      if (options_.pixel_error > 0.0 && out_.pixel_error <= options_.pixel_error) return false;
      if (options_.seconds > 0.0 && out_.seconds >= options_.seconds) return false;
    }
  }

  // Word w of view cell v's tiles within the maximum distance (all: no maximum distance, or one
  // beyond the field's diagonal).
  std::uint32_t reach(int v, int w) const {
    return in_reach_.empty() ? ~0u : in_reach_[std::size_t(v) * out_.words + w];
  }

  // Fills in_reach_: for each computed view cell, the tiles whose valid cells come less than d
  // from its own on the ground (the bounding boxes of the valid cells, so that nodata between
  // leaves out pairs no eye and hit can make; squares exactly d apart meet only where a pair of
  // their points is, which no sample finds). Row by row of tiles: the run of tiles whose squares
  // are in reach is set a word at a time, then the tiles with nodata at their edges (a valid box
  // smaller than their square) tested alone. Without d, or with d across the field, nothing.
  void reachIn(double d) {
    const PvsLayout& l = out_.layout;
    if (!(d > 0.0) || d > std::hypot(l.cells_x * cx_, l.cells_y * cy_)) return;
    struct Box {
      int x0, y0, x1, y1;  // pixels
    };
    const auto valid = [&](const std::vector<int>& cells, Box square) {
      if (cells.empty()) return square;
      Box b{l.cells_x, l.cells_y, 0, 0};
      for (int c : cells) {
        const int x = c % l.cells_x, y = c / l.cells_x;
        b = {std::min(b.x0, x), std::min(b.y0, y), std::max(b.x1, x + 1), std::max(b.y1, y + 1)};
      }
      return b;
    };
    const auto gap = [](int a0, int a1, int b0, int b1) { return std::max({0, b0 - a1, a0 - b1}); };
    const auto near = [&](const Box& a, const Box& b) {
      const double gx = gap(a.x0, a.x1, b.x0, b.x1) * cx_, gy = gap(a.y0, a.y1, b.y0, b.y1) * cy_;
      return gx * gx + gy * gy < d * d;
    };
    const auto square = [&](int t) {
      const int x = (t % l.tiles_x) * l.tile, y = (t / l.tiles_x) * l.tile;
      return Box{x, y, std::min(x + l.tile, l.cells_x), std::min(y + l.tile, l.cells_y)};
    };
    std::vector<Box> tile_box(l.tiles());
    std::vector<std::vector<int>> edged(l.tiles_y);  // per row of tiles, those with nodata at an edge
    for (int t = 0; t < l.tiles(); ++t) {
      const Box full = square(t), b = tile_box[t] = valid(tile_cells_[t], full);
      if (b.x0 != full.x0 || b.y0 != full.y0 || b.x1 != full.x1 || b.y1 != full.y1)
        edged[t / l.tiles_x].push_back(t);
    }
    in_reach_.assign(std::size_t(l.viewCells()) * out_.words, 0u);
    for (int v = 0; v < l.viewCells(); ++v) {
      if (!out_.computed[v]) continue;
      const int sx = (v % l.view_x) * l.view_cell, sy = (v / l.view_x) * l.view_cell;
      const Box vb = valid(view_cells_[v], {sx, sy, std::min(sx + l.view_cell, l.cells_x),
                                            std::min(sy + l.view_cell, l.cells_y)});
      std::uint32_t* words = &in_reach_[std::size_t(v) * out_.words];
      for (int ty = 0; ty < l.tiles_y; ++ty) {
        const double gy = gap(vb.y0, vb.y1, ty * l.tile, std::min(ty * l.tile + l.tile, l.cells_y)) * cy_;
        if (!(gy * gy < d * d)) continue;
        const double rest = std::sqrt(d * d - gy * gy) / cx_;  // pixels across
        int a = int(std::max(0.0, std::floor((vb.x0 - rest) / l.tile)));
        int b = int(std::min<double>(l.tiles_x - 1, std::floor((vb.x1 + rest) / l.tile)));
        while (a <= b && !near(vb, square(ty * l.tiles_x + a))) ++a;
        while (b >= a && !near(vb, square(ty * l.tiles_x + b))) --b;
        for (int t = ty * l.tiles_x + a, end = ty * l.tiles_x + b; t <= end;) {  // the run, a word at a time
          const int first = t % 32, last = std::min(31, first + (end - t));
          words[t / 32] |= (last == 31 ? ~0u : (1u << (last + 1)) - 1u) & ~((1u << first) - 1u);
          t += last - first + 1;
        }
        for (int t : edged[ty])
          if (t % l.tiles_x >= a && t % l.tiles_x <= b && !near(vb, tile_box[t]))
            words[t / 32] &= ~(1u << (t % 32));
      }
    }
  }

  // Every computed view cell with a valid cell holds every tile with a surface within reach (every
  // entry a sample can find; nodata tiles and view cells pair with nothing, nor do a view cell and
  // a tile farther apart than the maximum distance): no ray can differ, whatever
  // the estimate's floor of one entry per uniform ray says (a pixel-error budget would go on for
  // ever toward a small E), and no sample can add anything (a samples or seconds budget would be
  // spent for nothing), so the estimate is 0 (batch() sets it, before the history and the progress
  // callback see it) and the run ends, whatever its budget. (Counts only those entries: sets to
  // resume from may hold others.)
  bool complete() const { return reachable_found_ == reachable_; }

  // Settles the estimate (PvsOptions::estimate_entries): while fewer entries found once than asked
  // carry it, view-direction samples (uniform view rays) go on, at most as many samples as the
  // run cast before them (and under a seconds budget at most as many seconds as it took). Not
  // when no entry is found once: the estimate is then its floor, one entry over the uniform rays,
  // and a run that has converged would cast its budget again for nothing. The entries they find
  // join the sets; the mixture and the mutations stay.
  void settle(detail::RayCaster& caster, std::chrono::steady_clock::time_point start) {
    if (options_.estimate_entries == 0 || only_finders_.empty() || complete()) return;
    const std::uint64_t most = out_.samples - out_.estimate_samples;
    const double before = out_.seconds - settle_seconds_;
    const auto unsettled = [&] {
      return only_finders_.size() < options_.estimate_entries && !complete() &&
             out_.estimate_samples < most && (options_.seconds <= 0.0 || settle_seconds_ < before);
    };
    settling_ = true;
    while (unsettled()) {
      const std::uint64_t n = std::min<std::uint64_t>(options_.batch, most - out_.estimate_samples);
      const double t0 = out_.seconds;
      batch(caster, static_cast<int>(n));
      out_.estimate_samples += n;
      record(start);
      settle_seconds_ += out_.seconds - t0;
    }
    settling_ = false;
  }

  // A row of the history after a batch, and the progress callback.
  void record(std::chrono::steady_clock::time_point start) {
    out_.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    PvsProgress row;
    row.samples = out_.samples;
    row.rays = out_.rays;
    row.entries = out_.entries();
    row.seconds = out_.seconds;
    row.pixel_error = out_.pixel_error;
    row.probability = probability_;
    row.settling = settling_;
    out_.history.push_back(row);
    if (options_.progress) options_.progress(out_);
  }

  // ---- Geometry

  float surface(double x, double y) const {  // pixels
    return detail::region_surface_at(heights_.data(), field_.width, field_.height, float(x), float(y));
  }
  Vec ground(double x, double y, double z) const { return {x * cx_, y * cy_, z}; }
  // The ray from o along d: with curvature the straight line over the curved surface, whose height
  // over the grid is o.z + t d.z + C t^2 (rise(d): C; the caster's own, hf_ray_cast). A sample's
  // line is its origin and direction so: the reverse ray, from o along -d, is the same line.
  HeightRay ray(Vec o, Vec d) const {
    HeightRay r;
    r.ox = float(o.x / cx_), r.oy = float(o.y / cy_), r.oz = float(o.z);
    r.dx = float(d.x / cx_), r.dy = float(d.y / cy_), r.dz = float(d.z);
    r.t_max = INFINITY;
    return r;
  }
  double rise(Vec d) const { return curvature_ * (d.x * d.x + d.y * d.y); }
  // The point at t of the line from o along d (ray(o, d)).
  Vec along(Vec o, Vec d, double t) const { return o + t * d + Vec{0.0, 0.0, rise(d) * t * t}; }
  // The line through a and b, a at t = -u and b at t = 1 - u from its origin (the origin at a for
  // u = 0, halfway for u = 1/2): the origin into `origin` and the direction into `direction`.
  // Without curvature the straight segment's; with it, its height's slope and the origin's height
  // are moved so that the curved line meets both points.
  void through(Vec a, Vec b, double u, Vec& origin, Vec& direction) const {
    // ((1 - u) a + u b: without curvature the very operations of the straight segment's origin, a
    // or the midpoint (a + b) / 2, so that flat runs draw the samples they drew before curvature)
    direction = b - a;
    const double c = rise(direction);
    direction.z -= c * (1.0 - 2.0 * u);
    origin = (1.0 - u) * a + u * b;
    origin.z -= c * u * (1.0 - u);
  }
  // The height at t of the cast ray q (hf_ray_height, in double).
  double heightAt(const HeightRay& q, double t) const {
    const double gx = q.dx * cx_, gy = q.dy * cy_;
    return q.oz + t * q.dz + curvature_ * (gx * gx + gy * gy) * t * t;
  }
  // A uniform point of a cell (pixels), and the cell's corner.
  void inCell(int cell, double& x, double& y) {
    const PvsLayout& l = out_.layout;
    x = cell % l.cells_x + random_.uniform();
    y = cell / l.cells_x + random_.uniform();
  }
  // A uniform point of view space (of view cell v when v >= 0): its volume over valid cells.
  Vec viewPoint(int v = -1) {
    const std::vector<int>& cells = v < 0 ? view_space_ : view_cells_[v];
    double x, y;
    inCell(cells[random_.below(cells.size())], x, y);
    const double band = grid_.band_low + (grid_.band_high - grid_.band_low) * random_.uniform();
    return ground(x, y, surface(x, y) + band);
  }
  // A uniform point on a random object's surface, and its cell.
  Vec objectPoint(int& cell) {
    const std::vector<int>& cells = tile_cells_[objects_[random_.below(objects_.size())]];
    cell = cells[random_.below(cells.size())];
    double x, y;
    inCell(cell, x, y);
    return ground(x, y, surface(x, y));
  }
  // A cosine-weighted direction about the surface normal of cell `cell` at p (Sec. 4.3:
  // phi = 2 pi psi1, theta = acos sqrt(psi2)).
  Vec cosineDirection(int cell, Vec p) {
    const PvsLayout& l = out_.layout;
    const int x0 = cell % l.cells_x, y0 = cell / l.cells_x;
    const std::size_t q = std::size_t(y0) * field_.width + x0;
    const double h00 = heights_[q], h10 = heights_[q + 1], h01 = heights_[q + field_.width],
                 h11 = heights_[q + field_.width + 1];
    const double u = p.x / cx_ - x0, v = p.y / cy_ - y0, twist = h00 - h10 - h01 + h11;
    const Vec n = unit({-((h10 - h00) + twist * v) / cx_, -((h01 - h00) + twist * u) / cy_, 1.0});
    const Vec a = unit(std::fabs(n.x) < 0.9 ? cross(n, Vec{1, 0, 0}) : cross(n, Vec{0, 1, 0})),
              b = cross(n, a);
    const double phi = 2.0 * kPi * random_.uniform(), c = std::sqrt(random_.uniform());
    const double s = std::sqrt(std::max(0.0, 1.0 - c * c));
    return (s * std::cos(phi)) * a + (s * std::sin(phi)) * b + c * n;
  }
  // A point of the plane through p perpendicular to `axis`, Gaussian about p with deviation sigma.
  Vec perpendicularGaussian(Vec p, Vec axis, double sigma) {
    const Vec n = unit(axis);
    const Vec a = unit(std::fabs(n.x) < 0.9 ? cross(n, Vec{1, 0, 0}) : cross(n, Vec{0, 1, 0})),
              b = cross(n, a);
    return p + (sigma * random_.gaussian()) * a + (sigma * random_.gaussian()) * b;
  }

  // ---- Drawing samples

  int pick() {
    double u = random_.uniform(), sum = 0.0;
    for (int d = 0; d < kPvsDistributions; ++d) {
      sum += probability_[d];
      if (u < sum) return d;
    }
    return kViewDirection;
  }

  Sample draw() {
    Sample s;
    if (options_.method == PvsMethod::PerCell) {
      s.view_cell = sampled_views_[per_cell_next_++ % sampled_views_.size()];
      s.origin = viewPoint(s.view_cell);
      s.direction = random_.sphere();
      return s;
    }
    s.distribution = settling_ ? kViewDirection : pick();
    if ((s.distribution == kTwoPointMutation || s.distribution == kSilhouetteMutation) && mutations_.empty())
      s.distribution = kViewDirection;
    switch (s.distribution) {
      case kObjectDirection: {
        int cell;
        s.origin = objectPoint(cell);
        s.direction = cosineDirection(cell, s.origin);
        break;
      }
      case kTwoPoint: {
        int cell;
        const Vec v = viewPoint(), o = objectPoint(cell);
        through(v, o, 0.0, s.origin, s.direction);
        break;
      }
      case kTwoPointMutation: {
        const MutationCandidate c = mutations_.take();
        s.lineage = c.lineage;
        const Vec axis = c.target - c.origin;
        const Vec so = perpendicularGaussian(c.origin, axis, c.origin_radius);
        const Vec st = perpendicularGaussian(c.target, axis, c.target_radius);
        through(so, st, 0.5, s.origin, s.direction);
        break;
      }
      case kSilhouetteMutation: {
        // The discovery rays are cast first (silhouette()); here the candidate and the direction.
        // A depth discontinuity an earlier silhouette ray reported comes first (Sec. 4.4: its
        // segment from the silhouette point to the far hit is mutated in turn).
        const bool follow_up = !discontinuities_.empty();
        const MutationCandidate c = follow_up ? discontinuities_.front() : mutations_.take();
        if (follow_up) discontinuities_.pop_front(), ++out_.discontinuities;
        s.follow_up = follow_up;
        s.lineage = c.lineage;
        const Vec axis = c.target - c.origin;
        const Vec off = perpendicularGaussian(Vec{}, axis, 1.0);
        silhouettes_.push_back({c, unit(off.x == 0 && off.y == 0 && off.z == 0 ? Vec{1, 0, 0} : off)});
        s.origin = c.origin;
        s.direction = axis;
        break;
      }
      default:
        s.origin = viewPoint();
        s.direction = random_.sphere();
    }
    if (!(dot(s.direction, s.direction) > 0.0)) s.direction = random_.sphere();
    return s;
  }

  // Sec. 4.4's silhouette search: from s_o toward s_t + lambda r(o) d. The first round casts
  // lambda = 1/4 .. 1; each later round splits the interval between the last lambda that hit the
  // object and the first that missed it in four (three new rays, the miss known), kSearchRounds in
  // all. The least lambda found to miss becomes the sample's target (lambda = 1 when all hit: then
  // no later round). The rays each sample cast are counted in silhouette_rays_ (the mixture's cost).
  void silhouettes(detail::RayCaster& caster, std::vector<Sample>& samples) {
    silhouette_rays_ = 0;
    if (silhouettes_.empty()) return;
    const std::size_t n = silhouettes_.size();
    std::vector<double> hit(n, 0.0), missed(n, 1.0);  // the interval holding the silhouette
    std::vector<char> searching(n, 1);
    for (int round = 0; round < kSearchRounds; ++round) {
      const int last = round == 0 ? kDiscoveryRays : kDiscoveryRays - 1;
      std::vector<HeightRay> rays;
      std::vector<std::size_t> owner;
      for (std::size_t j = 0; j < n; ++j) {
        if (!searching[j]) continue;
        const Silhouette& s = silhouettes_[j];
        for (int i = 1; i <= last; ++i) {
          const double lambda = hit[j] + (missed[j] - hit[j]) * i / kDiscoveryRays;
          const Vec end = s.candidate.target + (s.candidate.target_radius * lambda) * s.direction,
                    span = end - s.candidate.origin;
          Vec origin, direction;
          through(s.candidate.origin, end, 0.0, origin, direction);
          rays.push_back(ray(origin, direction));
          // Only whether the ray meets the object first matters (Sec. 4.4: "the region of
          // interest can be restricted to the bounding volume of the object"): it ends once it is
          // 4 radii past the end across the ground (the end lies within a radius of the hit
          // point, the object within two of it), so a ray that misses the object stops there
          // instead of crossing the field. The same hit or miss as an unbounded ray.
          const double across = std::hypot(span.x, span.y);
          if (across > 0.0) rays.back().t_max = float(1.0 + 4.0 * s.candidate.target_radius / across);
        }
        owner.push_back(j);
      }
      if (rays.empty()) break;
      const detail::RayCasts hits = caster.cast(rays, false);
      out_.rays += rays.size();
      silhouette_rays_ += rays.size();
      const int per = last;
      for (std::size_t o = 0; o < owner.size(); ++o) {
        const std::size_t j = owner[o];
        const Silhouette& s = silhouettes_[j];
        const double low = hit[j], high = missed[j];
        int miss = -1;
        for (int i = 1; i <= last; ++i) {
          const int cell = hits.cell[o * per + (i - 1)];
          if (cell < 0 || out_.layout.tileOfCell(cell) != s.candidate.tile) {
            miss = i;
            break;
          }
        }
        if (miss < 0 && round == 0) {  // every ray hit the object: lambda = 1, no narrowing
          searching[j] = 0;
          continue;
        }
        const int at = miss < 0 ? kDiscoveryRays : miss;  // (later rounds: the known miss)
        hit[j] = low + (high - low) * (at - 1) / kDiscoveryRays;
        missed[j] = low + (high - low) * at / kDiscoveryRays;
      }
    }
    std::size_t next = 0;
    for (Sample& sample : samples) {
      if (sample.distribution != kSilhouetteMutation) continue;
      const Silhouette& s = silhouettes_[next];
      const Vec end = s.candidate.target + (s.candidate.target_radius * missed[next]) * s.direction;
      through(s.candidate.origin, end, 0.5, sample.origin, sample.direction);
      ++next;
    }
    silhouettes_.clear();
  }

  // ---- Folding results in

  // Adds tile `tile` to view cell v with the witness (eye, target) when it is new and the witness
  // passes the exact line-of-sight test; 1 when added. `lineage` is the sample's (Sample::lineage);
  // `uniform` says that the sample is a uniform view ray from v (the pixel error's rays).
  int add(int v, int tile, float ex, float ey, float ez, float tx, float ty, std::uint64_t lineage,
          bool uniform) {
    if (!out_.computed[v]) return 0;
    // Beyond the maximum distance: no sighting (not even of an entry found before, which would take
    // it from the entries found once), and no witness rejected (the sight test's own check, in its
    // float operations).
    const float gx = (tx - ex) * float(cx_), gy = (ty - ey) * float(cy_);
    if (max_d2_ > 0.0f && gx * gx + gy * gy > max_d2_) return 0;
    const std::size_t word = std::size_t(v) * out_.words + tile / 32;
    const std::uint32_t bit = 1u << (tile % 32);
    if (out_.bits[word] & bit) {
      foundAgain(word, bit, std::size_t(v) * out_.layout.tiles() + tile, lineage);
      return 0;
    }
    // The eye into the band over its point (the caster's t puts it there to rounding).
    const float s = surface(ex, ey), tz = surface(tx, ty);
    if (std::isnan(s) || std::isnan(tz)) return 0;
    const float lo = s + float(grid_.band_low), hi = s + float(grid_.band_high);
    ez = ez < lo ? lo : (ez > hi ? hi : ez);
    if (!detail::region_sight_visible(heights_.data(), field_.width, field_.height, float(cx_), float(cy_),
                                      float(curvature_), max_d2_, ex, ey, ez, tx, ty, tz)) {
      ++out_.rejected;
      return 0;
    }
    out_.bits[word] |= bit;
    // (counted as complete() counts: a view cell of sampled_views_, a tile within reach)
    if (!view_cells_[v].empty() && (reach(v, tile / 32) & reachable_tiles_[tile / 32] & bit))
      ++reachable_found_;
    if (uniform) {
      only_finder_[word] |= bit;
      only_finders_[std::size_t(v) * out_.layout.tiles() + tile] = lineage;
    }
    if (options_.witnesses) {
      PvsWitness w;
      w.view_cell = v;
      w.tile = tile;
      w.eye[0] = ex, w.eye[1] = ey, w.eye[2] = ez;
      w.target[0] = tx, w.target[1] = ty, w.target[2] = tz;
      out_.witnesses.push_back(w);
    }
    return 1;
  }

  void batch(detail::RayCaster& caster, int n) {
    std::vector<Sample> samples(n);
    for (int i = 0; i < n; ++i) {
      samples[i] = draw();
      if (samples[i].lineage == 0) samples[i].lineage = out_.samples + std::uint64_t(i) + 1;
    }
    silhouettes(caster, samples);
    const bool global = options_.method != PvsMethod::PerCell;
    std::vector<HeightRay> rays;
    rays.reserve(std::size_t(n) * (global ? 2 : 1));
    for (const Sample& s : samples) {
      rays.push_back(ray(s.origin, s.direction));
      if (global) rays.push_back(ray(s.origin, -1.0 * s.direction));
    }
    const detail::RayCasts r = caster.cast(rays, global);
    out_.rays += rays.size();
    out_.samples += std::uint64_t(n);
    const PvsLayout& l = out_.layout;
    std::vector<double> contribution(kPvsDistributions, 0.0), drawn(kPvsDistributions, 0.0);
    for (int i = 0; i < n; ++i) {
      const Sample& s = samples[i];
      drawn[s.distribution] += 1.0;
      if (!global) {
        const std::size_t k = std::size_t(i);
        const HeightRay& q = rays[k];
        if (r.cell[k] >= 0)
          add(s.view_cell, l.tileOfCell(r.cell[k]), q.ox, q.oy, q.oz, q.ox + r.t[k] * q.dx,
              q.oy + r.t[k] * q.dy, s.lineage, true);
        ++uniform_rays_;
        continue;
      }
      // The segment's two ends: ray k = 2i forward, 2i + 1 reverse.
      int total = 0, end_contribution[2] = {0, 0};
      const int origin_view = l.viewOfCell(std::min(int(s.origin.y / cy_), l.cells_y - 1) * l.cells_x +
                                           std::min(int(s.origin.x / cx_), l.cells_x - 1));
      for (int end = 0; end < 2; ++end) {
        const std::size_t k = 2 * std::size_t(i) + end;
        if (r.cell[k] < 0) continue;
        const int tile = l.tileOfCell(r.cell[k]);
        const HeightRay& q = rays[k];
        const float tx = q.ox + r.t[k] * q.dx, ty = q.oy + r.t[k] * q.dy;
        // The origin's view cell, when the origin lies in view space (the caster may round a
        // point at the band's very edge out of it), then every view cell of both rays' lists:
        // each sees this end through the origin.
        if (s.distribution == kViewDirection || s.distribution == kTwoPoint) {
          const HeightRay& o = rays[2 * std::size_t(i)];
          const int c =
              add(origin_view, tile, o.ox, o.oy, o.oz, tx, ty, s.lineage, s.distribution == kViewDirection);
          end_contribution[end] += c;
          total += c;
        }
        for (int side = 0; side < 2; ++side) {
          const std::size_t m = 2 * std::size_t(i) + side;
          const HeightRay& p = rays[m];
          const detail::ViewCellPoint* list = r.view_cells.data() + r.list_first[m];
          for (int j = 0; j < r.list_count[m]; ++j) {
            const int v = list[j].view_cell;
            const float t = list[j].t;
            // (flat: the float operations of before curvature, so that flat runs add what they did)
            const float ez = curvature_ == 0.0 ? p.oz + t * p.dz : float(heightAt(p, t));
            const int c = add(v, tile, p.ox + t * p.dx, p.oy + t * p.dy, ez, tx, ty, s.lineage, false);
            end_contribution[end] += c;
            total += c;
          }
        }
      }
      if (s.distribution == kViewDirection) uniform_rays_ += 2;
      contribution[s.distribution] += total;
      if (s.distribution == kSilhouetteMutation && !s.follow_up && !settling_) discontinuity(s, rays, r, i);
      // Mutation candidates (Sec. 4.4): each end that contributed, the other end its origin.
      if (options_.method == PvsMethod::Agvs && !settling_)
        for (int end = 0; end < 2; ++end) {
          if (!end_contribution[end]) continue;
          const std::size_t k = 2 * std::size_t(i) + end, o = 2 * std::size_t(i) + 1 - end;
          MutationCandidate c;
          c.target = hitPoint(rays[k], r.t[k]);
          c.tile = l.tileOfCell(r.cell[k]);
          c.lineage = s.lineage;
          c.target_radius = tile_radius_;
          if (r.cell[o] >= 0) {
            c.origin = hitPoint(rays[o], r.t[o]);
            c.origin_radius = tile_radius_;
          } else {
            c.origin = s.origin;
            c.origin_radius = view_radius_;
          }
          mutations_.add(c);
        }
    }
    out_.uniform_rays = uniform_rays_;
    // Never below one entry found once: N rays without one do not tell an error below 1 / N from
    // 0 (so a --pixel-error budget E asks for 1 / E uniform rays at least).
    if (uniform_rays_ > 0)
      out_.pixel_error = options_.resolution * double(std::max<std::size_t>(1, only_finders_.size())) /
                         double(uniform_rays_);
    if (complete()) out_.pixel_error = 0.0;  // (no ray can differ)
    if (options_.method == PvsMethod::Agvs && !settling_) updateMixture(contribution, drawn);
  }

  // Sec. 4.4's depth discontinuity: the silhouette sample's forward ray passed its end (the point
  // just off the object's silhouette, at t = 1/2 from the segment's middle) and hit a surface more
  // than kDiscontinuityRadii object radii beyond it. Instead of searching for the discontinuity
  // itself (Wonka et al. 2006's reverse sampling), the segment from that end to the far hit is
  // queued for a silhouette mutation of its own (drawn before the buffer's candidates), so the
  // samples go along the far object's visible edge behind the silhouette. Only hits beyond the
  // end: a hit before it is an occluder the search's own rays did not meet, not a silhouette.
  void discontinuity(const Sample& s, const std::vector<HeightRay>& rays, const detail::RayCasts& r, int i) {
    const std::size_t k = 2 * std::size_t(i);
    if (r.cell[k] < 0 || !(r.t[k] > 0.5f)) return;
    const Vec end = along(s.origin, s.direction, 0.5), hit = hitPoint(rays[k], r.t[k]), gap = hit - end;
    if (!(dot(gap, gap) > kDiscontinuityRadii * kDiscontinuityRadii * tile_radius_ * tile_radius_)) return;
    MutationCandidate c;
    c.origin = end;
    c.target = hit;
    c.origin_radius = c.target_radius = tile_radius_;
    c.tile = out_.layout.tileOfCell(r.cell[k]);
    c.lineage = s.lineage;
    discontinuities_.push_back(c);
  }

  Vec hitPoint(const HeightRay& q, float t) const {
    const double x = q.ox + double(t) * q.dx, y = q.oy + double(t) * q.dy;
    return ground(x, y, heightAt(q, t));
  }

  // Sec. 4.5's pixel error, estimated by leaving one sample out: a uniform view ray (the
  // view-direction samples, and every per-cell sample) from view cell v that hits tile t would
  // be a wrong pixel for the sets without it exactly when its (v, t) is in them only through it.
  // So the error of the sets now is estimated by the entries that one such ray added and no other
  // sample has found since (Good-Turing's missing mass), over all uniform rays of the run, the
  // early ones included: each is checked against the sets now, so the estimate is of the sets
  // now, not of when it was cast (Eq. 5's window of the newest rays estimated the sets' past: up
  // to 9x the measured error where it fell fast; bench/report/pvs.md). Found again means by a
  // sample not descending from the finder by mutation (a mutation of it exists only because it
  // was cast).
  void foundAgain(std::size_t word, std::uint32_t bit, std::size_t entry, std::uint64_t lineage) {
    if (!(only_finder_[word] & bit)) return;
    const auto found = only_finders_.find(entry);
    if (found->second == lineage) return;
    only_finders_.erase(found);
    only_finder_[word] &= ~bit;
  }

  // Sec. 4.2 with the window one batch: weight = contribution per sample per cost, the cost
  // counted in rays (a silhouette mutation casts its discovery rays more: silhouette_rays_ over
  // the batch's), so that a seed reproduces the run exactly (a wall-clock cost would not).
  void updateMixture(const std::vector<double>& contribution, const std::vector<double>& drawn) {
    std::vector<double> weight(kPvsDistributions, 0.0);
    double sum = 0.0;
    for (int d = 0; d < kPvsDistributions; ++d) {
      const bool available = d < kTwoPointMutation || !mutations_.empty();
      if (!available) continue;
      const double cost =
          d == kSilhouetteMutation && drawn[d] > 0.0 ? 2.0 + double(silhouette_rays_) / drawn[d] : 2.0;
      // A distribution not drawn this batch keeps its last weight.
      weight[d] = drawn[d] > 0.0 ? contribution[d] / drawn[d] / cost : last_weight_[d];
      if (!(weight[d] > 0.0)) weight[d] = 1e-12;
      last_weight_[d] = weight[d];
      sum += weight[d];
    }
    int available = 0;
    for (int d = 0; d < kPvsDistributions; ++d) available += weight[d] > 0.0;
    for (int d = 0; d < kPvsDistributions; ++d)
      probability_[d] =
          weight[d] > 0.0 ? kMinProbability + (1.0 - kMinProbability * available) * weight[d] / sum : 0.0;
    if (probability_[kViewDirection] < kMinViewDirection) {
      const double others = 1.0 - probability_[kViewDirection];
      for (int d = 0; d < kPvsDistributions; ++d)
        if (d != kViewDirection) probability_[d] *= (1.0 - kMinViewDirection) / others;
      probability_[kViewDirection] = kMinViewDirection;
    }
  }

  // Sec. 5's filters, both from the sampled sets: what they add is counted in PvsResult::filtered.
  void filters() {
    const std::vector<std::uint32_t> sampled = out_.bits;
    if (options_.filter > 0.0) objectFilter(sampled);
    if (options_.view_filter > 0) viewFilter(sampled);
    out_.filtered = 0;
    for (std::size_t i = 0; i < sampled.size(); ++i)
      out_.filtered += __builtin_popcount(out_.bits[i] & ~sampled[i]);
  }

  // Sec. 5's object-space filter with the global extension e = k 2 d / sqrt(n): n the run's
  // samples per sampled view cell, d the distance between the view cell's and the tile's centres;
  // every tile within e of a visible tile is added (no witness), if it has a surface (a tile whose
  // every cell has a nodata corner is no object). Tiles adjoin, so any e > 0 reaches the ring
  // around a tile: the paper's local extension (at most the tile's radius over the root of the
  // samples that hit it) would cap e below a tile's width for k < sqrt 2, where it already adds
  // one ring, and is not built.
  void objectFilter(const std::vector<std::uint32_t>& sampled) {
    const PvsLayout& l = out_.layout;
    const double samples_per_cell =
        double(out_.samples) / double(std::max<std::size_t>(1, sampled_views_.size()));
    for (int v = 0; v < l.viewCells(); ++v) {
      if (!out_.computed[v]) continue;
      const double vx = ((v % l.view_x) + 0.5) * l.view_cell * cx_,
                   vy = ((v / l.view_x) + 0.5) * l.view_cell * cy_;
      for (int t = 0; t < l.tiles(); ++t) {
        if (!((sampled[std::size_t(v) * out_.words + t / 32] >> (t % 32)) & 1u)) continue;
        const double tx = ((t % l.tiles_x) + 0.5) * l.tile * cx_, ty = ((t / l.tiles_x) + 0.5) * l.tile * cy_;
        const double e = options_.filter * 2.0 * std::hypot(tx - vx, ty - vy) / std::sqrt(samples_per_cell);
        const int rx = int(std::ceil(e / (l.tile * cx_))), ry = int(std::ceil(e / (l.tile * cy_)));
        for (int y = std::max(0, t / l.tiles_x - ry); y <= std::min(l.tiles_y - 1, t / l.tiles_x + ry); ++y)
          for (int x = std::max(0, t % l.tiles_x - rx); x <= std::min(l.tiles_x - 1, t % l.tiles_x + rx);
               ++x) {
            const int u = y * l.tiles_x + x;
            if (!tile_cells_[u].empty() && (reach(v, u / 32) >> (u % 32)) & 1u)
              out_.bits[std::size_t(v) * out_.words + u / 32] |= 1u << (u % 32);
          }
      }
    }
  }

  // Sec. 5's view-space filter: each computed view cell takes the sampled sets of the
  // view_filter computed neighbours (of its 8) whose sampled sets are the most like its own by
  // Jaccard's index (shared entries over the union's; ties to the lower index; neighbours with
  // no entries in common are not taken).
  void viewFilter(const std::vector<std::uint32_t>& sampled) {
    const PvsLayout& l = out_.layout;
    const int words = out_.words;
    for (int v = 0; v < l.viewCells(); ++v) {
      if (!out_.computed[v]) continue;
      std::vector<std::pair<double, int>> like;  // (- similarity, neighbour)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          const int x = v % l.view_x + dx, y = v / l.view_x + dy, u = y * l.view_x + x;
          if ((dx == 0 && dy == 0) || x < 0 || y < 0 || x >= l.view_x || y >= l.view_y || !out_.computed[u])
            continue;
          std::size_t both = 0, either = 0;
          for (int w = 0; w < words; ++w) {
            const std::uint32_t a = sampled[std::size_t(v) * words + w],
                                b = sampled[std::size_t(u) * words + w];
            both += __builtin_popcount(a & b);
            either += __builtin_popcount(a | b);
          }
          if (both > 0) like.push_back({-double(both) / double(either), u});
        }
      std::sort(like.begin(), like.end());
      for (std::size_t i = 0; i < like.size() && int(i) < options_.view_filter; ++i)
        for (int w = 0; w < words; ++w)
          out_.bits[std::size_t(v) * words + w] |=
              sampled[std::size_t(like[i].second) * words + w] & reach(v, w);
    }
  }

  struct Silhouette {
    MutationCandidate candidate;
    Vec direction;
  };

  const HeightField& field_;
  const PvsGrid& grid_;
  const PvsOptions& options_;
  PvsResult& out_;
  Random random_;
  std::vector<float> heights_;
  double cx_ = 1, cy_ = 1, tile_radius_ = 0, view_radius_ = 0;
  double curvature_ = 0;  // PvsOptions::curvature
  std::vector<std::vector<int>> view_cells_, tile_cells_;
  std::vector<int> view_space_, sampled_views_, objects_;
  std::size_t per_cell_next_ = 0;
  std::vector<double> probability_;
  double last_weight_[kPvsDistributions] = {0, 0, 0, 0, 0};
  MutationBuffer mutations_;
  std::vector<Silhouette> silhouettes_;
  std::size_t silhouette_rays_ = 0;                // the discovery rays of this batch's silhouette mutations
  std::deque<MutationCandidate> discontinuities_;  // Sec. 4.4's depth discontinuities, to mutate next
  std::uint64_t uniform_rays_ = 0;  // uniform view rays cast so far (foundAgain)
  bool settling_ = false;           // settle(): view-direction samples alone
  double settle_seconds_ = 0.0;     // the time settle() took
  std::vector<std::uint32_t> reachable_tiles_;  // the tiles with a surface (objects_), a bit each
  // Per view cell (words of tiles), the tiles within the maximum distance (reach(); empty: all)
  std::vector<std::uint32_t> in_reach_;
  std::size_t reachable_ = 0;  // the entries a sample can find: sampled_views_ x objects_ within reach
  std::size_t reachable_found_ = 0;  // those of them in the sets (counted as add() finds them)
  float max_d2_ = 0.0f;        // the maximum distance squared (float, as the sight test takes it); 0: none
  // The entries only one uniform view ray has found (foundAgain): a bit per entry as out_.bits,
  // and the finder's lineage by entry (v * tiles + t).
  std::vector<std::uint32_t> only_finder_;
  std::unordered_map<std::size_t, std::uint64_t> only_finders_;
};

}  // namespace

const char* pvsDistributionName(int index) {
  static const char* names[kPvsDistributions] = {"view-direction", "object-direction", "two-point",
                                                 "two-point-mutation", "silhouette-mutation"};
  return index >= 0 && index < kPvsDistributions ? names[index] : "";
}

void validate(const PvsOptions& options) {
  // (an enum value cast from a bad integer ran as one of them)
  if (options.method != PvsMethod::Agvs && options.method != PvsMethod::Sgvs &&
      options.method != PvsMethod::PerCell)
    throw InvalidArgument("unknown PVS method " + std::to_string(static_cast<int>(options.method)));
  if (!std::isfinite(options.pixel_error) || options.pixel_error < 0.0 || !std::isfinite(options.seconds) ||
      options.seconds < 0.0)
    throw InvalidArgument("the pixel error and seconds budgets must be finite and >= 0");
  if (options.samples == 0 && options.pixel_error == 0.0 && options.seconds == 0.0)
    throw InvalidArgument("a PVS run needs a budget above 0: samples, pixel error or seconds");
  // The estimate never falls below one entry found once (resolution / uniform rays): a pixel
  // error alone that asks for more uniform rays than days of casting is refused, not run.
  if (options.pixel_error > 0.0 && options.samples == 0 && options.seconds == 0.0 &&
      options.resolution / options.pixel_error > kMaxPixelErrorRays) {
    std::ostringstream message;
    message << "a pixel error of " << options.pixel_error << " asks for at least "
            << options.resolution / options.pixel_error
            << " uniform rays (the estimate is at least " << options.resolution
            << " over the uniform rays cast), more than " << kMaxPixelErrorRays
            << ": ask for a larger error, or give a samples or seconds budget as well";
    throw InvalidArgument(message.str());
  }
  if (options.batch < 1) throw InvalidArgument("the batch must hold at least 1 sample");
  if (!std::isfinite(options.filter) || options.filter < 0.0)
    throw InvalidArgument("the visibility filter's k must be finite and >= 0");
  if (options.view_filter < 0 || options.view_filter > 8)
    throw InvalidArgument("the view-space filter takes 0 .. 8 neighbouring view cells, not " +
                          std::to_string(options.view_filter));
  if (!std::isfinite(options.resolution) || options.resolution < 1.0)
    throw InvalidArgument("the pixel error's resolution must be at least 1 ray");
  detail::validateCurvature(options.curvature, "the curvature");
  if (!std::isfinite(options.max_distance) || options.max_distance < 0.0 ||
      (options.max_distance > 0.0 && options.max_distance < kLeastMaxDistance))
    throw InvalidArgument("the maximum distance must be 0 (none) or a finite length of at least " +
                          detail::shortNumber(kLeastMaxDistance) + " (got " +
                          detail::shortNumber(options.max_distance) + ")");
}

PvsResult computePvs(const ComputeContext& context, const HeightField& field, const PvsGrid& grid,
                     const PvsOptions& options) {
  validate(options);
  PvsResult out;
  Sampler sampler(field, grid, options, out);
  detail::withRayCaster(context, field, grid, options.curvature, options.memory_budget_bytes,
                        [&](detail::RayCaster& caster) { sampler.run(caster); });
  return out;
}

}  // namespace hfvis
