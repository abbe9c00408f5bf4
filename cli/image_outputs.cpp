// cli/image_outputs.cpp: see image_outputs.hpp.
#include "image_outputs.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "hfvis/errors.hpp"

namespace hfvis::cli {

std::vector<std::string> directionChannelNames(const std::string& prefix, int count) {
  if (count < 0)
    throw InvalidArgument("direction count must not be negative (got " + std::to_string(count) + ")");
  const int digits = static_cast<int>(std::to_string(std::max(count - 1, 0)).size());
  const int width = std::max(3, digits);
  std::vector<std::string> names;
  names.reserve(static_cast<std::size_t>(count));
  for (int k = 0; k < count; ++k) {
    const std::string index = std::to_string(k);
    names.push_back(prefix + std::string(static_cast<std::size_t>(width) - index.size(), '0') + index);
  }
  return names;
}

std::pair<float, float> quantileRange(const std::vector<float>& plane, double lo_q, double hi_q) {
  std::vector<float> finite;
  for (float v : plane)
    if (std::isfinite(v)) finite.push_back(v);
  if (finite.empty()) return {0.0f, 0.0f};
  auto at = [&](double q) {
    const std::size_t rank = static_cast<std::size_t>(std::clamp(q, 0.0, 1.0) * (finite.size() - 1) + 0.5);
    std::nth_element(finite.begin(), finite.begin() + rank, finite.end());
    return finite[rank];
  };
  const float lo = at(lo_q), hi = at(hi_q);
  return {lo, hi};
}

std::vector<float> hillshade(const HeightField& f) {
  std::vector<float> shade(f.pixelCount(), 0.0f);
  const double lx = -0.5, ly = -0.5, lz = std::sqrt(0.5);  // toward -column, -row (north-west), up
  auto at = [&](int x, int y) {
    const float v = f.at(std::clamp(x, 0, f.width - 1), std::clamp(y, 0, f.height - 1));
    return std::isfinite(v) ? v * f.z_scale : std::numeric_limits<double>::quiet_NaN();
  };
  for (int y = 0; y < f.height; ++y)
    for (int x = 0; x < f.width; ++x) {
      const double gx = (at(x + 1, y) - at(x - 1, y)) / (2.0 * f.cell_size_x);
      const double gy = (at(x, y + 1) - at(x, y - 1)) / (2.0 * f.cell_size_y);
      const double n = std::sqrt(gx * gx + gy * gy + 1.0);
      const double lit = (-gx * lx - gy * ly + lz) / n;
      shade[static_cast<std::size_t>(y) * f.width + x] =
          std::isfinite(lit) ? static_cast<float>(std::max(lit, 0.0)) : 0.0f;
    }
  return shade;
}

}  // namespace hfvis::cli
