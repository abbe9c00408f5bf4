// test_intervisibility.cpp: the convex hull tree sweep against its oracles: the exact
// predicate against big-integer arithmetic; on identical line samples, the tree's horizons
// and visible sets against brute-force enumeration (every hard case, awkward sizes, tie-rich
// random lines); the Section 6 bound t <= 2m + n on every line; kernels against the scalar
// references; the sweep against the naive visibility march; analytic flat-plane values.
//
// Tie rule everywhere: a farther sample q is visible from receiver p when no sample strictly
// between them lies strictly above the chord q-p (slope from p >= every slope in between).
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <functional>
#include <limits>
#include <random>
#include <set>

#include "core/chord_side.hpp"
#include "core/horizon_common.hpp"
#include "core/hull_tree.hpp"
#include "core/hull_tree_device.hpp"
#include "core/lattice_geometry.hpp"
#include "core/opencl_context.hpp"
#include "core/tree_peaks.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/image_io.hpp"
#include "hfvis/intervisibility.hpp"
#include "hfvis_testing/intervisibility_reference.hpp"
#include "hfvis_testing/sight_along_line.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "reference_internal.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

using testing::awkwardSizes;
using testing::fieldFrom;
using testing::nearlyEqual;
using testing::testContext;

// Lattice steps (a, b): the four axes, a diagonal and steps of longer periods in every quadrant.
const std::pair<int, int> kSteps[] = {{1, 0}, {0, 1}, {-1, 0}, {0, -1}, {1, 1}, {3, 1}, {-4, 3}, {-2, -3}, {5, -2}};

// The tree direction of step (a, b) at S samples per unit, one of 8 equal directions.
detail::TreeDirection treeStep(const HeightField& field, std::pair<int, int> step, double samples_per_unit = 1.0) {
  detail::LatticeDirection lattice = detail::latticeStep(field, step.first, step.second);
  lattice.weight = 1.0 / 8;
  return detail::makeTreeDirection(field, lattice, samples_per_unit, 8);
}

// The same on a field with per-row spacing (testing::setRowSpacing): positions in units.
detail::TreeDirection treeStepFollowingRows(const HeightField& field, std::pair<int, int> step,
                                            double samples_per_unit = 1.0) {
  detail::TreeDirection d = treeStep(field, step, samples_per_unit);
  const auto rows = detail::latticeRowTables(field, {d.lattice}, false);
  detail::followRows(d, field, rows[0], detail::groundUnit(field), samples_per_unit, 8, 0.0, 0.0);
  return d;
}

// The scalar reference's lines of direction d, every horizon kept, with the prepared heights'
// base (the tie rule's rounding) as production takes it.
detail::IntervisibilityLines referenceLines(const HeightField& field, const detail::PreparedHeights& prepared,
                                            const detail::TreeDirection& d,
                                            const HullTreeTuning& tuning = {}) {
  auto lines = detail::latticeTreeLines(field, prepared.heights, d);
  lines.height_base = prepared.base;
  detail::sweepPresampledLines(lines, tuning, true);
  return lines;
}

// ---------------------------------------------------------------------------------------
// The exact predicate against big-integer arithmetic.

// A signed 512-bit integer in units of 2^-149 (the smallest denormal), two's complement.
struct BigFixed {
  std::array<std::uint32_t, 16> limb{};
  // Adds sign * mantissa * 2^shift (mantissa < 2^64).
  void add(bool negative, std::uint64_t mantissa, int shift) {
    std::array<std::uint32_t, 16> term{};
    for (int bit = 0; bit < 64; ++bit) {
      if (!((mantissa >> bit) & 1)) continue;
      const int at = bit + shift;
      term[at / 32] |= 1u << (at % 32);
    }
    if (negative) {  // two's complement of the term
      std::uint64_t carry = 1;
      for (auto& l : term) {
        const std::uint64_t v = static_cast<std::uint64_t>(~l) + carry;
        l = static_cast<std::uint32_t>(v);
        carry = v >> 32;
      }
    }
    std::uint64_t carry = 0;
    for (int i = 0; i < 16; ++i) {
      const std::uint64_t v = static_cast<std::uint64_t>(limb[i]) + term[i] + carry;
      limb[i] = static_cast<std::uint32_t>(v);
      carry = v >> 32;
    }
  }
  int sign() const {
    if (limb[15] >> 31) return -1;
    for (auto l : limb)
      if (l) return 1;
    return 0;
  }
};

// Adds sign * f * d exactly (f finite, |f| < 2^200, d a non-negative integer below 2^24).
void addProduct(BigFixed& sum, int sign, float f, std::uint32_t d) {
  if (f == 0.0f || d == 0) return;
  int exponent;
  const float fraction = std::frexp(std::fabs(f), &exponent);  // |f| = fraction * 2^exponent
  // |f| = m * 2^(exponent - 24) with m a 24-bit integer; in units of 2^-149:
  const auto m = static_cast<std::uint64_t>(std::ldexp(fraction, 24));
  int shift = exponent - 24 + 149;
  std::uint64_t mantissa = m * d;
  while (shift < 0) {  // denormals: m has trailing zeros to spare
    ASSERT_EQ(mantissa & 1, 0u);
    mantissa >>= 1;
    ++shift;
  }
  sum.add((f < 0) != (sign < 0), mantissa, shift);
}

int bigChordSide(float ha, float hb, float hc, std::uint32_t dab, std::uint32_t dbc) {
  BigFixed sum;
  addProduct(sum, 1, hb, dab + dbc);
  addProduct(sum, -1, ha, dbc);
  addProduct(sum, -1, hc, dab);
  return sum.sign();
}

TEST(IntervisibilityPredicate, ChordSideIsExactOnRandomAndNearCollinearTriples) {
  std::mt19937 rng(11);
  std::uniform_int_distribution<std::uint32_t> step(1, 3000);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  std::uniform_int_distribution<int> scale(-140, 60);
  std::uniform_int_distribution<int> ulps(-3, 3);
  int ties = 0, checked = 0;
  for (int n = 0; n < 400000; ++n) {
    const std::uint32_t dab = step(rng), dbc = step(rng);
    float ha, hb, hc;
    const int kind = n % 5;
    if (kind == 0) {  // independent heights over a wide range of scales
      ha = std::ldexp(unit(rng), scale(rng));
      hb = std::ldexp(unit(rng), scale(rng));
      hc = std::ldexp(unit(rng), scale(rng));
    } else if (kind == 1) {  // small integers: exact ties are common
      std::uniform_int_distribution<int> small(0, 4);
      ha = float(small(rng)), hb = float(small(rng)), hc = float(small(rng));
    } else {  // b within a few ulps of the chord, at one common scale (incl. denormals)
      const int s = kind == 4 ? -135 : scale(rng);
      ha = std::ldexp(unit(rng), s);
      hc = std::ldexp(unit(rng), s);
      if (kind == 3) ha += 8848.0f, hc += 8848.0f;  // large offset, tiny slope
      const double on = (double(ha) * dbc + double(hc) * dab) / double(dab + dbc);
      hb = static_cast<float>(on);
      for (int u = ulps(rng); u > 0; --u) hb = std::nextafter(hb, std::numeric_limits<float>::infinity());
      for (int u = ulps(rng); u < 0; ++u) hb = std::nextafter(hb, -std::numeric_limits<float>::infinity());
    }
    const int expected = bigChordSide(ha, hb, hc, dab, dbc);
    const int actual = detail::chordSide(ha, hb, hc, float(dab), float(dbc));
    ASSERT_EQ(actual, expected) << "ha " << ha << " hb " << hb << " hc " << hc << " dab " << dab << " dbc "
                                << dbc;
    ties += expected == 0;
    ++checked;
  }
  EXPECT_GT(ties, 1000) << "the test should exercise exact ties";
}

// ---------------------------------------------------------------------------------------
// Brute force on one line, independent of the tree: visibility by its definition, the
// segment starts of Eq. 1 and the horizons of Eq. 2 (the farthest sample of maximal slope
// from the receiver among samples j .. receiver - 1, per segment start j).

struct LineSample {
  int step;  // its tree slot: the step, or with peaks 2 step + 1 (a peak: 2 step)
  float h;
  float position;  // in 2^-shift steps, or its units with per-row spacing
  float distance;  // the step, or its units with per-row spacing (what distance sums add)
  float ring;      // 1, or the units of its step toward the receivers (its ring width)
  bool peak;       // an occluder alone: never counted
};

// The present nodes of line j, in sweep order (far end first): its samples and, with peaks,
// those that rise above both samples around them.
std::vector<LineSample> presentSamples(const detail::IntervisibilityLines& lines, int j) {
  std::vector<LineSample> present;
  const auto& d = lines.geometry;
  const int shift = lines.position_shift;
  const bool peaks = !lines.peaks.empty(), rows = !lines.positions.empty();
  auto entry = [&](int i) { return static_cast<std::size_t>(i) * d.n_lines + j; };
  // Positions: the step in 2^-shift steps, or its units with per-row spacing.
  auto position = [&](int i) { return rows ? lines.positions[entry(i)] : i << shift; };
  for (int i = 0; i < d.n_steps; ++i) {
    const std::size_t e = entry(i);
    const float h = lines.samples[e];
    if (peaks && i > 0) {
      const float peak = lines.peaks[e];
      if (detail::tree_peak_inserted(lines.samples[e - d.n_lines], peak, h, lines.peak_offsets[e],
                                     position(i) - position(i - 1)))
        present.push_back({2 * i, peak, float(position(i - 1) + lines.peak_offsets[e]), 0.0f, 0.0f, true});
    }
    if (std::isnan(h)) continue;
    const int slot = peaks ? 2 * i + 1 : i;
    if (!rows)
      present.push_back({slot, h, float(position(i)), float(i), 1.0f, false});
    else
      present.push_back(
          {slot, h, float(lines.positions[e]), float(lines.positions[e]), float(lines.step_units[e]), false});
  }
  return present;
}

// Eq. 1 segment starts of a line's present samples: the first, and every convex sample
// after a concave one. Sample i's class needs sample i + 1 only, so for a receiver r the
// starts before r are the same whatever follows r.
std::vector<bool> segmentStarts(const std::vector<LineSample>& s) {
  std::vector<bool> start(s.size(), false);
  if (s.empty()) return start;
  start[0] = true;
  std::vector<int> cls(s.size(), 1);  // 1 convex, 0 concave; the first is convex
  for (std::size_t i = 1; i + 1 < s.size(); ++i) {
    const int side = detail::chordSide(s[i - 1].h, s[i].h, s[i + 1].h, s[i].position - s[i - 1].position,
                                       s[i + 1].position - s[i].position);
    cls[i] = side > 0 ? 1 : side < 0 ? 0 : cls[i - 1];
    start[i] = cls[i] == 1 && cls[i - 1] == 0;
  }
  return start;
}

struct BruteForce {
  std::vector<int> visible;   // indices into present, nearest first: exactly visible
  std::vector<int> forgiven;  // hidden samples seen within the heights' rounding
  std::vector<int> horizons;  // steps, farthest first, distinct
};

// For receiver present[r]: what it sees of the samples before it (sightAlongLine: the tie rule,
// kernels/intervisibility.cl's forgiven_stretch), and for each segment start x (Eq. 1) its
// horizon (Eq. 2): the farthest sample of maximal slope in [x, r), the steepest node from x.
BruteForce bruteForce(const std::vector<LineSample>& s, const std::vector<bool>& starts, int r,
                      float height_base) {
  std::vector<LineNode> nodes(static_cast<std::size_t>(r) + 1);
  for (int x = 0; x <= r; ++x) nodes[x] = {s[x].h, s[x].position, s[x].peak};
  const LineSight sight = sightAlongLine(nodes, static_cast<std::size_t>(r), height_base);
  BruteForce out;
  std::set<int> horizons;
  for (int x = r - 1; x >= 0; --x) {
    if (sight.exactly[x]) out.visible.push_back(x);
    if (sight.forgiven[x]) out.forgiven.push_back(x);
    if (starts[x]) horizons.insert(s[sight.steepest[x]].step);
  }
  out.horizons.assign(horizons.begin(), horizons.end());
  return out;
}

// The tree tunings under test: Algorithm 1's walk as written, each optimisation alone, both
// (the default), and the safe zone's extreme spans. Each must build the same trees.
struct NamedTuning {
  const char* name;
  HullTreeTuning tuning;
};
const NamedTuning kTunings[] = {
    {"plain", {false, false, false, 16}},
    {"deferred writes", {true, false, false, 16}},
    {"replacement check (default)", {true, true, false, 16}},
    {"safe zone", {true, true, true, 16}},
    {"safe zone 1 step", {true, true, true, 1}},
    {"safe zone 4096 steps", {true, true, true, 4096}},
};

void expectTreeEqualsBruteForce(const HeightField& field, const detail::TreeDirection& direction,
                                bool check_device, std::uint64_t* receivers_checked,
                                const HullTreeTuning& tuning = {}, std::uint64_t* peaks_inserted = nullptr,
                                std::uint64_t* forgiven = nullptr) {
  const auto prepared = detail::prepareHeights(field);
  const auto ref = referenceLines(field, prepared, direction, tuning);
  const auto& d = ref.geometry;
  if (check_device) {
    // Alternate the layouts from call to call: both are covered without doubling the time.
    static int calls = 0;
    const LineLayout layout = ++calls % 2 ? LineLayout::LineMajor : LineLayout::StepMajor;
    const auto dev = detail::intervisibilityLinesOnDevice(testing::testContext(layout), field, prepared,
                                                          direction, tuning);
    ASSERT_TRUE(nearlyEqual(dev.samples, ref.samples, 0.0f)) << "sampled heights differ";
    ASSERT_TRUE(nearlyEqual(dev.counts, ref.counts, 0.0f)) << "visible counts: kernel vs reference";
    ASSERT_TRUE(nearlyEqual(dev.distance_sums, ref.distance_sums, 0.0f))
        << "distance sums: kernel vs reference";
    ASSERT_EQ(dev.horizons, ref.horizons) << "horizon counts m_i: kernel vs reference";
    ASSERT_EQ(dev.horizon_hashes, ref.horizon_hashes) << "horizon lists: kernel vs reference";
    // The safe zone's bound divides: kernel and reference take the same walks only where the
    // device divides as C++ does (then programs get -cl-fp32-correctly-rounded-divide-sqrt);
    // elsewhere the zone's margin still keeps every result exact, checked above and below.
    if (!tuning.safe_zone || testContext().device().correctly_rounded_divide) {
      ASSERT_EQ(dev.iterations, ref.iterations) << "iterations t_i: kernel vs reference";
      ASSERT_EQ(dev.walks_skipped, ref.walks_skipped) << "safe-zone skips: kernel vs reference";
    }
  }
  for (int j = 0; j < d.n_lines; ++j) {
    const auto s = presentSamples(ref, j);
    const auto starts = segmentStarts(s);
    std::uint64_t m = 0, t = 0;
    for (int r = 0; r < static_cast<int>(s.size()); ++r) {
      if (s[r].peak) {  // no receiver; its horizons count in the bound below
        m += ref.peak_horizons[static_cast<std::size_t>(s[r].step / 2) * d.n_lines + j];
        if (peaks_inserted) ++*peaks_inserted;
        continue;
      }
      const std::size_t e =
          static_cast<std::size_t>(ref.peaks.empty() ? s[r].step : s[r].step / 2) * d.n_lines + j;
      const BruteForce brute = bruteForce(s, starts, r, ref.height_base);
      if (forgiven) *forgiven += brute.forgiven.size();
      SCOPED_TRACE("line " + std::to_string(j) + " receiver step " + std::to_string(s[r].step));
      // The horizons are Eq. 2's, distinct and farthest first.
      ASSERT_EQ(ref.horizon_steps[e], brute.horizons);
      std::uint32_t hash = detail::kHorizonHashSeed;
      for (int step : brute.horizons) hash = detail::hashHorizon(hash, step);
      ASSERT_EQ(ref.horizon_hashes[e], hash);
      ASSERT_EQ(ref.horizons[e], brute.horizons.size());
      // Visible counts and distances equal the enumeration (samples alone: peaks occlude).
      int counted = 0;
      double distance = 0.0;
      std::vector<int> seen = brute.forgiven;
      seen.insert(seen.end(), brute.visible.begin(), brute.visible.end());
      std::sort(seen.begin(), seen.end(), std::greater<int>());  // nearest first, as the sums add
      for (int x : seen) {
        if (s[x].peak) continue;
        ++counted;
        distance += double(s[r].distance - s[x].distance) * s[x].ring;
      }
      ASSERT_EQ(ref.counts[e], float(counted));
      ASSERT_EQ(ref.distance_sums[e], float(distance));
      // Every start of a visible run (a visible sample whose farther neighbour is hidden)
      // is a horizon, and every horizon is visible.
      std::set<int> visible_steps;
      for (int x : brute.visible) visible_steps.insert(s[x].step);
      const std::set<int> horizon_set(brute.horizons.begin(), brute.horizons.end());
      for (int x : brute.visible) {
        const bool run_start = x == 0 || !visible_steps.count(s[x - 1].step);
        if (run_start) {
          ASSERT_TRUE(horizon_set.count(s[x].step)) << "run start " << s[x].step << " is no horizon";
        }
      }
      for (int step : brute.horizons)
        ASSERT_TRUE(visible_steps.count(step)) << "horizon " << step << " hidden";
      m += ref.horizons[e];
      t += ref.iterations[e];
      ++*receivers_checked;
    }
    // Section 6: t <= 2m + n on every line.
    ASSERT_LE(t, 2 * m + s.size()) << "line " << j << ": t = " << t << ", m = " << m << ", n = " << s.size();
  }
}

TEST(IntervisibilityLine, TreeEqualsBruteForceOnEveryHardCase) {
  for (const NamedTuning& variant : kTunings) {
    std::uint64_t checked = 0;
    for (const auto& name : syntheticFieldNames()) {
      for (auto [w, h] : awkwardSizes()) {
        const HeightField field = makeSyntheticField(name, w, h, 7);
        for (auto step : kSteps) {
          SCOPED_TRACE(std::string(variant.name) + ": " + name + " " + std::to_string(w) + "x" +
                       std::to_string(h) + " step " + std::to_string(step.first) + "," + std::to_string(step.second));
          expectTreeEqualsBruteForce(field, treeStep(field, step), true, &checked, variant.tuning);
          if (::testing::Test::HasFatalFailure()) return;
        }
      }
    }
    EXPECT_GT(checked, 100000u) << variant.name;
  }
}

// On a field whose rows have their own spacing (a latitude / longitude grid), positions
// along the lines are whole units of ground length that differ from row to row: the tree
// still equals brute force on them, and its kernel the reference, on every hard case, in
// every direction of kSteps and in every tuning (the safe zone is off there).
TEST(IntervisibilityLine, TreeEqualsBruteForceOnRowsOfTheirOwnSpacing) {
  std::uint64_t checked = 0, peaks = 0;
  for (const NamedTuning& variant : {kTunings[0], kTunings[2], kTunings[3]}) {
    for (const auto& name : syntheticFieldNames()) {
      for (auto [w, h] : awkwardSizes()) {
        HeightField field = makeSyntheticField(name, w, h, 7);
        testing::setRowSpacing(field);
        for (auto step : kSteps) {
          SCOPED_TRACE(std::string(variant.name) + ": " + name + " " + std::to_string(w) + "x" + std::to_string(h) +
                       " step " + std::to_string(step.first) + "," + std::to_string(step.second));
          const auto d = treeStepFollowingRows(field, step, step.second == 1 ? 2.0 : 1.0);
          // The steps really differ in length along lines that cross rows.
          if (step.second != 0 && h > 2) {
            ASSERT_NE(d.row_units.front(), d.row_units.back());
          }
          expectTreeEqualsBruteForce(field, d, true, &checked, variant.tuning, &peaks);
          if (::testing::Test::HasFatalFailure()) return;
        }
      }
    }
  }
  EXPECT_GT(checked, 50000u);
  // The peaks between samples, at positions in the steps' own units, are in these trees too.
  EXPECT_GT(peaks, checked / 100) << "peaks inserted";
}

// The tunings change the work, never the result: per receiver the same counts, distances
// and horizons as Algorithm 1's walk. Per receiver: the deferred writes make the same
// convexity checks, the replacement check at most one more (on the fractal far fewer in
// all), the safe zone at most as many as without it and exactly one where it skips the walk
// (and it does skip walks there).
TEST(IntervisibilityLine, TuningsChangeTheWorkNotTheResult) {
  const HeightField fractal = readHeightField(std::string(HFVIS_DATA_DIR) + "/fractal_256.exr");
  const HeightField fields[] = {fractal, makeSyntheticField("noise", 97, 61, 2),
                                makeSyntheticField("dome", 80, 80, 1),
                                makeSyntheticField("terraces", 64, 50, 1)};
  for (const HeightField& field : fields) {
    const auto prepared = detail::prepareHeights(field);
    for (auto step : {std::pair<int, int>{1, 0}, {4, 3}, {-2, -1}}) {
      const double azimuth = std::atan2(step.second, step.first);
      const auto d = treeStep(field, step);
      const auto plain =
          detail::intervisibilityLinesOnDevice(testContext(), field, prepared, d, kTunings[0].tuning);
      HullTreeTuning replacement = kTunings[0].tuning;
      replacement.deferred_writes = replacement.replacement_check = true;
      const auto no_zone =
          detail::intervisibilityLinesOnDevice(testContext(), field, prepared, d, replacement);
      std::uint64_t plain_t = 0, receivers = 0;
      for (auto t : plain.iterations) plain_t += t;
      for (float h : plain.samples) receivers += !std::isnan(h);
      for (const NamedTuning& variant : kTunings) {
        SCOPED_TRACE(std::string(variant.name) + ", " + std::to_string(field.width) + "x" +
                     std::to_string(field.height) + ", azimuth " + std::to_string(azimuth));
        const auto v =
            detail::intervisibilityLinesOnDevice(testContext(), field, prepared, d, variant.tuning);
        ASSERT_TRUE(nearlyEqual(v.counts, plain.counts, 0.0f));
        ASSERT_TRUE(nearlyEqual(v.distance_sums, plain.distance_sums, 0.0f));
        ASSERT_EQ(v.horizons, plain.horizons);
        ASSERT_EQ(v.horizon_hashes, plain.horizon_hashes);
        std::uint64_t t = 0;
        for (auto x : v.iterations) t += x;
        std::uint64_t skipped = 0;
        for (auto x : v.walks_skipped) skipped += x;
        for (std::size_t e = 0; e < v.iterations.size(); ++e) {
          if (variant.tuning.replacement_check) {  // one more check per node: the sample, its peak
            ASSERT_LE(v.iterations[e], plain.iterations[e] + 2) << e;
          }
          if (variant.tuning.safe_zone) {
            ASSERT_LE(v.iterations[e], no_zone.iterations[e]) << e;
          }
          ASSERT_GE(v.iterations[e], v.walks_skipped[e]) << e;  // a skipped walk costs its check
        }
        if (!variant.tuning.safe_zone) {
          EXPECT_EQ(skipped, 0u);
        } else if (field.width == 256) {
          EXPECT_GT(skipped, 0u);
        }
        if (!variant.tuning.replacement_check) {
          EXPECT_EQ(v.iterations, plain.iterations);
        } else {
          // At most one check more per receiver: the last child's, when an earlier child
          // passes as well.
          EXPECT_LE(t, plain_t + receivers);
          if (field.width == 256) {
            EXPECT_LT(double(t), 0.9 * double(plain_t));
          }
        }
      }
    }
  }
}

// Long lines of tie-rich random heights (small integers), smooth random walks and float
// noise, on one axis direction so every line is long; and the bowl's quadratic worst case.
TEST(IntervisibilityLine, TreeEqualsBruteForceOnLongRandomLines) {
  std::mt19937 rng(5);
  std::uint64_t checked = 0;
  for (int kind = 0; kind < 4; ++kind) {
    const int w = 301, h = 5;
    const HeightField field = fieldFrom(w, h, testing::randomLineHeights(kind, w, h, 100.0f, rng));
    for (auto step : {std::pair<int, int>{1, 0}, {-1, 0}, {20, 1}}) {
      for (const NamedTuning& variant : kTunings) {
        SCOPED_TRACE("kind " + std::to_string(kind) + " step " + std::to_string(step.first) + ", " +
                     variant.name);
        expectTreeEqualsBruteForce(field, treeStep(field, step), true, &checked, variant.tuning);
        if (::testing::Test::HasFatalFailure()) return;
      }
    }
  }
  const HeightField bowl = makeSyntheticField("bowl", 257, 3, 1);
  // Denser sampling: samples between pixels, several per bilinear cell.
  const HeightField noise = makeSyntheticField("noise", 23, 17, 4);
  for (const NamedTuning& variant : kTunings) {
    SCOPED_TRACE(variant.name);
    expectTreeEqualsBruteForce(bowl, treeStep(bowl, {1, 0}), true, &checked, variant.tuning);
    expectTreeEqualsBruteForce(noise, treeStep(noise, {1, 2}, 3.0), true, &checked, variant.tuning);
  }
}

// Far from 0 the tie rule forgives more (its rounding grows with the heights' absolute value,
// prepared height + base): kernel, reference and brute force still agree when they take the base
// that production passes, on hard cases lifted by 1e3 and 1e5 and on an exactly tilted plane
// at 1000 m, in both layouts (expectTreeEqualsBruteForce alternates them); and the rule is put
// to work there, not only allowed.
TEST(IntervisibilityLine, TreeEqualsBruteForceFarFromZero) {
  std::uint64_t checked = 0, forgiven = 0;
  auto check = [&](const HeightField& field, const std::string& what) {
    const auto prepared = detail::prepareHeights(field);
    ASSERT_GT(prepared.base, 900.0f) << what;
    for (auto step : {std::pair<int, int>{1, 0}, {-2, 1}, {3, -2}}) {
      for (const NamedTuning& variant : {kTunings[0], kTunings[2], kTunings[3]}) {
        SCOPED_TRACE(what + " step " + std::to_string(step.first) + "," + std::to_string(step.second) + ", " +
                     variant.name);
        expectTreeEqualsBruteForce(field, treeStep(field, step), true, &checked, variant.tuning, nullptr,
                                   &forgiven);
        if (::testing::Test::HasFatalFailure()) return;
      }
    }
  };
  for (const float lift : {1e3f, 1e5f}) {
    for (const char* name : {"city", "noise", "terraces", "spikes", "tilted_plane"}) {
      HeightField field = makeSyntheticField(name, 37, 29, 7);
      for (float& z : field.heights) z += lift;
      check(field, std::string(name) + " + " + std::to_string(lift));
      if (::testing::Test::HasFatalFailure()) return;
    }
  }
  std::vector<float> plane(48 * 20);
  for (int r = 0; r < 20; ++r)
    for (int c = 0; c < 48; ++c) plane[static_cast<std::size_t>(r) * 48 + c] = 1000.0f + 2.6255f * c;
  check(fieldFrom(48, 20, plane), "tilted plane at 1000");
  EXPECT_GT(checked, 20000u);
  EXPECT_GT(forgiven, 1000u) << "the rounding forgave no hidden sample: the base was not taken";
}

// The worst case of Section 6: on the bowl (every other point depressed) horizons and
// iterations grow linearly per receiver, and still t <= 2m + n.
TEST(IntervisibilityLine, BowlIsQuadraticButWithinTheBound) {
  const HeightField bowl = makeSyntheticField("bowl", 201, 1, 1);
  const auto prepared = detail::prepareHeights(bowl);
  const auto lines =
      detail::intervisibilityLinesOnDevice(testContext(), bowl, prepared, treeStep(bowl, {1, 0}));
  std::uint64_t m = 0, t = 0, n = 0;
  for (std::size_t e = 0; e < lines.samples.size(); ++e) {
    if (std::isnan(lines.samples[e])) continue;
    m += lines.horizons[e], t += lines.iterations[e], ++n;
  }
  EXPECT_EQ(n, 201u);
  EXPECT_GT(m, n * n / 8) << "the bowl should have many horizons per receiver";
  EXPECT_LE(t, 2 * m + n);
}

// ---------------------------------------------------------------------------------------
// Whole operation: kernels against references, sweep against naive, analytic values.

IntervisibilityOutputs allOutputs() {
  IntervisibilityOutputs o;
  o.visible_count = o.visible_area = o.statistics = true;
  return o;
}

void expectStatisticsEqual(const IntervisibilityStatistics& a, const IntervisibilityStatistics& b) {
  EXPECT_EQ(a.receivers, b.receivers);
  EXPECT_EQ(a.lines, b.lines);
  EXPECT_EQ(a.horizons, b.horizons);
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.visible_samples, b.visible_samples);
  EXPECT_EQ(a.naive_iterations, b.naive_iterations);
  EXPECT_EQ(a.lines_over_bound, b.lines_over_bound);
  EXPECT_EQ(a.safe_zone_skips, b.safe_zone_skips);
}

// Areas relative to their size.
float areaTolerance(const std::vector<float>& area) {
  float largest = 0.0f;
  for (float a : area)
    if (!std::isnan(a)) largest = std::max(largest, a);
  return 1e-5f * largest + 1e-6f;
}

// In both layouts; the tree with statistics (every sample reads its horizons) and without
// (only receivers do: the production path).
void expectKernelMatchesReference(IntervisibilityMethod method, double samples_per_unit,
                                  const HullTreeTuning& tuning = {}, double curvature = 0.0,
                                  double max_distance = 0.0, bool row_spacing = false) {
  testing::forEachLayout([&](const ComputeContext& context) {
    for (const auto& name : syntheticFieldNames()) {
      for (auto [w, h] : awkwardSizes()) {
        SCOPED_TRACE(name + " " + std::to_string(w) + "x" + std::to_string(h));
        HeightField field = makeSyntheticField(name, w, h, 3);
        field.cell_size_x = 1.5;
        if (row_spacing) testing::setRowSpacing(field);
        IntervisibilityOptions options;
        options.directions = 7;
        options.azimuth_offset = 0.1;
        options.method = method;
        options.samples_per_unit = samples_per_unit;
        options.tree = tuning;
        options.curvature = curvature;
        options.max_distance = max_distance;
        for (bool statistics : {true, false}) {
          if (statistics && method != IntervisibilityMethod::HullTree) continue;
          auto outputs = allOutputs();
          outputs.statistics = statistics;
          const auto device = computeIntervisibility(context, field, options, outputs);
          const auto reference = referenceIntervisibility(field, options, outputs);
          // The same float operations in the same order: equal bit for bit (NaN at nodata).
          EXPECT_TRUE(nearlyEqual(device.visible_count, reference.visible_count, 0.0f)) << statistics;
          EXPECT_TRUE(nearlyEqual(device.visible_area, reference.visible_area, 0.0f)) << statistics;
          if (!statistics) continue;
          if (!tuning.safe_zone ||
              context.device().correctly_rounded_divide)  // see expectTreeEqualsBruteForce
            expectStatisticsEqual(device.statistics, reference.statistics);
          EXPECT_EQ(device.statistics.lines_over_bound, 0u);
        }
      }
    }
  });
}

TEST(IntervisibilityKernels, TreeMatchesScalarReference) {
  expectKernelMatchesReference(IntervisibilityMethod::HullTree, 1.0);
}

TEST(IntervisibilityKernels, TreeMatchesScalarReferenceWithDenserSampling) {
  expectKernelMatchesReference(IntervisibilityMethod::HullTree, 2.5);
}

// The whole operation (sampling, sweep, pixel sums, statistics) in the other tunings.
TEST(IntervisibilityKernels, TreeMatchesScalarReferenceInEveryTuning) {
  for (const char* name : {"plain", "deferred", "zone"}) {
    SCOPED_TRACE(name);
    expectKernelMatchesReference(IntervisibilityMethod::HullTree, 1.0, *hullTreeTuningNamed(name));
  }
}

// The prepass (kernel intervisibility_peaks) on one field and direction against the reference:
// every step's sample height and the peak before it that the tree inserts (tree_peak_inserted of
// the reference's candidate), bit for bit, and that peak's position. Counts the present samples
// and the inserted peaks.
void expectPeakPrepassMatchesReference(const ComputeContext& context, const HeightField& field,
                                       const std::vector<float>& prepared, std::pair<int, int> step,
                                       float drop, std::size_t& samples, std::size_t& peaks) {
  detail::TreeDirection d = treeStep(field, step);
  d.drop = drop;
  const auto ref = detail::latticeTreeLines(field, prepared, d, drop != 0.0f);
  const auto dev = detail::treePeakInputsOnDevice(detail::stateOf(context), field, prepared, d);
  const int n_lines = ref.geometry.n_lines, scale = 1 << ref.position_shift;
  ASSERT_EQ(dev.samples.size(), ref.samples.size());
  for (std::size_t e = 0; e < ref.samples.size(); ++e) {
    const int i = static_cast<int>(e / n_lines);
    ASSERT_TRUE(nearlyEqual({dev.samples[e]}, {ref.samples[e]}, 0.0f)) << "entry " << e;
    float expected = std::numeric_limits<float>::quiet_NaN();
    if (i > 0 && scale > 1 &&
        detail::tree_peak_inserted(ref.samples[e - n_lines], ref.peaks[e], ref.samples[e],
                                   ref.peak_offsets[e], scale))
      expected = ref.peaks[e];
    ASSERT_TRUE(nearlyEqual({dev.peaks[e]}, {expected}, 0.0f)) << "entry " << e;
    samples += !std::isnan(ref.samples[e]);
    if (std::isnan(expected)) continue;
    ++peaks;
    ASSERT_EQ(dev.positions[e], ((i - 1) << ref.position_shift) + ref.peak_offsets[e]) << "entry " << e;
  }
}

// The peaks' prepass alone, in both layouts (8 lines a work-item in the line-major one, 1 in the
// step-major one), on every hard case and size, in every direction of kSteps, with and without
// the Earth's drop.
TEST(IntervisibilityKernels, PeakPrepassMatchesTheReference) {
  std::size_t samples = 0, peaks = 0;
  testing::forEachLayout([&](const ComputeContext& context) {
    for (const auto& name : syntheticFieldNames()) {
      for (auto [w, h] : awkwardSizes()) {
        const HeightField field = makeSyntheticField(name, w, h, 5);
        const auto prepared = detail::prepareHeights(field);
        for (auto step : kSteps) {
          for (float drop : {0.0f, 0.05f}) {
            SCOPED_TRACE(name + " " + std::to_string(w) + "x" + std::to_string(h) + " step " +
                         std::to_string(step.first) + "," + std::to_string(step.second) + " drop " +
                         std::to_string(drop));
            expectPeakPrepassMatchesReference(context, field, prepared.heights, step, drop, samples, peaks);
          }
        }
      }
    }
  });
  EXPECT_GT(samples, 100000u);
  EXPECT_GT(peaks, 10000u);
}

// Heights so small (about 1e-33) that the exact predicate's float filter cannot decide (its
// magnitudes fall below 2^-100): the prepass's lanes decide whether a peak enters lane by lane
// with the exact expansion, as the reference does.
TEST(IntervisibilityKernels, PeakPrepassMatchesTheReferenceOnTinyHeights) {
  std::size_t samples = 0, peaks = 0;
  testing::forEachLayout([&](const ComputeContext& context) {
    for (const char* name : {"noise", "city", "terraces"}) {
      HeightField field = makeSyntheticField(name, 41, 33, 7);
      for (float& v : field.heights) v *= 1e-35f;
      const auto prepared = detail::prepareHeights(field);
      for (auto step : kSteps) {
        SCOPED_TRACE(std::string(name) + " step " + std::to_string(step.first) + "," +
                     std::to_string(step.second));
        expectPeakPrepassMatchesReference(context, field, prepared.heights, step, 0.0f, samples, peaks);
      }
    }
  });
  EXPECT_GT(samples, 10000u);
  EXPECT_GT(peaks, 1000u);
}

// Earth curvature, large enough to matter on these small fields.
TEST(IntervisibilityKernels, TreeMatchesScalarReferenceWithCurvature) {
  expectKernelMatchesReference(IntervisibilityMethod::HullTree, 1.0, {}, 0.004);
}

TEST(IntervisibilityKernels, NaiveMatchesScalarReferenceWithCurvature) {
  expectKernelMatchesReference(IntervisibilityMethod::Naive, 1.0, {}, 0.004);
}

// Within a maximum distance (4.5 ground units: 3 pixels across, 4.5 along the columns).
TEST(IntervisibilityKernels, TreeMatchesScalarReferenceWithinAMaximumDistance) {
  expectKernelMatchesReference(IntervisibilityMethod::HullTree, 1.0, {}, 0.0, 4.5);
}

TEST(IntervisibilityKernels, NaiveMatchesScalarReferenceWithinAMaximumDistance) {
  expectKernelMatchesReference(IntervisibilityMethod::Naive, 1.0, {}, 0.0, 4.5);
}

// On rows of their own spacing (testing::setRowSpacing): plain, denser and in the safe zone's
// tuning (off there); curved and within a maximum distance.
TEST(IntervisibilityKernels, TreeMatchesScalarReferenceOnRowsOfTheirOwnSpacing) {
  expectKernelMatchesReference(IntervisibilityMethod::HullTree, 1.0, {}, 0.0, 0.0, true);
  expectKernelMatchesReference(IntervisibilityMethod::HullTree, 2.5, *hullTreeTuningNamed("zone"), 0.0, 0.0, true);
  expectKernelMatchesReference(IntervisibilityMethod::HullTree, 1.0, {}, 0.004, 4.5, true);
}

TEST(IntervisibilityKernels, NaiveMatchesScalarReferenceOnRowsOfTheirOwnSpacing) {
  expectKernelMatchesReference(IntervisibilityMethod::Naive, 1.0, {}, 0.0, 0.0, true);
  expectKernelMatchesReference(IntervisibilityMethod::Naive, 1.0, {}, 0.004, 4.5, true);
}

// On a flat plane within a maximum distance D, a pixel sees along each axis direction the
// min(D, distance to the edge) samples of its row or column, with both methods.
TEST(IntervisibilityAnalytic, FlatPlaneWithinAMaximumDistance) {
  const HeightField field = makeSyntheticField("flat", 21, 15);
  for (auto method : {IntervisibilityMethod::HullTree, IntervisibilityMethod::Naive}) {
    IntervisibilityOptions options;
    options.directions = 4;
    options.method = method;
    options.max_distance = 5.0;
    IntervisibilityOutputs outputs;
    outputs.visible_count = true;
    const auto r = computeIntervisibility(testContext(), field, options, outputs);
    for (int row = 0; row < field.height; ++row) {
      for (int c = 0; c < field.width; ++c) {
        const int expected = std::min(5, field.width - 1 - c) + std::min(5, c) + std::min(5, field.height - 1 - row) +
                             std::min(5, row);
        ASSERT_EQ(r.visible_count[row * field.width + c], float(expected)) << c << "," << row;
      }
    }
  }
}

// Flat ground over a curved Earth falls away from every receiver: along each direction only
// its nearest sample is seen (each farther one lies below the line of sight over it). At
// K = 4 (steps of one pixel) an interior pixel sees 4 samples, with both methods.
TEST(IntervisibilityAnalytic, FlatGroundOverACurvedEarthShowsOnlyTheNearestSamples) {
  const HeightField field = makeSyntheticField("flat", 21, 15);
  for (auto method : {IntervisibilityMethod::HullTree, IntervisibilityMethod::Naive}) {
    IntervisibilityOptions options;
    options.directions = 4;
    options.method = method;
    options.curvature = 0.001;
    IntervisibilityOutputs outputs;
    outputs.visible_count = true;
    const auto r = computeIntervisibility(testContext(), field, options, outputs);
    for (int row = 1; row < field.height - 1; ++row)
      for (int c = 1; c < field.width - 1; ++c)
        ASSERT_EQ(r.visible_count[row * field.width + c], 4.0f) << c << "," << row;
  }
}

// A tower of height 1 on flat ground over a curved Earth (drop c d^2) sees the ground out to
// about sqrt(1 / c): along a row, that many samples of the row's own east-west spacing. On a
// latitude / longitude grid the spacing shrinks toward the pole, so a tower near it sees more
// samples: K = 4, rows spaced 1 to 2 apart east-west and 1 north-south, towers at several
// rows (one field each), against the march of each axis in double on the true spacing, with
// both methods; and the centre row's spacing, as the whole field's, would be off by more.
TEST(IntervisibilityAnalytic, TowerOverACurvedEarthSeesItsRowsOwnSpacing) {
  const int width = 81, height = 41, col = 40;
  const double c = 0.001;
  auto spacing_x = [&](int row) { return 1.0 + double(row) / (height - 1); };
  // Visible samples along one axis from the tower: k = 1 .. samples at k * spacing.
  auto march = [&](int samples, double spacing) {
    double best = -1e300;
    int visible = 0;
    for (int k = 1; k <= samples; ++k) {
      const double d = k * spacing, slope = (-c * d * d - 1.0) / d;
      if (slope >= best) ++visible, best = slope;
    }
    return visible;
  };
  for (int tower_row : {3, 20, 37}) {
    SCOPED_TRACE("tower at row " + std::to_string(tower_row));
    std::vector<float> heights(std::size_t(width) * height, 0.0f);
    heights[std::size_t(tower_row) * width + col] = 1.0f;
    HeightField field = fieldFrom(width, height, heights);
    for (int r = 0; r < height; ++r) {
      field.row_cell_size_x.push_back(spacing_x(r));
      field.row_cell_size_y.push_back(1.0);
    }
    field.cell_size_x = spacing_x(height / 2);
    const int east_west = 2 * march(col, spacing_x(tower_row));
    const int north_south = march(tower_row, 1.0) + march(height - 1 - tower_row, 1.0);
    const int centre_row = 2 * march(col, spacing_x(height / 2)) + north_south;
    if (tower_row != 20) {
      EXPECT_GE(std::abs(east_west + north_south - centre_row), 8);
    }
    for (auto method : {IntervisibilityMethod::HullTree, IntervisibilityMethod::Naive}) {
      IntervisibilityOptions options;
      options.directions = 4;
      options.method = method;
      options.curvature = c;
      IntervisibilityOutputs outputs;
      outputs.visible_count = true;
      const auto r = computeIntervisibility(testContext(), field, options, outputs);
      EXPECT_EQ(r.visible_count[std::size_t(tower_row) * width + col], float(east_west + north_south))
          << (method == IntervisibilityMethod::Naive ? "naive" : "tree");
    }
  }
}

TEST(IntervisibilityKernels, NaiveMatchesScalarReference) {
  expectKernelMatchesReference(IntervisibilityMethod::Naive, 1.0);
}

// On the four axis directions the lines pass through the pixel centres, so the tree and
// the naive march see the very same samples: counts must be identical, areas equal to
// rounding; within a maximum distance too.
TEST(IntervisibilityKernels, TreeEqualsNaiveOnAxisDirections) {
  for (const auto& name : syntheticFieldNames()) {
    for (auto [w, h] : awkwardSizes()) {
      for (bool row_spacing : {false, true}) {  // also on rows of their own spacing (same units)
        SCOPED_TRACE(name + " " + std::to_string(w) + "x" + std::to_string(h) + (row_spacing ? " rows" : ""));
        HeightField field = makeSyntheticField(name, w, h, 5);
        field.cell_size_y = 0.5;
        if (row_spacing) testing::setRowSpacing(field);
        for (double max_distance : {0.0, 3.75}) {  // the whole field; 7 rows, 3 columns (uniform)
          IntervisibilityOptions options;
          options.directions = 4;
          options.max_distance = max_distance;
          IntervisibilityOutputs outputs;
          outputs.visible_count = outputs.visible_area = true;
          const auto tree = computeIntervisibility(testContext(), field, options, outputs);
          options.method = IntervisibilityMethod::Naive;
          const auto naive = computeIntervisibility(testContext(), field, options, outputs);
          EXPECT_TRUE(nearlyEqual(tree.visible_count, naive.visible_count, 0.0f)) << max_distance;
          // The area's factors round differently (2 pi w g^2 in double, then float), and with
          // per-row spacing the naive march sums its area in float.
          EXPECT_TRUE(nearlyEqual(tree.visible_area, naive.visible_area, areaTolerance(naive.visible_area)));
        }
      }
    }
  }
}

// Dense reference of the visible counts: K times the mean over azimuth of the visible length
// of a pixel's ray (in pixel lengths, the unit-step count's unit) on the bilinear surface,
// over 4 K azimuths, each marched in double at 1/8 pixel: a point is visible when its slope
// from the receiver is at least every nearer point's. The K directions of the sweep and of
// the naive march are two quadratures of the same azimuthal integral.
std::vector<double> denseVisibleCounts(const HeightField& field, const IntervisibilityOptions& options) {
  const auto h = detail::prepareHeights(field).heights;
  const int w = field.width, hh = field.height, dense = 8, azimuths = 4 * options.directions;
  auto at = [&](double x, double y) {
    const int x0 = std::min(static_cast<int>(x), w - 2), y0 = std::min(static_cast<int>(y), hh - 2);
    const double fx = x - x0, fy = y - y0;
    auto v = [&](int c, int r) { return double(h[static_cast<std::size_t>(r) * w + c]); };
    return (1 - fx) * (1 - fy) * v(x0, y0) + fx * (1 - fy) * v(x0 + 1, y0) + (1 - fx) * fy * v(x0, y0 + 1) +
           fx * fy * v(x0 + 1, y0 + 1);
  };
  std::vector<double> counts(field.pixelCount(), 0.0);
  for (int r = 0; r < hh; ++r) {
    for (int c = 0; c < w; ++c) {
      const double h0 = h[static_cast<std::size_t>(r) * w + c];
      for (int k = 0; k < azimuths; ++k) {
        const double phi = options.azimuth_offset + 2.0 * M_PI * k / azimuths, dx = std::cos(phi), dy = std::sin(phi);
        double best = -1e300;
        int visible = 0;
        for (int i = 1;; ++i) {
          const double t = double(i) / dense, x = c + t * dx, y = r + t * dy;
          if (x < -1e-9 || y < -1e-9 || x > w - 1 + 1e-9 || y > hh - 1 + 1e-9) break;
          const double slope = (at(std::clamp(x, 0.0, w - 1.0), std::clamp(y, 0.0, hh - 1.0)) - h0) / t;
          if (slope >= best) ++visible, best = slope;
        }
        counts[static_cast<std::size_t>(r) * w + c] += double(visible) / dense * options.directions / azimuths;
      }
    }
  }
  return counts;
}

// sum |count - reference| / sum reference over the pixels.
double relativeError(const std::vector<float>& counts, const std::vector<double>& reference) {
  double error = 0.0, total = 0.0;
  for (std::size_t p = 0; p < counts.size(); ++p) error += std::abs(counts[p] - reference[p]), total += reference[p];
  return error / total;
}

// The tree's receivers sit on the lattice lines through their own centres, at their own
// heights: its counts are as close to the dense reference as the per-pixel unit march's
// (the naive method, which marches each pixel's own ray) or closer (within 10 %), on smooth
// fields, real terrain and the rough hard cases. (The benchmark measures the same at scale.)
// Not on the float-quantised tilted plane: its visibility is a matter of exact ties, which
// the exact predicate keeps and the reference's double arithmetic breaks at random.
TEST(IntervisibilityKernels, TreeAsCloseToDenseReferenceAsTheNaiveMarch) {
  const HeightField fractal = readHeightField(std::string(HFVIS_DATA_DIR) + "/fractal_256.exr");
  for (const char* name : {"dome", "sine", "flat", "fractal", "noise", "terraces", "bowl"}) {
    SCOPED_TRACE(name);
    const int w = 64, h = 63;
    HeightField field = makeSyntheticField(name == std::string("fractal") ? "flat" : name, w, h, 5);
    if (name == std::string("fractal"))
      for (int r = 0; r < h; ++r)
        for (int c = 0; c < w; ++c) field.heights[r * w + c] = fractal.at(c + 100, r + 100);
    IntervisibilityOptions options;
    options.directions = 16;
    options.azimuth_offset = 0.2;
    IntervisibilityOutputs outputs;
    outputs.visible_count = true;
    const auto tree = computeIntervisibility(testContext(), field, options, outputs);
    options.method = IntervisibilityMethod::Naive;
    const auto naive = computeIntervisibility(testContext(), field, options, outputs);
    const auto dense = denseVisibleCounts(field, options);
    const double tree_error = relativeError(tree.visible_count, dense),
                 naive_error = relativeError(naive.visible_count, dense);
    std::printf("%-13s relative error against the dense reference: tree %.4f, naive %.4f\n", name, tree_error,
                naive_error);
    EXPECT_LE(tree_error, 1.1 * naive_error);
  }
}

// Issue 25's count target on the city DSM hard case (one-pixel streets and walls, roofs touching
// at corners, an axis grid and a rotated one) at K = 64, against the same reference dense in
// azimuth (256 directions): the tree no worse than the naive unit march.
TEST(IntervisibilityKernels, TreeNoWorseThanTheNaiveMarchOnACityAtK64) {
  const HeightField field = makeSyntheticField("city", 64, 63, 5);
  IntervisibilityOptions options;
  options.directions = 64;
  IntervisibilityOutputs outputs;
  outputs.visible_count = true;
  const auto tree = computeIntervisibility(testContext(), field, options, outputs);
  options.method = IntervisibilityMethod::Naive;
  const auto naive = computeIntervisibility(testContext(), field, options, outputs);
  const auto dense = denseVisibleCounts(field, options);
  const double tree_error = relativeError(tree.visible_count, dense),
               naive_error = relativeError(naive.visible_count, dense);
  std::printf("city, K = 64: relative error against the dense reference: tree %.4f, naive %.4f\n", tree_error,
              naive_error);
  EXPECT_LE(tree_error, naive_error);
}

// Each tree step stands for the wedge of azimuth of its phi_k, 1 / K, as each ray of the naive
// march does (a step that several phi_k share, at large K, for each of them): the weights are
// whole multiples of 1 / K that sum to 1, whatever the steps' own azimuths.
TEST(IntervisibilityDirections, EachTreeStepStandsForItsPhiKWedge) {
  HeightField field = makeSyntheticField("flat", 300, 200);
  for (int k : {16, 64, 1000, 4096}) {
    SCOPED_TRACE(k);
    SweepOptions options;
    options.directions = k;
    const auto lattice = detail::latticeDirections(field, options, false, 0.0);
    const auto tree = detail::treeDirections(field, options);
    double total = 0.0;
    std::size_t shared = 0;
    for (const detail::TreeDirection& d : tree) {
      int sweeps_for = 0;  // the phi_k whose lattice step is d's
      for (const auto& l : lattice) sweeps_for += l.a == d.lattice.a && l.b == d.lattice.b;
      EXPECT_NEAR(d.lattice.weight, double(sweeps_for) / k, 1e-12) << d.lattice.a << "," << d.lattice.b;
      shared += sweeps_for > 1;
      total += d.lattice.weight;
    }
    EXPECT_NEAR(total, 1.0, 1e-9);
    if (k == 4096) {
      EXPECT_GT(shared, 0u);  // the merged steps are covered
    }
  }
}

// A one-pixel street along the columns between walls 1000 high, seen from its west end: only
// the axis direction sees far (the street's 128 pixels); the others climb a wall within a few
// pixels. The count is about the street's length once, as the naive march's (170 here): the axis
// step stands for its wedge, 1 / K, not for the half gaps to the cheapest steps next to it (at
// K = 64, (7, 1) and (7, -1) at 8.1 deg against phi_1 = 5.6 deg: 1.45 / K, which counted the
// street's 128 pixels 1.45 times, 57 too many).
TEST(IntervisibilityAnalytic, AStreetAlongAnAxisCountsItsLengthOnce) {
  const int w = 129, h = 9;
  HeightField field = makeSyntheticField("flat", w, h);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) field.heights[static_cast<std::size_t>(r) * w + c] = r == 4 ? 0.0f : 1000.0f;
  IntervisibilityOptions options;
  options.directions = 64;
  IntervisibilityOutputs outputs;
  outputs.visible_count = true;
  const float tree = computeIntervisibility(testContext(), field, options, outputs).visible_count[4 * w];
  options.method = IntervisibilityMethod::Naive;
  const float naive = computeIntervisibility(testContext(), field, options, outputs).visible_count[4 * w];
  std::printf("street end: tree %.2f, naive %.2f\n", tree, naive);
  EXPECT_GE(tree, 128.0f);
  EXPECT_NEAR(tree, naive, 0.1f * naive);
}

// Analytic: on a flat plane every sample is visible. On the axes a pixel sees the rest of
// its row and column; with many directions the area seen from the centre tends to the
// field's area.
TEST(IntervisibilityAnalytic, FlatPlaneSeesEverything) {
  const int w = 31, h = 21;
  HeightField field = makeSyntheticField("flat", w, h);
  IntervisibilityOptions options;
  options.directions = 4;
  IntervisibilityOutputs outputs;
  outputs.visible_count = outputs.visible_area = true;
  const auto axes = computeIntervisibility(testContext(), field, options, outputs);
  for (float count : axes.visible_count) ASSERT_EQ(count, float(w + h - 2));
  options.directions = 256;
  field.cell_size_x = 2.0, field.cell_size_y = 3.0;
  const auto many = computeIntervisibility(testContext(), field, options, outputs);
  const std::size_t centre = static_cast<std::size_t>(h / 2) * w + w / 2;
  const double area = (w - 1) * 2.0 * (h - 1) * 3.0;
  EXPECT_NEAR(many.visible_area[centre] / area, 1.0, 0.04);
}

// Analytic: on a tilted plane, as on a flat one, every point sees every other (grazing sees).
// The samples' heights are bilinear interpolations rounded to floats, so a tilted plane's
// samples are collinear only up to their rounding, and decided exactly on those heights about
// half of them came out hidden (at K = 8 on the 48 x 64 plane h = 100 + 2.6255 column: a mean
// count of 83 for the tree and 81 for the naive march, against 209 and 207 flat). The tie rule
// forgives the rounding (kernels/shared/chord_side.cl): each method counts on every tilted plane
// what it counts on the flat one, in both layouts, also within a maximum distance and the tree in
// strips of rows. (On rows of
// their own spacing, a latitude / longitude grid, heights linear in the pixels are no plane.)
TEST(IntervisibilityAnalytic, EveryPointOfATiltedPlaneSeesEveryOther) {
  const int w = 48, h = 64;
  struct Plane {
    const char* name;
    float base, per_column, per_row;
  };
  const Plane planes[] = {{"whole numbers", 100.0f, 1.0f, 0.0f},
                          {"2.6255 a column", 100.0f, 2.6255f, 0.0f},
                          {"both axes, below zero", -50.0f, 0.75f, -1.3f},
                          {"steep, far from zero", 8848.0f, -40.0f, 17.0f},
                          // float32 rounds these at 500 and 1000, a spacing near the rise per cell
                          // (counted from the field's base, the same spacing or less)
                          {"gentle, far from zero", 500.0f, 0.1f, 0.0f},
                          {"half a per mille, far from zero", 1000.0f, 0.0f, 0.005f},
                          // crossing 0 mid-field, where the heights (counted from the base, their
                          // median) are near 0 and a sample's rounded position times the slope
                          // passed the tie rule's rounding: the naive count fell from 300 to 3 on
                          // a row of 2 (column - 50) (a probe's find)
                          {"steep, crossing 0 mid-field", -48.0f, 2.0f, 0.0f},
                          {"crossing 0 on a diagonal", -35.0f, 0.375f, 1.25f}};
  HeightField flat = makeSyntheticField("flat", w, h);
  flat.cell_size_x = flat.cell_size_y = 10.0;
  IntervisibilityOutputs outputs;
  outputs.visible_count = outputs.visible_area = true;
  testing::forEachLayout([&](const ComputeContext& context) {
    for (double max_distance : {0.0, 150.0}) {
      for (auto method : {IntervisibilityMethod::HullTree, IntervisibilityMethod::Naive}) {
        for (int k : {8, 16}) {
          IntervisibilityOptions options;
          options.method = method;
          options.max_distance = max_distance;
          options.directions = k;
          const auto expected = computeIntervisibility(context, flat, options, outputs);
          for (const Plane& plane : planes) {
            SCOPED_TRACE(std::string(plane.name) +
                         (method == IntervisibilityMethod::Naive ? ", naive" : ", tree") +
                         ", K = " + std::to_string(k) + ", max distance " + std::to_string(max_distance));
            HeightField field = flat;
            for (int r = 0; r < h; ++r)
              for (int c = 0; c < w; ++c)
                field.heights[static_cast<std::size_t>(r) * w + c] =
                    plane.base + plane.per_column * float(c) + plane.per_row * float(r);
            const auto tilted = computeIntervisibility(context, field, options, outputs);
            EXPECT_TRUE(nearlyEqual(tilted.visible_count, expected.visible_count, 0.0f));
            EXPECT_TRUE(nearlyEqual(tilted.visible_area, expected.visible_area, 0.0f));
            if (method != IntervisibilityMethod::HullTree) continue;
            // In strips of rows, the stretches reach back into the strips before.
            IntervisibilityOptions in_strips = options;
            in_strips.strip_rows = 5;
            const auto strips = computeIntervisibility(context, field, in_strips, outputs);
            EXPECT_TRUE(nearlyEqual(strips.visible_count, expected.visible_count, 0.0f));
          }
        }
      }
    }
  });
}

// What the rounding's tolerance must not forgive: a wall of 2 cm on a plane at 100 hides what is
// behind it, also where the heights are counted from far below (a base of -9999: a Dask chunk's
// origin may hold any base; the heights, about 10 100 above it, are then rounded to about a
// millimetre, and the tolerance is a few of those: an earlier one, 2^-18 of their sum, made a
// 5 cm wall transparent; counted from the lowest, one unflagged -9999 pixel did that), and on a
// tilted plane; in both layouts.
TEST(IntervisibilityAnalytic, AWallOfTwoCentimetresHidesWhateverTheBase) {
  testing::forEachLayout([&](const ComputeContext& context) {
    for (float tilt : {0.0f, 0.1f}) {
      for (bool far_base : {false, true}) {
        for (auto method : {IntervisibilityMethod::HullTree, IntervisibilityMethod::Naive}) {
          SCOPED_TRACE(std::string(method == IntervisibilityMethod::Naive ? "naive" : "tree") + ", tilt " +
                       std::to_string(tilt) + (far_base ? ", counted from -9999" : ""));
          const int w = 64, h = 16;
          std::vector<float> open(static_cast<std::size_t>(w) * h);
          for (int r = 0; r < h; ++r)
            for (int c = 0; c < w; ++c) open[static_cast<std::size_t>(r) * w + c] = 100.0f + tilt * float(c);
          std::vector<float> walled = open;
          for (int r = 0; r < h; ++r) walled[static_cast<std::size_t>(r) * w + 32] += 0.02f;
          HeightField plain = fieldFrom(w, h, open), wall = fieldFrom(w, h, walled);
          if (far_base) plain.origin = wall.origin = {0, 0, w, h, -9999.0};  // (its own larger field)
          IntervisibilityOptions options;
          options.directions = 8;
          options.method = method;
          IntervisibilityOutputs outputs;
          outputs.visible_count = true;
          const auto without = computeIntervisibility(context, plain, options, outputs);
          const auto with = computeIntervisibility(context, wall, options, outputs);
          const std::size_t before_wall = static_cast<std::size_t>(8) * w + 10;
          EXPECT_LT(with.visible_count[before_wall] + 20.0f, without.visible_count[before_wall]);
        }
      }
    }
  });
}

// Analytic: behind a wall nothing farther is seen; the wall's top is.
TEST(IntervisibilityAnalytic, WallHidesWhatIsBehindIt) {
  const int w = 21;
  std::vector<float> heights(w * 3, 0.0f);
  for (int r = 0; r < 3; ++r) heights[r * w + 10] = 100.0f;  // a wall at column 10
  const HeightField field = fieldFrom(w, 3, heights);
  const auto prepared = detail::prepareHeights(field);
  const auto d = treeStep(field, {1, 0});  // looking toward +x: one sample per pixel
  const auto lines = detail::intervisibilityLinesOnDevice(testContext(), field, prepared, d);
  for (int j = 0; j < lines.geometry.n_lines; ++j) {
    for (int i = 0; i < d.lines[j].receivers; ++i) {
      const std::size_t e = static_cast<std::size_t>(i) * lines.geometry.n_lines + j;
      const int column = d.lines[j].col - i;
      // Left of the wall: the ground up to the wall, and the wall; right of it: the rest.
      const int expected = column < 10 ? 10 - column : w - 1 - column;
      EXPECT_EQ(lines.counts[e], float(expected)) << "column " << column;
    }
  }
}

// The visible counts of lines' receivers by the exact line of sight on the bilinear surface
// (the viewshed's definition, checked densely: 64 points per step in double precision): a
// sample is hidden where the surface rises more than `tolerance` above the sight line strictly
// between it and the receiver. (A slope's samples are collinear only up to their rounding; the
// tie rule forgives it, so this need not.)
std::vector<int> exactCounts(const HeightField& field, const std::vector<float>& heights,
                             const detail::TreeDirection& d, const detail::IntervisibilityLines& lines, int j,
                             double tolerance) {
  const int n = static_cast<int>(d.samples.size()), steps = lines.geometry.n_steps;
  const detail::LatticeLine& line = d.lines[j];
  auto surface = [&](double u) {  // the surface at step position u of line j (NaN outside)
    const double x = line.col + (n - 1 - u) / n * d.lattice.a, y = line.row + (n - 1 - u) / n * d.lattice.b;
    const int x0 = std::min(static_cast<int>(std::floor(x)), field.width - 2);
    const int y0 = std::min(static_cast<int>(std::floor(y)), field.height - 2);
    if (x0 < 0 || y0 < 0) return std::nan("");
    const double fx = x - x0, fy = y - y0;
    auto at = [&](int c, int r) { return double(heights[static_cast<std::size_t>(r) * field.width + c]); };
    return at(x0, y0) * (1 - fx) * (1 - fy) + at(x0 + 1, y0) * fx * (1 - fy) +
           at(x0, y0 + 1) * (1 - fx) * fy + at(x0 + 1, y0 + 1) * fx * fy;
  };
  std::vector<int> counts(steps, -1);
  for (int r = 0; r < steps; ++r) {
    const float hr = lines.samples[static_cast<std::size_t>(r) * lines.geometry.n_lines + j];
    if (std::isnan(hr) || r % n != n - 1) continue;
    int count = 0;
    for (int x = 0; x < r; ++x) {
      const float hx = lines.samples[static_cast<std::size_t>(x) * lines.geometry.n_lines + j];
      if (std::isnan(hx)) continue;
      // The surface between them (the samples among its points).
      bool hidden = false;
      for (int k = 1; k < 64 * (r - x) && !hidden; ++k) {
        const double u = x + k / 64.0, sight = hx + (double(hr) - hx) * (u - x) / (r - x);
        hidden = surface(u) > sight + tolerance;
      }
      count += !hidden;
    }
    counts[r] = count;
  }
  return counts;
}

// The Earth's drop lowers a peak, not which point of its interval it is: the candidates (crossings,
// concave pieces' vertices) are points of the surface before the drop, so the chord they are
// measured against must be too. Measured against the lowered samples' chord, the drop's growth
// along an interval (2 drop step per step) would pick the candidate nearest the near sample far
// out on a line. With a drop large enough to dwarf the terrain, the reference (which the kernel
// equals) picks the same offset as without it, but for near-ties of the rounding.
TEST(IntervisibilityLattice, CurvatureLowersThePeaksNotTheirChoice) {
  const HeightField field = makeSyntheticField("city", 90, 70, 3);
  const auto prepared = detail::prepareHeights(field);
  for (const auto& step :
       {std::pair<int, int>{3, 1}, std::pair<int, int>{-4, 3}, std::pair<int, int>{5, -2}}) {
    SCOPED_TRACE(std::to_string(step.first) + "," + std::to_string(step.second));
    detail::TreeDirection d = treeStep(field, step);
    const auto flat = detail::latticeTreeLines(field, prepared.heights, d);
    d.drop = 0.05f;
    const auto curved = detail::latticeTreeLines(field, prepared.heights, d, true);
    std::size_t candidates = 0, moved = 0;
    for (std::size_t e = 0; e < flat.peaks.size(); ++e) {
      if (!std::isfinite(flat.peaks[e]) || !std::isfinite(curved.peaks[e])) continue;
      ++candidates;
      moved += flat.peak_offsets[e] != curved.peak_offsets[e];
    }
    EXPECT_GT(candidates, 1000u);
    EXPECT_LE(moved, candidates / 100) << moved << " of " << candidates << " peaks moved";
  }
}

// Roofs that touch at a corner and one-pixel walls, seen off the axes: between two of the
// tree's samples the bilinear surface rises above both (at a crossing, or at the vertex of a
// concave cell piece), and the samples alone see past it. Against the exact line of sight on
// the bilinear surface, the peaks as occluders put right the receivers the samples alone (the
// same lines, peaks dropped) get wrong, and break next to none.
TEST(IntervisibilityAnalytic, RoofsTouchingAtACornerHideWhatIsBehindThem) {
  const int w = 40, h = 40;
  std::vector<float> heights(static_cast<std::size_t>(w) * h, 0.0f);
  for (int r = 0; r < h; ++r)
    for (int c = 0; c < w; ++c) {
      float& z = heights[static_cast<std::size_t>(r) * w + c];
      if ((c <= 19 && r >= 20 && r < 26 && c > 13) || (c >= 20 && r <= 19 && c < 26 && r > 13))
        z = 12.0f;                      // roofs
      if (c == 30 && r > 4) z = 9.0f;   // a one-pixel wall
      if (c > 33) z = 1.5f * (c - 33);  // a slope beyond: its samples rise
    }
  const HeightField field = fieldFrom(w, h, heights);
  const auto prepared = detail::prepareHeights(field);
  std::int64_t with_error = 0, without_error = 0, receivers = 0, fixed = 0, broken = 0, more = 0;
  for (auto step : {std::pair<int, int>{2, 1}, {3, 1}, {3, 2}, {1, 2}, {-2, -1}, {2, -3}}) {
    const auto d = treeStep(field, step);
    const auto with = referenceLines(field, prepared, d);
    auto without = detail::latticeTreeLines(field, prepared.heights, d);
    without.height_base = prepared.base;
    without.position_shift = 0;
    without.peaks.clear();
    without.peak_offsets.clear();
    detail::sweepPresampledLines(without, {}, false);
    for (int j = 0; j < with.geometry.n_lines; ++j) {
      const auto exact = exactCounts(field, prepared.heights, d, with, j, 1e-4);
      for (int r = 0; r < with.geometry.n_steps; ++r) {
        if (exact[r] < 0) continue;
        const std::size_t e = static_cast<std::size_t>(r) * with.geometry.n_lines + j;
        more += with.counts[e] > without.counts[e];
        with_error += std::llabs(static_cast<long long>(with.counts[e]) - exact[r]);
        without_error += std::llabs(static_cast<long long>(without.counts[e]) - exact[r]);
        fixed += with.counts[e] == exact[r] && without.counts[e] != exact[r];
        broken += with.counts[e] != exact[r] && without.counts[e] == exact[r];
        ++receivers;
      }
    }
  }
  // One occluder per interval is not the whole upper hull of the surface between two samples
  // (two walls in one interval, a concave piece's curve): a few receivers keep an error.
  EXPECT_GT(receivers, 1000);
  EXPECT_GT(without_error, 1000) << "the case should need the peaks";
  EXPECT_LT(with_error * 10, without_error);
  // A peak hides what the surface does not only at the rounding of the samples' heights (a
  // roof's foot seen from the ground: the sample on the roof's edge comes out an ulp below the
  // straight line from the receiver through the peak on the slope).
  EXPECT_GT(fixed, 500);
  EXPECT_LE(broken * 50, fixed) << broken << " receivers see less than the surface allows";
  // Peaks hide: but a peak that is a horizon ends a stretch of samples forgiven their rounding
  // (run_end), which without it a sample farther out that is not forgiven would have cut.
  EXPECT_LE(more * 100, receivers) << more << " receivers see more with the peaks";
}

TEST(IntervisibilityKernels, BatchingUnderATinyMemoryBudgetChangesNothing) {
  const HeightField field = makeSyntheticField("noise", 40, 41, 9);
  testing::forEachLayout([&](const ComputeContext& context) {
  IntervisibilityOptions options;
  options.directions = 9;
  const auto outputs = allOutputs();
  const auto whole = computeIntervisibility(context, field, options, outputs);
  int reports = 0, last = 0;
  // The field's planes take 3 * 4 * 1640 bytes; the tree scratch (24 bytes per slot with the
  // peaks' prepass, two slots a step: at least 3280 slots per direction) gets room for 700 less
  // the statistics' per-line totals: every direction runs whole, in chunks of lines (not strips).
  options.memory_budget_bytes = 3 * 4 * 1640 + 24 * 700;
  options.strip_progress = [](int, int) { ADD_FAILURE() << "ran in strips, not in chunks of the whole field"; };
  options.progress = [&](int done, int all) {
    ++reports;
    last = done;
    EXPECT_EQ(all, 9);  // no two of the nine directions share a step here
  };
  const auto batched = computeIntervisibility(context, field, options, outputs);
  EXPECT_EQ(reports, 9);
  EXPECT_EQ(last, 9);
  EXPECT_TRUE(nearlyEqual(batched.visible_count, whole.visible_count, 0.0f));
  EXPECT_TRUE(nearlyEqual(batched.visible_area, whole.visible_area, 0.0f));
  expectStatisticsEqual(batched.statistics, whole.statistics);
  options.memory_budget_bytes = 1024;
  EXPECT_THROW(computeIntervisibility(context, field, options, outputs), MemoryBudgetError);
  });
}

// A field in strips of rows (forced with strip_rows): each line's tree stays on the device
// from strip to strip, so counts, areas and statistics equal the whole-field run bit for bit,
// on every hard case, in both layouts, in every tuning; with curvature within a maximum
// distance, denser sampling and rows of their own spacing.
TEST(IntervisibilityKernels, StripsEqualTheWholeFieldBitForBit) {
  auto expectEqual = [](const IntervisibilityResult& strips, const IntervisibilityResult& whole) {
    EXPECT_TRUE(nearlyEqual(strips.visible_count, whole.visible_count, 0.0f));
    EXPECT_TRUE(nearlyEqual(strips.visible_area, whole.visible_area, 0.0f));
    expectStatisticsEqual(strips.statistics, whole.statistics);
  };
  testing::forEachLayout([&](const ComputeContext& context) {
    for (const auto& name : syntheticFieldNames()) {
      for (auto [w, h] : {std::pair{1, 9}, std::pair{7, 13}, std::pair{33, 20}}) {
        const HeightField field = makeSyntheticField(name, w, h, 3);
        IntervisibilityOptions options;
        options.directions = 24;  // steps of up to 4 rows
        const auto whole = computeIntervisibility(context, field, options, allOutputs());
        for (int rows : {1, 6}) {
          SCOPED_TRACE(name + " " + std::to_string(w) + "x" + std::to_string(h) + ", strips of " +
                       std::to_string(rows) + " rows");
          options.strip_rows = rows;
          int strips = 0;
          const int strips_per_run = (h + rows - 1) / rows;  // (C++17 lambdas take no structured binding)
          options.strip_progress = [&](int done, int all) {
            EXPECT_EQ(all % strips_per_run, 0);  // chunks times strips
            strips += done == all;
          };
          expectEqual(computeIntervisibility(context, field, options, allOutputs()), whole);
          EXPECT_EQ(strips, int(detail::treeDirections(field, options).size()));  // one run per direction
          options.strip_progress = nullptr;
          options.strip_rows = 0;
        }
      }
    }
    HeightField field = makeSyntheticField("noise", 37, 45, 1);
    for (int variant = 0; variant < 5; ++variant) {
      SCOPED_TRACE("variant " + std::to_string(variant));
      IntervisibilityOptions options;
      options.directions = 16;
      if (variant == 0) options.curvature = 0.01, options.max_distance = 9.5;
      if (variant == 1) options.samples_per_unit = 2.5;
      if (variant == 2) testing::setRowSpacing(field);
      if (variant == 3) options.tree = *hullTreeTuningNamed("plain");
      if (variant == 4) options.tree = *hullTreeTuningNamed("zone");
      const auto whole = computeIntervisibility(context, field, options, allOutputs());
      options.strip_rows = 4;
      expectEqual(computeIntervisibility(context, field, options, allOutputs()), whole);
    }
  });
}

// A budget below the field's heights and sums runs it in strips by itself, with the same result;
// below one row's strip beside the longest line's tree it is a MemoryBudgetError.
TEST(IntervisibilityKernels, ABudgetBelowTheWholeFieldRunsItInStrips) {
  const HeightField field = makeSyntheticField("noise", 64, 60, 2);
  IntervisibilityOptions options;
  options.directions = 8;
  IntervisibilityOutputs outputs;
  outputs.visible_count = outputs.visible_area = true;
  const auto whole = computeIntervisibility(testContext(), field, options, outputs);
  options.memory_budget_bytes = 3 * 4 * 64 * 60 * 3 / 4;  // three quarters of the heights and sums
  int strips = 0;
  options.strip_progress = [&](int, int all) { strips = std::max(strips, all); };
  const auto in_strips = computeIntervisibility(testContext(), field, options, outputs);
  EXPECT_GT(strips, 1);
  EXPECT_TRUE(nearlyEqual(in_strips.visible_count, whole.visible_count, 0.0f));
  EXPECT_TRUE(nearlyEqual(in_strips.visible_area, whole.visible_area, 0.0f));
  options.memory_budget_bytes = 2048;
  EXPECT_THROW(computeIntervisibility(testContext(), field, options, outputs), MemoryBudgetError);
  options.memory_budget_bytes = 0;
  options.strip_rows = -1;
  EXPECT_THROW(computeIntervisibility(testContext(), field, options, outputs), InvalidArgument);
  options.strip_rows = 4;
  options.method = IntervisibilityMethod::Naive;
  EXPECT_THROW(computeIntervisibility(testContext(), field, options, outputs), InvalidArgument);
}

TEST(IntervisibilityKernels, NodataReceiversAreNaNAndNeverPoisonNeighbours) {
  for (const char* name : {"nan_holes", "infinities"}) {
    const HeightField field = makeSyntheticField(name, 33, 20, 2);
    IntervisibilityOptions options;
    options.directions = 8;
    IntervisibilityOutputs outputs;
    outputs.visible_count = outputs.visible_area = true;
    for (auto method : {IntervisibilityMethod::HullTree, IntervisibilityMethod::Naive}) {
      options.method = method;
      const auto r = computeIntervisibility(testContext(), field, options, outputs);
      for (std::size_t p = 0; p < field.pixelCount(); ++p) {
        const bool nodata = !std::isfinite(field.heights[p]);
        ASSERT_EQ(std::isnan(r.visible_count[p]), nodata) << name << " pixel " << p;
        ASSERT_EQ(std::isnan(r.visible_area[p]), nodata) << name << " pixel " << p;
      }
    }
  }
}

// The bundled fractal terrain: the bound holds on every line, and the statistics are of
// the paper's order (Table 2 at N = 1024: m_a = 9.25, t_a = 11.7; smaller here, N = 256).
TEST(IntervisibilityKernels, StatisticsOnTheFractalTerrain) {
  const HeightField field = readHeightField(std::string(HFVIS_DATA_DIR) + "/fractal_256.exr");
  IntervisibilityOptions options;
  options.directions = 8;
  options.azimuth_offset = 0.3;
  IntervisibilityOutputs outputs;
  outputs.statistics = true;
  const auto r = computeIntervisibility(testContext(), field, options, outputs);
  const auto& s = r.statistics;
  std::printf("fractal_256, K = 8: m_a %.2f, t_a %.2f, visible %.2f, naive %.1f per point and direction\n",
              s.meanHorizons(), s.meanIterations(), s.meanVisible(), s.meanNaiveIterations());
  EXPECT_EQ(s.lines_over_bound, 0u);
  EXPECT_GT(s.receivers, 8u * 256 * 256 * 9 / 10);
  EXPECT_GT(s.meanHorizons(), 1.0);
  EXPECT_LT(s.meanIterations(), 2 * s.meanHorizons() + 1);
  EXPECT_GE(s.meanVisible(), s.meanHorizons());
  EXPECT_LT(s.meanIterations(), 0.2 * s.meanNaiveIterations());
}

TEST(IntervisibilityKernels, InvalidOptionsAreRejectedBeforeLaunch) {
  const HeightField field = makeSyntheticField("flat", 5, 5);
  IntervisibilityOptions options;
  options.directions = 0;
  EXPECT_THROW(computeIntervisibility(testContext(), field, options, allOutputs()), InvalidArgument);
  options.directions = 4;
  EXPECT_THROW(computeIntervisibility(testContext(), field, options, IntervisibilityOutputs{}),
               InvalidArgument);
  options.samples_per_unit = 0.0;
  EXPECT_THROW(computeIntervisibility(testContext(), field, options, allOutputs()), InvalidArgument);
  options.samples_per_unit = 1.0;
  options.method = IntervisibilityMethod::Naive;
  const HeightField long_row = makeSyntheticField("flat", 1500, 1, 1);
  IntervisibilityOptions dense = options;
  dense.samples_per_unit = 64.0;  // 96064 samples a ray: distance sums past 32 bits
  IntervisibilityOutputs area;
  area.visible_area = true;
  EXPECT_THROW(computeIntervisibility(testContext(), long_row, dense, area), InvalidArgument);
  // statistics exist only for the tree
  EXPECT_THROW(computeIntervisibility(testContext(), field, options, allOutputs()), InvalidArgument);
  HeightField empty;
  EXPECT_THROW(computeIntervisibility(testContext(), empty, IntervisibilityOptions{}, allOutputs()),
               InvalidArgument);
  HeightField huge = field;
  huge.heights[0] = 1e36f;  // |h| * steps would overflow the predicate's products
  EXPECT_THROW(computeIntervisibility(testContext(), huge, IntervisibilityOptions{}, allOutputs()),
               InvalidArgument);
  IntervisibilityOptions zone;
  for (int steps : {0, 3, 8192}) {  // not a power of two in 1 .. 4096
    zone.tree.safe_zone_steps = steps;
    EXPECT_THROW(computeIntervisibility(testContext(), field, zone, allOutputs()), InvalidArgument) << steps;
  }
  zone.tree = {};
  zone.tree.deferred_writes = false;  // the replacement check works inside the deferred walk
  EXPECT_THROW(computeIntervisibility(testContext(), field, zone, allOutputs()), InvalidArgument);
  zone.tree = {};
  zone.tree.replacement_check = false;
  zone.tree.safe_zone = true;  // the safe zone needs the replacement check
  EXPECT_THROW(computeIntervisibility(testContext(), field, zone, allOutputs()), InvalidArgument);
}

}  // namespace
}  // namespace hfvis
