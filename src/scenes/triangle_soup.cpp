#include "triangle_soup.hpp"

#include <algorithm>
#include <map>

namespace occull::scenes {

void cluster_triangles(std::vector<SoupTriangle>& tris, std::size_t begin, std::size_t end,
                       std::uint32_t target, std::vector<std::pair<std::size_t, std::size_t>>& groups) {
  if (end - begin <= target) {
    if (end > begin) groups.emplace_back(begin, end);
    return;
  }
  Aabb box;
  for (std::size_t i = begin; i < end; ++i) box.extend((tris[i].p[0] + tris[i].p[1] + tris[i].p[2]) / 3.0f);
  const glm::vec3 e = box.extent();
  const int axis = e.x >= e.y && e.x >= e.z ? 0 : (e.y >= e.z ? 1 : 2);
  const std::size_t mid = begin + (end - begin) / 2;
  std::nth_element(tris.begin() + long(begin), tris.begin() + long(mid), tris.begin() + long(end),
                   [axis](const SoupTriangle& a, const SoupTriangle& b) {
                     return a.p[0][axis] + a.p[1][axis] + a.p[2][axis] < b.p[0][axis] + b.p[1][axis] + b.p[2][axis];
                   });
  cluster_triangles(tris, begin, mid, target, groups);
  cluster_triangles(tris, mid, end, target, groups);
}

std::pair<Mesh, std::int32_t> mesh_of(const std::vector<SoupTriangle>& tris, std::size_t begin,
                                      std::size_t end) {
  Mesh mesh;
  std::map<std::int32_t, std::size_t> count;
  for (std::size_t i = begin; i < end; ++i) {
    const SoupTriangle& t = tris[i];
    const auto base = std::uint32_t(mesh.positions.size());
    for (int c = 0; c < 3; ++c) {
      mesh.positions.push_back(t.p[c]);
      const float len = glm::length(t.n[c]);
      mesh.normals.push_back(len > 0 ? t.n[c] / len : glm::vec3(0, 1, 0));
    }
    mesh.indices.insert(mesh.indices.end(), {base, base + 1, base + 2});
    ++count[t.material];
  }
  const std::int32_t dominant =
      count.empty() ? 0
                    : std::max_element(count.begin(), count.end(), [](auto& a, auto& b) { return a.second < b.second; })->first;
  return {std::move(mesh), dominant};
}

}  // namespace occull::scenes
