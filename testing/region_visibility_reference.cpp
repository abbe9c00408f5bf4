// region_visibility_reference.cpp: see hfvis_testing/region_visibility_reference.hpp.
#include "hfvis_testing/region_visibility_reference.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "core/sweep_geometry.hpp"
#include "hfvis/errors.hpp"
#include "ops/region_visibility_sight.hpp"

namespace hfvis {
namespace {

struct Pairs {
  const HeightField& field;
  const std::vector<float>& heights;
  const RegionVisibilityOptions& options;
  const std::vector<float>& sources;
  bool source_absolute;

  // The bits of a receiver at (x, y, z) with source stream `key`; none where z is NaN.
  void receiverBits(float x, float y, float z, unsigned key, std::uint32_t* words) const {
    const int samples = detail::regionTableSamples(sources);
    const float max_d2 =
        options.max_distance > 0.0 ? float(options.max_distance * options.max_distance) : 0.0f;
    for (int s = 0; s < samples; ++s) {
      if (std::isnan(z)) break;
      float xs, ys, zs;
      detail::region_sample(sources.data(), heights.data(), field.width, field.height, source_absolute,
                            detail::region_table_seed(sources.data(), options.seed), key, s, &xs, &ys, &zs);
      if (detail::region_sight_visible(heights.data(), field.width, field.height, float(field.cell_size_x),
                                       float(field.cell_size_y), float(options.curvature), max_d2, xs, ys, zs,
                                       x, y, z))
        words[s / 32] |= 1u << (s % 32);
    }
  }
};

int popcount(std::uint32_t v) { return __builtin_popcount(v); }

// Channel c of the light image at (x, y) over the rectangle of `table`, straight from
// LightImage's definition: the image's texel centres spread over the rectangle, bilinear between
// the four around (x, y), the edge texels held beyond the outermost centres.
double lightValue(const LightImage& image, const std::vector<float>& table, int c, double x, double y) {
  const auto axis = [](double at, double lo, double hi, int n, int& i0, int& i1, double& f) {
    const double centre0 = lo + 0.5 * (hi - lo) / n;  // texel 0's centre
    const double step = (hi - lo) / n;
    double t = step > 0.0 ? (at - centre0) / step : 0.5 * n - 0.5;
    t = std::fmax(0.0, std::fmin(t, n - 1.0));
    i0 = static_cast<int>(std::floor(t));
    i1 = std::min(i0 + 1, n - 1);
    f = t - i0;
  };
  int i0, i1, j0, j1;
  double fx, fy;
  axis(x, table[0], table[2], image.width, i0, i1, fx);
  axis(y, table[1], table[3], image.height, j0, j1, fy);
  const auto v = [&](int i, int j) {
    return double(image.rgb[(std::size_t(c) * image.height + j) * image.width + i]);
  };
  return (1 - fx) * (1 - fy) * v(i0, j0) + fx * (1 - fy) * v(i1, j0) + (1 - fx) * fy * v(i0, j1) +
         fx * fy * v(i1, j1);
}

}  // namespace

RegionVisibilityResult referenceRegionVisibility(const HeightField& field, const RegionSampling& sources,
                                                 const RegionVisibilityOptions& options) {
  validate(field);
  validate(options);
  const std::vector<float> table = detail::regionSampleTable(field, sources);
  const std::vector<float> heights = detail::prepareHeights(field, detail::HeightOrigin::Zero).heights;
  RegionVisibilityResult out;
  out.width = field.width;
  out.height = field.height;
  out.samples = detail::regionTableSamples(table);
  out.words = (out.samples + 31) / 32;
  out.bits.assign(field.pixelCount() * out.words, 0u);
  out.fraction.resize(field.pixelCount());
  const Pairs pairs{field, heights, options, table, sources.absolute};
  const bool coloured = options.light_image.width > 0;
  if (coloured && !sources.points.empty())
    throw InvalidArgument("a light image lies over a rectangle light, not over explicit points");
  if (coloured)
    for (auto* plane : {&out.red, &out.green, &out.blue}) plane->resize(field.pixelCount());
  for (std::size_t p = 0; p < field.pixelCount(); ++p) {
    const float x = float(p % field.width), y = float(p / field.width);
    const float z = heights[p] + float(options.target_height);
    std::uint32_t* words = &out.bits[p * out.words];
    pairs.receiverBits(x, y, z, options.decorrelate ? unsigned(p) + 1u : 0u, words);
    int seen = 0;
    for (int w = 0; w < out.words; ++w) seen += popcount(words[w]);
    out.fraction[p] = std::isnan(heights[p]) ? std::numeric_limits<float>::quiet_NaN()
                                             : static_cast<float>(static_cast<double>(seen) / out.samples);
    if (!coloured) continue;
    // Per channel the colours of the visible samples, at their own positions, over S.
    std::vector<float>* planes[3] = {&out.red, &out.green, &out.blue};
    for (int c = 0; c < 3; ++c) {
      double sum = 0.0;
      for (int s = 0; s < out.samples; ++s) {
        if (!((words[s / 32] >> (s % 32)) & 1u)) continue;
        float xs, ys, zs;
        detail::region_sample(table.data(), heights.data(), field.width, field.height, sources.absolute,
                              detail::region_table_seed(table.data(), options.seed),
                              options.decorrelate ? unsigned(p) + 1u : 0u, s, &xs, &ys, &zs);
        sum += lightValue(options.light_image, table, c, xs, ys);
      }
      (*planes[c])[p] = std::isnan(heights[p]) ? std::numeric_limits<float>::quiet_NaN()
                                               : static_cast<float>(sum / out.samples);
    }
  }
  return out;
}

RegionPairVisibilityResult referenceRegionPairVisibility(const HeightField& field,
                                                         const RegionSampling& sources,
                                                         const RegionSampling& receivers,
                                                         const RegionVisibilityOptions& options) {
  validate(field);
  validate(options);
  const std::vector<float> source_table = detail::regionSampleTable(field, sources);
  const std::vector<float> receiver_table = detail::regionSampleTable(field, receivers);
  const std::vector<float> heights = detail::prepareHeights(field, detail::HeightOrigin::Zero).heights;
  RegionPairVisibilityResult out;
  out.source_samples = detail::regionTableSamples(source_table);
  out.receiver_samples = detail::regionTableSamples(receiver_table);
  out.words = (out.source_samples + 31) / 32;
  out.sources = regionSamplePoints(field, sources, options.seed);
  out.receivers = regionSamplePoints(field, receivers, options.seed);
  out.bits.assign(std::size_t(out.receiver_samples) * out.words, 0u);
  const Pairs pairs{field, heights, options, source_table, sources.absolute};
  for (int r = 0; r < out.receiver_samples; ++r) {
    float x, y, z;
    detail::region_sample(receiver_table.data(), heights.data(), field.width, field.height,
                          receivers.absolute, detail::region_table_seed(receiver_table.data(), options.seed),
                          0u, r, &x, &y, &z);
    pairs.receiverBits(x, y, z, options.decorrelate ? unsigned(r) + 1u : 0u,
                       &out.bits[std::size_t(r) * out.words]);
  }
  detail::countPairFractions(out);  // the bits are what the reference decides; the counts are arithmetic
  return out;
}

}  // namespace hfvis
