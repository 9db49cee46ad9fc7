// Internal: pieces shared by the hierarchical cullers — per-node temporal
// state, the front-to-back distance queue, the eye-inside rule, pull-up of
// visibility, rendering a node's objects and shaping a node's query.
#pragma once

#include "occull/bvh.hpp"
#include "config_table.hpp"
#include "cullers.hpp"
#include "occull/cpu_test_backend.hpp"
#include "occull/culler.hpp"

#include <algorithm>
#include <array>
#include <cstdint>
#include <memory>
#include <optional>
#include <queue>
#include <vector>

namespace occull::detail {

inline constexpr std::uint32_t kNever = 0xffffffffu;

/// What a coherent culler remembers of a node between frames.
struct NodeState {
  std::uint32_t last_visited = kNever;  ///< frame number of the last visit
  std::uint32_t next_query = 0;         ///< a visible leaf is queried again from this frame on
  std::uint32_t invisible_tests = 0;    ///< consecutive tests that found it invisible (persistence)
  bool visible = false;                 ///< classification after its last visit
};

/// Visible in the previous frame (CHC's WasVisible).
inline bool was_visible(const NodeState& s, std::uint32_t frame) {
  return s.visible && s.last_visited != kNever && s.last_visited + 1 == frame;
}

/// Marks `n` and its ancestors visible, stopping at the first ancestor that
/// already is (CHC's PullUpVisibility).
/// `Node`: NodeState, or any per-node record with a `visible` flag.
template <class Node>
void pull_up_visibility(std::vector<Node>& state, const Bvh& bvh, NodeId n) {
  while (n != kNoNode && !state[n].visible) {
    state[n].visible = true;
    n = bvh.node(n).parent;
  }
}

/// The two children of interior node `n`, the one nearer to `eye` first.
inline std::array<NodeId, 2> children_front_to_back(const Bvh& bvh, NodeId n, const glm::vec3& eye) {
  const NodeId l = Bvh::left(n);
  const NodeId r = bvh.right(n);
  if (distance_squared(eye, bvh.node(r).bounds) < distance_squared(eye, bvh.node(l).bounds)) return {r, l};
  return {l, r};
}

/// The counters of a query culler's frame beyond FrameResult.
struct QueryCounters {
  std::uint64_t query_batches = 0;        ///< batches of queries issued together
  std::uint64_t multiqueries = 0;         ///< queries covering more than one node
  std::uint64_t failed_multiqueries = 0;  ///< multiqueries that came back visible

  void visit(const CounterVisitor& visit) const {
    visit("query_batches", double(query_batches));
    visit("multiqueries", double(multiqueries));
    visit("failed_multiqueries", double(failed_multiqueries));
  }
};

/// What a hierarchical culler knows during one frame: its counters, the
/// view and the backend, and the near-plane radius of the eye-inside rule.
struct FrameContext {
  std::uint64_t nodes_visited = 0;
  QueryCounters counters;  ///< kept after the frame, for Culler::visit_counters
  const View* view = nullptr;   ///< during a frame only
  Backend* backend = nullptr;   ///< during a frame only: no culler keeps a backend between frames
  float near_radius = 0.0f;

  void begin(const View& v, Backend& b) {
    nodes_visited = 0;
    counters = {};
    view = &v;
    backend = &b;
    near_radius = near_plane_radius(v);
  }
  /// Ends the frame: forgets the view and backend; returns the frame's result.
  FrameResult end() {
    view = nullptr;
    backend = nullptr;
    return {.nodes_visited = nodes_visited};
  }
};

/// Per-object visibility that outlives the hierarchy's nodes: which objects a
/// culler drew in which frame. When the BVH is rebuilt (Bvh::generation),
/// a culler that keeps state per node starts its new nodes from it: a leaf
/// was visible last frame when one of its objects was drawn then, and so
/// were its ancestors. Objects added since are simply unknown (not visible).
class ObjectVisibility {
 public:
  /// Call once per frame before drawing; sizes the record to the scene.
  void begin(const Scene& scene) {
    if (drawn_.size() < scene.objects().size()) drawn_.resize(scene.objects().size(), kNever);
  }
  void drawn(std::span<const ObjectId> objects, std::uint32_t frame) {
    for (ObjectId id : objects) drawn_[id] = frame;
  }
  /// Forgets what was recorded for `frame` and records `objects` instead.
  void replace(std::span<const ObjectId> objects, std::uint32_t frame) {
    std::replace(drawn_.begin(), drawn_.end(), frame, kNever);
    drawn(objects, frame);
  }
  [[nodiscard]] bool drawn_in(ObjectId id, std::uint32_t frame) const {
    return id < drawn_.size() && drawn_[id] == frame;
  }
  /// Whether the hierarchy changed since the last call (and remembers it).
  [[nodiscard]] bool rebuilt(const Bvh& bvh) {
    const bool changed = bvh.generation() != generation_ || !known_;
    generation_ = bvh.generation();
    known_ = true;
    return changed;
  }

 private:
  std::vector<std::uint32_t> drawn_;  // per object: last frame drawn (kNever: never)
  std::uint64_t generation_ = 0;
  bool known_ = false;
};

/// Node states for a rebuilt hierarchy from what a culler drew in `frame`
/// (its last): a leaf whose objects include one drawn then was visible, and
/// so were its ancestors; every node counts as visited in `frame`, so the
/// others are queried as CHC queries the previously invisible. Conservative
/// whatever `seen` says: only queries cull.
template <class Node>  // NodeState, or a record with `visible` and `last_visited`
void carry_over(std::vector<Node>& state, const Bvh& bvh, const ObjectVisibility& seen, std::uint32_t frame) {
  state.assign(bvh.size(), Node{});
  for (Node& s : state) s.last_visited = frame;
  for (NodeId n = 0; n < NodeId(bvh.size()); ++n) {
    if (!bvh.node(n).is_leaf()) continue;
    for (ObjectId id : bvh.objects(n))
      if (seen.drawn_in(id, frame)) {
        pull_up_visibility(state, bvh, n);
        break;
      }
  }
}

/// Traversal queue ordered by distance from the eye to the node's box,
/// nearest first (ties: lower node id first, so traversal is deterministic).
/// The entry pushed last is held outside the heap until a nearer push
/// displaces it, and pop() takes the nearer of it and the heap's top: a walk
/// that pushes a node's two children and pops the nearer one at once (most
/// of a front-to-back descent) pays one heap push instead of two pushes and
/// a pop. The order is the heap's exactly.
class DistanceQueue {
 public:
  void push(const Bvh& bvh, NodeId n, const glm::vec3& eye) {
    const BvhNode& node = bvh.node(n);
    // When n is popped its children are pushed: the left one follows n in
    // the array, the right one lies far away (a cache miss in soc's
    // front-to-back walk, which leaves the array's order). Fetch it now.
    if (!node.is_leaf()) __builtin_prefetch(&bvh.node(node.right));
    const Entry e{distance_squared(eye, node.bounds), n};
    if (!held_) {
      held_ = e;
    } else if (*held_ > e) {
      heap_.push(*held_);
      held_ = e;
    } else {
      heap_.push(e);
    }
  }
  NodeId pop() {
    if (held_ && (heap_.empty() || heap_.top() > *held_)) {
      const NodeId n = held_->node;
      held_.reset();
      return n;
    }
    const NodeId n = heap_.top().node;
    heap_.pop();
    return n;
  }
  [[nodiscard]] bool empty() const { return !held_ && heap_.empty(); }

 private:
  struct Entry {
    float distance_squared;
    NodeId node;
    bool operator>(const Entry& o) const {
      return distance_squared > o.distance_squared || (distance_squared == o.distance_squared && node > o.node);
    }
  };
  std::optional<Entry> held_;  // the last push, unless a nearer one displaced it into heap_
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> heap_;
};

/// Appends the objects of node `n` whose boxes are not outside the frustum
/// and hold a sample (occull/view.hpp holds_no_sample: exact sub-pixel
/// culling; every culler but vfc skips such objects).
/// `planes`: the frustum planes `n` is not known to lie fully inside (a
/// Frustum plane mask); objects are tested against those only.
void append_objects_in_frustum(const SceneIndex& index, NodeId n, const View& view,
                               std::vector<ObjectId>& out, std::uint32_t planes = Frustum::all_planes);

/// Per-node frustum tests of one view, made once per frame: a node's test
/// skips the planes its parent lies fully inside (front-to-back traversals
/// classify a parent before its children; any order stays correct).
class FrustumCache {
 public:
  /// Forgets the previous frame's tests (call at the start of each frame).
  void begin(const Bvh& bvh, const View& view) {
    if (nodes_.size() != bvh.size()) nodes_.assign(bvh.size(), Entry{});
    ++frame_;
    view_ = &view;
  }
  /// Whether node `n`'s box lies outside the frustum or holds no sample
  /// (holds_no_sample: exact sub-pixel culling; `subpixel` false leaves
  /// that test out for an interior node a caller expects to hold one,
  /// which culls less, never more: its leaves are tested in full).
  bool outside(const Bvh& bvh, NodeId n, bool subpixel = true) {
    Entry& e = nodes_[n];
    if (e.frame != frame_) {
      const NodeId parent = bvh.node(n).parent;
      std::uint32_t mask =
          parent != kNoNode && nodes_[parent].frame == frame_ ? nodes_[parent].planes : Frustum::all_planes;
      // An empty box (removed objects only) is outside whatever the planes, as in in_frustum().
      e.outside = (mask != 0 ? view_->frustum.classify(bvh.node(n).bounds, mask) == Containment::outside
                             : bvh.node(n).bounds.empty()) ||
                  ((subpixel || bvh.node(n).is_leaf()) && holds_no_sample(bvh.node(n).bounds, *view_));
      e.planes = std::uint8_t(mask);
      e.frame = frame_;
    }
    return e.outside;
  }
  /// The planes node `n` is not fully inside. Precondition: outside(n) was asked this frame.
  [[nodiscard]] std::uint32_t planes(NodeId n) const { return nodes_[n].planes; }

  /// Appends the objects of leaf `n` in the frustum that hold a sample, as
  /// append_objects_in_frustum(index, n, view, out, planes(n)) does. A real
  /// leaf of one object that outside(n) passed this frame is appended with
  /// no test of its own: its box is its object's (Bvh: a node's box is the
  /// union of its objects'), the box outside(n) tested. Any other node is
  /// tested object by object.
  void append_objects(const SceneIndex& index, NodeId n, std::vector<ObjectId>& out) const {
    const BvhNode& node = index.bvh.node(n);
    const Entry& e = nodes_[n];
    if (node.is_leaf() && node.object_count == 1 && e.frame == frame_ && !e.outside) {
      out.push_back(index.bvh.objects(n).front());
      return;
    }
    append_objects_in_frustum(index, n, *view_, out, e.frame == frame_ ? e.planes : Frustum::all_planes);
  }

 private:
  struct Entry {
    std::uint32_t frame = kNever;
    std::uint8_t planes = 0;
    bool outside = false;
  };
  std::vector<Entry> nodes_;
  std::uint32_t frame_ = 0;
  const View* view_ = nullptr;
};

/// Hands a culler's queries to the device in groups of `every`. A query the
/// device has not been handed cannot be done, and polling it would make the
/// driver flush for that one query (on llvmpipe each flush wakes the
/// rasterizer threads and churns memory: hundreds per frame cost more than
/// the culling saves). So a culler polls a query only once submitted(), and
/// calls submit() before it must wait.
class QuerySubmitter {
 public:
  explicit QuerySubmitter(std::uint32_t every = 8) : every_(every) {}
  /// Call after each issue_query; returns the tag to keep with the query.
  std::uint32_t issued(Backend& backend) {
    const std::uint32_t tag = round_;
    if (++pending_ >= every_) submit(backend);
    return tag;
  }
  /// Flushes the queries issued since the last submission, if any.
  void submit(Backend& backend) {
    if (pending_ == 0) return;
    backend.flush();
    ++round_;
    pending_ = 0;
  }
  /// Whether the query issued with `tag` has been handed to the device.
  [[nodiscard]] bool submitted(std::uint32_t tag) const { return tag != round_; }

 private:
  std::uint32_t every_;
  std::uint32_t round_ = 0;
  std::uint32_t pending_ = 0;
};

/// The eye-inside rule (from an engine's occlusion notes): a box that, grown by the near
/// plane radius, contains the eye is visible without a query — its query
/// could miss the faces around the camera, and an object that close is
/// visible anyway.
inline bool near_eye(const Aabb& box, const View& view, float radius) {
  return box.grown(radius).contains(view.eye);
}

/// Hierarchical frustum culling: appends every object whose box is not
/// outside the frustum, nearest subtree first (plane masks skip the planes a
/// node is fully inside), and, with `subpixel`, holds a sample
/// (holds_no_sample skips whole subtrees). Counts visited nodes in
/// `nodes_visited`.
void collect_in_frustum_front_to_back(const SceneIndex& index, const View& view,
                                      std::vector<ObjectId>& out, std::uint64_t& nodes_visited,
                                      bool subpixel = true);

/// Appends the boxes of node `n`'s query.
inline void append_query_boxes(const SceneIndex& index, NodeId n, const QueryShape& shape,
                               std::vector<Aabb>& out) {
  if (shape.tight)
    index.bvh.gather_tight_boxes(n, shape.d_max, shape.s_max, index.scene, out);
  else
    out.push_back(index.bvh.node(n).bounds);
}

/// A query culler whose frames run through the CPU first test when its
/// options ask for it (QueryOptions::cpu_test; occull/cpu_test_backend.hpp):
/// the culler's cull_frame() sees a CpuTestBackend over the frame's backend.
class CpuTestedCuller : public Culler, public Resumable {
 public:
  CpuTestedCuller(const SceneIndex& index, const QueryOptions& options)
      : cpu_test_(options.cpu_test
                      ? std::make_unique<CpuTestBackend>(index.scene, CpuTestBackend::Options{.scale = options.cpu_scale, .threads = options.cpu_threads})
                      : nullptr) {}

  FrameResult cull(const View& view, Backend& backend) final {
    if (!cpu_test_) return cull_frame(view, backend);
    cpu_test_->begin_frame(backend, view);
    const FrameResult result = cull_frame(view, *cpu_test_);
    cpu_test_->end_frame();
    return result;
  }
  /// The first test's counters (the occlusion buffer's), when it is on; a
  /// culler adds its own.
  void visit_counters(const CounterVisitor& visit) const override {
    if (cpu_test_) cpu_test_->visit_counters(visit);
  }
  [[nodiscard]] const OcclusionBuffer* occlusion_buffer() const final {
    return cpu_test_ ? cpu_test_->buffer() : nullptr;
  }

  /// Hand-over (auto, Resumable): the next frame starts from `drawn` as if
  /// this culler had drawn it in its own last frame; its node states are
  /// rebuilt from it (carry_over).
  void resume_from(std::span<const ObjectId> drawn) final {
    handed_over_.assign(drawn.begin(), drawn.end());
    resume_ = true;
  }

 protected:
  /// At the start of a frame (after `seen.begin`): whether the node states
  /// must be rebuilt from `seen` with carry_over — the hierarchy was
  /// rebuilt, or a hand-over came (recorded in `seen` as drawn in
  /// `last_frame`).
  bool states_restart(ObjectVisibility& seen, const Bvh& bvh, std::uint32_t last_frame) {
    const bool rebuilt = seen.rebuilt(bvh);
    if (!resume_) return rebuilt;
    resume_ = false;
    seen.replace(handed_over_, last_frame);
    return true;
  }

  /// The culler's frame, through the first test when it is on.
  virtual FrameResult cull_frame(const View& view, Backend& backend) = 0;

 private:
  std::unique_ptr<CpuTestBackend> cpu_test_;
  std::vector<ObjectId> handed_over_;
  bool resume_ = false;
};

/// Adds the fields of the QueryOptions at `at` (see ConfigTable) to `table`.
template <class Config, class At>
ConfigTable<Config>&& with_common_options(ConfigTable<Config>&& table, At at) {
  return std::move(table)
      .integer("threshold", [at](auto& c) -> auto& { return std::invoke(at, c).threshold; }, 0, 1 << 24,
               "a node is visible when more samples (pixels) pass")
      .approximate_unless_default()
      .integer("virtual_leaf", [at](auto& c) -> auto& { return std::invoke(at, c).virtual_leaf_triangles; }, 0,
               1 << 30, "subtrees with at most this many triangles count as leaves (0: off)")
      .flag("cpu_test", [at](auto& c) -> auto& { return std::invoke(at, c).cpu_test; },
            "ask a conservative CPU occlusion buffer of the occluders drawn so far before each query; issue it only "
            "when the buffer cannot prove the boxes hidden (CpuTestBackend)")
      .integer("cpu_scale", [at](auto& c) -> auto& { return std::invoke(at, c).cpu_scale; }, 1, 64,
               "the CPU test's buffer = viewport / cpu_scale on each axis")
      .integer("cpu_threads", [at](auto& c) -> auto& { return std::invoke(at, c).cpu_threads; }, 1,
               OcclusionBuffer::max_threads,
               "threads rasterizing the CPU test's occluders (each batch drawn shared among them)");
}

}  // namespace occull::detail
