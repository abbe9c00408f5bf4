// environment_swaths.cpp: see environment_swaths.hpp.
#include "core/environment_swaths.hpp"

#include <algorithm>
#include <cmath>

namespace hfvis {
namespace detail {

EnvironmentSwaths environmentSwaths(const EnvironmentMap& map, const std::vector<LatticeDirection>& directions) {
  const std::size_t K = directions.size();
  std::vector<std::vector<std::array<double, 2>>> spans(K);
  for (std::size_t k = 0; k < K; ++k) {
    const double azimuth = directions[k].azimuth;
    // One direction stands for the whole circle, two for half of it each.
    double before = 2.0 * M_PI, after = 2.0 * M_PI;
    if (K > 2) {
      before = angleDifference(azimuth, directions[(k + K - 1) % K].azimuth);
      after = angleDifference(directions[(k + 1) % K].azimuth, azimuth);
    } else if (K == 2) {
      before = after = M_PI;
    }
    std::size_t owner = k;
    for (std::size_t m = 0; m < k && directions[k].weight == 0.0; ++m) {
      const LatticeDirection& e = directions[m];
      if (e.a == directions[k].a && e.b == directions[k].b && e.weight > 0.0) {
        owner = m;
        break;
      }
    }
    spans[owner].push_back({azimuth - 0.5 * before, azimuth + 0.5 * after});
  }
  const double column = 2.0 * M_PI / map.width;
  // Column 0's left edge, hfvis azimuth; the rotation within a turn first (exact: fmod rounds
  // nothing), as 1e300 degrees lost every digit of the edges and the kernel's walk over the
  // columns never ended.
  const double origin = std::fmod(map.rotation_deg, 360.0) * M_PI / 180.0 - 0.5 * M_PI;
  EnvironmentSwaths out;
  for (std::size_t k = 0; k < K; ++k) {
    out.spans.push_back({static_cast<int>(out.bins.size()), static_cast<int>(spans[k].size())});
    const double ref = directions[k].azimuth;
    for (const auto& [lo, hi] : spans[k]) {
      const double first = std::floor((lo - origin) / column);
      const double edge = origin + first * column - ref;
      const double wrapped = first - map.width * std::floor(first / map.width);
      out.bins.push_back({static_cast<float>(lo - ref), static_cast<float>(hi - ref), static_cast<float>(edge),
                          static_cast<float>(wrapped)});
    }
  }
  return out;
}

}  // namespace detail
}  // namespace hfvis
