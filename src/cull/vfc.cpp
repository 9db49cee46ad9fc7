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

  FrameResult cull(const View& view, Backend& backend) override {
    FrameResult result;
    queue_.clear();
    collect_in_frustum_front_to_back(index_, view, queue_, result.nodes_visited, /*subpixel=*/false);  // the baseline: frustum only
    if (!queue_.empty()) backend.render(queue_);
    return result;
  }

 private:
  SceneIndex index_;
  std::vector<ObjectId> queue_;
};

}  // namespace

Registration vfc_registration() {
  static const ConfigTable<VfcConfig> table;
  return registered({"vfc", "hierarchical view-frustum culling over the BVH, front to back"}, table,
                    [](const SceneIndex& index, const VfcConfig&, const Options&, const CullerContext&) {
                      return std::make_unique<VfcCuller>(index);
                    });
}

}  // namespace occull::detail
