// `chc`: coherent hierarchical culling (Bittner & Wimmer 2004; Bittner et al. 2009,
// Listing 8.4.1).
//
// Front-to-back traversal that queries only previously invisible nodes and
// previously visible leaves. Previously visible leaves are rendered at once
// without waiting (their query only updates the classification for the next
// frame: the one-frame delay of visible-to-invisible changes); previously
// invisible nodes are assumed invisible until their query comes back, and
// the traversal goes on with other nodes meanwhile. Visibility is pulled up
// to the ancestors. Each query and each rendered leaf is its own backend
// call, interleaved — the state changes CHC++ later removes.
//
// Options: threshold (pixels), skip (n_av: a visible leaf is assumed to
// stay visible for n_av frames and queried again in frame n_av + 1),
// virtual_leaf (triangles), flush_every (queries are handed to the device
// in groups and only those handed over are polled — the paper polls the
// oldest query at every step, which makes a driver flush for each query;
// flush_every=1 comes closest to that).
#include "cullers.hpp"
#include "traversal.hpp"

#include <deque>

namespace occull::detail {
namespace {

class ChcCuller final : public CpuTestedCuller {
 public:
  ChcCuller(const SceneIndex& index, const ChcConfig& c)
      : CpuTestedCuller(index, c.common), index_(index), common_(c.common), skip_(c.skip), state_(index.bvh.size()), submitter_(c.flush_every) {}

 private:
  void visit_counters(const CounterVisitor& visit) const override {
    f_.counters.visit(visit);
    CpuTestedCuller::visit_counters(visit);
  }

  FrameResult cull_frame(const View& view, Backend& backend) override {
    ++frame_;
    seen_.begin(index_.scene);
    if (states_restart(seen_, index_.bvh, frame_ - 1)) carry_over(state_, index_.bvh, seen_, frame_ - 1);
    f_.begin(view, backend);

    queue_.push(index_.bvh, Bvh::root(), view.eye);
    while (!queue_.empty() || !queries_.empty()) {
      // Handle returned queries; when there is nothing else to do, wait.
      if (queue_.empty()) submitter_.submit(backend);
      while (!queries_.empty() &&
             (queue_.empty() ||
              (submitter_.submitted(queries_.front().submission) && backend.result_available(queries_.front().id)))) {
        const Pending p = queries_.front();
        queries_.pop_front();
        handle_returned_query(p, backend.result(p.id));
      }
      if (queue_.empty()) continue;
      const NodeId n = queue_.pop();
      ++f_.nodes_visited;
      NodeState& s = state_[n];
      const bool previously_visible = was_visible(s, frame_);
      s.visible = false;  // invisible until shown otherwise
      s.last_visited = frame_;
      const BvhNode& node = index_.bvh.node(n);
      if (node.object_count == 0 || view.frustum.classify(node.bounds) == Containment::outside ||
          holds_no_sample(node.bounds, view))
        continue;
      if (near_eye(node.bounds, view, f_.near_radius)) {
        pull_up_visibility(state_, index_.bvh, n);
        traverse(n);
        continue;
      }
      if (!previously_visible) {
        query(n, false);  // the previously invisible boundary
      } else {
        if (is_leaf(n)) {
          if (frame_ >= s.next_query)
            query(n, true);  // result only updates the next frame
          else
            pull_up_visibility(state_, index_.bvh, n);
        }
        traverse(n);
      }
    }
    return f_.end();
  }

 private:
  struct Pending {
    QueryId id;
    NodeId node;
    bool previously_visible;
    std::uint32_t submission;  // QuerySubmitter tag: polled only once handed to the device
  };

  bool is_leaf(NodeId n) const { return index_.bvh.is_leaf(n, common_.virtual_leaf_triangles); }

  void query(NodeId n, bool previously_visible) {
    boxes_.clear();
    append_query_boxes(index_, n, {}, boxes_);
    const QueryId q = f_.backend->issue_query(boxes_);
    queries_.push_back({q, n, previously_visible, submitter_.issued(*f_.backend)});
    ++f_.counters.query_batches;
  }

  void handle_returned_query(const Pending& p, std::uint64_t samples) {
    if (samples <= common_.threshold) return;  // stays invisible
    if (!p.previously_visible) traverse(p.node);  // turned visible: process it now
    pull_up_visibility(state_, index_.bvh, p.node);
    if (is_leaf(p.node)) state_[p.node].next_query = frame_ + skip_ + 1;
  }

  void traverse(NodeId n) {
    if (is_leaf(n)) {
      objects_.clear();
      append_objects_in_frustum(index_, n, *f_.view, objects_);
      if (!objects_.empty()) f_.backend->render(objects_);
      seen_.drawn(objects_, frame_);
    } else {
      queue_.push(index_.bvh, Bvh::left(n), f_.view->eye);
      queue_.push(index_.bvh, index_.bvh.right(n), f_.view->eye);
    }
  }

  SceneIndex index_;
  QueryOptions common_;
  std::uint32_t skip_;
  std::vector<NodeState> state_;
  ObjectVisibility seen_;  // what was drawn, for state_ after a rebuild of the hierarchy
  std::uint32_t frame_ = 0;

  // Per frame.
  FrameContext f_;
  DistanceQueue queue_;
  std::deque<Pending> queries_;
  std::vector<Aabb> boxes_;
  std::vector<ObjectId> objects_;
  QuerySubmitter submitter_;
};

}  // namespace

Registration chc_registration() {
  static const ConfigTable<ChcConfig> table =
      with_common_options(ConfigTable<ChcConfig>(), &ChcConfig::common)
          .integer("skip", &ChcConfig::skip, 0, 1000,
                   "n_av: a visible leaf is assumed visible for n_av frames, queried in frame n_av+1")
          .integer("flush_every", &ChcConfig::flush_every, 1, 1 << 20,
                   "hand queries to the device this many at a time, and poll only those handed over (1: each at once)");
  return registered({"chc", "coherent hierarchical culling (Bittner & Wimmer 2004; Bittner et al. 2009 Listing 8.4.1)"}, table,
                    [](const SceneIndex& index, const ChcConfig& c, const Options&, const CullerContext&) {
                      return std::make_unique<ChcCuller>(index, c);
                    });
}

}  // namespace occull::detail
