// sight_along_line.cpp: see hfvis_testing/sight_along_line.hpp.
#include "hfvis_testing/sight_along_line.hpp"

#include "core/chord_side.hpp"

namespace hfvis {

LineSight sightAlongLine(const std::vector<LineNode>& nodes, std::size_t receiver, float height_base) {
  LineSight out;
  out.exactly.assign(receiver, false);
  out.forgiven.assign(receiver, false);
  out.steepest.assign(receiver, -1);
  const LineNode& r = nodes[receiver];
  int best = -1;           // the steepest node so far, the farthest on ties
  bool forgiving = false;  // every hidden node since `best` was forgiven
  for (std::size_t x = receiver; x-- > 0;) {
    const LineNode& q = nodes[x];
    if (best < 0 || detail::chordSide(q.h, nodes[best].h, r.h, nodes[best].position - q.position,
                                      r.position - nodes[best].position) <= 0) {
      out.exactly[x] = true;
      best = static_cast<int>(x);
      forgiving = true;
    } else if (!q.occluder_only) {
      forgiving = forgiving &&
                  detail::seen_within_rounding(q.h, nodes[best].h, r.h, nodes[best].position - q.position,
                                               r.position - nodes[best].position, height_base);
      out.forgiven[x] = forgiving;
    }
    out.steepest[x] = best;
  }
  return out;
}

}  // namespace hfvis
