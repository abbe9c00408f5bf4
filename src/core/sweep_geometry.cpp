// sweep_geometry.cpp: prepared heights, the ray geometry of a sweep direction and the scalar
// mirrors of the kernels' sampling helpers (kernels/shared/sweep_framework.cl).
#include "core/sweep_geometry.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

#include "core/host_bands.hpp"
#include "core/number_text.hpp"
#include "hfvis/errors.hpp"

namespace hfvis::detail {

namespace {
// Components this small are rounding noise of an axis-aligned direction: snap them to 0
// so that axis-aligned sweeps sample exactly the pixel centres.
double snap(double v) { return std::abs(v) < 1e-12 ? 0.0 : v; }
}  // namespace

SweepDirection makeSweepDirection(const HeightField& field, double azimuth, double samples_per_unit) {
  const double lines_per_unit = 1.0;
  SweepDirection d{};
  const double cos_az = snap(std::cos(azimuth)), sin_az = snap(std::sin(azimuth));
  // The ground direction (cos, sin) seen in pixel axes, where cells may not be square.
  double px = cos_az / field.cell_size_x, py = sin_az / field.cell_size_y;
  const double norm = std::hypot(px, py);
  px /= norm;
  py /= norm;
  d.dir_x = static_cast<float>(px);
  d.dir_y = static_cast<float>(py);
  d.perp_x = -d.dir_y;
  d.perp_y = d.dir_x;
  d.line_spacing = static_cast<float>(1.0 / lines_per_unit);
  d.lines_per_unit = static_cast<float>(lines_per_unit);
  d.step_length = static_cast<float>(1.0 / samples_per_unit);
  d.samples_per_unit = static_cast<float>(samples_per_unit);
  d.ground_per_pixel = static_cast<float>(std::hypot(px * field.cell_size_x, py * field.cell_size_y));
  d.cos_azimuth = static_cast<float>(cos_az);
  d.sin_azimuth = static_cast<float>(sin_az);

  // Offsets of the field's corners across (s) and along (t) the lines.
  double s_lo = std::numeric_limits<double>::max(), s_hi = -s_lo, t_lo = s_lo, t_hi = -s_lo;
  for (double x : {0.0, double(field.width - 1)}) {
    for (double y : {0.0, double(field.height - 1)}) {
      const double s = x * d.perp_x + y * d.perp_y, t = x * d.dir_x + y * d.dir_y;
      s_lo = std::min(s_lo, s), s_hi = std::max(s_hi, s), t_lo = std::min(t_lo, t), t_hi = std::max(t_hi, t);
    }
  }
  d.line_first = static_cast<std::int32_t>(std::floor(s_lo * lines_per_unit)) - 1;
  d.n_lines = static_cast<std::int32_t>(std::ceil(s_hi * lines_per_unit)) + 1 - d.line_first + 1;
  d.step_top = static_cast<std::int32_t>(std::ceil(t_hi * samples_per_unit)) + 1;
  d.n_steps = d.step_top - (static_cast<std::int32_t>(std::floor(t_lo * samples_per_unit)) - 1) + 1;
  return d;
}

bool insideField(Point2 p, int width, int height) {
  return p.x >= -kEdgeEpsilon && p.x <= static_cast<float>(width - 1) + kEdgeEpsilon &&
         p.y >= -kEdgeEpsilon && p.y <= static_cast<float>(height - 1) + kEdgeEpsilon;
}

namespace {

// The bilinear height in the cell of lower corner (x0, y0) at fractions (fx, fy) of it (the
// kernels' sample_cell_at).
float sampleCellAt(const std::vector<float>& heights, int width, int height, int x0, int y0, float fx,
                   float fy) {
  const int x1 = std::min(x0 + 1, width - 1), y1 = std::min(y0 + 1, height - 1);
  const float h00 = heights[y0 * width + x0], h10 = heights[y0 * width + x1];
  const float h01 = heights[y1 * width + x0], h11 = heights[y1 * width + x1];
  const float w00 = (1.0f - fx) * (1.0f - fy), w10 = fx * (1.0f - fy);
  const float w01 = (1.0f - fx) * fy, w11 = fx * fy;
  const float plain = cornerBilinear(h00, h10, h01, h11, w10, w01, w11);
  return std::isnan(plain) ? bilinearBesideNodata(h00, h10, h01, h11, w00, w10, w01, w11) : plain;
}

}  // namespace

float sampleHeight(const std::vector<float>& heights, int width, int height, Point2 p) {
  const float x = std::clamp(p.x, 0.0f, static_cast<float>(width - 1));
  const float y = std::clamp(p.y, 0.0f, static_cast<float>(height - 1));
  const int x0 = std::min(static_cast<int>(std::floor(x)), std::max(width - 2, 0));
  const int y0 = std::min(static_cast<int>(std::floor(y)), std::max(height - 2, 0));
  return sampleCellAt(heights, width, height, x0, y0, x - static_cast<float>(x0), y - static_cast<float>(y0));
}

float sampleHeightFrom(const std::vector<float>& heights, int width, int height, int c, int r, float ox,
                       float oy) {
  const float px = static_cast<float>(c) + ox, py = static_cast<float>(r) + oy;
  const float x = std::clamp(px, 0.0f, static_cast<float>(width - 1));
  const float y = std::clamp(py, 0.0f, static_cast<float>(height - 1));
  const int x0 = std::min(static_cast<int>(std::floor(x)), std::max(width - 2, 0));
  const int y0 = std::min(static_cast<int>(std::floor(y)), std::max(height - 2, 0));
  const float fx = x == px ? static_cast<float>(c - x0) + ox : x - static_cast<float>(x0);
  const float fy = y == py ? static_cast<float>(r - y0) + oy : y - static_cast<float>(y0);
  return sampleCellAt(heights, width, height, x0, y0, fx, fy);
}

PreparedHeights prepareHeights(const HeightField& field, HeightOrigin origin, int bands) {
  // Both passes in bands of rows on the host's threads (host_bands.hpp: at 4096^2 they took about
  // 100 ms on one), each band's extremes in float (exact), then combined.
  const std::size_t count = field.heights.size();
  const int rows = field.height > 0 ? field.height : 1;
  const std::size_t per_row = (count + rows - 1) / rows;
  if (bands <= 0) bands = bandsFor(rows, static_cast<long long>(per_row));
  bands = std::min(bands, rows);
  const auto band_range = [&](int first, int last) {
    return std::pair<std::size_t, std::size_t>(std::min(count, std::size_t(first) * per_row),
                                               std::min(count, std::size_t(last) * per_row));
  };
  std::vector<float> band_lowest(bands, std::numeric_limits<float>::infinity()),
      band_highest(bands, -std::numeric_limits<float>::infinity());
  forEachBand(rows, bands, [&](int band, int first, int last) {
    const auto [begin, end] = band_range(first, last);
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    for (std::size_t i = begin; i < end; ++i) {
      const float h = field.heights[i];
      // (NaN fails both; an infinite height is no finite extreme)
      if (std::fabs(h) <= std::numeric_limits<float>::max()) lo = std::min(lo, h), hi = std::max(hi, h);
    }
    band_lowest[band] = lo, band_highest[band] = hi;
  });
  double lowest = std::numeric_limits<double>::max(), highest = std::numeric_limits<double>::lowest();
  for (int b = 0; b < bands; ++b)
    if (band_lowest[b] <= band_highest[b])
      lowest = std::min(lowest, double(band_lowest[b])), highest = std::max(highest, double(band_highest[b]));
  // (a field cut from a larger one takes that one's base, so that its heights are the same floats)
  const double base = origin == HeightOrigin::Zero ? 0.0  // h - 0.0 is h exactly
                      : field.origin.present()     ? field.origin.base
                                                   : heightBase(field);
  // The kernels multiply height differences by distances in float: keep the products finite.
  const double rise = std::max(highest, base) - std::min(lowest, base);
  if (origin == HeightOrigin::Base && highest >= lowest && rise * field.z_scale > kMaxPreparedHeight) {
    std::ostringstream message;
    message << "the heights span " << lowest << " .. " << highest << " (counted from " << base
            << "), a rise of " << rise * field.z_scale << " with the z-scale " << field.z_scale
            << ": more than the " << kMaxPreparedHeight << " the kernels' float arithmetic holds";
    throw InvalidArgument(message.str());
  }
  // From 0 (the viewshed's, region visibility's and the ray caster's heights), the heights
  // themselves: the same products, and beyond float's range a height would become infinite.
  if (origin == HeightOrigin::Zero && highest >= lowest &&
      std::max(std::fabs(lowest), std::fabs(highest)) * field.z_scale > kMaxPreparedHeight) {
    std::ostringstream message;
    message << "the heights span " << lowest << " .. " << highest << ", up to "
            << std::max(std::fabs(lowest), std::fabs(highest)) * field.z_scale << " from 0 with the z-scale "
            << field.z_scale << ": more than the " << kMaxPreparedHeight
            << " the kernels' float arithmetic holds";
    throw InvalidArgument(message.str());
  }
  // From 0, float32's spacing grows with the heights themselves: heights near 1e9 keep steps of
  // 64, and an eye 20 above them was lost (a viewshed 11 times too small, exit 0; the sweep's
  // heights, from their lowest, kept it). Refused where the spacing passes a tenth of a cell (a
  // slope error of a twentieth across one at most). A rule of the arithmetic near the heights,
  // apart from requireHeightsKeptInFloat32's of values a reader changed: it takes no relief, so
  // that a window of a field (a Dask viewshed's) is judged as the whole field is; a plateau at
  // 1e6 on cells of 1 (steps of 1/16, a hard case the kernels and their references share) is kept.
  if (origin == HeightOrigin::Zero && highest >= lowest) {
    const float top = static_cast<float>(std::max(std::fabs(lowest), std::fabs(highest)) * field.z_scale);
    const double spacing = double(std::nextafter(top, std::numeric_limits<float>::infinity())) - double(top);
    if (spacing > 0.1 * std::min(field.cell_size_x, field.cell_size_y)) {
      std::ostringstream message;
      message << "the heights span " << exactNumber(lowest) << " .. " << exactNumber(highest)
              << " with the z-scale " << field.z_scale
              << ", so far from 0 that float32, in which hfvis follows sight lines from given heights, holds "
                 "them "
                 "only in steps of "
              << spacing << " there: more than a tenth of a cell; subtract a constant from them first";
      throw InvalidArgument(message.str());
    }
  }
  PreparedHeights prepared;
  if (std::isfinite(base)) prepared.base = static_cast<float>(base * field.z_scale);  // (none: no height is)
  prepared.heights.resize(count);
  std::vector<char> band_nodata(bands, 0);
  const double z_scale = field.z_scale;
  forEachBand(rows, bands, [&](int band, int first, int last) {
    const auto [begin, end] = band_range(first, last);
    const float* in = field.heights.data();
    float* out = prepared.heights.data();
    bool nodata = false;
    float lo = std::numeric_limits<float>::infinity(), hi = -lo;
    for (std::size_t i = begin; i < end; ++i) {
      const float h = in[i];
      const bool finite = std::fabs(h) <= std::numeric_limits<float>::max();
      nodata |= !finite;
      const float v = static_cast<float>((static_cast<double>(h) - base) * z_scale);
      out[i] = finite ? v : std::numeric_limits<float>::quiet_NaN();
      lo = finite ? std::min(lo, v) : lo, hi = finite ? std::max(hi, v) : hi;
    }
    band_nodata[band] = nodata;
    band_lowest[band] = lo, band_highest[band] = hi;
  });
  for (int b = 0; b < bands; ++b) {
    prepared.has_nodata = prepared.has_nodata || band_nodata[b];
    prepared.lowest = std::min(prepared.lowest, band_lowest[b]);
    prepared.highest = std::max(prepared.highest, band_highest[b]);
  }
  return prepared;
}

void checkPixelIndexing(const HeightField& field, int planes) {
  const std::size_t pixels = field.pixelCount();
  if (pixels >= (std::size_t(1) << 31) || pixels * static_cast<std::size_t>(planes) >= (std::size_t(1) << 32)) {
    throw InvalidArgument("fields of 2^31 pixels or more (or planes of them beyond 2^32 values) are not supported "
                          "yet (got " + std::to_string(field.width) + " x " + std::to_string(field.height) +
                          "); split the field into tiles");
  }
}

int stepsWithin(double max_distance, double step_ground) {
  if (max_distance <= 0.0) return kAllSteps;
  return static_cast<int>(std::min<double>(kAllSteps, std::floor(max_distance / step_ground)));
}


}  // namespace hfvis::detail
