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
// flush_every=1 comes closest to that), reads (frame: results read in the
// frame that issued their query, as published; earlier: only at the next
// frame's start, as engines on explicit APIs read them — previously
// invisible nodes that turned visible are drawn a frame late, so it is not
// conservative, and the verifier counts what it misses).
#include "cullers.hpp"
#include "traversal.hpp"

#include <deque>

namespace occull::detail {
namespace {

class ChcCuller final : public CpuTestedCuller {
 public:
  ChcCuller(const SceneIndex& index, const ChcConfig& c)
      : CpuTestedCuller(index, c.common), index_(index), common_(c.common), skip_(c.skip),
        reads_earlier_(c.reads_earlier), state_(index.bvh.size()), submitter_(c.flush_every) {}

  // reads=earlier holds the queries of the last frame until the next one.
  void release(Backend& backend) override {
    if (queries_.empty()) return;
    take_held_results(backend, true);
  }
  [[nodiscard]] std::size_t queries_held() const override { return queries_.size(); }

 private:
  void visit_counters(const CounterVisitor& visit) const override {
    f_.counters.visit(visit);
    CpuTestedCuller::visit_counters(visit);
  }

  FrameResult cull_frame(const View& view, Backend& backend) override {
    ++frame_;
    seen_.begin(index_.scene);
    const bool restart = states_restart(seen_, index_.bvh, frame_ - 1);
    if (restart) carry_over(state_, index_.bvh, seen_, frame_ - 1);
    // reads=earlier: the last frame's answers, now that it is done (read
    // and dropped when the hierarchy changed under them).
    if (!queries_.empty()) take_held_results(backend, !restart);
    f_.begin(view, backend);

    queue_.push(index_.bvh, Bvh::root(), view.eye);
    while (!queue_.empty() || (!reads_earlier_ && !queries_.empty())) {
      if (reads_earlier_) {  // no reads in this frame: its queries wait for the next
        visit(queue_.pop());
        continue;
      }
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
      visit(queue_.pop());
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

  // The held queries of the last frame (reads=earlier), read now; with
  // `apply`, a node found visible counts as visible in that frame, so this
  // frame's traversal treats it as previously visible.
  // A previously invisible node that came back visible counts as visible
  // with its whole subtree, as the frame that issued its query would have
  // traversed it (else each level of the hierarchy below it would take a
  // frame of its own to appear).
  void take_held_results(Backend& backend, bool apply) {
    for (const Pending& p : queries_) {
      const std::uint64_t samples = backend.result(p.id);
      if (!apply || samples <= common_.threshold) continue;
      if (!p.previously_visible) open_subtree(p.node);
      pull_up_visibility(state_, index_.bvh, p.node);
      if (is_leaf(p.node)) state_[p.node].next_query = frame_ + skip_;  // as if read in the frame that issued it
    }
    queries_.clear();
  }

  // Every node below `n` (a leaf's subtree: none) visible in the last frame.
  void open_subtree(NodeId n) {
    if (is_leaf(n)) return;
    for (const NodeId c : {Bvh::left(n), index_.bvh.right(n)}) {
      state_[c].visible = true;
      state_[c].last_visited = frame_ - 1;
      open_subtree(c);
    }
  }

  // One node of the front-to-back traversal (CHC's main loop body).
  void visit(NodeId n) {
    const View& view = *f_.view;
    ++f_.nodes_visited;
    NodeState& s = state_[n];
    const bool previously_visible = was_visible(s, frame_);
    s.visible = false;  // invisible until shown otherwise
    s.last_visited = frame_;
    const BvhNode& node = index_.bvh.node(n);
    if (node.object_count == 0 || view.frustum.classify(node.bounds) == Containment::outside ||
        holds_no_sample(node.bounds, view))
      return;
    if (near_eye(node.bounds, view, f_.near_radius)) {
      pull_up_visibility(state_, index_.bvh, n);
      traverse(n);
      return;
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

  bool is_leaf(NodeId n) const { return index_.bvh.is_leaf(n, common_.virtual_leaf_triangles); }

  void query(NodeId n, bool previously_visible) {
    boxes_.clear();
    append_query_boxes(index_, n, {}, boxes_);
    const QueryId q = f_.backend->issue_query(boxes_);
    // reads=earlier hands the frame's queries to the device with the frame: no flush before.
    queries_.push_back({q, n, previously_visible, reads_earlier_ ? 0u : submitter_.issued(*f_.backend)});
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
  bool reads_earlier_;
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
                   "hand queries to the device this many at a time, and poll only those handed over (1: each at once)")
          .choice("reads", &ChcConfig::reads_earlier, {{"frame", false}, {"earlier", true}},
                  "frame: read results in the frame that issued them (as published); earlier: at the next "
                  "frame's start only, as engines on explicit APIs (Vulkan) do: no mid-frame submission, newly "
                  "visible nodes a frame late (not conservative)")
          .approximate_unless_default();
  return registered({"chc", "coherent hierarchical culling (Bittner & Wimmer 2004; Bittner et al. 2009 Listing 8.4.1)"}, table,
                    [](const SceneIndex& index, const ChcConfig& c, const Options&, const CullerContext&) {
                      if (c.reads_earlier && c.common.cpu_test)
                        throw InputError("chc: reads=earlier holds queries from one frame to the next, and the "
                                         "CPU test's queries live within their frame: use one or the other");
                      return std::make_unique<ChcCuller>(index, c);
                    });
}

}  // namespace occull::detail
