// `chcpp`: CHC++ (Mattausch, Bittner, Wimmer 2008; Bittner et al. 2009, Listing 8.4.2).
//
// CHC with the game-engine-friendly changes of the article:
//   - i-queue: previously invisible nodes are queried in batches of `batch`
//     nodes (one render/query state change per batch);
//   - v-queue: queries of previously visible leaves wait in a queue, fill
//     idle time while results are outstanding, and go out as one batch at
//     the end of the frame;
//   - render queue: nodes to render are collected and handed to the engine
//     (Backend::render, which sorts by material) just before a query batch;
//   - multiqueries: i-queue nodes sorted by p_keep — the learned probability
//     that a node invisible for i tests stays invisible — are grouped
//     greedily where V = |M| / (1 + p_fail(M) |M|) peaks; a group that comes
//     back visible is re-queried node by node;
//   - jittered re-queries: a newly visible leaf is first re-queried after a
//     random 0 < r < n_av frames, then every n_av frames;
//   - tight bounding volumes: a node is queried with its descendants' boxes
//     down to d_max levels within s_max times its surface area, and small
//     subtrees are virtual leaves.
// Every feature has an option to switch it off, so its effect can be measured.
#include "chcpp.hpp"

#include "cullers.hpp"

#include <algorithm>
#include <cmath>
#include <deque>

namespace occull::detail {

// ---- p_keep: visibility persistence statistics ---------------------------

double VisibilityPersistence::analytic(std::uint32_t i) {
  return 0.99 - 0.7 * std::exp(-double(i));
}

void VisibilityPersistence::record(std::uint32_t i, bool kept) {
  i = std::min<std::uint32_t>(i, kMaxPersistence);
  ++all_[i];
  if (kept) ++keep_[i];
}

double VisibilityPersistence::p_keep(std::uint32_t i) const {
  i = std::min<std::uint32_t>(i, kMaxPersistence);
  // Measured where there are enough samples; otherwise the nearest lower i
  // that has them (piecewise-constant propagation); otherwise the formula.
  for (std::uint32_t j = i + 1; j-- > 0;)
    if (all_[j] >= min_samples_) return double(keep_[j]) / double(all_[j]);
  return analytic(i);
}

// ---- multiquery grouping -------------------------------------------------

std::size_t best_multiquery_size(std::span<const double> p_keep_sorted) {
  // One query per node has V = 1 (benefit 1 at cost 1 each): a group must
  // beat that to be worth its risk, so the search starts from there.
  double keep_all = 1.0;
  double best_value = 1.0;
  std::size_t best = 1;
  for (std::size_t j = 0; j < p_keep_sorted.size(); ++j) {
    keep_all *= p_keep_sorted[j];
    const double size = double(j + 1);
    const double value = size / (1.0 + (1.0 - keep_all) * size);  // B(M) / C(M)
    if (value > best_value) {
      best_value = value;
      best = j + 1;
    }
  }
  return best;
}

void EnteringGate::add(Counts& c, bool occluded, double window) {
  if (c.tests >= window) {  // forget slowly: older outcomes weigh half
    c.tests *= 0.5;
    c.occluded *= 0.5;
  }
  c.tests += 1.0;
  if (occluded) c.occluded += 1.0;
}

void EnteringGate::record(std::size_t region, bool occluded) {
  add(regions_.at(region), occluded, 32.0);
  add(global_, occluded, 256.0);
}

double EnteringGate::p_occluded(std::size_t region) const {
  // The region's own share, pulled toward the global one by 4 outcomes'
  // worth: a region with few outcomes follows the scene as a whole.
  constexpr double kPull = 4.0;
  const Counts& r = regions_.at(region);
  const double global = global_.occluded / global_.tests;
  return (r.occluded + kPull * global) / (r.tests + kPull);
}

std::uint32_t first_requery_delay(std::uint32_t n_av, std::uint64_t random) {
  if (n_av <= 1) return n_av;
  return 1 + std::uint32_t(random % (n_av - 1));  // 0 < r < n_av
}

namespace {


// SplitMix64, for the jitter: deterministic for a given seed.
std::uint64_t next_random(std::uint64_t& state) {
  std::uint64_t z = (state += 0x9E3779B97F4A7C15ull);
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

class ChcppCuller final : public CpuTestedCuller {
 public:
  ChcppCuller(const SceneIndex& index, const ChcppConfig& config)
      : CpuTestedCuller(index, config.common), index_(index), config_(config), persistence_(config.pkeep_min_samples),
        state_(index.bvh.size()), random_(config.seed), gate_(reset_nodes(), config.enter_p_min) {}

 private:
  void visit_counters(const CounterVisitor& visit) const override {
    f_.counters.visit(visit);
    CpuTestedCuller::visit_counters(visit);
  }

  FrameResult cull_frame(const View& view, Backend& backend) override {
    ++frame_;
    seen_.begin(index_.scene);
    if (states_restart(seen_, index_.bvh, frame_ - 1)) {
      carry_over(state_, index_.bvh, seen_, frame_ - 1);
      // A leaf carried over visible was drawn last frame: its next query
      // comes as a newly visible leaf's would, not all at once now.
      for (NodeState& s : state_)
        if (s.visible) s.next_query = frame_ + requery_delay();
      gate_ = EnteringGate(reset_nodes(), config_.enter_p_min);
    }
    f_.begin(view, backend);
    frustum_.begin(index_.bvh, view);
    query_nodes_.clear();

    distance_queue_.push(index_.bvh, Bvh::root(), view.eye);
    while (!distance_queue_.empty() || !query_queue_.empty() || !i_queue_.empty()) {
      while (!query_queue_.empty()) {
        const bool available = backend.result_available(query_queue_.front().id);
        if (!available && !distance_queue_.empty()) break;  // go on traversing
        if (available)
          handle_returned_query();
        else if (!v_queue_.empty())
          issue_v_query();  // fill the idle time
        else
          handle_returned_query();  // nothing else to do: wait
      }
      if (!distance_queue_.empty()) process_node(distance_queue_.pop());
      if (distance_queue_.empty()) issue_multiqueries();
    }
    // One last batch for the visible leaves not queried yet, then their results.
    if (!v_queue_.empty()) {
      flush_render_queue();
      ++f_.counters.query_batches;
      while (!v_queue_.empty()) {
        const NodeId n = v_queue_.front();
        v_queue_.pop_front();
        issue_one(n, true);
      }
    }
    flush_render_queue();
    while (!query_queue_.empty()) handle_returned_query();
    return f_.end();
  }

 private:
  struct Pending {
    QueryId id;
    std::uint32_t first;  // its nodes: query_nodes_[first, first + count); count > 1: a multiquery
    std::uint32_t count;
    bool previously_visible;
  };
  struct Invisible {
    NodeId node;
    bool single;  // re-queried alone after a failed multiquery
  };

  // Per-node flags besides NodeState.
  static constexpr std::uint8_t kOccluded = 1;  // its last test found it occluded
  static constexpr std::uint8_t kEntering = 2;  // queried as an entering node: its answer teaches the gate
  static constexpr std::uint8_t kProbe = 4;     // drawn on entering without a query: so does its first re-query

  // Sizes and clears the per-node data besides NodeState, and gives every
  // node its gate region: the subtree rooted at depth gate_depth it lies in
  // (nodes above that depth are regions of their own). Returns the number of regions.
  std::size_t reset_nodes() {
    const Bvh& bvh = index_.bvh;
    region_.assign(bvh.size(), 0);
    flags_.assign(bvh.size(), 0);
    visible_streak_.assign(bvh.size(), 0);
    std::uint32_t regions = 0;
    for (NodeId n = 0; n < NodeId(bvh.size()); ++n) {  // parents come before their children
      const BvhNode& node = bvh.node(n);
      region_[n] = node.parent == kNoNode || node.depth <= config_.gate_depth ? regions++ : region_[node.parent];
    }
    return regions;
  }

  std::uint32_t requery_delay() {
    return config_.jitter ? first_requery_delay(config_.n_av, next_random(random_)) : config_.n_av;
  }

  // A real leaf, or a virtual one: few triangles and few objects (a subtree
  // of many small meshes spread far apart is no leaf: queried as one it is
  // almost always visible and culls nothing).
  bool is_leaf(NodeId n) const {
    const BvhNode& node = index_.bvh.node(n);
    return node.is_leaf() || (node.triangles <= config_.common.virtual_leaf_triangles &&
                              (config_.leaf_objects == 0 || node.object_count <= config_.leaf_objects));
  }

  void process_node(NodeId n) {
    ++f_.nodes_visited;
    NodeState& s = state_[n];
    const bool previously_visible = was_visible(s, frame_);
    const bool previously_occluded =
        s.last_visited != kNever && s.last_visited + 1 == frame_ && (flags_[n] & kOccluded) != 0;
    flags_[n] &= std::uint8_t(~(kOccluded | kEntering));
    s.visible = false;  // invisible by default
    s.last_visited = frame_;
    if (previously_visible) s.invisible_tests = 0;  // if invisible now, its persistence starts over
    const BvhNode& node = index_.bvh.node(n);
    if (node.object_count == 0 || frustum_.outside(index_.bvh, n)) return;
    if (near_eye(node.bounds, *f_.view, f_.near_radius)) {
      pull_up_visibility(state_, index_.bvh, n);
      traverse(n);
      return;
    }
    if (!previously_visible) {
      if (!previously_occluded) {
        if (!gate_.query(region_[n])) {  // entering where queries do not pay: draw it
          if (is_leaf(n)) {
            flags_[n] |= kProbe;
            s.next_query = frame_ + requery_delay();
            pull_up_visibility(state_, index_.bvh, n);
          }
          traverse(n);
          return;
        }
        flags_[n] |= kEntering;
      }
      i_queue_.push_back({n, false});
      if (i_queue_.size() >= config_.batch) issue_multiqueries();
      return;
    }
    if (is_leaf(n)) {
      if (frame_ >= s.next_query) {
        if (config_.v_queue) {
          v_queue_.push_back(n);
        } else {
          flush_render_queue();  // CHC order: query the leaf, then render it
          ++f_.counters.query_batches;
          issue_one(n, true);
        }
      } else {
        pull_up_visibility(state_, index_.bvh, n);
      }
    }
    traverse(n);
  }

  void traverse(NodeId n) {
    if (is_leaf(n)) {
      frustum_.append_objects(index_, n, render_queue_);
      render_queue_triangles_ += index_.bvh.node(n).triangles;
      if (config_.render_batch_triangles > 0 && render_queue_triangles_ >= config_.render_batch_triangles) {
        flush_render_queue();
        if (config_.flush_batches) f_.backend->flush();
      }
    } else {
      distance_queue_.push(index_.bvh, Bvh::left(n), f_.view->eye);
      distance_queue_.push(index_.bvh, index_.bvh.right(n), f_.view->eye);
    }
  }

  void flush_render_queue() {
    if (render_queue_.empty()) return;
    f_.backend->render(render_queue_);
    seen_.drawn(render_queue_, frame_);
    render_queue_.clear();
    render_queue_triangles_ = 0;
  }

  // One query over the nodes query_nodes_[first, end()).
  void issue(std::uint32_t first, bool previously_visible) {
    const auto count = std::uint32_t(query_nodes_.size() - first);
    boxes_.clear();
    for (std::uint32_t i = first; i < first + count; ++i)
      append_query_boxes(index_, query_nodes_[i], config_.shape, boxes_);
    if (count > 1) ++f_.counters.multiqueries;
    query_queue_.push_back({f_.backend->issue_query(boxes_), first, count, previously_visible});
  }

  void issue_one(NodeId n, bool previously_visible) {
    const auto first = std::uint32_t(query_nodes_.size());
    query_nodes_.push_back(n);
    issue(first, previously_visible);
  }

  void issue_v_query() {
    flush_render_queue();
    ++f_.counters.query_batches;
    const NodeId n = v_queue_.front();
    v_queue_.pop_front();
    issue_one(n, true);
  }

  // Issues the i-queue as one batch: multiqueries grouped by p_keep, or
  // one query per node.
  void issue_multiqueries() {
    if (i_queue_.empty()) return;
    flush_render_queue();
    ++f_.counters.query_batches;
    // Most likely to stay invisible first.
    order_.clear();
    for (const Invisible& e : i_queue_) {
      if (e.single || !config_.multiquery)
        issue_one(e.node, false);
      else
        order_.emplace_back(persistence_.p_keep(state_[e.node].invisible_tests), e.node);
    }
    i_queue_.clear();
    if (order_.empty()) return;
    std::stable_sort(order_.begin(), order_.end(),
                     [](const auto& a, const auto& b) { return a.first > b.first; });
    p_keep_.resize(order_.size());
    for (std::size_t i = 0; i < order_.size(); ++i) p_keep_[i] = order_[i].first;
    for (std::size_t begin = 0; begin < order_.size();) {
      const std::size_t size = best_multiquery_size(std::span<const double>(p_keep_).subspan(begin));
      const auto first = std::uint32_t(query_nodes_.size());
      for (std::size_t i = begin; i < begin + size; ++i) query_nodes_.push_back(order_[i].second);
      issue(first, false);
      begin += size;
    }
    if (config_.flush_batches) f_.backend->flush();
  }

  void handle_returned_query() {
    const Pending q = query_queue_.front();
    query_queue_.pop_front();
    const bool visible = f_.backend->result(q.id) > config_.common.threshold;
    const std::span<const NodeId> nodes(query_nodes_.data() + q.first, q.count);
    if (q.previously_visible) {  // a v-queue query: classification for the next frame
      const NodeId n = nodes.front();
      if (flags_[n] & kProbe) {
        gate_.record(region_[n], !visible);
        flags_[n] &= std::uint8_t(~kProbe);
      }
      if (visible) {
        pull_up_visibility(state_, index_.bvh, n);
        // Found visible again: wait longer before the next query.
        const std::uint32_t streak = std::min<std::uint32_t>(visible_streak_[n], config_.backoff);
        if (visible_streak_[n] < 31) ++visible_streak_[n];
        state_[n].next_query = frame_ + (config_.n_av << streak);
      } else {
        flags_[n] |= kOccluded;
        visible_streak_[n] = 0;
        state_[n].invisible_tests = 0;  // newly invisible
      }
      return;
    }
    if (visible && nodes.size() > 1) {  // failed multiquery: query each node alone
      ++f_.counters.failed_multiqueries;
      for (NodeId n : nodes) i_queue_.push_back({n, true});
      return;
    }
    for (NodeId n : nodes) {
      NodeState& s = state_[n];
      persistence_.record(s.invisible_tests, !visible);
      if (flags_[n] & kEntering) gate_.record(region_[n], !visible);
      flags_[n] &= std::uint8_t(~kEntering);
      if (!visible) {
        ++s.invisible_tests;
        flags_[n] |= kOccluded;
        continue;
      }
      s.invisible_tests = 0;
      traverse(n);  // turned visible: process it now
      pull_up_visibility(state_, index_.bvh, n);
      if (is_leaf(n)) {
        s.next_query = frame_ + requery_delay();
        visible_streak_[n] = 0;
      }
    }
  }

  SceneIndex index_;
  ChcppConfig config_;
  VisibilityPersistence persistence_;
  std::vector<NodeState> state_;
  ObjectVisibility seen_;  // what was drawn, for state_ after a rebuild of the hierarchy
  std::uint32_t frame_ = 0;
  std::uint64_t random_;
  std::vector<std::uint32_t> region_;  // the gate's region of each node
  std::vector<std::uint8_t> flags_;    // kOccluded | kEntering | kProbe
  std::vector<std::uint8_t> visible_streak_;  // re-queries of a visible leaf in a row that found it visible
  EnteringGate gate_;

  // Per frame.
  FrameContext f_;
  FrustumCache frustum_;
  DistanceQueue distance_queue_;
  std::deque<Pending> query_queue_;
  std::vector<Invisible> i_queue_;
  std::deque<NodeId> v_queue_;
  std::vector<ObjectId> render_queue_;
  std::uint64_t render_queue_triangles_ = 0;
  std::vector<Aabb> boxes_;
  std::vector<NodeId> query_nodes_;  // the nodes of this frame's queries (Pending::first, count)
  std::vector<std::pair<double, NodeId>> order_;  // multiquery grouping scratch
  std::vector<double> p_keep_;
};

}  // namespace

Registration chcpp_registration() {
  using C = ChcppConfig;
  static const ConfigTable<C> table =
      with_common_options(ConfigTable<C>(), &C::common)
          .integer("batch", &C::batch, 1, 100000, "b: previously invisible nodes per query batch (1: no batching)")
          .flag("vqueue", &C::v_queue, "defer queries of visible leaves to fill idle time (off: query each at once)")
          .flag("multiquery", &C::multiquery, "group previously invisible nodes into multiqueries by p_keep")
          .flag("jitter", &C::jitter, "first re-query of a newly visible leaf after a random 0 < r < n_av frames")
          .integer("n_av", &C::n_av, 1, 1000, "frames between queries of a visible leaf")
          .flag("tight", [](auto& c) -> auto& { return c.shape.tight; },
                "query with the descendants' boxes (tighter bounding volumes)")
          .integer("d_max", [](auto& c) -> auto& { return c.shape.d_max; }, 0, 16, "tight bounds: levels below the node")
          .real("s_max", [](auto& c) -> auto& { return c.shape.s_max; }, 1.0, 100.0,
                "tight bounds: most total surface area, relative to the node's")
          .integer("leaf_objects", &C::leaf_objects, 0, 1 << 30,
                   "... and with at most this many objects (0: any number; 8 cost more queries than it saved on "
                   "track/lap)")
          .integer("pkeep_samples", &C::pkeep_min_samples, 1, 1 << 24,
                   "tests at persistence i before the measured p_keep(i) replaces the formula")
          .integer("seed", &C::seed, 0, 1 << 30, "random seed of the jitter")
          .flag("flush", &C::flush_batches, "flush the device after each query batch so its results come back sooner")
          .integer("render_batch", &C::render_batch_triangles, 0, 1 << 30,
                   "also hand the render queue over (and flush) once it holds this many triangles; 0: only before "
                   "query batches")
          .real("enter_p_min", &C::enter_p_min, 0.0, 1.0,
                "query nodes entering the view (not occluded last frame) only in BVH regions where at least this "
                "share of them was found occluded; elsewhere draw them and learn from their first re-query (0: "
                "always query, as CHC++)")
          .integer("backoff", &C::backoff, 0, 10,
                   "a visible leaf found visible again k times in a row waits n_av * 2^min(k-1, backoff) frames for "
                   "its next query (0: always n_av)")
          .integer("gate_depth", &C::gate_depth, 0, 30, "BVH depth of the regions that learn that share each on their own");
  return registered({"chcpp",
                     "CHC++: batched i/v-queues, render queue, multiqueries, jittered re-queries, tight bounds (seed "
                     "000)"},
                    table, [](const SceneIndex& index, const C& c, const Options&, const CullerContext&) {
                      return std::make_unique<ChcppCuller>(index, c);
                    });
}

}  // namespace occull::detail
