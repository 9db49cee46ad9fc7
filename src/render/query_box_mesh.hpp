// Internal to the renderers (occull_gl, occull_vk): the mesh query boxes are
// drawn with, one instance per box, the same in every API.
#pragma once

#include <glm/vec3.hpp>

#include <utility>
#include <vector>

namespace occull::render {

/// A vertex of the query mesh: `p` the box corner (0/1 per axis), and for a
/// silhouette band `q` its second end and `band` (x: 1 on a band; y: 1 at the
/// second end; z: side, -1 or +1). The query vertex shaders read these three.
struct QueryVertex {
  glm::vec3 p, q, band;
};

/// The 36 vertices of a unit cube's faces (outward, counter-clockwise in
/// OpenGL's terms; corner i has bit 0 = x, bit 1 = y, bit 2 = z, as
/// Aabb::corner), then 6 per edge for its silhouette band, which the query
/// vertex shaders widen by the margin where the edge is on the silhouette.
inline std::vector<QueryVertex> query_box_mesh() {
  const auto corner = [](int i) { return glm::vec3(float(i & 1), float((i >> 1) & 1), float((i >> 2) & 1)); };
  static constexpr int faces[36] = {0, 2, 3, 0, 3, 1,  4, 5, 7, 4, 7, 6,  0, 4, 6, 0, 6, 2,
                                    1, 3, 7, 1, 7, 5,  0, 1, 5, 0, 5, 4,  2, 6, 7, 2, 7, 3};
  std::vector<QueryVertex> v;
  for (int i : faces) v.push_back({corner(i), corner(i), {0, 0, 0}});
  for (int axis = 0; axis < 3; ++axis)
    for (int others = 0; others < 4; ++others) {
      // The corner with bit `axis` clear and the other two bits from `others`, and its partner.
      const int low = axis == 0 ? others << 1 : axis == 1 ? (others & 1) | ((others & 2) << 1) : others;
      const glm::vec3 p = corner(low), q = corner(low | (1 << axis));
      // (p,-) (q,-) (q,+)  (p,-) (q,+) (p,+)
      for (const auto& [end, side] : {std::pair{0.f, -1.f}, {1.f, -1.f}, {1.f, 1.f}, {0.f, -1.f}, {1.f, 1.f}, {0.f, 1.f}})
        v.push_back({p, q, {1.0f, end, side}});
    }
  return v;
}

}  // namespace occull::render
