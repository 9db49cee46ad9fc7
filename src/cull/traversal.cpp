#include "traversal.hpp"

#include <cmath>

namespace occull::detail {
namespace {

// An object's box in a node inside `planes` of the frustum is tested
// against those only (none: it is inside). An empty box (a mesh without
// triangles) never is, nor one that holds no sample when `subpixel`.
bool in_frustum(const Aabb& box, const View& view, std::uint32_t planes, bool subpixel) {
  if (planes == 0 ? box.empty() : view.frustum.classify(box, planes) == Containment::outside) return false;
  return !subpixel || !holds_no_sample(box, view);
}

}  // namespace

void append_objects_in_frustum(const SceneIndex& index, NodeId n, const View& view,
                               std::vector<ObjectId>& out, std::uint32_t planes) {
  for (ObjectId id : index.bvh.objects(n))
    if (in_frustum(index.scene.object(id).bounds, view, planes, true)) out.push_back(id);
}

namespace {

void collect(const SceneIndex& index, NodeId n, std::uint32_t planes, const View& view, bool subpixel,
             std::vector<ObjectId>& out, std::uint64_t& nodes_visited) {
  const Bvh& bvh = index.bvh;
  ++nodes_visited;
  if (bvh.node(n).object_count == 0) return;
  if (planes != 0 && view.frustum.classify(bvh.node(n).bounds, planes) == Containment::outside)
    return;
  if (subpixel && holds_no_sample(bvh.node(n).bounds, view)) return;
  if (bvh.is_leaf(n)) {
    for (ObjectId id : bvh.objects(n))
      if (in_frustum(index.scene.object(id).bounds, view, planes, subpixel)) out.push_back(id);
    return;
  }
  for (NodeId c : children_front_to_back(bvh, n, view.eye)) collect(index, c, planes, view, subpixel, out, nodes_visited);
}

}  // namespace

void collect_in_frustum_front_to_back(const SceneIndex& index, const View& view,
                                      std::vector<ObjectId>& out, std::uint64_t& nodes_visited, bool subpixel) {
  collect(index, Bvh::root(), Frustum::all_planes, view, subpixel, out, nodes_visited);
}

}  // namespace occull::detail
