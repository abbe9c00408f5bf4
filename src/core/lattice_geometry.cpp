// lattice_geometry.cpp: direction sets, per-period sample tables and line tables of the
// receiver-exact horizon sweep (see lattice_geometry.hpp).
#include "core/lattice_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <mutex>
#include <numeric>
#include <optional>
#include <sstream>

#include "hfvis/errors.hpp"

namespace hfvis::detail {
namespace {

constexpr double kTwoPi = 2.0 * M_PI;

}  // namespace

double angleDifference(double x, double y) {
  double d = std::fmod(x - y, kTwoPi);
  if (d > M_PI) d -= kTwoPi;
  if (d <= -M_PI) d += kTwoPi;
  return d;
}

namespace {

// A coordinate a crossing puts on a grid line, snapped onto it (its rounding undone).
double snapped(double v) { return std::abs(v - std::round(v)) < 1e-9 ? std::round(v) : v; }

struct Candidate {
  int a, b;
  int cost;        // crossings of one period: |a| + |b| - 1, or 1 on the axes
  double azimuth;  // ground azimuth
};

// Every primitive step with |a|, |b| <= kMaxLatticeStep, cheapest first (ties: shorter
// period first, then a fixed order, so the choice is deterministic).
std::vector<Candidate> allCandidates(double cell_size_x, double cell_size_y) {
  std::vector<Candidate> all;
  for (int a = -kMaxLatticeStep; a <= kMaxLatticeStep; ++a) {
    for (int b = -kMaxLatticeStep; b <= kMaxLatticeStep; ++b) {
      if (std::gcd(a, b) != 1) continue;
      const int cost = (a != 0 && b != 0) ? std::abs(a) + std::abs(b) - 1 : 1;
      all.push_back({a, b, cost, std::atan2(b * cell_size_y, a * cell_size_x)});
    }
  }
  std::stable_sort(all.begin(), all.end(), [](const Candidate& x, const Candidate& y) {
    if (x.cost != y.cost) return x.cost < y.cost;
    return x.a * x.a + x.b * x.b < y.a * y.a + y.b * y.b;
  });
  return all;
}

// allCandidates for the field's cell size, kept for the last 8 cell sizes first asked (the oldest
// dropped): about 10,000 steps, an atan2 each and a sort, about a millisecond, which every run's
// direction set and each K that max_error's chooser weighs (horizonWork) would pay again (several
// times a small run's own sweep at 128^2).
std::shared_ptr<const std::vector<Candidate>> candidates(const HeightField& field) {
  using Key = std::pair<double, double>;
  static std::mutex mutex;
  static std::vector<std::pair<Key, std::shared_ptr<const std::vector<Candidate>>>> kept;
  const Key key{field.cell_size_x, field.cell_size_y};
  {
    std::lock_guard<std::mutex> lock(mutex);
    for (const auto& [k, list] : kept)
      if (k == key) return list;
  }
  auto list = std::make_shared<const std::vector<Candidate>>(allCandidates(key.first, key.second));
  std::lock_guard<std::mutex> lock(mutex);
  if (kept.size() >= 8) kept.erase(kept.begin());
  kept.emplace_back(key, list);
  return list;
}

// A single direction at an exact azimuth (the sun's sweeps) where no step up to kMaxLatticeStep is
// within `tolerance` of `target`: the cheapest primitive step of up to kMaxExactStep pixels along
// its major axis that is; none when none is. For each major length, the minor one nearest the
// target's slope; a step's cost grows with its major length, so the first one within wins.
std::optional<Candidate> longStep(const HeightField& field, double target, double tolerance) {
  // The target's direction in pixels: ground (cos, sin) over the cell sizes.
  const double px = std::cos(target) / field.cell_size_x, py = std::sin(target) / field.cell_size_y;
  const bool x_major = std::fabs(px) >= std::fabs(py);
  const double slope = x_major ? std::fabs(py / px) : std::fabs(px / py);
  const int sx = px < 0.0 ? -1 : 1, sy = py < 0.0 ? -1 : 1;
  for (int major = 1; major <= kMaxExactStep; ++major) {
    const int minor = static_cast<int>(std::lround(major * slope));
    if (std::gcd(major, minor) != 1) continue;  // its reduced step came earlier
    const int a = sx * (x_major ? major : minor), b = sy * (x_major ? minor : major);
    const double azimuth = std::atan2(b * field.cell_size_y, a * field.cell_size_x);
    if (std::abs(angleDifference(azimuth, target)) <= tolerance)
      return Candidate{a, b, (a != 0 && b != 0) ? std::abs(a) + std::abs(b) - 1 : 1, azimuth};
  }
  return std::nullopt;
}

LatticeDirection makeDirection(const HeightField& field, const Candidate& c) {
  LatticeDirection d;
  d.a = c.a;
  d.b = c.b;
  d.azimuth = c.azimuth;
  d.period = std::hypot(double(c.a), double(c.b));
  d.ground_per_pixel = std::hypot(c.a * field.cell_size_x, c.b * field.cell_size_y) / d.period;
  return d;
}

// The sample at fraction f of the period from the receiver toward +(a, b).
LatticeSample sampleAt(const LatticeDirection& d, double f) {
  // Offsets from the receiver; crossings fall exactly on grid lines (snap the rounding).
  const double x = snapped(d.a * f), y = snapped(d.b * f);
  const double ox = std::floor(x), oy = std::floor(y);
  const float fx = static_cast<float>(x - ox), fy = static_cast<float>(y - oy);
  LatticeSample s;
  s.tau = static_cast<float>(f * d.period);
  s.ox = static_cast<std::int32_t>(ox);
  s.oy = static_cast<std::int32_t>(oy);
  s.ex = fx > 0.0f;
  s.ey = fy > 0.0f;
  s.w00 = (1.0f - fx) * (1.0f - fy);
  s.w10 = fx * (1.0f - fy);
  s.w01 = (1.0f - fx) * fy;
  s.w11 = fx * fy;
  return s;
}

}  // namespace

LatticeDirection latticeStep(const HeightField& field, int a, int b) {
  return makeDirection(field, {a, b, 0, std::atan2(b * field.cell_size_y, a * field.cell_size_x)});
}

std::vector<LatticeDirection> latticeDirections(const HeightField& field, const SweepOptions& options,
                                                bool exact_azimuths, double tolerance, bool parity_apart) {
  const std::shared_ptr<const std::vector<Candidate>> kept = candidates(field);
  const std::vector<Candidate>& all = *kept;
  const int K = options.directions;
  // Quadrature windows are strictly inside each direction's half-spacing.
  const double window = exact_azimuths ? tolerance : 0.4999 * kTwoPi / K;
  std::vector<LatticeDirection> out;
  for (int k = 0; k < K; ++k) {
    const double target = directionAzimuth(k, options);
    // The cheapest cost class with a step inside the window, and in it the closest step;
    // the closest of all when none is inside.
    const Candidate *chosen = nullptr, *closest = nullptr;
    double chosen_error = 0.0, closest_error = 0.0;
    for (const Candidate& c : all) {
      if (chosen && c.cost > chosen->cost) break;
      const double error = std::abs(angleDifference(c.azimuth, target));
      if (error <= window && (!chosen || error < chosen_error)) chosen = &c, chosen_error = error;
      if (!closest || error < closest_error) closest = &c, closest_error = error;
    }
    std::optional<Candidate> longer;
    if (!chosen && exact_azimuths && K == 1) longer = longStep(field, target, window);
    out.push_back(makeDirection(field, chosen ? *chosen : longer ? *longer : *closest));
    out.back().azimuth = target + angleDifference(out.back().azimuth, target);  // next to phi_k
  }
  if (exact_azimuths || K == 1) {
    for (auto& d : out) d.weight = 1.0 / K;
    return out;
  }
  setQuadratureWeights(out, parity_apart);
  return out;
}

std::vector<double> halfGapWeights(const std::vector<double>& azimuths) {
  const int K = static_cast<int>(azimuths.size());
  std::vector<double> weights(K, 1.0);
  if (K == 1) return weights;
  for (int k = 0; k < K; ++k) {
    double gap_before = angleDifference(azimuths[k], azimuths[(k + K - 1) % K]),
           gap_after = angleDifference(azimuths[(k + 1) % K], azimuths[k]);
    if (K == 2) gap_before = gap_after = M_PI;
    weights[k] = 0.5 * (gap_before + gap_after) / kTwoPi;
  }
  return weights;
}

void setQuadratureWeights(std::vector<LatticeDirection>& directions, bool parity_apart) {
  std::vector<double> azimuths;
  for (const LatticeDirection& d : directions) azimuths.push_back(d.azimuth);
  const std::vector<double> weights = halfGapWeights(azimuths);
  const std::size_t K = directions.size();
  for (std::size_t k = 0; k < K; ++k) directions[k].weight = weights[k];
  // Coinciding neighbours share their half gaps unevenly (the run's inner ones get none); for the
  // error estimate's halves every slot of a run takes an equal share, so that each parity keeps
  // the share of the circle its azimuths stand for. Runs are circular: the one on the axis at
  // azimuth 0 ends at k = K - 1 and goes on at k = 0, so the scan starts where a run starts.
  const auto same = [&](std::size_t i, std::size_t j) {
    return directions[i].a == directions[j].a && directions[i].b == directions[j].b;
  };
  std::size_t start = 0;
  while (parity_apart && start < K && same(start, (start + K - 1) % K)) ++start;
  if (start == K) start = 0;  // one step all around
  for (std::size_t n = 0; parity_apart && n < K;) {
    const std::size_t k = (start + n) % K;
    std::size_t length = 1;
    double total = directions[k].weight;
    for (; n + length < K && same((k + length) % K, k); ++length)
      total += directions[(k + length) % K].weight;
    for (std::size_t i = 0; i < length; ++i) directions[(k + i) % K].weight = total / double(length);
    n += length;
  }
  // Where no step lies inside a window (K beyond the lattice's angular resolution near
  // the axes: atan(1/64) = 0.9 deg) neighbours can fall back to the same step: the first
  // one takes their weight and the others get 0, so the sweep runs each step once.
  for (std::size_t k = 1; k < K; ++k) {
    for (std::size_t m = parity_apart ? k % 2 : 0; m < k; m += parity_apart ? 2 : 1) {
      if (directions[m].a == directions[k].a && directions[m].b == directions[k].b && directions[m].weight > 0.0) {
        directions[m].weight += directions[k].weight;
        directions[k].weight = 0.0;
        break;
      }
    }
  }
}

namespace {

// The fractions of the period at which the horizon sweep's samples of direction d lie,
// farthest first, the receiver's 0 last (latticeSamples).
std::vector<double> sampleFractions(const LatticeDirection& d, double samples_per_unit) {
  // Crossings as fractions of the period: columns at i / |a|, rows at j / |b|.
  std::vector<double> crossings = {0.0, 1.0};
  for (int i = 1; i < std::abs(d.a); ++i) crossings.push_back(double(i) / std::abs(d.a));
  for (int j = 1; j < std::abs(d.b); ++j) crossings.push_back(double(j) / std::abs(d.b));
  std::sort(crossings.begin(), crossings.end());
  std::vector<double> fractions;  // the receiver's 0 included, the next receiver's 1 not
  // Along a grid line the bilinear surface is linear between pixel centres: the centres are
  // the whole surface's hull there, and points between them would only add ties.
  const bool along_grid_line = d.a == 0 || d.b == 0;
  if (along_grid_line) fractions.push_back(0.0);
  for (std::size_t q = 0; q + 1 < crossings.size() && !along_grid_line; ++q) {
    const double span = crossings[q + 1] - crossings[q];
    const int parts = std::max(1, static_cast<int>(std::lround(samples_per_unit * span * d.period)));
    for (int s = 0; s < parts; ++s) fractions.push_back(crossings[q] + span * s / parts);
  }
  std::reverse(fractions.begin(), fractions.end());
  return fractions;
}

}  // namespace

std::vector<LatticeSample> latticeSamples(const LatticeDirection& d, double samples_per_unit) {
  std::vector<LatticeSample> samples;
  for (double f : sampleFractions(d, samples_per_unit)) samples.push_back(sampleAt(d, f));
  return samples;
}

std::vector<CellSegment> cellSegments(const LatticeDirection& d, double samples_per_unit) {
  const std::vector<double> fractions = sampleFractions(d, samples_per_unit);
  std::vector<CellSegment> segments;
  // The corners a sample reads itself (lane_sample_height): a crossing or a receiver the two at
  // (ox, oy) and (ox + ex, oy + ey); a sample inside a cell none that it passes on.
  using Corner = std::pair<int, int>;
  auto cornersOf = [&](const LatticeSample& s, int shift_x, int shift_y) {
    if (s.ex + s.ey == 2) return std::vector<Corner>{{INT32_MIN, INT32_MIN}, {INT32_MIN, INT32_MIN}};
    return std::vector<Corner>{{s.ox + shift_x, s.oy + shift_y}, {s.ox + s.ex + shift_x, s.oy + s.ey + shift_y}};
  };
  // Segment 0's far end is the next receiver along +(a, b): the last sample of the period
  // before, whose receiver sits (a, b) from this one.
  std::vector<Corner> far_corners = cornersOf(sampleAt(d, 0.0), d.a, d.b);
  double far = 1.0;
  for (double near : fractions) {
    const LatticeSample near_sample = sampleAt(d, near);
    const std::vector<Corner> near_corners = cornersOf(near_sample, 0, 0);
    CellSegment g{};
    g.tau_far = static_cast<float>(far * d.period);
    g.tau_near = near_sample.tau;
    // The cell holds the piece's middle (its ends may lie on the cell's edges).
    const double mx = d.a * 0.5 * (far + near), my = d.b * 0.5 * (far + near);
    const double ox = std::floor(mx), oy = std::floor(my);
    g.ox = static_cast<std::int32_t>(ox);
    g.oy = static_cast<std::int32_t>(oy);
    g.fx = static_cast<float>(d.a * far - ox);
    g.fy = static_cast<float>(d.b * far - oy);
    g.dx = static_cast<float>(d.a * (near - far));
    g.dy = static_cast<float>(d.b * (near - far));
    g.curved = d.a != 0 && d.b != 0;  // along a grid line the surface is linear
    auto from = [&](int cx, int cy) {
      const Corner corner{g.ox + cx, g.oy + cy};
      for (int k = 0; k < 2; ++k)
        if (far_corners[k] == corner) return k;
      for (int k = 0; k < 2; ++k)
        if (near_corners[k] == corner) return 2 + k;
      return 4;
    };
    g.from00 = from(0, 0);
    g.from10 = from(1, 0);
    g.from01 = from(0, 1);
    g.from11 = from(1, 1);
    segments.push_back(g);
    far = near;
    far_corners = near_corners;
  }
  return segments;
}

std::size_t stackEntriesPerPeriod(const std::vector<CellSegment>& segments) {
  std::size_t entries = segments.size();
  for (const CellSegment& g : segments) entries += g.curved != 0;
  return entries;
}

int samplesPerPeriod(const LatticeDirection& d, double samples_per_unit) {
  return std::max(1, static_cast<int>(std::ceil(d.period * samples_per_unit - 1e-9)));
}

std::vector<LatticeSample> uniformLatticeSamples(const LatticeDirection& d, int per_period) {
  std::vector<LatticeSample> samples;
  for (int q = per_period - 1; q >= 0; --q) samples.push_back(sampleAt(d, double(q) / per_period));
  return samples;
}

namespace {

// A piece in the cell whose lower corner is (ox, oy): its far end at (x_far, y_far), its change
// (dx, dy) to the near end, where its ends lie in the interval, and the interval's length it spans.
TreePiece treePiece(double ox, double oy, double x_far, double y_far, double dx, double dy, double t_far,
                    double t_near, double span, bool far_crossing) {
  TreePiece g{};
  g.ox = static_cast<std::int32_t>(ox);
  g.oy = static_cast<std::int32_t>(oy);
  g.fx = static_cast<float>(snapped(x_far) - ox);
  g.fy = static_cast<float>(snapped(y_far) - oy);
  g.dx = static_cast<float>(dx);
  g.dy = static_cast<float>(dy);
  g.t_far = static_cast<float>(t_far);
  g.t_near = static_cast<float>(t_near);
  g.inv_span = static_cast<float>(1.0 / span);
  g.far_crossing = far_crossing;
  return g;
}

}  // namespace

TreeIntervals treeIntervals(const LatticeDirection& d, int per_period) {
  TreeIntervals out;
  const bool along_grid_line = d.a == 0 || d.b == 0;
  for (int q = 0; q < per_period; ++q) {
    out.first.push_back(static_cast<std::int32_t>(out.pieces.size()));
    if (along_grid_line) continue;
    // Interval q runs from fraction f_far of the period down to f_near (its samples'), and is
    // cut where it crosses a column (i / |a|) or a row (j / |b|) strictly between them.
    const double f_near = double(per_period - 1 - q) / per_period,
                 f_far = double(per_period - q) / per_period;
    std::vector<double> cuts = {f_far};
    for (int i = 1; i < std::abs(d.a); ++i) cuts.push_back(double(i) / std::abs(d.a));
    for (int i = 1; i < std::abs(d.b); ++i) cuts.push_back(double(i) / std::abs(d.b));
    cuts.erase(std::remove_if(cuts.begin() + 1, cuts.end(),
                              [&](double f) { return !(f < f_far - 1e-12 && f > f_near + 1e-12); }),
               cuts.end());
    std::sort(cuts.begin(), cuts.end(), std::greater<double>());
    cuts.push_back(f_near);
    for (std::size_t k = 0; k + 1 < cuts.size(); ++k) {
      const double far = cuts[k], near = cuts[k + 1];
      const double ox = std::floor(d.a * 0.5 * (far + near)), oy = std::floor(d.b * 0.5 * (far + near));
      out.pieces.push_back(treePiece(ox, oy, d.a * far, d.b * far, d.a * (near - far), d.b * (near - far),
                                     (f_far - far) * per_period, (f_far - near) * per_period,
                                     (far - near) * per_period, k > 0));
    }
  }
  out.first.push_back(static_cast<std::int32_t>(out.pieces.size()));
  return out;
}

std::vector<TreePiece> segmentTreePieces(double x_far, double y_far, double x_near, double y_near, int width,
                                         int height) {
  // The cuts by their parameter t along the segment (0 at the far end, 1 at the near one).
  std::vector<double> cuts;
  auto cross = [&](double from, double to) {
    if (from == to) return;
    for (double g = std::floor(std::min(from, to)) + 1.0; g < std::max(from, to); ++g)
      cuts.push_back((g - from) / (to - from));
  };
  cross(x_far, x_near);
  cross(y_far, y_near);
  std::sort(cuts.begin(), cuts.end());
  std::vector<double> ends = {0.0};  // a vertex is a column and a row crossing at once: one cut
  for (double t : cuts)
    if (t > ends.back() + 1e-9 && t < 1.0 - 1e-9) ends.push_back(t);
  ends.push_back(1.0);
  std::vector<TreePiece> pieces;
  const double ex = x_near - x_far, ey = y_near - y_far;
  for (std::size_t k = 0; k + 1 < ends.size(); ++k) {
    const double t_far = ends[k], t_near = ends[k + 1];
    const double xf = x_far + t_far * ex, yf = y_far + t_far * ey;
    const double xm = x_far + 0.5 * (t_far + t_near) * ex, ym = y_far + 0.5 * (t_far + t_near) * ey;
    const double ox = std::clamp(std::floor(xm), 0.0, double(width - 2));
    const double oy = std::clamp(std::floor(ym), 0.0, double(height - 2));
    pieces.push_back(treePiece(ox, oy, xf, yf, (t_near - t_far) * ex, (t_near - t_far) * ey, t_far, t_near,
                               t_near - t_far, k > 0));
  }
  return pieces;
}

std::vector<LatticeLine> latticeLines(const LatticeDirection& d, int width, int height) {
  // Each line with a receiver has exactly one farthest receiver: a pixel whose next step
  // (c + a, r + b) leaves the field. Those lie in a band |a| columns wide at the far column
  // edge and |b| rows high at the far row edge.
  auto outside = [&](long c, long r) { return c < 0 || c >= width || r < 0 || r >= height; };
  auto receivers = [&](long c, long r) {
    // Steps back (c - m a, r - m b) that stay inside: m <= c / a for a > 0, and so on.
    long m = std::numeric_limits<long>::max();
    if (d.a > 0) m = std::min(m, c / d.a);
    if (d.a < 0) m = std::min(m, (width - 1 - c) / -d.a);
    if (d.b > 0) m = std::min(m, r / d.b);
    if (d.b < 0) m = std::min(m, (height - 1 - r) / -d.b);
    return m + 1;
  };
  std::vector<LatticeLine> lines;
  auto add = [&](int c, int r) { lines.push_back({c, r, static_cast<std::int32_t>(receivers(c, r)), 0}); };
  for (int r = 0; r < height; ++r) {
    if (outside(0, long(r) + d.b)) {  // the whole row is in the row band
      for (int c = 0; c < width; ++c) add(c, r);
    } else if (d.a > 0) {
      for (int c = std::max(0, width - d.a); c < width; ++c) add(c, r);
    } else if (d.a < 0) {
      for (int c = 0; c < std::min(width, -d.a); ++c) add(c, r);
    }
  }
  return lines;
}

int receiverIndex(const HeightField& field, int a, int b, int col, int row) {
  const FieldOrigin& o = field.origin;
  const int width = o.present() ? o.whole_width : field.width, height = o.present() ? o.whole_height : field.height;
  const int c = col + o.col, r = row + o.row;
  int m = std::numeric_limits<int>::max();
  if (a > 0) m = std::min(m, (width - 1 - c) / a);
  if (a < 0) m = std::min(m, c / -a);
  if (b > 0) m = std::min(m, (height - 1 - r) / b);
  if (b < 0) m = std::min(m, r / -b);
  return m;
}

std::pair<int, int> receiversInRows(const LatticeLine& line, int b, int first_row, int end_row) {
  // Receiver i sits in row line.row - i b.
  auto floorDiv = [](long x, long y) { return x / y - ((x % y != 0) && ((x < 0) != (y < 0))); };
  long lo = 0, hi = line.receivers;  // [lo, hi)
  if (b == 0) {
    if (line.row < first_row || line.row >= end_row) hi = 0;
  } else if (b > 0) {  // rows fall as i grows: row - i b < end_row and >= first_row
    lo = std::max(lo, floorDiv(long(line.row) - end_row, b) + 1);
    hi = std::min(hi, floorDiv(long(line.row) - first_row, b) + 1);
  } else {  // rows rise: row + i |b| >= first_row and < end_row
    lo = std::max(lo, -floorDiv(long(line.row) - first_row, -b));  // ceil((first_row - row) / |b|)
    hi = std::min(hi, floorDiv(long(end_row) - 1 - line.row, -b) + 1);
  }
  if (hi < lo) hi = lo;
  return {static_cast<int>(lo), static_cast<int>(hi)};
}

std::size_t lineCapacity(const LatticeLine& line, std::size_t samples_per_period) {
  return static_cast<std::size_t>(line.receivers) * samples_per_period;
}

std::vector<LineChunk> chunkLines(std::vector<LatticeLine>& lines, std::size_t samples_per_period,
                                  std::size_t max_entries, bool line_major, std::size_t align) {
  std::vector<std::size_t> capacities;
  capacities.reserve(lines.size());
  for (const LatticeLine& line : lines) capacities.push_back(lineCapacity(line, samples_per_period));
  return chunkLines(lines, capacities, max_entries, line_major, align);
}

std::vector<LineChunk> chunkLines(std::vector<LatticeLine>& lines, const std::vector<std::size_t>& capacities,
                                  std::size_t max_entries, bool line_major, std::size_t align) {
  std::vector<LineChunk> chunks;
  LineChunk chunk;
  std::size_t longest = 0;  // largest capacity in the chunk (step-major)
  auto close = [&] {
    if (chunk.count == 0) return;
    chunk.stack_entries = line_major ? chunk.stack_entries : longest * chunk.count;
    chunk.stride = line_major ? 1u : static_cast<std::uint32_t>(chunk.count);
    if (!line_major)
      for (std::size_t j = 0; j < chunk.count; ++j)
        lines[chunk.first + j].stack = static_cast<std::int32_t>(j);
    chunks.push_back(chunk);
  };
  for (std::size_t j = 0; j < lines.size(); ++j) {
    // A chunk may close before the `align` lines from j (all of them must fit).
    std::size_t capacity = 0, count = 0;
    if (j % align == 0) {
      for (std::size_t u = j; u < std::min(lines.size(), j + align); ++u) {
        capacity = line_major ? capacity + capacities[u] : std::max(capacity, capacities[u]);
        ++count;
      }
    }
    const std::size_t need =
        line_major ? chunk.stack_entries + capacity : std::max(longest, capacity) * (chunk.count + count);
    if (count > 0 && chunk.count > 0 && (need > max_entries || need >= (std::size_t(1) << 31))) {
      close();
      chunk = LineChunk{j, 0, 0, 1};
      longest = 0;
    }
    if (line_major) lines[j].stack = static_cast<std::int32_t>(chunk.stack_entries);
    chunk.stack_entries += line_major ? capacities[j] : 0;
    longest = std::max(longest, capacities[j]);
    ++chunk.count;
  }
  close();
  return chunks;
}

namespace {

// (W + H + extra pixels) times the largest per-row cell size, over 2^23: of the larger field
// (HeightField::origin; a chunk sees the positions it sees).
double unitOverExtent(const HeightField& field, double extra) {
  const FieldOrigin& o = field.origin;
  const bool larger = o.present();
  const auto& rows_x = larger ? o.row_cell_size_x : field.row_cell_size_x;
  const auto& rows_y = larger ? o.row_cell_size_y : field.row_cell_size_y;
  const double largest = std::max(*std::max_element(rows_x.begin(), rows_x.end()),
                                  *std::max_element(rows_y.begin(), rows_y.end()));
  const double extent = larger ? double(o.whole_width) + o.whole_height : double(field.width) + field.height;
  return (extent + extra) * largest / double(1 << 23);
}

}  // namespace

double groundUnit(const HeightField& field) {
  return unitOverExtent(field, 2.0 * std::hypot(double(kMaxLatticeStep), double(kMaxLatticeStep)));
}

double sweepUnit(const HeightField& field) { return unitOverExtent(field, 0.0); }

LatticeWindow latticeWindow(const HeightField& field, const LatticeDirection& d, double max_distance) {
  LatticeWindow w;
  if (max_distance <= 0.0) return w;
  // Positions along a line are pixels, below 2 (W + H), or with per-row spacing units of
  // sweepUnit, below 2^24. (A field cut from a larger one places them along the larger field's
  // lines.)
  const bool larger = field.origin.present();
  double unit = d.ground_per_pixel,
         longest = 2.0 * (static_cast<double>(larger ? field.origin.whole_width : field.width) +
                          (larger ? field.origin.whole_height : field.height));
  if (!field.row_cell_size_x.empty()) {
    unit = sweepUnit(field);
    longest = double(1 << 24);
  }
  const double positions = max_distance / unit;
  if (longest / positions >= double(1 << 30)) {
    std::ostringstream message;
    message << "the maximum distance " << max_distance << " is too short for a field of this size (at least "
            << longest / double(1 << 30) * unit << " ground units)";
    throw InvalidArgument(message.str());
  }
  w.window = static_cast<float>(positions);
  w.inv_window = static_cast<float>(1.0 / positions);
  return w;
}

void cellSizeAtRow(const HeightField& field, double y, double* cell_x, double* cell_y) {
  const double clamped = std::clamp(y, 0.0, static_cast<double>(field.height - 1));
  const std::size_t r0 = static_cast<std::size_t>(clamped);
  const std::size_t r1 = std::min(r0 + 1, static_cast<std::size_t>(field.height - 1));
  const double w = clamped - static_cast<double>(r0);
  *cell_x = (1.0 - w) * field.row_cell_size_x[r0] + w * field.row_cell_size_x[r1];
  *cell_y = (1.0 - w) * field.row_cell_size_y[r0] + w * field.row_cell_size_y[r1];
}


}  // namespace hfvis::detail
