// horizon_lists_reference.cpp: see hfvis_testing/horizon_lists_reference.hpp.
#include "hfvis_testing/horizon_lists_reference.hpp"

#include <cmath>
#include <set>

#include "core/chord_side.hpp"
#include "core/horizon_common.hpp"

namespace hfvis {

// The naive method's samples: sample i at distance i * step_length along d.
std::vector<float> referenceRay(const HeightField& field, const std::vector<float>& h,
                                const detail::SweepDirection& d, int c, int r) {
  std::vector<float> ray;
  for (int i = 1;; ++i) {
    const float t = float(i) * d.step_length;
    const detail::Point2 p{float(c) + t * d.dir_x, float(r) + t * d.dir_y};
    if (!detail::insideField(p, field.width, field.height)) break;
    ray.push_back(detail::sampleHeight(h, field.width, field.height, p));
  }
  return ray;
}

HorizonListReference referenceHorizonList(const std::vector<float>& ray, float hr) {
  const int n = static_cast<int>(ray.size());
  HorizonListReference out;
  out.visible.assign(n + 1, false);
  // Visible: no present sample strictly between lies strictly above the chord q-receiver;
  // keep the steepest present sample so far, nearest first.
  int best = 0;
  for (int i = 1; i <= n; ++i) {
    if (std::isnan(ray[i - 1])) continue;
    if (best == 0 || detail::chordSide(ray[i - 1], ray[best - 1], hr, float(i - best), float(best)) <= 0) {
      out.visible[i] = true;
      best = i;
    }
  }
  // Eq. 1 on the present samples in sweep order (farthest first, receiver last): the first
  // is a segment start, then every convex sample after a concave one (class from the chord
  // of its two neighbours; collinear keeps the previous class). Eq. 2: each start's horizon
  // is the farthest sample of maximal slope among the start .. the receiver's neighbour.
  std::vector<int> order;  // sample indices, farthest first; 0 = the receiver
  std::vector<float> height;
  for (int i = n; i >= 1; --i)
    if (!std::isnan(ray[i - 1])) order.push_back(i), height.push_back(ray[i - 1]);
  order.push_back(0);
  height.push_back(hr);
  std::set<int> horizons;
  int class_last = 1;
  for (std::size_t s = 0; s + 1 < order.size(); ++s) {
    bool start = s == 0;
    if (s > 0) {
      const int side = detail::chordSide(height[s - 1], height[s], height[s + 1],
                                         float(order[s - 1] - order[s]), float(order[s] - order[s + 1]));
      const int cls = side > 0 ? 1 : side < 0 ? 0 : class_last;
      start = cls == 1 && class_last == 0;
      class_last = cls;
    }
    if (!start) continue;
    int best_sample = -1;  // the farthest of maximal slope among order[s .. end - 1]
    for (std::size_t x = s; x + 1 < order.size(); ++x) {
      if (best_sample < 0) {
        best_sample = static_cast<int>(x);
        continue;
      }
      // x (nearer) replaces the best only when strictly steeper: best strictly below the chord x-receiver.
      const int b = order[best_sample], q = order[x];
      if (detail::chordSide(height[best_sample], height[x], hr, float(b - q), float(q)) > 0)
        best_sample = int(x);
    }
    horizons.insert(order[best_sample]);
  }
  out.horizons.assign(horizons.begin(), horizons.end());
  return out;
}

}  // namespace hfvis
