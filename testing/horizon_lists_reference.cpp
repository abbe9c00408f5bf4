// horizon_lists_reference.cpp: see hfvis_testing/horizon_lists_reference.hpp.
#include "hfvis_testing/horizon_lists_reference.hpp"

#include <cmath>
#include <set>

#include "core/chord_side.hpp"
#include "core/horizon_common.hpp"
#include "core/tree_peaks.hpp"
#include "hfvis_testing/sight_along_line.hpp"

namespace hfvis {

// The naive method's samples: sample i at distance i * step_length along d.
std::vector<float> referenceRay(const HeightField& field, const std::vector<float>& h,
                                const detail::SweepDirection& d, int c, int r) {
  std::vector<float> ray;
  for (int i = 1;; ++i) {
    const float t = float(i) * d.step_length;
    const detail::Point2 p{float(c) + t * d.dir_x, float(r) + t * d.dir_y};
    if (!detail::insideField(p, field.width, field.height)) break;
    ray.push_back(detail::sampleHeightFrom(h, field.width, field.height, c, r, t * d.dir_x, t * d.dir_y));
  }
  return ray;
}

HorizonListReference referenceHorizonList(const std::vector<float>& ray, float hr, const RayPeaks& peaks,
                                          float height_base) {
  const int n = static_cast<int>(ray.size());
  HorizonListReference out;
  out.visible.assign(n + 1, false);
  out.exactly.assign(n + 1, false);
  // The nodes, farthest first, the receiver last: present samples and admitted peaks, at their
  // positions (distances from the receiver); `sample` is i for sample i, -1 - j for the peak of
  // interval j.
  struct Node {
    float h;
    float distance;
    int sample;
  };
  std::vector<Node> nodes;
  auto height = [&](int i) { return i == 0 ? hr : ray[i - 1]; };
  auto position = [&](int i) {
    return i == 0 ? 0 : peaks.positions.empty() ? i << peaks.shift : peaks.positions[i - 1];
  };
  for (int i = n; i >= 1; --i) {
    if (!std::isnan(ray[i - 1])) nodes.push_back({ray[i - 1], float(position(i)), i});
    const int j = i - 1;  // the interval from sample i to the next nearer one
    if (!peaks.heights.empty() && detail::tree_peak_inserted(height(i), peaks.heights[j], height(j),
                                                             peaks.offsets[j], position(i) - position(j))) {
      nodes.push_back({peaks.heights[j], float(position(i) - peaks.offsets[j]), -1 - j});
      ++out.peaks_admitted;
    }
  }
  nodes.push_back({hr, 0.0f, 0});
  const std::size_t receiver = nodes.size() - 1;
  // Visible: no node nearer lies strictly above the sight line from the receiver, or the steepest
  // nearer node (the farthest on ties) hides it only within the heights' rounding, as it does every
  // hidden sample between them (the tie rule, sightAlongLine; positions: minus the distances);
  // `stretch` is each visible node's farthest forgiven sample (0: none).
  std::vector<LineNode> line(nodes.size());
  for (std::size_t x = 0; x < nodes.size(); ++x)
    line[x] = {nodes[x].h, -nodes[x].distance, nodes[x].sample <= 0};
  const LineSight sight = sightAlongLine(line, receiver, height_base);
  std::vector<int> stretch(receiver, 0);
  for (std::size_t x = receiver; x-- > 0;) {
    if (nodes[x].sample <= 0) continue;
    out.exactly[nodes[x].sample] = sight.exactly[x];
    out.visible[nodes[x].sample] = sight.exactly[x] || sight.forgiven[x];
    if (sight.forgiven[x]) stretch[sight.steepest[x]] = nodes[x].sample;
  }
  // Eq. 1 in sweep order: the first node is a segment start, then every convex node after a
  // concave one (class from the chord of its two neighbours; collinear keeps the previous
  // class). Eq. 2: each start's horizon is the farthest node of maximal slope among the start ..
  // the receiver's neighbour.
  std::set<int> horizons;
  int class_last = 1;
  for (std::size_t s = 0; s < receiver; ++s) {
    bool start = s == 0;
    if (s > 0) {
      const int side = detail::chordSide(nodes[s - 1].h, nodes[s].h, nodes[s + 1].h,
                                         nodes[s - 1].distance - nodes[s].distance,
                                         nodes[s].distance - nodes[s + 1].distance);
      const int cls = side > 0 ? 1 : side < 0 ? 0 : class_last;
      start = cls == 1 && class_last == 0;
      class_last = cls;
    }
    if (!start) continue;
    std::size_t best = s;
    for (std::size_t x = s + 1; x < receiver; ++x) {
      // x (nearer) replaces the best only when strictly steeper: best strictly below the chord x-receiver.
      if (detail::chordSide(nodes[best].h, nodes[x].h, hr, nodes[best].distance - nodes[x].distance,
                            nodes[x].distance) > 0)
        best = x;
    }
    // Listed by the farthest sample of its forgiven stretch, else by its own; a peak by the
    // sample right after it, where that one is visible.
    const int sample = nodes[best].sample;
    if (stretch[best] > 0)
      horizons.insert(stretch[best]);
    else if (sample > 0)
      horizons.insert(sample);
    else if (-1 - sample >= 1 && out.visible[-1 - sample])
      horizons.insert(-1 - sample);
  }
  out.horizons.assign(horizons.begin(), horizons.end());
  return out;
}

}  // namespace hfvis
