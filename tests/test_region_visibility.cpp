// test_region_visibility.cpp: region visibility (hfvis/region_visibility.hpp): the kernel
// against the scalar reference bit for bit on the hard cases in both layouts; A to B against the
// transpose of B to A; closed cases (flat ground, a wall, a tall light); one source against the
// viewshed; the samples' placement; bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <set>
#include <string>
#include <utility>

#include "core/sweep_geometry.hpp"
#include "hfvis/errors.hpp"
#include "hfvis/region_visibility.hpp"
#include "hfvis/viewshed.hpp"
#include "hfvis_testing/region_visibility_reference.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "hfvis_testing/viewshed_reference.hpp"
#include "ops/region_visibility_sight.hpp"
#include "test_support.hpp"

namespace hfvis {
namespace {

using testing::fieldFrom;
using testing::forEachLayout;
using testing::testContext;

// A rectangle of up to 5 x 4 points around the field's centre, or the first valid point alone
// where that one holds nodata.
RegionSampling sourcesIn(const HeightField& f, int samples, double height, bool absolute) {
  RegionSampling s;
  s.samples = samples;
  s.height = height;
  s.absolute = absolute;
  s.rectangle = {f.width / 2, f.height / 2, std::max(0, f.width / 2 - 4), std::max(0, f.height / 2 - 3)};
  try {
    validate(f, s);
  } catch (const InvalidArgument&) {
    const auto it =
        std::find_if(f.heights.begin(), f.heights.end(), [](float v) { return std::isfinite(v); });
    const int p = static_cast<int>(it - f.heights.begin());
    s.rectangle = {p % f.width, p / f.width, p % f.width, p / f.width};
  }
  return s;
}

// Equal bitmasks and fractions (NaN where NaN), the first differing receiver reported. The
// kernel and the reference run the same float operations; only a device without correctly
// rounded division (the crossings' parameters) may round a grazing pair the other way, on at
// most one pair in a thousand.
void expectSame(const RegionVisibilityResult& got, const RegionVisibilityResult& want) {
  ASSERT_EQ(got.words, want.words);
  ASSERT_EQ(got.bits.size(), want.bits.size());
  const bool exact = testContext().device().correctly_rounded_divide;
  std::size_t differ = 0;
  for (std::size_t i = 0; i < got.bits.size(); ++i) {
    differ += __builtin_popcount(got.bits[i] ^ want.bits[i]);
    if (exact && got.bits[i] != want.bits[i]) {
      ADD_FAILURE() << "receiver " << i / got.words << " word " << i % got.words << ": device " << std::hex
                    << got.bits[i] << ", reference " << want.bits[i];
      return;
    }
  }
  EXPECT_LE(differ, got.bits.size() * 32 / 1000);
  if (!exact) return;
  for (std::size_t p = 0; p < got.fraction.size(); ++p)
    if (!(got.fraction[p] == want.fraction[p] ||
          (std::isnan(got.fraction[p]) && std::isnan(want.fraction[p])))) {
      ADD_FAILURE() << "fraction at " << p << ": " << got.fraction[p] << " vs " << want.fraction[p];
      break;
    }
}

// The exact march and the culled one (the library's default), each against the reference.
class RegionMethods : public ::testing::TestWithParam<RegionVisibilityMethod> {};

INSTANTIATE_TEST_SUITE_P(RegionVisibility, RegionMethods,
                         ::testing::Values(RegionVisibilityMethod::Exact, RegionVisibilityMethod::Culled),
                         [](const auto& info) {
                           return std::string(info.param == RegionVisibilityMethod::Exact ? "Exact"
                                                                                          : "Culled");
                         });

TEST_P(RegionMethods, KernelMatchesTheReferenceOnEveryHardCase) {
  std::size_t visible = 0, bits = 0;
  forEachLayout([&](const ComputeContext& context) {
    testing::forEachHardCase([&](const std::string& name, const HeightField& field) {
      // 40 samples: a second, partly filled word. Relative and absolute heights, shared and
      // decorrelated jitter, curvature and a maximum distance.
      RegionVisibilityOptions options;
      options.method = GetParam();
      options.target_height = 0.5;
      options.seed = 7;
      const RegionSampling above = sourcesIn(field, 40, 1.5, false);
      expectSame(computeRegionVisibility(context, field, above, options),
                 referenceRegionVisibility(field, above, options));
      options.decorrelate = true;
      options.curvature = 0.002;
      options.max_distance = 20.0;
      const RegionVisibilityResult got = computeRegionVisibility(context, field, above, options);
      expectSame(got, referenceRegionVisibility(field, above, options));
      for (float f : got.fraction)
        if (std::isfinite(f)) visible += static_cast<std::size_t>(std::lround(f * 40)), bits += 40;
      options = {};
      options.method = GetParam();
      RegionSampling light = sourcesIn(field, 33, 4.0, true);
      // A plane near the heights (the cliff's are 1e6).
      for (float v : field.heights)
        if (std::isfinite(v)) light.height = std::max(light.height, double(v) * field.z_scale + 0.5);
      expectSame(computeRegionVisibility(context, field, light, options),
                 referenceRegionVisibility(field, light, options));
      (void)name;
    });
  });
  // Both answers occur often: the comparison is not between two all-clear results.
  EXPECT_GT(visible, bits / 10);
  EXPECT_LT(visible, bits * 9 / 10);
}

TEST_P(RegionMethods, PairMatchesTheReference) {
  for (const char* name : {"city", "noise", "nan_holes"}) {
    SCOPED_TRACE(name);
    const HeightField field = makeSyntheticField(name, 40, 41, 3);
    RegionSampling a, b;
    a.rectangle = {2, 3, 8, 6};
    a.samples = 45;
    a.height = 1.0;
    b.rectangle = {35, 37, 30, 28};
    b.samples = 20;
    b.height = 3.0;
    try {
      validate(field, a), validate(field, b);
    } catch (const InvalidArgument&) {  // nan_holes: its first and last valid points
      const auto first =
          std::find_if(field.heights.begin(), field.heights.end(), [](float v) { return std::isfinite(v); });
      const auto last = std::find_if(field.heights.rbegin(), field.heights.rend(),
                                     [](float v) { return std::isfinite(v); });
      const int p = static_cast<int>(first - field.heights.begin());
      const int q = static_cast<int>(field.heights.rend() - last) - 1;
      a.rectangle = {p % 40, p / 40, p % 40, p / 40};
      b.rectangle = {q % 40, q / 40, q % 40, q / 40};
    }
    for (bool decorrelate : {false, true}) {
      RegionVisibilityOptions options;
      options.method = GetParam();
      options.decorrelate = decorrelate;
      forEachLayout([&](const ComputeContext& context) {
        const RegionPairVisibilityResult got = computeRegionPairVisibility(context, field, a, b, options);
        const RegionPairVisibilityResult want = referenceRegionPairVisibility(field, a, b, options);
        EXPECT_EQ(got.pairs, want.pairs);
        // Bit for bit where the device divides correctly rounded (see expectSame).
        if (!context.device().correctly_rounded_divide) return;
        EXPECT_EQ(got.bits, want.bits);
        EXPECT_EQ(got.clear_pairs, want.clear_pairs);
        EXPECT_EQ(got.pairs, std::uint64_t(a.samples) * b.samples);
        EXPECT_EQ(got.source_fraction, want.source_fraction);
        EXPECT_EQ(got.receiver_fraction, want.receiver_fraction);
      });
    }
  }
}

// The lowest and highest finite heights of a field.
std::pair<double, double> finiteHeightRange(const HeightField& field) {
  double bottom = 1e30, top = -1e30;
  for (float v : field.heights)
    if (std::isfinite(v)) top = std::max(top, double(v)), bottom = std::min(bottom, double(v));
  return {bottom, top};
}

// The culled march leaps over blocks of up to 2^k cells: on fields large enough for several levels,
// and sight lines long enough to leap, its bits are the exact march's, bit for bit (both run on
// the device: no rounding of the reference's division to excuse), in both layouts. Area lights
// just above the surface and high above it, ground-level region pairs across the field, with
// curvature and without; the city's one-pixel walls, towers and corner contacts, nodata holes,
// infinite heights, a cliff of 1e6 and a plane 8848 high, where the rounding margin matters.
TEST(RegionVisibility, TheCulledMarchIsTheExactOne) {
  std::size_t clear = 0, total = 0;
  int many_words_fields = 0;  // fields and layouts where the many-words pair ran
  for (const char* name : {"city", "noise", "sine", "bowl", "nan_holes", "infinities", "cliff",
                           "tilted_plane", "terraces", "spikes", "dome"}) {
    SCOPED_TRACE(name);
    HeightField field = makeSyntheticField(name, 101, 77, 5);
    field.cell_size_y = 1.25;
    const std::pair<double, double> range = finiteHeightRange(field);
    const double bottom = range.first, top = range.second;
    forEachLayout([&](const ComputeContext& context) {
      RegionVisibilityOptions exact, culled;
      exact.method = RegionVisibilityMethod::Exact;
      culled.method = RegionVisibilityMethod::Culled;
      for (double above : {0.5 * (top - bottom), 2.0 + (top - bottom)}) {
        RegionSampling light = sourcesIn(field, 40, bottom + above, true);
        for (bool curved : {false, true}) {
          exact.curvature = culled.curvature = curved ? 0.0005 : 0.0;
          exact.target_height = culled.target_height = curved ? 1.0 : 0.0;
          const RegionVisibilityResult want = computeRegionVisibility(context, field, light, exact);
          const RegionVisibilityResult got = computeRegionVisibility(context, field, light, culled);
          ASSERT_EQ(got.bits.size(), want.bits.size());
          for (std::size_t i = 0; i < got.bits.size(); ++i)
            ASSERT_EQ(got.bits[i], want.bits[i]) << "receiver " << i / got.words << " word " << i % got.words;
          for (std::uint32_t w : got.bits) clear += __builtin_popcount(w), total += 32;
        }
      }
      RegionSampling a, b;
      a.rectangle = {0, 0, 20, 30};
      b.rectangle = {100, 76, 80, 50};
      a.samples = 96;
      b.samples = 80;
      a.height = 1.0, b.height = 3.0;
      try {
        validate(field, a), validate(field, b);
      } catch (const InvalidArgument&) {
        return;  // nodata in a rectangle: the light above covered this field
      }
      const RegionPairVisibilityResult want = computeRegionPairVisibility(context, field, a, b, exact);
      const RegionPairVisibilityResult got = computeRegionPairVisibility(context, field, a, b, culled);
      EXPECT_EQ(got.bits, want.bits);
      clear += got.clear_pairs, total += got.pairs;
      // Many words per receiver (the hiding cell carried from word to word, and the cell at the
      // same fraction of the next line tried), sight lines across the whole field.
      RegionSampling left, right;
      left.rectangle = {0, 0, 25, 76};
      right.rectangle = {100, 0, 75, 76};
      left.samples = 256, right.samples = 64;
      left.height = 0.5, right.height = 1.5;
      try {
        validate(field, left), validate(field, right);
      } catch (const InvalidArgument&) {
        return;  // a rectangle over nodata (nan_holes, infinities)
      }
      ++many_words_fields;
      for (bool decorrelate : {false, true}) {
        exact.decorrelate = culled.decorrelate = decorrelate;
        const RegionPairVisibilityResult all =
            computeRegionPairVisibility(context, field, right, left, exact);
        EXPECT_EQ(computeRegionPairVisibility(context, field, right, left, culled).bits, all.bits);
        clear += all.clear_pairs, total += all.pairs;
      }
      exact.decorrelate = culled.decorrelate = false;
    });
  }
  // Both answers occur often.
  EXPECT_GT(clear, total / 10);
  EXPECT_LT(clear, total * 9 / 10);
  // Every field without nodata under those rectangles ran it, in both layouts.
  EXPECT_GE(many_words_fields, 2 * 9) << "the many-words pair ran too seldom";
}

// Ground-level squares (one sample a pixel, 1 and 2 above the surface) on fields large enough
// for long runs of leaps, the benchmark's shape: most lines graze the surface near both ends, so
// the culled march leaps, resumes its state near an end and steps there. Its bits are the exact
// march's, on the city's walls and towers, flat ground, rough noise and nodata holes, in both
// layouts, with curvature and without.
TEST(RegionVisibility, TheCulledMarchIsTheExactOneNearTheGround) {
  std::uint64_t clear = 0, pairs = 0;
  int ran = 0;
  for (const char* name : {"city", "noise", "terraces", "nan_holes", "flat"}) {
    SCOPED_TRACE(name);
    const HeightField field = makeSyntheticField(name, 160, 130, 11);
    RegionSampling a, b;
    a.rectangle = {20, 50, 43, 73};
    b.rectangle = {115, 60, 138, 83};
    a.samples = b.samples = 576;
    a.height = 1.0, b.height = 2.0;
    try {
      validate(field, a), validate(field, b);
    } catch (const InvalidArgument&) {  // nodata under a square: a point each on valid heights
      const auto valid = [&](int c0, int r0) {
        for (int r = r0; r < r0 + 24; ++r)
          for (int c = c0; c < c0 + 24; ++c)
            if (std::isfinite(field.at(c, r))) return PixelRectangle{c, r, c, r};
        ADD_FAILURE() << "no valid height in the square at " << c0 << "," << r0;
        return PixelRectangle{};
      };
      a.rectangle = valid(20, 50), b.rectangle = valid(115, 60);
      a.samples = b.samples = 1;
    }
    forEachLayout([&](const ComputeContext& context) {
      for (double curvature : {0.0, 0.0005}) {
        RegionVisibilityOptions exact, culled;
        exact.method = RegionVisibilityMethod::Exact;
        culled.method = RegionVisibilityMethod::Culled;
        exact.curvature = culled.curvature = curvature;
        const RegionPairVisibilityResult want = computeRegionPairVisibility(context, field, a, b, exact);
        const RegionPairVisibilityResult got = computeRegionPairVisibility(context, field, a, b, culled);
        ASSERT_EQ(got.bits.size(), want.bits.size());
        for (std::size_t i = 0; i < got.bits.size(); ++i)
          ASSERT_EQ(got.bits[i], want.bits[i]) << "receiver " << i / got.words << " word " << i % got.words;
        if (std::string(name) == "flat" && curvature == 0.0) {
          EXPECT_EQ(got.clear_pairs, got.pairs);  // flat ground sees (the curved earth hides some)
        }
        clear += got.clear_pairs, pairs += got.pairs;
        ++ran;
      }
    });
  }
  EXPECT_EQ(ran, 5 * 2 * 2);
  // Both answers occur often (flat ground all clear, the rest mixed).
  EXPECT_GT(clear, pairs / 5);
  EXPECT_LT(clear, pairs * 4 / 5);
}

// The culling pyramid over a field whose every height is finite (cullPyramid's row-by-row pass):
// each level's block holds the highest corner of the cells in it, brute force, and the margin and
// gradient come from the field's largest height, step and twist; and the checked path (for fields
// with non-finite heights) gives the same pyramid on them.
TEST(RegionVisibility, CullPyramidHoldsEachBlocksHighestCorner) {
  for (const char* name : {"city", "noise", "terraces", "spikes", "tilted_plane"}) {
    SCOPED_TRACE(name);
    const HeightField field = makeSyntheticField(name, 75, 42, 5);
    const std::vector<float> h = detail::prepareHeights(field, detail::HeightOrigin::Zero).heights;
    const detail::CullPyramid pyramid = detail::cullPyramid(h, field.width, field.height);
    const int w = field.width, hh = field.height;
    ASSERT_TRUE(pyramid.finite);
    ASSERT_EQ(pyramid.levels, 8);  // 74 x 41 cells, 37 x 21, ..., 2 x 1, 1 x 1
    // The path for fields with non-finite heights gives the same pyramid, bit for bit.
    const detail::CullPyramid checked = detail::cullPyramid(h, field.width, field.height, true);
    EXPECT_EQ(checked.levels, pyramid.levels);
    EXPECT_EQ(checked.finite, pyramid.finite);
    EXPECT_EQ(checked.margin, pyramid.margin);
    EXPECT_EQ(checked.gradient, pyramid.gradient);
    EXPECT_EQ(checked.top, pyramid.top);
    double largest = 0.0, step = 0.0, twist = 0.0;
    for (int r = 0; r < hh; ++r)
      for (int c = 0; c < w; ++c) {
        const float v = h[std::size_t(r) * w + c];
        largest = std::max(largest, double(std::fabs(v)));
        if (c + 1 < w) step = std::max(step, double(std::fabs(h[std::size_t(r) * w + c + 1] - v)));
        if (r + 1 < hh) step = std::max(step, double(std::fabs(h[std::size_t(r + 1) * w + c] - v)));
        if (c + 1 < w && r + 1 < hh)
          twist =
              std::max(twist, std::fabs(double(v) - h[std::size_t(r) * w + c + 1] -
                                        h[std::size_t(r + 1) * w + c] + h[std::size_t(r + 1) * w + c + 1]));
      }
    EXPECT_EQ(pyramid.gradient, float(step + twist));
    EXPECT_EQ(pyramid.margin,
              float(8e-5 * largest + 4.0 * std::ldexp(double(std::max(w, hh)), -23) * (step + twist)));
    for (int k = 0; k < pyramid.levels; ++k) {
      const int kw = detail::region_cull_width(w, k), kh = detail::region_cull_width(hh, k);
      const int offset = detail::region_cull_offset(w, hh, k);
      for (int by = 0; by < kh; ++by)
        for (int bx = 0; bx < kw; ++bx) {
          float top = -std::numeric_limits<float>::infinity();
          for (int y = by << k; y <= std::min((by + 1) << k, hh - 1); ++y)
            for (int x = bx << k; x <= std::min((bx + 1) << k, w - 1); ++x)
              top = std::max(top, h[std::size_t(y) * w + x]);
          ASSERT_EQ(pyramid.top[offset + by * kw + bx], top) << "level " << k << " block " << bx << "," << by;
        }
    }
  }
}

// The per-end tables (region_end_table) certify only clear sight lines, and the march over the
// rest of a line (region_sight_visible_culled given both ends' certified stretches) gives the exact
// march's answer, with the pyramid and without, on the host: every line the tables certify whole is
// checked against the uncut march, and so is every partly certified one. Points just above the
// surface and higher, toward a square across the field (a cone of wedges) and toward their own
// square (every direction), with curvature and without, on the city's walls and towers, flat ground,
// terraces, spikes, nodata holes, infinite heights and a cliff of 1e6.
struct EndTableCounts {
  std::uint64_t lines = 0, whole = 0, part = 0, clear = 0;
};

// On `names` fields of width x height, 8 x 8 points in squares 24 pixels a side at (ax, ay) and
// (bx, by) (top-left corners), 3 pixels apart.
void checkEndTables(const std::vector<const char*>& names, int width, int height, float ax, float ay, float bx,
                    float by, EndTableCounts& counts) {
  std::uint64_t& lines = counts.lines;
  std::uint64_t& whole = counts.whole;
  std::uint64_t& part = counts.part;
  std::uint64_t& clear = counts.clear;
  for (const char* name : names) {
    SCOPED_TRACE(name);
    HeightField field = makeSyntheticField(name, width, height, 11);
    field.cell_size_y = 1.25;
    const std::vector<float> h = detail::prepareHeights(field, detail::HeightOrigin::Zero).heights;
    const detail::CullPyramid pyramid = detail::cullPyramid(h, field.width, field.height);
    ASSERT_GT(pyramid.levels, 3);
    struct End {
      float x, y, z;
      std::vector<float> rec;
    };
    float surface = 0.0f;
    for (const float v : h)
      if (std::isfinite(v)) surface = std::max(surface, std::fabs(v));
    // Points on a grid with a fractional offset in a square, `above` the surface; records toward
    // the rectangle `other` (the library's bound of the heights: the highest surface plus `above`).
    const auto ends = [&](float x0, float y0, float above, float curvature, const float* other) {
      std::vector<End> out;
      for (int j = 0; j < 8; ++j)
        for (int i = 0; i < 8; ++i) {
          End e{x0 + 3.0f * i + 0.37f, y0 + 3.0f * j + 0.61f, 0.0f, std::vector<float>(REGION_END_RECORD)};
          const float s = detail::region_surface_at(h.data(), field.width, field.height, e.x, e.y);
          if (!std::isfinite(s)) continue;
          e.z = s + above;
          detail::region_end_table(pyramid.top.data(), pyramid.levels, field.width, field.height,
                                   pyramid.margin, curvature, float(field.cell_size_x),
                                   float(field.cell_size_y), e.x, e.y, e.z, surface + above, other[0],
                                   other[1], other[2], other[3], e.rec.data());
          out.push_back(std::move(e));
        }
      return out;
    };
    const float square_a[4] = {ax, ay, ax + 24.0f, ay + 24.0f}, square_b[4] = {bx, by, bx + 24.0f, by + 24.0f};
    for (float above : {0.5f, 2.0f, 6.0f})
      for (float curvature : {0.0f, 0.0005f}) {
        const std::vector<End> a = ends(ax, ay, above, curvature, square_b),
                               b = ends(bx, by, above, curvature, square_a),
                               own = ends(ax, ay, above, curvature, square_a);
        // The reach from e toward p, as the kernel takes it.
        const auto reach = [&](const End& e, const End& p, float length) {
          const int w = detail::region_end_wedge(e.rec[0], e.rec[1], p.x - e.x, p.y - e.y);
          return w < 0 ? 0.0f
                       : detail::region_end_reach(e.rec.data() + 4 + 2 * w * REGION_END_BANDS, int(e.rec[2]),
                                                  length, e.z, p.z);
        };
        const auto check = [&](const End& p, const End& q) {
          const float length = std::sqrt((q.x - p.x) * (q.x - p.x) + (q.y - p.y) * (q.y - p.y));
          if (!(length > 0.0f)) return;
          const float rp = reach(p, q, length), rq = reach(q, p, length);
          const int exact = detail::region_sight_visible(h.data(), field.width, field.height,
                                                         float(field.cell_size_x), float(field.cell_size_y),
                                                         curvature, 0.0f, p.x, p.y, p.z, q.x, q.y, q.z);
          int blocked_at;
          for (int levels : {0, pyramid.levels}) {
            const int cut = detail::region_sight_visible_culled(
                h.data(), field.width, field.height, float(field.cell_size_x), float(field.cell_size_y),
                curvature, 0.0f, levels ? pyramid.top.data() : h.data(), levels, pyramid.margin, 1.0f, 0.0f,
                0.0f, 0.0f, p.x, p.y, p.z, q.x, q.y, q.z, rp, rq, &blocked_at);
            ASSERT_EQ(cut, exact) << p.x << "," << p.y << "," << p.z << " to " << q.x << "," << q.y << ","
                                  << q.z << ": certified " << rp << " + " << rq << " of " << length;
          }
          ++lines, clear += exact;
          if (rp + rq >= length) {
            ++whole;
            ASSERT_EQ(exact, 1);
          } else if (rp > 0.0f || rq > 0.0f) {
            ++part;
          }
        };
        for (const End& p : a)
          for (const End& q : b) {
            // q's record toward square a holds p's direction.
            check(p, q);
            if (::testing::Test::HasFatalFailure()) return;
          }
        for (const End& p : own)
          for (const End& q : own) check(p, q);
        if (::testing::Test::HasFatalFailure()) return;
      }
  }
}

TEST(RegionVisibility, EndTablesCertifyOnlyClearLines) {
  EndTableCounts c;
  checkEndTables({"city", "noise", "flat", "terraces", "spikes", "nan_holes", "infinities", "cliff", "tilted_plane"},
                 160, 130, 20.0f, 50.0f, 115.0f, 60.0f, c);
  if (::testing::Test::HasFatalFailure()) return;
  std::printf("%llu lines: %llu certified whole, %llu in part, %llu clear\n", (unsigned long long)c.lines,
              (unsigned long long)c.whole, (unsigned long long)c.part, (unsigned long long)c.clear);
  // The tables certify many clear lines whole and many in part, and not every line is clear.
  EXPECT_GT(c.whole, c.clear / 4);
  EXPECT_GT(c.part, c.lines / 20);
  EXPECT_LT(c.clear, c.lines * 9 / 10);
}

// The same far apart: squares about 1100 pixels apart reach the tables' outer bands (radii of
// hundreds of pixels, four bands to an octave) and the pyramid's upper levels.
TEST(RegionVisibility, EndTablesCertifyOnlyClearLinesFarApart) {
  EndTableCounts c;
  checkEndTables({"city", "noise", "terraces", "flat"}, 1200, 96, 20.0f, 30.0f, 1150.0f, 40.0f, c);
  if (::testing::Test::HasFatalFailure()) return;
  std::printf("%llu lines: %llu certified whole, %llu in part, %llu clear\n", (unsigned long long)c.lines,
              (unsigned long long)c.whole, (unsigned long long)c.part, (unsigned long long)c.clear);
  EXPECT_GT(c.whole + c.part, c.lines / 20);  // the far bands are used
  EXPECT_LT(c.clear, c.lines);
}

// The bitmask scatter (Eisemann & Décoret 2007) decides from its table what its conservative
// pair of back-projections decides and leaves the rest to the culled march: its bits are the
// exact march's, bit for bit, in both layouts, on the hard cases (the city's one-pixel walls and
// towers, flat ground, nodata holes, infinite heights, a cliff of 1e6), lights low over the
// surface and high above it, receivers on the ground and above it, with a maximum distance and
// without, for a coarse table and a fine one; and its table decides most bits itself.
TEST(RegionVisibility, TheBitmaskScatterIsTheExactOne) {
  std::uint64_t clear = 0, total = 0, tested = 0;
  std::uint64_t tested_by_size[2] = {0, 0};
  for (const char* name : {"city", "flat", "noise", "sine", "bowl", "nan_holes", "infinities", "cliff",
                           "terraces", "spikes", "dome"}) {
    SCOPED_TRACE(name);
    HeightField field = makeSyntheticField(name, 61, 47, 5);
    field.cell_size_y = 1.25;
    const std::pair<double, double> range = finiteHeightRange(field);
    const double bottom = range.first, top = range.second;
    forEachLayout([&](const ComputeContext& context) {
      RegionVisibilityOptions exact, bitmask;
      exact.method = RegionVisibilityMethod::Exact;
      bitmask.method = RegionVisibilityMethod::Bitmask;
      for (double above : {0.5 * (top - bottom) + 0.5, 2.0 + (top - bottom)}) {
        const RegionSampling light = sourcesIn(field, 72, bottom + above, true);
        for (int variant = 0; variant < 2; ++variant) {
          exact.target_height = bitmask.target_height = variant ? 0.5 : 0.0;
          exact.max_distance = bitmask.max_distance = variant ? 25.0 : 0.0;
          const RegionVisibilityResult want = computeRegionVisibility(context, field, light, exact);
          for (int size : {16, 64}) {
            bitmask.bitmask_table = size;
            const RegionVisibilityResult got = computeRegionVisibility(context, field, light, bitmask);
            ASSERT_EQ(got.bits.size(), want.bits.size());
            for (std::size_t i = 0; i < got.bits.size(); ++i)
              ASSERT_EQ(got.bits[i], want.bits[i])
                  << "receiver " << i / got.words << " word " << i % got.words << " table " << size;
            for (std::size_t p = 0; p < got.fraction.size(); ++p)
              ASSERT_TRUE(got.fraction[p] == want.fraction[p] ||
                          (std::isnan(got.fraction[p]) && std::isnan(want.fraction[p])));
            EXPECT_LE(got.exact_tested_visible, got.exact_tested);
            tested_by_size[size == 64] += got.exact_tested;
            if (size == 64) {
              tested += got.exact_tested;
              for (std::uint32_t w : got.bits) clear += __builtin_popcount(w);
              total += got.fraction.size() * 72;
            }
          }
        }
      }
    });
  }
  // Both answers occur often; the table decides most bits, the march some.
  EXPECT_GT(clear, total / 10);
  EXPECT_LT(clear, total * 9 / 10);
  EXPECT_GT(tested, 0u);
  EXPECT_LT(tested, total / 2);
  // A finer table leaves fewer bits to the march.
  EXPECT_LT(tested_by_size[1], tested_by_size[0]);
  std::printf("bitmask: %llu of %llu bits left to the march (table 64), %llu (table 16)\n",
              (unsigned long long)tested, (unsigned long long)total, (unsigned long long)tested_by_size[0]);
}

// Receivers just outside the samples' box (the light's, or a word's of 32 samples) see it over
// nearly half a turn, and a tall block beside them hides some samples: the walks over the pyramid
// (the bitmask scatter's and the culled march's shaft test) leave out only blocks beyond the
// wedge toward the samples, and the wedge's edges are its corners most turned from the box's
// centre, more than a quarter turn from it here (ordering them by that angle's sine once dropped
// the block, and lines through it came out clear: the bitmask scatter in the first case, both it
// and the culled march in the second). Every method's bits are the exact ones, in both layouts:
// a light just above the block's top, a lower block under a light of 256 samples, and a region
// pair whose rectangles touch.
TEST(RegionVisibility, ReceiversBesideTheSamplesBoxSeeTheBlockBetween) {
  struct Case {
    int row0;
    float top;
    int samples;
  };
  for (const Case c : {Case{12, 49.5f, 128}, Case{15, 45.0f, 256}}) {
    SCOPED_TRACE("block from row " + std::to_string(c.row0));
    const int w = 32, h = 32;
    std::vector<float> heights(w * h, 0.0f);
    for (int row = c.row0; row <= c.row0 + 1; ++row)
      for (int col = 12; col <= 13; ++col) heights[row * w + col] = c.top;
    const HeightField field = fieldFrom(w, h, heights);
    RegionSampling light;
    light.rectangle = {10, 10, 30, 20};
    light.samples = c.samples;
    light.height = 50.0;
    light.absolute = true;
    RegionSampling near_side, far_side;
    near_side.rectangle = {14, 4, 20, 9};
    far_side.rectangle = {8, 10, 14, 16};
    near_side.samples = far_side.samples = 64;
    near_side.height = 1.0, far_side.height = 45.0;
    std::size_t clear = 0, total = 0;
    forEachLayout([&](const ComputeContext& context) {
      RegionVisibilityOptions exact;
      exact.method = RegionVisibilityMethod::Exact;
      const RegionVisibilityResult want = computeRegionVisibility(context, field, light, exact);
      const RegionPairVisibilityResult want_pair =
          computeRegionPairVisibility(context, field, near_side, far_side, exact);
      for (RegionVisibilityMethod method :
           {RegionVisibilityMethod::Culled, RegionVisibilityMethod::Bitmask, RegionVisibilityMethod::Auto}) {
        SCOPED_TRACE(regionVisibilityMethodName(method));
        RegionVisibilityOptions options;
        options.method = method;
        const RegionVisibilityResult got = computeRegionVisibility(context, field, light, options);
        ASSERT_EQ(got.bits.size(), want.bits.size());
        for (std::size_t i = 0; i < got.bits.size(); ++i)
          ASSERT_EQ(got.bits[i], want.bits[i]) << "receiver " << i / got.words << " word " << i % got.words;
        if (method == RegionVisibilityMethod::Bitmask) continue;  // (pairs: no bitmask scatter)
        EXPECT_EQ(computeRegionPairVisibility(context, field, near_side, far_side, options).bits,
                  want_pair.bits);
      }
      for (std::uint32_t word : want.bits) clear += __builtin_popcount(word), total += 32;
    });
    // The block hides part of the light from part of the field.
    EXPECT_GT(clear, total / 2);
    EXPECT_LT(clear, total);
  }
}

// A rectangle's samples, `height` above the surface.
RegionSampling regionOf(const std::array<int, 4>& rectangle, int samples, double height) {
  RegionSampling region;
  region.rectangle = {rectangle[0], rectangle[1], rectangle[2], rectangle[3]};
  region.samples = samples;
  region.height = height;
  return region;
}
// A planar light (at an absolute height) over `rectangle`, and options for a method.
RegionSampling planarLight(const std::array<int, 4>& rectangle, int samples, double height) {
  RegionSampling light = regionOf(rectangle, samples, height);
  light.absolute = true;
  return light;
}
RegionVisibilityOptions withMethod(RegionVisibilityMethod method) {
  RegionVisibilityOptions options;
  options.method = method;
  return options;
}

// A wall between a light and the ground beyond it: the bitmask method's bits are the exact
// ones, the far side sees none of the light, the near side all of it; flat ground sees all.
TEST(RegionVisibility, TheBitmaskScatterBehindAWall) {
  const int w = 41, h = 23;
  std::vector<float> heights(w * h, 0.0f);
  const HeightField open = fieldFrom(w, h, heights);
  for (int row = 0; row < h; ++row) heights[row * w + 20] = 30.0f;
  const HeightField walled = fieldFrom(w, h, heights);
  const RegionSampling light = planarLight({2, 1, 12, 21}, 1024, 5.0);
  const RegionVisibilityOptions exact = withMethod(RegionVisibilityMethod::Exact),
                                bitmask = withMethod(RegionVisibilityMethod::Bitmask);
  forEachLayout([&](const ComputeContext& context) {
    const RegionVisibilityResult got = computeRegionVisibility(context, walled, light, bitmask);
    EXPECT_EQ(got.bits, computeRegionVisibility(context, walled, light, exact).bits);
    for (int row = 0; row < h; ++row) {
      EXPECT_EQ(got.fraction[row * w + 25], 0.0f) << row;
      EXPECT_EQ(got.fraction[row * w + 5], 1.0f) << row;
    }
    const RegionVisibilityResult flat = computeRegionVisibility(context, open, light, bitmask);
    for (float f : flat.fraction) ASSERT_EQ(f, 1.0f);
    // Over flat ground the table decides every bit: nothing rises into the shaft.
    EXPECT_EQ(flat.exact_tested, 0u);
  });
}

// A field one point thick (one row, one column) has no cells for the bitmask method to back-project:
// asked for, it is refused; the default takes the culled march there, whose bits are the exact
// ones, and the wall of the row hides the light behind it (the bitmask method had every pixel lit).
TEST(RegionVisibility, AFieldOnePointThickTakesTheMarch) {
  const std::vector<float> row = {0, 0, 0, 10, 0, 0, 0, 0};
  const RegionSampling light = planarLight({0, 0, 0, 0}, 64, 5.0);
  const RegionVisibilityOptions exact = withMethod(RegionVisibilityMethod::Exact),
                                bitmask = withMethod(RegionVisibilityMethod::Bitmask);
  forEachLayout([&](const ComputeContext& context) {
    for (const bool across : {true, false}) {
      SCOPED_TRACE(across ? "one row" : "one column");
      const HeightField field = across ? fieldFrom(8, 1, row) : fieldFrom(1, 8, row);
      EXPECT_THROW(computeRegionVisibility(context, field, light, bitmask), InvalidArgument);
      const RegionVisibilityResult got = computeRegionVisibility(context, field, light, {});
      EXPECT_EQ(got.method, RegionVisibilityMethod::Culled);
      EXPECT_EQ(got.bits, computeRegionVisibility(context, field, light, exact).bits);
      for (int p = 0; p < 8; ++p) EXPECT_EQ(got.fraction[p], p <= 3 ? 1.0f : 0.0f) << p;
    }
  });
}

// The default (Auto) takes the bitmask method for a planar light of kBitmaskFromSamples or more
// samples and the culled march otherwise (fewer samples, a light above the surface, decorrelated
// samples, a region pair), and either way gives the exact bits.
TEST(RegionVisibility, TheDefaultPicksTheBitmaskForALargePlanarLight) {
  const HeightField field = makeSyntheticField("city", 37, 29, 5);
  const auto light = [](int samples, bool absolute) {
    RegionSampling s;
    s.rectangle = {3, 4, 12, 10};
    s.samples = samples;
    s.height = absolute ? 60.0 : 8.0;
    s.absolute = absolute;
    return s;
  };
  RegionVisibilityOptions exact;
  exact.method = RegionVisibilityMethod::Exact;
  RegionVisibilityOptions decorrelated;
  decorrelated.decorrelate = true;
  struct Case {
    RegionSampling sources;
    RegionVisibilityOptions options;
    RegionVisibilityMethod want;
  };
  const std::vector<Case> cases = {
      {light(kBitmaskFromSamples, true), {}, RegionVisibilityMethod::Bitmask},
      {light(kBitmaskFromSamples - 1, true), {}, RegionVisibilityMethod::Culled},
      {light(kBitmaskFromSamples, false), {}, RegionVisibilityMethod::Culled},
      {light(kBitmaskFromSamples, true), decorrelated, RegionVisibilityMethod::Culled},
  };
  forEachLayout([&](const ComputeContext& context) {
    for (const Case& c : cases) {
      SCOPED_TRACE(std::to_string(c.sources.samples) + (c.sources.absolute ? " absolute" : " above"));
      ASSERT_EQ(c.options.method, RegionVisibilityMethod::Auto);
      const RegionVisibilityResult got = computeRegionVisibility(context, field, c.sources, c.options);
      EXPECT_EQ(got.method, c.want);
      RegionVisibilityOptions reference = exact;
      reference.decorrelate = c.options.decorrelate;
      EXPECT_EQ(got.bits, computeRegionVisibility(context, field, c.sources, reference).bits);
    }
    // A pair takes the culled march: the same bits as the exact one.
    const RegionPairVisibilityResult pair =
        computeRegionPairVisibility(context, field, light(70, true), light(40, false), {});
    EXPECT_EQ(pair.bits, computeRegionPairVisibility(context, field, light(70, true), light(40, false), exact).bits);
  });
}

// Also for two rectangles of one size and sample count, whose jitters differ (each rectangle's own
// share of the seed) and whose samples are each the same on either side.
TEST(RegionVisibility, AToBIsTheTransposeOfBToA) {
  std::uint64_t clear = 0, pairs = 0;
  for (const char* name : {"city", "noise", "sine", "terraces"})
    for (const bool same_size : {false, true}) {
      SCOPED_TRACE(std::string(name) + (same_size ? ", rectangles of one size" : ""));
      HeightField field = makeSyntheticField(name, 40, 41, 3);
      field.cell_size_x = 1.5;
      RegionSampling a, b;
      a.rectangle = {1, 2, 12, 9};
      a.samples = 70;
      a.height = 12.0;
      b.rectangle = same_size ? PixelRectangle{38, 39, 27, 32} : PixelRectangle{38, 39, 25, 20};
      b.samples = same_size ? 70 : 50;
      b.height = 0.5;
      RegionVisibilityOptions options;
      options.curvature = 0.001;
      const RegionPairVisibilityResult ab = computeRegionPairVisibility(testContext(), field, a, b, options);
      const RegionPairVisibilityResult ba = computeRegionPairVisibility(testContext(), field, b, a, options);
      // The same samples on both sides.
      ASSERT_EQ(ab.sources.size(), ba.receivers.size());
      std::size_t same_place = 0;  // in their strata: samples k of A and of B
      for (std::size_t s = 0; s < ab.sources.size(); ++s) {
        EXPECT_EQ(ab.sources[s].col, ba.receivers[s].col);
        EXPECT_EQ(ab.sources[s].row, ba.receivers[s].row);
        EXPECT_EQ(ab.sources[s].height, ba.receivers[s].height);
        if (same_size && s < ab.receivers.size())
          same_place += ab.sources[s].col - ab.receivers[s].col == ab.sources[0].col - ab.receivers[0].col;
      }
      if (same_size) EXPECT_LT(same_place, 10u) << "samples k of two rectangles of one size moved together";
      std::size_t differ = 0;
      for (int r = 0; r < ab.receiver_samples; ++r)
        for (int s = 0; s < ab.source_samples; ++s) differ += ab.visible(r, s) != ba.visible(s, r);
      EXPECT_EQ(differ, 0u);
      EXPECT_EQ(ab.clear_pairs, ba.clear_pairs);
      EXPECT_EQ(ab.source_fraction, ba.receiver_fraction);
      clear += ab.clear_pairs, pairs += ab.pairs;
      std::printf("%s: %llu of %llu pairs clear\n", name, static_cast<unsigned long long>(ab.clear_pairs),
                  static_cast<unsigned long long>(ab.pairs));
    }
  EXPECT_GT(clear, pairs / 20);
  EXPECT_LT(clear, pairs * 19 / 20);
}

TEST(RegionVisibility, FlatGroundIsAllClear) {
  // Sight lines lying on the ground only touch it: every pair sees, at any height.
  HeightField field = fieldFrom(31, 17, std::vector<float>(31 * 17, 12.5f));
  field.cell_size_y = 2.0;
  for (double height : {0.0, 0.25, 3.0}) {
    RegionSampling sources;
    sources.rectangle = {3, 2, 9, 14};
    sources.samples = 64;
    sources.height = height;
    forEachLayout([&](const ComputeContext& context) {
      const RegionVisibilityResult r = computeRegionVisibility(context, field, sources, {});
      for (std::size_t p = 0; p < r.fraction.size(); ++p) ASSERT_EQ(r.fraction[p], 1.0f) << "at " << p;
      for (std::uint32_t w : r.bits) ASSERT_EQ(w, 0xffffffffu);
    });
  }
}

// Every pair of a and b sees, and every pixel sees all of a, by the exact and the culled march, in
// both layouts.
void expectEverySampleSeen(const HeightField& field, const RegionSampling& a, const RegionSampling& b,
                           const std::string& what) {
  for (const RegionVisibilityMethod method :
       {RegionVisibilityMethod::Exact, RegionVisibilityMethod::Culled}) {
    RegionVisibilityOptions options;
    options.method = method;
    forEachLayout([&](const ComputeContext& context) {
      const RegionPairVisibilityResult pair = computeRegionPairVisibility(context, field, a, b, options);
      EXPECT_EQ(pair.clear_pairs, pair.pairs) << what;
      const RegionVisibilityResult pixels = computeRegionVisibility(context, field, a, options);
      EXPECT_EQ(std::count(pixels.fraction.begin(), pixels.fraction.end(), 1.0f), long(field.pixelCount()))
          << what;
    });
  }
}

TEST(RegionVisibility, ATiltedPlaneSeesItselfWhereverItLies) {
  // Sight lines between points of a tilted plane run along it: every pair sees (the tie rule), as on
  // flat ground, though the float32 heights and the march's values round a hair above or below the
  // line (an exact sign hid nearly every pair on the plane at 8848). A bowl sees itself too: its
  // chords run above it. A wall of 2 cm across the plane at 8848 (about 20 units in the last place
  // there) still hides the pairs on either side of it.
  const int w = 61, h = 37;
  const RegionSampling a = regionOf({1, 2, 17, 34}, 64, 0.0), b = regionOf({40, 0, 59, 36}, 64, 0.0);
  for (const testing::GrazingSurface& surface : testing::grazingSurfaces()) {
    const std::vector<float> heights = testing::grazingHeights(surface, w, h);
    expectEverySampleSeen(fieldFrom(w, h, heights), a, b, surface.name);
    if (surface.base != 8848.0) continue;
    std::vector<float> walled = heights;
    for (int row = 0; row < h; ++row) walled[row * w + 30] += 0.02f;
    for (const RegionVisibilityMethod method :
         {RegionVisibilityMethod::Exact, RegionVisibilityMethod::Culled}) {
      RegionVisibilityOptions options;
      options.method = method;
      forEachLayout([&](const ComputeContext& context) {
        EXPECT_EQ(computeRegionPairVisibility(context, fieldFrom(w, h, walled), a, b, options).clear_pairs,
                  0u);
      });
    }
  }
}

TEST(RegionVisibility, APlaneCrossingZeroFarFromTheCornerSeesItself) {
  // The march rounds its crossings' positions by units in the last place of the coordinates, which
  // the heights' rounding does not bound where a plane crosses 0 far from the field's corner: on h =
  // x - 200 the pairs between points on it near x = 200 (heights 0 .. 3, positions rounding by 1e-5)
  // were hidden but for 1568 of 65536 (the region probe's find); the march now forgives that
  // rounding (region_position_reach, region_crossing_slope). Every pair sees, and every pixel sees
  // all of a region on it.
  const int w = 216, h = 40;
  for (const testing::GrazingSurface& surface : testing::planesCrossingZeroFarFromTheCorner())
    expectEverySampleSeen(fieldFrom(w, h, testing::grazingHeights(surface, w, h)),
                          regionOf({199, 0, 203, 39}, 64, 0.0), regionOf({196, 1, 201, 38}, 64, 0.0),
                          surface.name);
}

TEST(RegionVisibility, AWallBlocksEveryPair) {
  // Two regions on flat ground either side of a wall across the whole field.
  const int w = 41, h = 23;
  std::vector<float> heights(w * h, 0.0f);
  HeightField open = fieldFrom(w, h, heights);
  for (int row = 0; row < h; ++row) heights[row * w + 20] = 30.0f;
  const HeightField walled = fieldFrom(w, h, heights);
  const RegionSampling a = regionOf({2, 1, 12, 21}, 50, 5.0), b = regionOf({28, 0, 39, 22}, 30, 5.0);
  forEachLayout([&](const ComputeContext& context) {
    const RegionPairVisibilityResult blocked = computeRegionPairVisibility(context, walled, a, b, {});
    EXPECT_EQ(blocked.clear_pairs, 0u);
    EXPECT_EQ(blocked.pairs, 1500u);
    const RegionPairVisibilityResult clear = computeRegionPairVisibility(context, open, a, b, {});
    EXPECT_EQ(clear.clear_pairs, 1500u);
    // Every pixel: the wall's far side sees none of a (the wall's top, 30 high, hides the
    // ground behind it from lights 5 high), a's own side all of it.
    const RegionVisibilityResult pixels = computeRegionVisibility(context, walled, a, {});
    for (int row = 0; row < h; ++row) {
      EXPECT_EQ(pixels.fraction[row * w + 25], 0.0f) << row;
      EXPECT_EQ(pixels.fraction[row * w + 5], 1.0f) << row;
    }
  });
}

TEST(RegionVisibility, ATallLightLightsFlatGround) {
  HeightField field = fieldFrom(37, 29, std::vector<float>(37 * 29, -3.0f));
  field.z_scale = 2.0;
  RegionSampling light;
  light.rectangle = {10, 10, 20, 15};
  light.samples = 100;
  light.height = 500.0;
  light.absolute = true;
  const RegionVisibilityResult r = computeRegionVisibility(testContext(), field, light, {});
  for (float f : r.fraction) ASSERT_EQ(f, 1.0f);
  // A light below the ground (absolute: -7 under ground at -6, z-scaled) lights only the
  // point it stands under.
  light.height = -7.0;
  light.samples = 1;
  light.rectangle = {18, 12, 18, 12};
  const RegionVisibilityResult under = computeRegionVisibility(testContext(), field, light, {});
  for (std::size_t p = 0; p < under.fraction.size(); ++p)
    EXPECT_EQ(under.fraction[p], p == 12 * 37 + 18 ? 1.0f : 0.0f) << p;
}

// Agreement with the viewshed: exact, but where the sight line grazes the surface within `graze`
// (both decide in single precision, marching from different ends), on at most 1 % of the
// targets.
void expectViewshed(const ComputeContext& context, const HeightField& field, const Observer& o,
                    const ViewshedOptions& vo, int samples, double graze) {
  RegionSampling one;
  one.rectangle = {o.col, o.row, o.col, o.row};
  one.samples = samples;  // every sample on the one point
  one.height = o.height;
  one.absolute = vo.absolute;
  RegionVisibilityOptions options;
  options.target_height = vo.target_height;
  options.curvature = vo.curvature;
  options.max_distance = vo.max_distance;
  const RegionVisibilityResult got = computeRegionVisibility(context, field, one, options);
  const ViewshedResult want = computeViewshed(context, field, o, vo);
  std::size_t targets = 0, grazing = 0, visible = 0;
  for (std::size_t p = 0; p < want.visible.size(); ++p) {
    if (std::isnan(want.visible[p])) {
      EXPECT_TRUE(std::isnan(got.fraction[p])) << p;
      continue;
    }
    ++targets;
    visible += want.visible[p] == 1.0f;
    for (int s = 0; s < samples; ++s) ASSERT_EQ(got.visible(p, s), got.visible(p, 0));
    if (float(got.fraction[p]) == want.visible[p]) continue;
    const int col = static_cast<int>(p % field.width), row = static_cast<int>(p / field.width);
    const double clearance = referenceSightLine(field, o, vo, col, row).interior_rise;
    if (std::fabs(clearance) <= graze)
      ++grazing;
    else
      ADD_FAILURE() << "target " << col << "," << row << ": region " << got.fraction[p] << ", viewshed "
                    << want.visible[p] << ", the surface " << clearance << " above the sight line at most";
  }
  EXPECT_LE(grazing, targets / 100);
  EXPECT_GT(visible, 0u);
  std::printf("%zu targets, %zu visible, %zu grazing disagreements\n", targets, visible, grazing);
}

TEST(RegionVisibility, OneSourceIsTheViewshed) {
  forEachLayout([&](const ComputeContext& context) {
    for (const char* name : {"city", "noise", "sine", "bowl", "nan_holes", "terraces", "spikes"}) {
      SCOPED_TRACE(name);
      HeightField field = makeSyntheticField(name, 61, 53);
      field.cell_size_x = 1.5;
      Observer o{30, 26, 1.5};
      if (!std::isfinite(field.at(o.col, o.row))) o.col = 31;
      if (!std::isfinite(field.at(o.col, o.row))) o.row = 27;
      ViewshedOptions vo;
      vo.target_height = 0.5;
      expectViewshed(context, field, o, vo, 1, 1e-4);
      vo.curvature = 0.003;
      vo.max_distance = 25.3;
      expectViewshed(context, field, {5, 7, 4.0}, vo, 3, 1e-4);
    }
  });
}

// The viewsheds method against the exact one: the same bits, but where the sight line grazes
// the surface, coming within 1e-5 of the field's height scale of it and the rounding of positions
// the exact march forgives (the viewshed walks the
// line from the source's end, in its own float operations), on at most 1 % of the pairs, as
// the viewshed's own tests allow against brute force (the bowl and the terraces graze on
// about 0.1 %).
void expectSameBarGrazing(const HeightField& field, const RegionSampling& sources,
                          const RegionVisibilityResult& exact, const RegionVisibilityResult& viewsheds,
                          const RegionVisibilityOptions& options) {
  ASSERT_EQ(exact.bits.size(), viewsheds.bits.size());
  double scale = 1.0, step = 0.0;
  for (std::size_t p = 0; p < field.pixelCount(); ++p) {
    const double v = double(field.heights[p]) * field.z_scale;
    if (!std::isfinite(v)) continue;
    scale = std::max(scale, std::fabs(v));
    for (const std::size_t q : {p + 1, p + field.width})
      if (q < field.pixelCount() && (q != p + 1 || q % field.width != 0) && std::isfinite(field.heights[q]))
        step = std::max(step, std::fabs(double(field.heights[q]) * field.z_scale - v));
  }
  // (and what the exact march forgives of its crossings' rounded positions: region_position_reach at
  // the field's far corner times the steepest step between neighbouring heights)
  const double grazing = 1e-5 * scale + std::ldexp(double(field.width + field.height + 2), -21) * step;
  const std::vector<RegionPoint> samples = regionSamplePoints(field, sources, options.seed);
  ViewshedOptions vo;
  vo.absolute = true;
  vo.target_height = options.target_height;
  vo.curvature = options.curvature;
  std::size_t differ = 0;
  for (std::size_t p = 0; p < field.pixelCount(); ++p)
    for (int s = 0; s < exact.samples; ++s) {
      if (exact.visible(p, s) == viewsheds.visible(p, s)) continue;
      ++differ;
      const Observer o{int(samples[s].col), int(samples[s].row), samples[s].height};
      const double rise =
          referenceSightLine(field, o, vo, int(p % field.width), int(p / field.width)).interior_rise;
      EXPECT_LE(std::fabs(rise), grazing)
          << "target " << p % field.width << "," << p / field.width << " from sample " << s << ": exact "
          << exact.visible(p, s) << ", viewshed " << viewsheds.visible(p, s);
    }
  EXPECT_LE(differ, field.pixelCount() * exact.samples / 100);
}

TEST(RegionVisibility, TheViewshedsMethodAgreesWithTheExactOne) {
  // Sources on grid points: up to 12 valid points spread over the field, then a one-point
  // rectangle (all its samples on the point).
  std::size_t visible = 0, bits = 0;
  forEachLayout([&](const ComputeContext& context) {
    testing::forEachHardCase([&](const std::string&, const HeightField& field) {
      RegionSampling points;
      points.height = 1.5;
      const std::size_t step = std::max<std::size_t>(1, field.pixelCount() / 12);
      for (std::size_t p = step / 2; p < field.pixelCount(); p += step)
        if (std::isfinite(field.heights[p]))
          points.points.push_back({double(p % field.width), double(p / field.width), 0.5 + 0.25 * (p % 5)});
      if (points.points.empty()) return;
      RegionVisibilityOptions exact, viewsheds;
      exact.target_height = viewsheds.target_height = 0.5;
      viewsheds.method = RegionVisibilityMethod::Viewsheds;
      const RegionVisibilityResult a = computeRegionVisibility(context, field, points, exact);
      const RegionVisibilityResult b = computeRegionVisibility(context, field, points, viewsheds);
      expectSameBarGrazing(field, points, a, b, exact);
      for (float f : a.fraction)
        if (std::isfinite(f)) visible += std::lround(f * a.samples), bits += a.samples;
      // Curvature and a maximum distance, absolute heights, a one-point rectangle.
      RegionSampling one;
      const RegionPoint& q = points.points.front();
      one.rectangle = {int(q.col), int(q.row), int(q.col), int(q.row)};
      one.samples = 3;
      one.absolute = true;
      one.height = field.at(int(q.col), int(q.row)) * field.z_scale + 2.0;
      exact.curvature = viewsheds.curvature = 0.004;
      exact.max_distance = viewsheds.max_distance = 17.3;
      expectSameBarGrazing(field, one, computeRegionVisibility(context, field, one, exact),
                           computeRegionVisibility(context, field, one, viewsheds), exact);
    });
  });
  EXPECT_GT(visible, bits / 10);
  EXPECT_LT(visible, bits * 9 / 10);
  // What it cannot take.
  const HeightField field = makeSyntheticField("sine", 20, 20);
  RegionSampling jittered;
  jittered.rectangle = {2, 2, 6, 6};
  RegionVisibilityOptions viewsheds;
  viewsheds.method = RegionVisibilityMethod::Viewsheds;
  EXPECT_THROW(computeRegionVisibility(testContext(), field, jittered, viewsheds), InvalidArgument);
  RegionSampling on_point;
  on_point.rectangle = {3, 3, 3, 3};
  EXPECT_NO_THROW(computeRegionVisibility(testContext(), field, on_point, viewsheds));
  EXPECT_THROW(computeRegionPairVisibility(testContext(), field, on_point, on_point, viewsheds),
               InvalidArgument);
  viewsheds.decorrelate = true;
  EXPECT_THROW(computeRegionVisibility(testContext(), field, on_point, viewsheds), InvalidArgument);
}

TEST(RegionVisibility, SamplesAreStratifiedAndDeterministic) {
  const HeightField field = makeSyntheticField("sine", 30, 30);
  RegionSampling region;
  region.rectangle = {20, 4, 4, 20};  // corners in any order: 16 x 16 pixels
  region.samples = 64;                // 8 x 8 strata of 2 x 2 pixels
  region.height = 1.0;
  const std::vector<RegionPoint> a = regionSamplePoints(field, region, 3);
  const std::vector<RegionPoint> b = regionSamplePoints(field, region, 3);
  const std::vector<RegionPoint> c = regionSamplePoints(field, region, 4);
  ASSERT_EQ(a.size(), 64u);
  std::set<std::pair<int, int>> strata;
  std::size_t moved = 0;
  for (std::size_t s = 0; s < a.size(); ++s) {
    EXPECT_EQ(a[s].col, b[s].col);
    EXPECT_EQ(a[s].row, b[s].row);
    moved += a[s].col != c[s].col;
    EXPECT_GE(a[s].col, 4.0);
    EXPECT_LE(a[s].col, 20.0);
    EXPECT_GE(a[s].row, 4.0);
    EXPECT_LE(a[s].row, 20.0);
    strata.insert({std::min(7, int((a[s].col - 4.0) / 2.0)), std::min(7, int((a[s].row - 4.0) / 2.0))});
  }
  EXPECT_EQ(strata.size(), 64u);  // one sample in every stratum
  EXPECT_GT(moved, 60u);          // another seed, other jitter
  // A rectangle of the same size elsewhere, with the same seed: its own jitter (a pair's samples
  // k and k at the same place in their strata would be correlated).
  RegionSampling shifted = region;
  shifted.rectangle = {4 + 9, 4, 20 + 9, 20};
  const std::vector<RegionPoint> d = regionSamplePoints(field, shifted, 3);
  ASSERT_EQ(d.size(), a.size());
  std::size_t same_place = 0;
  for (std::size_t s = 0; s < a.size(); ++s) same_place += d[s].col - 9.0 == a[s].col || d[s].row == a[s].row;
  EXPECT_LT(same_place, 4u);
  // 10 samples over a 9 x 1 strip: rows of 4 + 4 + 2 wider strata, still one per stratum.
  region.rectangle = {0, 0, 8, 1};
  region.samples = 10;
  const std::vector<RegionPoint> strip = regionSamplePoints(field, region, 1);
  ASSERT_EQ(strip.size(), 10u);
  for (const RegionPoint& p : strip)
    EXPECT_TRUE(p.col >= 0.0 && p.col <= 8.0 && p.row >= 0.0 && p.row <= 1.0);
  // Heights above the surface under the sample.
  region.points = {{2.5, 3.0, 1.0}, {0.0, 0.0, 2.0}};
  const std::vector<RegionPoint> points = regionSamplePoints(field, region, 1);
  ASSERT_EQ(points.size(), 2u);
  EXPECT_NEAR(points[1].height, field.at(0, 0) + 2.0, 1e-5);
  EXPECT_NEAR(points[0].height, 0.5 * (field.at(2, 3) + field.at(3, 3)) + 1.0, 1e-4);
}

TEST(RegionVisibility, ManySamplesAndDecorrelation) {
  // 1030 samples: 33 words, the last holding 6 bits; the bits past S stay zero.
  HeightField field = makeSyntheticField("city", 23, 17);
  field.cell_size_y = 0.75;
  RegionSampling sources;
  sources.rectangle = {2, 2, 12, 9};
  sources.samples = 1030;
  sources.height = 8.0;
  RegionVisibilityOptions options;
  options.target_height = 1.0;
  options.seed = 11;
  std::vector<std::uint32_t> shared;
  for (bool decorrelate : {false, true}) {
    options.decorrelate = decorrelate;
    forEachLayout([&](const ComputeContext& context) {
      const RegionVisibilityResult got = computeRegionVisibility(context, field, sources, options);
      ASSERT_EQ(got.words, 33);
      expectSame(got, referenceRegionVisibility(field, sources, options));
      for (std::size_t p = 0; p < field.pixelCount(); ++p) EXPECT_EQ(got.bits[p * 33 + 32] >> 6, 0u) << p;
      // The same run again: the same bits (the jitter is a hash, not a random state).
      EXPECT_EQ(computeRegionVisibility(context, field, sources, options).bits, got.bits);
      if (!decorrelate) {
        shared = got.bits;
        return;
      }
      // Each receiver its own samples: other bits where a receiver sees part of the sources.
      std::size_t differ = 0;
      for (std::size_t i = 0; i < got.bits.size(); ++i) differ += got.bits[i] != shared[i];
      EXPECT_GT(differ, got.bits.size() / 10);
    });
  }
}

// A light image of width x height texels, each channel a different pattern of positive values.
LightImage patternImage(int width, int height) {
  LightImage image;
  image.width = width;
  image.height = height;
  for (int c = 0; c < 3; ++c)
    for (int j = 0; j < height; ++j)
      for (int i = 0; i < width; ++i) image.rgb.push_back(0.25f + float((i * (c + 2) + j * (3 - c)) % 7));
  return image;
}

// Colours equal to the reference's (NaN where NaN), within the rounding of two ways of writing
// the bilinear lookup; the bits already compared.
void expectSameColours(const RegionVisibilityResult& got, const RegionVisibilityResult& want) {
  const std::vector<float>* got_planes[3] = {&got.red, &got.green, &got.blue};
  const std::vector<float>* want_planes[3] = {&want.red, &want.green, &want.blue};
  for (int c = 0; c < 3; ++c) {
    ASSERT_EQ(got_planes[c]->size(), got.fraction.size());
    ASSERT_EQ(want_planes[c]->size(), got.fraction.size());
    for (std::size_t p = 0; p < got.fraction.size(); ++p) {
      const float a = (*got_planes[c])[p], b = (*want_planes[c])[p];
      if (std::isnan(a) || std::isnan(b)) {
        ASSERT_TRUE(std::isnan(a) && std::isnan(b) && std::isnan(got.fraction[p]))
            << "channel " << c << " at " << p << ": " << a << " vs " << b;
        continue;
      }
      ASSERT_NEAR(a, b, 1e-5 * (1.0 + std::fabs(b))) << "channel " << c << " at " << p;
    }
  }
}

TEST_P(RegionMethods, LightColoursMatchTheReference) {
  std::size_t partial = 0;
  forEachLayout([&](const ComputeContext& context) {
    for (const char* name : {"city", "nan_holes"}) {
      SCOPED_TRACE(name);
      const HeightField field = makeSyntheticField(name, 40, 41, 3);
      RegionSampling light;
      light.rectangle = {14, 30, 6, 24};  // corners in any order
      light.samples = 40;
      light.height = 6.0;
      // nan_holes: the first 5 x 3 rectangle of valid points, scanning rows.
      const bool holes = std::string(name) == "nan_holes";
      for (int r = 0; holes && r + 2 < field.height; ++r)
        for (int c = 0; c + 4 < field.width; ++c) {
          bool valid = true;
          for (int y = r; y <= r + 2 && valid; ++y)
            for (int x = c; x <= c + 4; ++x) valid = valid && std::isfinite(field.at(x, y));
          if (valid) {
            light.rectangle = {c + 4, r + 2, c, r};
            r = field.height;
            break;
          }
        }
      ASSERT_NO_THROW(validate(field, light));
      ASSERT_EQ(holes, std::any_of(field.heights.begin(), field.heights.end(),
                                   [](float v) { return std::isnan(v); }));
      RegionVisibilityOptions options;
      options.method = GetParam();
      options.seed = 3;
      options.light_image = patternImage(5, 3);
      for (bool decorrelate : {false, true}) {
        options.decorrelate = decorrelate;
        const RegionVisibilityResult got = computeRegionVisibility(context, field, light, options);
        const RegionVisibilityResult want = referenceRegionVisibility(field, light, options);
        expectSame(got, want);
        expectSameColours(got, want);
        for (float f : got.fraction) partial += f > 0.0f && f < 1.0f;
      }
    }
  });
  EXPECT_GT(partial, 100u);  // a partly seen light: colours of some samples, not all or none
}

TEST(RegionVisibility, AWhiteLightIsTheVisibleFraction) {
  // Every method, a one-point light for the viewsheds one; nodata NaN in every channel.
  const HeightField field = makeSyntheticField("nan_holes", 30, 31, 5);
  RegionSampling light = sourcesIn(field, 37, 2.0, false);
  RegionSampling point = light;
  point.rectangle = {light.rectangle.col0, light.rectangle.row0, light.rectangle.col0, light.rectangle.row0};
  LightImage white;
  white.width = 3, white.height = 2;
  white.rgb.assign(18, 1.0f);
  forEachLayout([&](const ComputeContext& context) {
    for (const auto method :
         {RegionVisibilityMethod::Exact, RegionVisibilityMethod::Culled, RegionVisibilityMethod::Viewsheds}) {
      RegionVisibilityOptions options;
      options.method = method;
      options.light_image = white;
      const RegionVisibilityResult r = computeRegionVisibility(
          context, field, method == RegionVisibilityMethod::Viewsheds ? point : light, options);
      for (std::size_t p = 0; p < r.fraction.size(); ++p)
        for (const auto* plane : {&r.red, &r.green, &r.blue})
          ASSERT_TRUE((*plane)[p] == r.fraction[p] || (std::isnan((*plane)[p]) && std::isnan(r.fraction[p])))
              << int(method) << " at " << p << ": " << (*plane)[p] << " vs " << r.fraction[p];
    }
  });
}

TEST(RegionVisibility, EachSampleTakesTheColourWhereItLies) {
  // A light along row 10 of flat ground, its image red on the left half and blue on the right,
  // and a wall across the field at column 20: a receiver left of the wall sees only the red half,
  // one right of it only the blue. Colours given to the wrong samples (the image mirrored,
  // looked up by sample index, by the receiver's position) would not give that.
  const int w = 41, h = 21;
  std::vector<float> heights(w * h, 0.0f);
  for (int row = 0; row < h; ++row) heights[row * w + 20] = 8.0f;
  const HeightField field = fieldFrom(w, h, heights);
  RegionSampling light;
  light.rectangle = {35, 10, 5, 10};
  light.samples = 64;
  light.height = 1.0;
  RegionVisibilityOptions options;
  options.light_image.width = 2, options.light_image.height = 1;
  options.light_image.rgb = {1.0f, 0.0f, /*G*/ 0.0f, 0.0f, /*B*/ 0.0f, 1.0f};
  forEachLayout([&](const ComputeContext& context) {
    const RegionVisibilityResult r = computeRegionVisibility(context, field, light, options);
    for (int row : {2, 10, 18})
      for (int col : {1, 6, 12}) {
        const std::size_t left = std::size_t(row) * w + col, right = std::size_t(row) * w + (w - 1 - col);
        SCOPED_TRACE(std::to_string(col) + "," + std::to_string(row));
        EXPECT_GT(r.fraction[left], 0.2f);
        EXPECT_LT(r.fraction[left], 0.8f);
        // Left of the wall: red samples (and the blended middle's red side) only.
        EXPECT_GT(r.red[left], 2.0f * r.blue[left]);
        EXPECT_GT(r.blue[right], 2.0f * r.red[right]);
        EXPECT_EQ(r.green[left], 0.0f);
        EXPECT_NEAR(r.red[left] + r.blue[left], r.fraction[left], 1e-6);  // red + blue = 1 everywhere
      }
  });
}

// A prepared field (RegionField: heights and pyramid built and uploaded once) gives the one-shot
// calls' results, bit for bit, call after call on the same object: region pairs by every method a
// pair takes (decorrelated, curved, explicit points), area lights by the culled march, the bitmask
// scatter, the exact march and the viewsheds, in both layouts, with one-shot calls on another field
// in between on the same context; and it keeps its own copy of the field (the caller's heights
// changed after preparing change nothing).
TEST(RegionVisibility, APreparedFieldGivesTheOneShotBits) {
  std::uint64_t clear = 0, pairs = 0;
  int calls = 0;
  for (const char* name : {"city", "noise", "nan_holes", "terraces"}) {
    SCOPED_TRACE(name);
    HeightField field = makeSyntheticField(name, 101, 77, 5);
    field.cell_size_y = 1.25;
    const HeightField other = makeSyntheticField("spikes", 64, 48, 9);
    const std::vector<float> h = detail::prepareHeights(field, detail::HeightOrigin::Zero).heights;
    double top = -1e30;
    for (float v : h)
      if (std::isfinite(v)) top = std::max(top, double(v));
    forEachLayout([&](const ComputeContext& context) {
      HeightField callers = field;
      const RegionField prepared(context, callers);
      // (the caller's field changed afterwards: the prepared one keeps its copy)
      for (float& v : callers.heights) v = 2.0f * v + 50.0f;
      ASSERT_EQ(prepared.field().heights.size(), field.heights.size());
      EXPECT_EQ(std::memcmp(prepared.field().heights.data(), field.heights.data(),
                            field.heights.size() * sizeof(float)),
                0);
      RegionSampling a, b;
      a.rectangle = {2, 3, 30, 40};
      b.rectangle = {98, 70, 60, 20};
      a.samples = 70, b.samples = 48;
      a.height = 1.0, b.height = 2.5;
      try {
        validate(field, a), validate(field, b);
      } catch (const InvalidArgument&) {  // nodata under a rectangle: points over valid surface instead
        a = {}, b = {};
        for (int i = 0; i < 80; ++i) {
          const double x = 1.0 + (i * 37) % 97 + 0.25, y = 1.0 + (i * 53) % 73 + 0.5;
          const float s = detail::region_surface_at(h.data(), field.width, field.height, float(x), float(y));
          if (std::isfinite(s)) (i % 2 ? a : b).points.push_back({x, y, double(s) + 1.5});
        }
        ASSERT_GT(a.points.size(), 4u);
        ASSERT_GT(b.points.size(), 4u);
        a.absolute = b.absolute = true;
      }
      RegionSampling tiny;  // the other field's: one point each side
      tiny.rectangle = {1, 1, 1, 1};
      RegionSampling tiny_far = tiny;
      tiny_far.rectangle = {60, 40, 60, 40};
      for (RegionVisibilityMethod method :
           {RegionVisibilityMethod::Exact, RegionVisibilityMethod::Culled, RegionVisibilityMethod::Auto})
        for (int variant = 0; variant < 3; ++variant) {
          SCOPED_TRACE(std::string(regionVisibilityMethodName(method)) + " variant " +
                       std::to_string(variant));
          RegionVisibilityOptions options;
          options.method = method;
          options.decorrelate = variant == 1;
          options.curvature = variant == 2 ? 0.0005 : 0.0;
          options.max_distance = variant == 2 ? 90.0 : 0.0;
          const RegionPairVisibilityResult got = computeRegionPairVisibility(prepared, a, b, options);
          // (another field on the same context between the calls)
          (void)computeRegionPairVisibility(context, other, tiny, tiny_far, options);
          const RegionPairVisibilityResult want = computeRegionPairVisibility(context, field, a, b, options);
          ASSERT_EQ(got.bits, want.bits);
          EXPECT_EQ(got.source_fraction, want.source_fraction);
          EXPECT_EQ(got.receiver_fraction, want.receiver_fraction);
          ASSERT_EQ(got.receivers.size(), want.receivers.size());
          for (std::size_t i = 0; i < got.receivers.size(); ++i)
            EXPECT_EQ(got.receivers[i].height, want.receivers[i].height);
          clear += got.clear_pairs, pairs += got.pairs, ++calls;
        }
      // Area lights: a planar one (the bitmask scatter, the default's pick at 64 samples) and one
      // above the surface; a one-point light by the viewsheds.
      RegionSampling light = sourcesIn(field, 64, top + 3.0, true);
      RegionSampling low = sourcesIn(field, 40, 2.0, false);
      RegionSampling point = light;
      point.rectangle.col1 = point.rectangle.col0, point.rectangle.row1 = point.rectangle.row0;
      point.samples = 1;
      const std::pair<const RegionSampling*, RegionVisibilityMethod> runs[] = {
          {&light, RegionVisibilityMethod::Auto},
          {&light, RegionVisibilityMethod::Culled},
          {&low, RegionVisibilityMethod::Exact},
          {&low, RegionVisibilityMethod::Culled},
          {&point, RegionVisibilityMethod::Viewsheds}};
      for (const auto& [sources, method] : runs) {
        SCOPED_TRACE(regionVisibilityMethodName(method));
        RegionVisibilityOptions options;
        options.method = method;
        options.target_height = 0.5;
        const RegionVisibilityResult got = computeRegionVisibility(prepared, *sources, options);
        const RegionVisibilityResult want = computeRegionVisibility(context, field, *sources, options);
        EXPECT_EQ(got.method, want.method);
        EXPECT_EQ(got.exact_tested, want.exact_tested);
        ASSERT_EQ(got.bits, want.bits);
        for (std::size_t p = 0; p < got.fraction.size(); ++p)
          ASSERT_TRUE(got.fraction[p] == want.fraction[p] ||
                      (std::isnan(got.fraction[p]) && std::isnan(want.fraction[p])))
              << "fraction at " << p;
        ++calls;
      }
    });
  }
  EXPECT_EQ(calls, 4 * 2 * (9 + 5));
  // Both answers occur often among the pairs.
  EXPECT_GT(clear, pairs / 20);
  EXPECT_LT(clear, pairs * 19 / 20);
}

TEST(RegionVisibility, BadInputIsRefused) {
  HeightField field = makeSyntheticField("noise", 20, 10);
  field.heights[5 * 20 + 5] = std::numeric_limits<float>::quiet_NaN();
  const ComputeContext& context = testContext();
  const RegionField prepared(context, field);
  // Each refused by the one-shot call and by the call on the prepared field, which checks the
  // samples against its own prepared heights.
  auto refused = [&](RegionSampling s, RegionVisibilityOptions o, const std::string& says) {
    for (bool on_prepared : {false, true})
      try {
        if (on_prepared)
          computeRegionVisibility(prepared, s, o);
        else
          computeRegionVisibility(context, field, s, o);
        ADD_FAILURE() << "accepted" << (on_prepared ? " on the prepared field" : "")
                      << "; expected an error saying " << says;
      } catch (const InvalidArgument& e) {
        EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
      }
  };
  // A prepared field is checked as the calls check theirs.
  EXPECT_THROW(RegionField(context, HeightField{}), InvalidArgument);
  RegionSampling good;
  good.rectangle = {0, 0, 3, 3};
  RegionVisibilityOptions options;
  EXPECT_NO_THROW(computeRegionVisibility(context, field, good, options));
  RegionSampling s = good;
  s.rectangle = {0, 0, 20, 3};
  refused(s, options, "outside");
  s.rectangle = {-1, 0, 3, 3};
  refused(s, options, "outside");
  s = good;
  s.samples = 0;
  refused(s, options, "samples");
  s.samples = kMaxRegionSamples + 1;
  refused(s, options, "samples");
  s = good;
  s.rectangle = {4, 4, 8, 6};
  refused(s, options, "nodata");
  s = good;
  s.height = std::numeric_limits<double>::infinity();
  refused(s, options, "finite");
  // (beyond float, a light at 1e300 was seen from everywhere, without a word)
  s.height = 1e300;
  refused(s, options, "within +-1e+12 (got 1e+300)");
  s.height = -1e13;
  refused(s, options, "within +-1e+12");
  s = good;
  s.points = {{5.5, 4.5, 1.0}};
  refused(s, options, "nodata");
  s.points = {{19.5, 2.0, 1.0}};
  refused(s, options, "outside");
  s.points = {{1.0, 2.0, std::numeric_limits<double>::quiet_NaN()}};
  refused(s, options, "finite");
  s.points = {{1.0, 2.0, -1e39}};
  refused(s, options, "beyond +-1e+12");
  RegionVisibilityOptions o = options;
  o.max_distance = -1.0;
  refused(good, o, "maximum distance");
  // (its square in float32 would be 0, which means no limit: every pair within it)
  for (const double tiny : {1e-30, 1e-19}) {
    o.max_distance = tiny;
    refused(good, o, "too short");
  }
  o.max_distance = kLeastMaxDistance;
  EXPECT_NO_THROW(computeRegionVisibility(context, field, good, o));
  o = options;
  o.target_height = std::numeric_limits<double>::quiet_NaN();
  refused(good, o, "target height");
  o = options;
  for (const double curvature : {std::numeric_limits<double>::infinity(), 1.5, -1e38}) {
    o.curvature = curvature;
    refused(good, o, "curvature");
  }
  HeightField latlon = field;
  latlon.row_cell_size_x.assign(field.height, 1.0);
  latlon.row_cell_size_y.assign(field.height, 1.0);
  EXPECT_THROW(computeRegionVisibility(context, latlon, good, options), InvalidArgument);
  EXPECT_THROW(RegionField(context, latlon), InvalidArgument);
  // A moved-from prepared field holds nothing: a call on it is refused, not a crash.
  RegionField moved(context, field);
  const RegionField taker = std::move(moved);
  EXPECT_NO_THROW(computeRegionVisibility(taker, good, options));
  EXPECT_THROW(computeRegionVisibility(moved, good, options), InvalidArgument);  // NOLINT(bugprone-use-after-move)
  EXPECT_THROW(moved.field(), InvalidArgument);  // NOLINT(bugprone-use-after-move)
  // A light image: of 3 * width * height finite values >= 0, over a rectangle, every-pixel receivers.
  o = options;
  o.light_image.width = 2, o.light_image.height = 2;
  o.light_image.rgb.assign(11, 1.0f);
  refused(good, o, "3 * width * height");
  o.light_image.rgb.assign(12, 1.0f);
  EXPECT_NO_THROW(computeRegionVisibility(context, field, good, o));
  o.light_image.rgb[7] = -0.5f;
  refused(good, o, "channel G at column 1, row 1");
  o.light_image.rgb[7] = std::numeric_limits<float>::infinity();
  refused(good, o, "finite");
  o.light_image.rgb[7] = 1.0f;
  RegionSampling points = good;
  points.points = {{1.0, 2.0, 1.0}};
  refused(points, o, "rectangle");
  EXPECT_THROW(computeRegionPairVisibility(context, field, good, good, o), InvalidArgument);
  // The bitmask method: a planar light (a rectangle at an absolute height), shared samples, at
  // most kMaxBitmaskSamples of them, no curvature, every-pixel receivers, a table of 8 .. 1024.
  o = options;
  o.method = RegionVisibilityMethod::Bitmask;
  refused(good, o, "absolute height");
  RegionSampling plane = good;
  plane.absolute = true;
  plane.height = 100.0;
  EXPECT_NO_THROW(computeRegionVisibility(context, field, plane, o));
  RegionSampling plane_points = plane;
  plane_points.points = {{1.0, 2.0, 100.0}, {2.0, 2.0, 100.0}};
  EXPECT_NO_THROW(computeRegionVisibility(context, field, plane_points, o));
  plane_points.points[1].height = 101.0;
  refused(plane_points, o, "one absolute height");
  plane.samples = kMaxBitmaskSamples + 1;
  refused(plane, o, "at most");
  plane.samples = 16;
  o.decorrelate = true;
  refused(plane, o, "decorrelation");
  o.decorrelate = false;
  o.curvature = 1e-7;
  refused(plane, o, "curvature");
  o.curvature = 0.0;
  o.bitmask_table = 4;
  refused(plane, o, "table");
  o.bitmask_table = 64;
  EXPECT_THROW(computeRegionPairVisibility(context, field, plane, plane, o), InvalidArgument);
  // A region pair checks both regions.
  EXPECT_THROW(computeRegionPairVisibility(context, field, good, s, options), InvalidArgument);
  EXPECT_THROW(computeRegionPairVisibility(context, field, s, good, options), InvalidArgument);
  EXPECT_THROW(computeRegionPairVisibility(prepared, good, s, options), InvalidArgument);
  EXPECT_THROW(computeRegionPairVisibility(prepared, s, good, options), InvalidArgument);
  EXPECT_THROW(computeRegionPairVisibility(prepared, plane, plane, o), InvalidArgument);
}

}  // namespace
}  // namespace hfvis
