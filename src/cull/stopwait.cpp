// `stopwait`: hierarchical stop-and-wait occlusion culling — the baseline
// the CHC papers beat. The BVH is traversed front to back; every node in
// the frustum is queried and the traversal waits for the answer before it
// goes on. Visible leaves are rendered at once, so later queries test
// against everything nearer. No temporal coherence, no batching.
#include "cullers.hpp"
#include "traversal.hpp"

namespace occull::detail {
namespace {

class StopWaitCuller final : public Culler {
 public:
  StopWaitCuller(const SceneIndex& index, const QueryOptions& common) : index_(index), common_(common) {}

  void visit_counters(const CounterVisitor& visit) const override { counters_.visit(visit); }

  FrameResult cull(const View& view, Backend& backend) override {
    FrameResult result;
    counters_ = {};
    const Bvh& bvh = index_.bvh;
    const float radius = near_plane_radius(view);
    DistanceQueue queue;
    queue.push(bvh, Bvh::root(), view.eye);
    while (!queue.empty()) {
      const NodeId n = queue.pop();
      ++result.nodes_visited;
      const BvhNode& node = bvh.node(n);
      if (node.object_count == 0 || view.frustum.classify(node.bounds) == Containment::outside ||
          holds_no_sample(node.bounds, view))
        continue;
      if (!near_eye(node.bounds, view, radius)) {
        boxes_.clear();
        append_query_boxes(index_, n, {}, boxes_);
        const QueryId q = backend.issue_query(boxes_);
        ++counters_.query_batches;
        if (backend.result(q) <= common_.threshold) continue;  // stop and wait
      }
      if (bvh.is_leaf(n, common_.virtual_leaf_triangles)) {
        objects_.clear();
        append_objects_in_frustum(index_, n, view, objects_);
        if (!objects_.empty()) backend.render(objects_);
      } else {
        queue.push(bvh, Bvh::left(n), view.eye);
        queue.push(bvh, bvh.right(n), view.eye);
      }
    }
    return result;
  }

 private:
  QueryCounters counters_;  // of the last frame
  SceneIndex index_;
  QueryOptions common_;
  std::vector<Aabb> boxes_;
  std::vector<ObjectId> objects_;
};

}  // namespace

Registration stopwait_registration() {
  static const ConfigTable<StopWaitConfig> table =
      with_common_options(ConfigTable<StopWaitConfig>(), &StopWaitConfig::common);
  return registered(
      {"stopwait", "hierarchical stop-and-wait: query every node in the frustum front to back, wait for each"},
      table, [](const SceneIndex& index, const StopWaitConfig& c, const Options&, const CullerContext&) {
        return std::make_unique<StopWaitCuller>(index, c.common);
      });
}

}  // namespace occull::detail
