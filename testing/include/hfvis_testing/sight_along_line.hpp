// hfvis_testing/sight_along_line.hpp: the brute-force oracle of the tie rule along one line, which
// the intervisibility, bounce and horizon-list tests share: what a receiver sees of the nodes
// (samples, and peaks between them that only occlude) farther along its line, each decided by the
// exact chord_side predicate, with the heights' rounding forgiven as the kernels forgive it
// (kernels/shared/chord_side.cl, seen_within_rounding). Test support library hfvis_testing; not
// installed.
#pragma once

#include <cstddef>
#include <vector>

namespace hfvis {

// A node of a line: its height and its position along the line (growing toward the receiver;
// any unit, the same for every node); an occluder alone (a peak between samples) hides but is
// never forgiven.
struct LineNode {
  float h = 0.0f;
  float position = 0.0f;
  bool occluder_only = false;
};

// Per node before the receiver (index as in the nodes).
struct LineSight {
  std::vector<bool> exactly;   // no nearer node strictly above its sight line to the receiver
  std::vector<bool> forgiven;  // hidden, but seen within the heights' rounding (never an occluder alone)
  // The steepest node between it and the receiver once it is decided, the farthest on ties (itself
  // where exactly visible): the node that hides it where it is hidden.
  std::vector<int> steepest;
};

// nodes[0, receiver) farthest first, nodes[receiver] the receiver. One sweep outward from the
// receiver keeping the steepest node so far (Timonen 2013's horizon): a node is exactly visible
// when that node is not strictly above its chord to the receiver; a hidden node is forgiven where
// the steepest node hides it only within the heights' rounding (`height_base`: the prepared
// heights' base, PreparedHeights::base), and so is every hidden node between them, so the
// forgiven nodes are stretches outward from each visible one.
LineSight sightAlongLine(const std::vector<LineNode>& nodes, std::size_t receiver, float height_base);

}  // namespace hfvis
