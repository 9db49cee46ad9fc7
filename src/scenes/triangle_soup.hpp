// Internal: loose triangles from loaded levels and models, grouped into
// culling-sized objects by spatial clustering.
#pragma once

#include "occull/scene.hpp"

#include <cstdint>
#include <utility>
#include <vector>

namespace occull::scenes {

struct SoupTriangle {
  glm::vec3 p[3];
  glm::vec3 n[3];
  std::int32_t material;  ///< loader-defined material key
  std::int32_t source = -1;  ///< loader-defined origin (a Quake 3 face), -1 when none
};

/// Splits [begin, end) recursively at the median centroid along the longest
/// axis until every group has at most `target` triangles; appends the groups
/// as index ranges (reordering `tris`).
void cluster_triangles(std::vector<SoupTriangle>& tris, std::size_t begin, std::size_t end,
                       std::uint32_t target, std::vector<std::pair<std::size_t, std::size_t>>& groups);

/// One mesh of the triangles [begin, end), normals normalised, plus the
/// material key most of them use.
std::pair<Mesh, std::int32_t> mesh_of(const std::vector<SoupTriangle>& tris, std::size_t begin,
                                      std::size_t end);

}  // namespace occull::scenes
