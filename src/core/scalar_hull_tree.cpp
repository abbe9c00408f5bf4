// scalar_hull_tree.cpp: the convex hull tree sweep (Timonen 2013) of sampled lines on
// the host, a scalar mirror of kernels/intervisibility.cl's sweep (same tree layout, same
// walk, same exact predicate, in the kernel's order, with the bounce gather): the horizon
// lists run it, and the scalar references of the tests build on it.

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>

#include "core/chord_side.hpp"
#include "core/fast_math.hpp"
#include "core/horizon_common.hpp"
#include "core/hull_tree.hpp"
#include "core/tree_peaks.hpp"
#include "hfvis/bounce.hpp"
#include "hfvis/errors.hpp"

namespace hfvis {
namespace detail {
namespace {

constexpr float kNaN = std::numeric_limits<float>::quiet_NaN();
constexpr int kNone = -1;
constexpr int kConcave = 0, kConvex = 1;

// A tree node as the kernel's int4: (height, rank * 2 + leaf flag, first child, next
// sibling); the node of slot k in tree[k], links by slot. (The kernel's rank is ranks[k] here.)
struct Node {
  float h = 0.0f;
  bool leaf = false;
  int first = kNone;
  int next = kNone;
};

// The sampled heights of one line, their peaks and their positions, by tree slot: with peaks
// (lines.peaks set) slot 2 s + 1 is step s's sample and 2 s the peak before it, else slot s is
// step s.
struct LineView {
  const IntervisibilityLines& lines;
  std::size_t offset;  // entry of step 0 of this line
  std::size_t stride;  // n_lines
  int shift;           // position_shift
  bool peaks() const { return !lines.peaks.empty(); }
  int sampleOf(int slot) const { return peaks() ? slot >> 1 : slot; }  // the step of a slot's sample or peak
  bool isSample(int slot) const { return !peaks() || (slot & 1) != 0; }
  int slotOf(int step) const { return peaks() ? 2 * step + 1 : step; }  // a step's sample
  std::size_t entry(int step) const { return offset + static_cast<std::size_t>(step) * stride; }
  float sampleHeight(int step) const { return lines.samples[entry(step)]; }
  // Position along the line of a step's sample: the step in units of 2^-shift step, or its
  // units with per-row spacing (exact in a float).
  std::int32_t stepPosition(int step) const {
    return lines.positions.empty() ? step << shift : lines.positions[entry(step)];
  }
  // The positions of the step into `step` (> 0): 2^shift, or its units (where a peak lies
  // strictly inside, at its offset).
  int stepScale(int step) const { return stepPosition(step) - stepPosition(step - 1); }
  // Position of a slot's node: its sample's, or the peak's: the step before's plus its offset.
  float position(int slot) const {
    const int s = sampleOf(slot);
    if (isSample(slot)) return static_cast<float>(stepPosition(s));
    return static_cast<float>(stepPosition(s - 1) + lines.peak_offsets[entry(s)]);
  }
};

bool seenOver(const LineView& line, float hx, int x, float hn, int n, float hr, int r) {
  const float px = line.position(x), pn = line.position(n), pr = line.position(r);
  return chordSide(hx, hn, hr, pn - px, pr - pn) <= 0;
}

// Mirror of run_end(): over the samples between horizon `start` and the next horizon `next`
// (slots), the first hidden one's slot, or `next`. Peaks are never counted, so only samples
// are searched: the visible nodes between two horizons are a prefix, the samples among them too.
int runEnd(const LineView& line, int start, int next, float h_next, int receiver, float h_receiver,
           bool holes) {
  // The last sample known visible: the horizon's own, or the step before a peak's.
  int lo = line.sampleOf(start) - (line.isSample(start) ? 0 : 1);
  const int last = line.sampleOf(next);
  auto seen = [&](int x) {
    return seenOver(line, line.sampleHeight(x), line.slotOf(x), h_next, next, h_receiver, receiver);
  };
  if (!holes) {
    int hi = last, jump = 1;
    while (lo + jump < hi) {
      const int x = lo + jump;
      if (seen(x)) {
        lo = x;
        jump *= 2;
      } else {
        hi = x;
        break;
      }
    }
    while (hi - lo > 1) {
      const int mid = lo + (hi - lo) / 2;
      if (seen(mid))
        lo = mid;
      else
        hi = mid;
    }
    return hi == last ? next : line.slotOf(hi);
  }
  for (int x = lo + 1; x < last; ++x)
    if (!std::isnan(line.sampleHeight(x)) && !seen(x)) return line.slotOf(x);
  return next;
}

// Mirror of forgiven_stretch(): going farther out from horizon `horizon` (slot, height h_h) down
// to step `last_step`, no farther than the line's first present sample (rank 0), the present samples
// it hides only within the heights' rounding, up to the first that is not; the farthest's step,
// or -1.
int forgivenStretch(const LineView& line, const std::vector<int>& ranks, int last_step, int horizon,
                    float h_h, int receiver, float h_receiver) {
  const float p_h = line.position(horizon), p_r = line.position(receiver);
  int farthest = -1;
  for (int x = line.sampleOf(horizon) - 1; x >= last_step; --x) {
    const float hx = line.sampleHeight(x);
    if (std::isnan(hx)) continue;
    if (!seen_within_rounding(hx, h_h, h_receiver, p_h - line.position(line.slotOf(x)), p_r - p_h,
                              line.lines.height_base))
      break;
    farthest = x;
    if (ranks[line.slotOf(x)] == 0) break;  // the line's first present sample
  }
  return farthest;
}

// Mirror of the bounce gather of kernels/intervisibility.cl (BounceGather and its helpers):
// the visible samples of one receiver, visited farthest first, each adding its radiance
// times the projected solid angle of its elevation band.
class BounceGather {
 public:
  BounceGather(const BounceLines& in, const SweepDirection& d, std::size_t receiver_entry, float h)
      : in_(in), h_(h), ground_(in.step_ground) {
    const float* normal = &in.attributes[receiver_entry * (in.channels + kBounceNormalFloats) + in.channels];
    const float toward = normal[0] * d.cos_azimuth + normal[1] * d.sin_azimuth;
    nz_term_ = normal[2] * in.half_sector;
    nh_term_ = toward * in.wedge;
    tangent_ = std::atan2(-nh_term_, 2.0f * nz_term_);
  }

  // Visible sample of `entry` at height hx, `distance` steps from the receiver; nearer than
  // every node visited before it.
  void visit(float hx, float distance, std::size_t entry) {
    visit(hx, distance, &in_.attributes[entry * (in_.channels + kBounceNormalFloats)]);
  }

  // Visible peak at height hx, `distance` steps from the receiver, `toward` of the step from the
  // sample before it (entry `before`) to the one after it (`after`): their radiance so weighted.
  void visitPeak(float hx, float distance, std::size_t before, std::size_t after, float toward) {
    const int stride = in_.channels + kBounceNormalFloats;
    float radiance[kMaxBounceChannels];
    for (int c = 0; c < in_.channels; ++c) {
      const float r0 = in_.attributes[before * stride + c], r1 = in_.attributes[after * stride + c];
      radiance[c] = r0 + toward * (r1 - r0);
    }
    visit(hx, distance, radiance);
  }

  // At a run's end: whether the next sample visited stays adjacent to the last one (no hidden
  // sample between).
  void endRun(bool reached_next) { adjacent_ = adjacent_ && reached_next; }

  void finish(float* irradiance) {
    if (have_prev_) {
      const float g_lo = g(tangent_);  // (the nearest sample's band reaches down to the tangent)
      for (int c = 0; c < in_.channels; ++c) sum_[c] += prev_radiance_[c] * (prev_g_hi_ - g_lo);
    }
    for (int c = 0; c < in_.channels; ++c) irradiance[c] = sum_[c];
  }

 private:
  void visit(float hx, float distance, const float* radiance) {
    const float theta = std::atan2(hx - h_, distance * ground_);
    float g_hi;
    if (!have_prev_) {
      g_hi = g(theta);
    } else {
      const float edge = adjacent_ ? 0.5f * (prev_theta_ + theta) : theta;
      const float g_edge = g(edge);
      for (int c = 0; c < in_.channels; ++c) sum_[c] += prev_radiance_[c] * (prev_g_hi_ - g_edge);
      g_hi = g_edge;
    }
    prev_theta_ = theta;
    prev_g_hi_ = g_hi;
    for (int c = 0; c < in_.channels; ++c) prev_radiance_[c] = radiance[c];
    have_prev_ = true;
    adjacent_ = true;
  }

  float g(float theta) const {
    const float t = hfMax(theta, tangent_);
    const float s = std::sin(t), c = std::cos(t);
    return nz_term_ * (s * s) + nh_term_ * (0.5f * (t + s * c));
  }

  const BounceLines& in_;
  float h_;
  float ground_;
  float nz_term_ = 0.0f, nh_term_ = 0.0f, tangent_ = 0.0f;
  bool have_prev_ = false, adjacent_ = false;
  float prev_theta_ = 0.0f, prev_g_hi_ = 0.0f;
  float prev_radiance_[kMaxBounceChannels] = {};
  float sum_[kMaxBounceChannels] = {};
};

// Mirror of RootList / root_append(): the root's new child list; `tail_next` is what the
// last child's `next` holds in the tree, so deferred writes skip links already right.
struct RootList {
  int head = kNone, tail = kNone, tail_next = kNone;
  float tail_h = 0.0f;
  void append(std::vector<Node>& tree, bool deferred, int x, float hx, int x_next_in_tree) {
    if (tail == kNone)
      head = x;
    else if (!deferred || tail_next != x)
      tree[tail].next = x;
    tail = x;
    tail_next = x_next_in_tree;
    tail_h = hx;
  }
};

// Mirror of hull_tree_walk(): Algorithm 1 below `top`; returns the convexity checks.
std::uint32_t hullTreeWalk(const LineView& line, std::vector<Node>& tree, bool deferred, int top, Node node,
                           float h, int slot, RootList& list) {
  std::uint32_t t = 0;
  int cur = top;
  for (;;) {
    const int c = node.first;
    if (c != kNone) {
      Node child = tree[c];
      ++t;
      const int side = chordSide(child.h, node.h, h, line.position(cur) - line.position(c),
                                 line.position(slot) - line.position(cur));
      if (side <= 0) {
        tree[cur].first = child.next;
        tree[c].next = cur;
        child.next = cur;
        cur = c;
        node = child;
        continue;
      }
    }
    if (c != kNone || node.leaf) list.append(tree, deferred, cur, node.h, node.next);
    if (cur == top) break;
    cur = node.next;
    node = tree[cur];
  }
  return t;
}

// Mirror of SafeZone and its helpers, the same float operations in the same order.
struct SafeZone {
  int steps = 16;
  float first = 0.0f, last = 0.0f;  // positions
  float z1 = 0.0f, z2 = 0.0f, margin = 0.0f;
  void begin(float p, float unit) {
    first = p + 1.0f;
    last = first + unit * static_cast<float>(steps);
    z1 = z2 = std::numeric_limits<float>::max();
    margin = 0.0f;
  }
  void add(float hc, float c, float hg, float g) {
    const float slope = (hc - hg) / (c - g);
    const float at1 = hc + slope * (first - c);
    const float at2 = hc + slope * (last - c);
    z1 = hfMin(z1, at1);
    z2 = hfMin(z2, at2);
    margin = hfMax(margin, std::fabs(hc) + std::fabs(slope) * (last - c));
  }
  void end() { margin = margin * 0x1p-16f + 0x1p-100f; }
  bool inside(float p, float h) const {
    const float bound = z1 + (z2 - z1) * ((p - first) / (last - first));
    return p <= last && h < bound - margin;
  }
};

// Mirror of intervisibility_lattice()'s sweep of line j: per step, its peak (an occluder alone,
// where there is one) and then its sample.
void sweepLine(const SweepDirection& d, int j, const HullTreeTuning& tuning, IntervisibilityLines& out,
               bool keep_horizons, BounceLines* bounce) {
  const bool deferred = tuning.deferred_writes;
  const std::size_t stride = static_cast<std::size_t>(d.n_lines);
  const LineView line{out, static_cast<std::size_t>(j), stride, out.position_shift};
  const bool row_spacing = !out.positions.empty();
  const std::size_t slots = static_cast<std::size_t>(d.n_steps) * (line.peaks() ? 2 : 1);
  std::vector<Node> tree(slots);
  // Per slot, over the present samples before it: their count (rank), the sum of their steps,
  // and with per-row spacing the sum of their step units and of position * units (the kernel's
  // positions[].y and prefix[]).
  std::vector<int> ranks(slots);
  std::vector<std::uint64_t> step_sums(slots), unit_sums(slots), weighted_sums(slots);

  int rank = 0;
  std::uint64_t step_sum = 0, unit_sum = 0, weighted_sum = 0;
  int root = kNone, prev = kNone, prev2 = kNone;
  float h_prev = 0.0f, h_prev2 = 0.0f;
  float h_sample_prev = kNaN;  // the step before's sample (a peak must rise above its chord)
  int class_last = kConvex;
  int head = kNone, tail = kNone;  // the root's first and last child
  float tail_h = 0.0f;
  SafeZone zone;
  zone.steps = tuning.safe_zone_steps;
  bool zone_valid = false;
  for (int step = 0; step < d.n_steps; ++step) {
    const std::size_t e = line.entry(step);
    const float h_sample = out.samples[e];
    std::uint32_t t = 0;  // the step's convexity checks, its peak's included
    for (int part = line.peaks() ? 0 : 1; part < 2; ++part) {
      const bool peak = part == 0;
      const int slot = line.peaks() ? 2 * step + part : step;
      ranks[slot] = rank;
      step_sums[slot] = step_sum;
      unit_sums[slot] = unit_sum;
      weighted_sums[slot] = weighted_sum;
      const float h = peak ? out.peaks[e] : h_sample;
      // (Step 0 has no step before it, nor a peak.)
      if (peak ? step == 0 || !tree_peak_inserted(h_sample_prev, h, h_sample, out.peak_offsets[e],
                                                  line.stepScale(step))
               : std::isnan(h)) {
        if (peak) tree[slot].h = kNaN;  // no peak (the bounce's gather skips its slot)
        continue;                       // outputs stay NaN / zero
      }
      const float p = line.position(slot);
      std::uint32_t m = 0, hash = kHorizonHashSeed;
      int count = 0;
      std::uint64_t distance_sum = 0;
      std::vector<int> horizons, run_starts, run_ends;
      const bool receiver = !peak && step % out.receiver_every == out.receiver_every - 1;
      const bool visit = receiver || out.horizons_at_every_sample;  // a peak's only for the statistics
      std::optional<BounceGather> gather;
      if (bounce && receiver) gather.emplace(*bounce, d, e, h);
      if (root == kNone) {
        tree[slot] = {h, true, kNone, kNone};
        head = tail = kNone;
      } else {
        // 1. Algorithm 1 for the new root (see the kernel for the variants).
        RootList list;
        const Node old_root = tree[root];
        bool walk = true;
        bool replaced = false;
        if (tuning.replacement_check && tail != kNone) {
          ++t;
          replaced = chordSide(tail_h, h_prev, h, line.position(root) - line.position(tail),
                               p - line.position(root)) <= 0;
        }
        if (tuning.safe_zone) {
          zone_valid = zone_valid && replaced && zone.inside(p, h);
          if (zone_valid) {
            walk = false;
            ++out.walks_skipped[e];  // (its peak's and its sample's)
            list.head = head;
            list.tail = tail;
            list.tail_h = tail_h;
          }
        }
        if (walk) {
          if (deferred) {
            int c = old_root.first;
            while (c != kNone) {
              const Node child = tree[c];
              if (!replaced) {
                if (tuning.replacement_check && c == tail) break;
                ++t;
                if (chordSide(child.h, h_prev, h, line.position(root) - line.position(c),
                              p - line.position(root)) > 0)
                  break;
              }
              t += hullTreeWalk(line, tree, deferred, c, child, h, slot, list);
              c = child.next;
            }
            if (c != kNone || old_root.leaf) {
              if (c != old_root.first) tree[root].first = c;
              list.append(tree, deferred, root, h_prev, kNone);
            }
          } else {
            t += hullTreeWalk(line, tree, deferred, root, old_root, h, slot, list);
          }
        }

        // 2. Eq. 1 for the old root; a segment start's node becomes (or is re-created as) a
        // leaf, the root's last child.
        if (prev2 != kNone) {
          const int side = chordSide(h_prev2, h_prev, h, line.position(prev) - line.position(prev2),
                                     p - line.position(prev));
          const int cls = side > 0 ? kConvex : side < 0 ? kConcave : class_last;
          if (cls == kConvex && class_last == kConcave) {
            if (list.tail == prev) {
              tree[prev].leaf = true;
            } else {
              tree[prev] = {h_prev, true, kNone, kNone};
              list.append(tree, deferred, prev, h_prev, kNone);
            }
          }
          class_last = cls;
        }
        if (!deferred || list.tail_next != kNone) tree[list.tail].next = kNone;
        tree[slot] = {h, false, list.head, kNone};
        head = list.head;
        tail = list.tail;
        tail_h = list.tail_h;

        // 3. Visible samples from the horizons, farthest first (closed forms without holes);
        // at receivers, or at every sample when asked (statistics). Runs are slots; what they
        // count are the samples among them (sampleOf), never the peaks.
        if (visit) {
          // Within the maximum distance: the first step within max_steps (units) of this one.
          int cut = step - out.max_steps;
          if (row_spacing) {
            cut = 0;
            while (static_cast<std::int64_t>(out.positions[line.entry(step)]) -
                       out.positions[line.entry(cut)] >
                   out.max_steps)
              ++cut;
          }
          const bool refresh_zone = tuning.safe_zone && !zone_valid;
          if (refresh_zone) zone.begin(p, static_cast<float>(1 << line.shift));
          int hp = head;
          Node hz = tree[hp];
          int hp_rank = ranks[hp];
          // A horizon's run begins with its forgiven stretch (forgivenStretch), the farthest
          // horizon's reaching back to the line's first sample, none past the cut.
          int run_first = hp, run_first_rank = hp_rank;
          if (hp_rank > 0) {
            const int f = forgivenStretch(line, ranks, std::max(cut, 0), hp, hz.h, slot, h);
            if (f >= 0) run_first = line.slotOf(f), run_first_rank = ranks[run_first];
          }
          for (;;) {
            const int np = hz.next;
            ++m;
            if (refresh_zone && hz.first != kNone)
              zone.add(hz.h, line.position(hp), tree[hz.first].h, line.position(hz.first));
            hash = hashHorizon(hash, hp);
            if (keep_horizons) horizons.push_back(hp);
            int end = slot, end_rank = rank, np_rank = rank;
            Node nz = hz;
            if (np != kNone) {
              nz = tree[np];
              np_rank = ranks[np];
              end = np;
              end_rank = np_rank;
            }
            const bool holes = end_rank - hp_rank != line.sampleOf(end) - line.sampleOf(hp);
            if (np != kNone) {
              end = runEnd(line, hp, np, nz.h, slot, h, holes);
              end_rank = end == np ? np_rank
                         : holes   ? ranks[end]
                                   : hp_rank + (line.sampleOf(end) - line.sampleOf(hp));
            }
            // The next horizon's forgiven stretch, over the hidden samples [end, np).
            int np_first = np, np_first_rank = np_rank;
            if (np != kNone && end != np) {
              const int f =
                  forgivenStretch(line, ranks, std::max(line.sampleOf(end), cut), np, nz.h, slot, h);
              if (f >= 0) np_first = line.slotOf(f), np_first_rank = ranks[np_first];
            }
            const bool run_holes = end_rank - run_first_rank != line.sampleOf(end) - line.sampleOf(run_first);
            if (keep_horizons) run_starts.push_back(run_first), run_ends.push_back(end);
            if (gather) {
              for (int x = run_first; x < end; ++x) {
                const int xs = line.sampleOf(x);
                const float distance = static_cast<float>(step - xs);
                if (line.isSample(x)) {
                  const float hx = line.sampleHeight(xs);
                  if (!std::isnan(hx)) gather->visit(hx, distance, line.entry(xs));
                  continue;
                }
                // A peak where it is seen (as the kernel's gather takes it).
                const float hx = tree[x].h;
                if (std::isnan(hx) || x < hp ||
                    (x != hp && x + 1 >= end && np != kNone && !seenOver(line, hx, x, nz.h, np, h, slot)))
                  continue;
                const float toward = static_cast<float>(out.peak_offsets[line.entry(xs)]) /
                                     static_cast<float>(1 << line.shift);
                gather->visitPeak(hx, distance + (1.0f - toward), line.entry(xs - 1), line.entry(xs), toward);
              }
              gather->endRun(end == np_first);
            }
            // Within the maximum distance: the run's samples from `first` on (the slot of the
            // first step within it, its peak's with peaks).
            const int first = cut > line.sampleOf(run_first) ? (line.peaks() ? 2 * cut : cut) : run_first;
            const int first_rank = first == run_first ? run_first_rank
                                   : run_holes
                                       ? ranks[first]
                                       : run_first_rank + (line.sampleOf(first) - line.sampleOf(run_first));
            const int run = first < end ? end_rank - first_rank : 0;
            count += run;
            std::uint64_t steps_sum = 0;
            if (run == 0) {
            } else if (row_spacing) {
              // Sum of (p - position) * units over the run (the sums at `step`: before it).
              const std::uint64_t units = unit_sums[end] - unit_sums[first];
              distance_sum += static_cast<std::uint64_t>(out.positions[line.entry(step)]) * units -
                              (weighted_sums[end] - weighted_sums[first]);
            } else if (!run_holes) {
              steps_sum = static_cast<std::uint64_t>(run) *
                          static_cast<std::uint64_t>(line.sampleOf(first) + line.sampleOf(end) - 1) / 2;
            } else {
              const std::uint64_t end_sum = end == slot ? step_sum : step_sums[end];
              steps_sum = end_sum - step_sums[first];
            }
            if (!row_spacing)
              distance_sum += static_cast<std::uint64_t>(step) * static_cast<std::uint64_t>(run) - steps_sum;
            if (np == kNone) break;
            hz = nz;
            hp = np;
            hp_rank = np_rank;
            run_first = np_first;
            run_first_rank = np_first_rank;
          }
          if (refresh_zone) {
            zone.end();
            zone_valid = true;
          }
        }
      }
      if (peak) out.peak_horizons[e] = m;
      if (!peak) {
        out.counts[e] = visit ? static_cast<float>(count) : kNaN;
        out.distance_sums[e] = visit ? static_cast<float>(distance_sum) : kNaN;
        out.horizons[e] = m;
        out.iterations[e] = t;
        out.horizon_hashes[e] = hash;
        if (keep_horizons) {
          out.horizon_steps[e] = std::move(horizons);
          out.horizon_run_starts[e] = std::move(run_starts);
          out.horizon_run_ends[e] = std::move(run_ends);
        }
        if (gather) gather->finish(&bounce->irradiance[e * bounce->channels]);
      }
      prev2 = prev;
      h_prev2 = h_prev;
      prev = slot;
      h_prev = h;
      root = slot;
      if (peak) continue;
      ++rank;
      step_sum += static_cast<std::uint64_t>(step);
      if (row_spacing) {
        const std::uint64_t units = static_cast<std::uint64_t>(out.step_units[e]);
        unit_sum += units;
        weighted_sum += static_cast<std::uint64_t>(out.positions[e]) * units;
      }
    }
    h_sample_prev = h_sample;
  }
}

}  // namespace

void sweepPresampledLines(IntervisibilityLines& lines, const HullTreeTuning& requested, bool keep_horizons,
                          BounceLines* bounce) {
  validate(requested);
  const HullTreeTuning tuning = tuningFor(requested, !lines.positions.empty());
  if (bounce && !lines.positions.empty()) throw InvalidArgument("internal error: the bounce takes uniform steps");
  const SweepDirection& d = lines.geometry;
  const std::size_t entries = d.entries();
  if (lines.samples.size() != entries ||
      (!lines.peaks.empty() && (lines.peaks.size() != entries || lines.peak_offsets.size() != entries)))
    throw InvalidArgument("internal error: line samples do not fit the geometry");
  lines.resetResults(keep_horizons);
  if (bounce) {
    if (bounce->channels < 1 || bounce->channels > kMaxBounceChannels ||
        bounce->attributes.size() != entries * (bounce->channels + kBounceNormalFloats)) {
      throw InvalidArgument("internal error: bounce attributes do not fit the lines");
    }
    bounce->irradiance.assign(entries * bounce->channels, kNaN);
  }
  for (int j = 0; j < d.n_lines; ++j) sweepLine(d, j, tuning, lines, keep_horizons, bounce);
}

}  // namespace detail

}  // namespace hfvis
