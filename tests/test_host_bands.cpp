// test_host_bands.cpp: the host passes split into bands of rows (core/host_bands.hpp): every row
// once, a band's exception rethrown, and the passes that run in bands (prepareHeights, the region
// culling pyramid) giving what one pass over the whole field gives, in 1, 3 and 7 bands (uneven)
// and in the bands the machine would take.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstring>
#include <limits>
#include <mutex>
#include <stdexcept>
#include <string>
#include <vector>

#include "core/host_bands.hpp"
#include "core/sweep_geometry.hpp"
#include "hfvis_testing/synthetic_fields.hpp"
#include "ops/region_visibility_sight.hpp"

namespace hfvis {
namespace {

TEST(HostBands, EveryRowOnceInContiguousBands) {
  for (const int count : {0, 1, 2, 7, 1000}) {
    for (const int bands : {1, 2, 3, 8}) {
      SCOPED_TRACE(std::to_string(count) + " rows, " + std::to_string(bands) + " bands");
      std::vector<int> seen(count, 0);
      std::vector<std::pair<int, int>> ranges;
      std::mutex lock;
      std::atomic<int> calls{0};
      detail::forEachBand(count, bands, [&](int band, int first, int last) {
        ++calls;
        std::lock_guard<std::mutex> hold(lock);
        if (band >= int(ranges.size())) ranges.resize(band + 1, {-1, -1});
        ranges[band] = {first, last};
        for (int r = first; r < last; ++r) ++seen[r];
      });
      for (int r = 0; r < count; ++r) EXPECT_EQ(seen[r], 1) << "row " << r;
      // As many bands as asked where there are rows enough, none empty, in order.
      EXPECT_EQ(calls.load(), std::min(count, bands));
      for (std::size_t b = 0; b < ranges.size(); ++b) {
        EXPECT_LT(ranges[b].first, ranges[b].second);
        EXPECT_EQ(ranges[b].first, b == 0 ? 0 : ranges[b - 1].second);
      }
    }
  }
}

TEST(HostBands, ABandsExceptionReachesTheCaller) {
  std::atomic<int> finished{0};
  EXPECT_THROW(detail::forEachBand(10, 3,
                                   [&](int band, int, int) {
                                     if (band == 2) throw std::runtime_error("band 2");
                                     ++finished;
                                   }),
               std::runtime_error);
  EXPECT_EQ(finished.load(), 2);  // the other bands ran to their end first
}

// A field of 1601 x 1400 with nodata, infinities, a z-scale and the lowest and highest heights in
// the first and last rows, in 1, 3 and 7 bands (the rows do not split evenly) and the machine's:
// prepareHeights gives each height as one conversion would, and the extremes of the prepared
// heights.
TEST(HostBands, PreparedHeightsAreThoseOfOnePass) {
  HeightField field;
  field.width = 1601, field.height = 1400;
  field.heights.resize(field.pixelCount());
  for (std::size_t i = 0; i < field.heights.size(); ++i)
    field.heights[i] = float(std::sin(0.001 * double(i)) * 300.0 + 0.5 * double(i % 97));
  field.heights[5] = 2000.0f;                          // the highest, in the first rows
  field.heights[field.heights.size() - 3] = -900.0f;  // the lowest, in the last
  field.heights[1601 * 700 + 3] = std::numeric_limits<float>::quiet_NaN();
  field.heights[1601 * 1300] = std::numeric_limits<float>::infinity();
  field.z_scale = 1.7;
  for (const auto origin : {detail::HeightOrigin::Zero, detail::HeightOrigin::Base})
    for (const int bands : {0, 1, 3, 7}) {
      SCOPED_TRACE(std::to_string(bands) + " bands");
      const detail::PreparedHeights p = detail::prepareHeights(field, origin, bands);
      const double base = origin == detail::HeightOrigin::Base ? heightBase(field) : 0.0;
      ASSERT_EQ(p.heights.size(), field.heights.size());
      EXPECT_TRUE(p.has_nodata);
      std::size_t differing = 0;
      for (std::size_t i = 0; i < field.heights.size(); ++i) {
        const float h = field.heights[i];
        if (!std::isfinite(h)) {
          differing += !std::isnan(p.heights[i]);
          continue;
        }
        const float want = float((double(h) - base) * 1.7);
        differing += p.heights[i] != want;
      }
      EXPECT_EQ(differing, 0u);
      EXPECT_EQ(p.lowest, float((-900.0 - base) * 1.7));
      EXPECT_EQ(p.highest, float((2000.0 - base) * 1.7));
    }
  // Every height finite: no nodata; and a field with no finite height has no extremes.
  field.heights[1601 * 700 + 3] = 1.0f, field.heights[1601 * 1300] = 2.0f;
  EXPECT_FALSE(detail::prepareHeights(field, detail::HeightOrigin::Zero, 3).has_nodata);
  std::fill(field.heights.begin(), field.heights.end(), std::numeric_limits<float>::quiet_NaN());
  const detail::PreparedHeights none = detail::prepareHeights(field, detail::HeightOrigin::Zero, 3);
  EXPECT_TRUE(none.has_nodata);
  EXPECT_GT(none.lowest, none.highest);
}

// The culling pyramid's pass for fields whose every height is finite runs in bands; the checked
// pass (for fields with non-finite heights) runs in one: on a city, on noise, and on the noise
// with a spike in its last rows (the largest height, step and twist in the last band, the lowest
// in the first), in 1, 3 and 7 bands and the machine's, both give the same pyramid, margin and
// gradient, bit for bit.
TEST(HostBands, CullPyramidInBandsIsTheCheckedOne) {
  for (const char* name : {"city", "noise", "spike"}) {
    SCOPED_TRACE(name);
    HeightField field = makeSyntheticField(name == std::string("spike") ? "noise" : name, 1537, 1409, 3);
    if (name == std::string("spike"))
      field.heights[std::size_t(1405) * 1537 + 1000] = 5000.0f, field.heights[7] = -4000.0f;
    const std::vector<float> h = detail::prepareHeights(field, detail::HeightOrigin::Zero).heights;
    const detail::CullPyramid checked = detail::cullPyramid(h, field.width, field.height, true);
    for (const int bands : {0, 1, 3, 7}) {
      SCOPED_TRACE(std::to_string(bands) + " bands");
      const detail::CullPyramid banded = detail::cullPyramid(h, field.width, field.height, false, bands);
      ASSERT_GT(banded.levels, 10);
      EXPECT_EQ(banded.levels, checked.levels);
      EXPECT_TRUE(banded.finite);
      EXPECT_EQ(banded.margin, checked.margin);
      EXPECT_EQ(banded.gradient, checked.gradient);
      ASSERT_EQ(banded.top.size(), checked.top.size());
      std::size_t differing = 0;
      for (std::size_t i = 0; i < banded.top.size(); ++i)
        differing += std::memcmp(&banded.top[i], &checked.top[i], sizeof(float)) != 0;
      EXPECT_EQ(differing, 0u);
    }
  }
}

}  // namespace
}  // namespace hfvis
