// Internal helpers shared by the hierarchical cullers.
#pragma once

#include "occull/bvh.hpp"

#include <array>

namespace occull::detail {

/// The two children of interior node `n`, the one nearer to `eye` first
/// (distance from the eye to each child's box; ties keep left first).
/// Precondition: n is not a leaf.
inline std::array<NodeId, 2> children_front_to_back(const Bvh& bvh, NodeId n,
                                                    const glm::vec3& eye) {
  const NodeId l = Bvh::left(n);
  const NodeId r = bvh.right(n);
  if (distance(eye, bvh.node(r).bounds) < distance(eye, bvh.node(l).bounds)) return {r, l};
  return {l, r};
}

}  // namespace occull::detail
