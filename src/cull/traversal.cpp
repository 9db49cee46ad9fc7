#include "traversal.hpp"

#include <cmath>

namespace occull::detail {
namespace {

// An object's box in a node inside `planes` of the frustum is tested
// against those only (none: it is inside). An empty box (a mesh without
// triangles) never is.
bool in_frustum(const Aabb& box, const View& view, std::uint32_t planes) {
  if (planes == 0) return !box.empty();
  return view.frustum.classify(box, planes) != Containment::outside;
}

}  // namespace

void append_objects_in_frustum(const SceneIndex& index, NodeId n, const View& view,
                               std::vector<ObjectId>& out, std::uint32_t planes) {
  for (ObjectId id : index.bvh.objects(n))
    if (in_frustum(index.scene.object(id).bounds, view, planes)) out.push_back(id);
}

namespace {

void collect(const SceneIndex& index, NodeId n, std::uint32_t planes, const View& view,
             std::vector<ObjectId>& out, FrameStats& stats) {
  const Bvh& bvh = index.bvh;
  ++stats.nodes_visited;
  if (bvh.node(n).object_count == 0) return;
  if (planes != 0 && view.frustum.classify(bvh.node(n).bounds, planes) == Containment::outside)
    return;
  if (bvh.is_leaf(n)) {
    for (ObjectId id : bvh.objects(n))
      if (in_frustum(index.scene.object(id).bounds, view, planes)) out.push_back(id);
    return;
  }
  for (NodeId c : children_front_to_back(bvh, n, view.eye)) collect(index, c, planes, view, out, stats);
}

}  // namespace

void collect_in_frustum_front_to_back(const SceneIndex& index, const View& view,
                                      std::vector<ObjectId>& out, FrameStats& stats) {
  collect(index, Bvh::root(), Frustum::all_planes, view, out, stats);
}

}  // namespace occull::detail
