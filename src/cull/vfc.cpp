// `vfc`: hierarchical view-frustum culling over the BVH, front to back.
//
// Nodes outside the frustum are skipped with their subtree; the planes a
// node lies fully inside are not tested again below it. Objects of visited
// leaves are tested one by one and queued nearest subtree first, then
// rendered as one render-queue flush.
#include "cullers.hpp"
#include "traversal.hpp"

namespace occull::detail {
namespace {

class VfcCuller final : public Culler {
 public:
  explicit VfcCuller(const SceneIndex& index) : index_(index) {}

  FrameStats render_frame(const View& view, Backend& backend) override {
    FrameStats stats;
    queue_.clear();
    visit(Bvh::root(), Frustum::all_planes, view, stats);
    if (!queue_.empty()) backend.render(queue_);
    return stats;
  }

 private:
  void visit(NodeId n, std::uint32_t planes, const View& view, FrameStats& stats) {
    const Bvh& bvh = index_.bvh;
    ++stats.nodes_visited;
    if (bvh.node(n).object_count == 0) return;
    if (planes != 0 && view.frustum.classify(bvh.node(n).bounds, planes) == Containment::outside)
      return;
    if (bvh.is_leaf(n)) {
      for (ObjectId id : bvh.objects(n)) {
        std::uint32_t mask = planes;
        if (planes == 0 ||
            view.frustum.classify(index_.scene.object(id).bounds, mask) != Containment::outside)
          queue_.push_back(id);
      }
      return;
    }
    for (NodeId c : children_front_to_back(bvh, n, view.eye)) visit(c, planes, view, stats);
  }

  SceneIndex index_;
  std::vector<ObjectId> queue_;
};

}  // namespace

std::unique_ptr<Culler> make_vfc(const SceneIndex& index, const Options&) {
  return std::make_unique<VfcCuller>(index);
}

}  // namespace occull::detail
