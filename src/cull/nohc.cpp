// `nohc`: near optimal hierarchical culling (Guthe, Balázs, Klein 2006;
// Guthe et al. 2006, Figures 4 and 5).
//
// A front-to-back traversal like CHC's, but every query is a priced
// decision. Each node gets an occlusion probability from the screen
// coverage accumulated by what was rendered before it (c_scr), its box's
// coverage (c_bb), the object-to-box ratio R_cov and its state in the last
// frame; and a rendering time t_r and query time t_o from the calibrated
// hardware profile. A query is issued only where the expected saving pays
// for it (query_reasonable). The children of a queried node are traversed
// at once unless the node was occluded last frame (then they wait for the
// answer); an occluded answer cancels the children already queued. At most
// N_q queries are in flight before the oldest is taken as finished.
//
// Rendering goes through a render queue handed to the backend before each
// query and each wait, so every query still tests against everything nearer.
#include "nohc.hpp"

#include "cullers.hpp"
#include "occull/error.hpp"
#include "traversal.hpp"
#include "core/format.hpp"

#include <algorithm>
#include <cmath>
#include <deque>
#include <numeric>

namespace occull::detail {

double query_benefit(const NodeEstimate& n, double levels) {
  return n.p_occl * (n.t_r - n.t_o) / std::max(levels, 1e-9);
}

bool query_reasonable(const ReasonabilityInput& in) {
  const NodeEstimate& n = in.node;
  double children_cost = 0.0, children_benefit = 0.0;
  bool cheap_child = false;
  for (const NodeEstimate& c : in.children) {
    children_cost += c.t_o;
    children_benefit += query_benefit(c, in.levels);
    cheap_child = cheap_child || c.t_r < c.t_o;
  }
  if (n.t_r < n.t_o) return false;
  if (!in.children.empty() && children_cost < n.t_o) return false;
  if (in.previous == PreviousState::occluded) return true;
  if (in.previous == PreviousState::outside) {
    // No coherence to use: query only if that is expected to be faster.
    if (n.t_o + (1.0 - n.p_occl) * n.t_r >= n.t_r) return false;
  } else if (n.t_o > double(in.frames_since_query) * query_benefit(n, in.levels)) {
    return false;
  }
  if (cheap_child) return true;
  return query_benefit(n, in.levels) > children_benefit &&
         in.query_overhead_ms * double(n.leaves) > n.t_o;
}

void OcclusionCalibration::record(PreviousState previous, double predicted, bool occluded) {
  Sums& s = sums_[std::size_t(previous)];
  if (s.queries >= 256.0) {
    s.predicted *= 0.5;
    s.occluded *= 0.5;
    s.queries *= 0.5;
  }
  s.predicted += predicted;
  s.occluded += occluded ? 1.0 : 0.0;
  s.queries += 1.0;
}

double OcclusionCalibration::ratio(PreviousState previous) const {
  if (previous == PreviousState::occluded) return 1.0;
  const Sums& s = sums_[std::size_t(previous)];
  return std::clamp(s.occluded / std::max(s.predicted, 1e-9), 1.0 / 16.0, 4.0);
}

double OcclusionCalibration::scale(PreviousState previous, double p) const {
  return std::clamp(p * ratio(previous), 0.0, 1.0);
}

namespace {

class NohcCuller final : public CpuTestedCuller {
 public:
  NohcCuller(const SceneIndex& index, const NohcConfig& config, HardwareProfile profile)
      : CpuTestedCuller(index, config.common), index_(index), config_(config), hw_(std::move(profile)), nodes_(index.bvh.size()),
        submitter_(config.flush_every) {
    (void)seen_.rebuilt(index.bvh);
    describe_nodes();
    max_parallel_ = config.max_parallel > 0 ? config.max_parallel : std::max(1, hw_.max_parallel_queries());
  }

 private:
  void visit_counters(const CounterVisitor& visit) const override {
    f_.counters.visit(visit);
    CpuTestedCuller::visit_counters(visit);
  }

  FrameResult cull_frame(const View& view, Backend& backend) override {
    ++frame_;
    // A rebuilt hierarchy starts from what was drawn last frame (carry_over;
    // conservative whatever it says: only queries cull); a changed set of
    // objects changes the nodes' areas and shading.
    seen_.begin(index_.scene);
    const bool rebuilt = states_restart(seen_, index_.bvh, frame_ - 1);
    if (rebuilt || layout_ != index_.scene.layout_revision()) describe_nodes(rebuilt);
    f_.begin(view, backend);
    frustum_.begin(index_.bvh, view);
    c_scr_ = 0.0;

    distance_queue_.push(index_.bvh, Bvh::root(), view.eye);
    while (!distance_queue_.empty() || !query_queue_.empty()) {
      while (!query_queue_.empty() && first_query_finished()) handle_returned_query();
      if (distance_queue_.empty()) {
        if (!query_queue_.empty()) {
          flush_render_queue();
          submitter_.submit(*f_.backend);
          handle_returned_query();  // nothing else to do: wait
        }
        continue;
      }
      const NodeId n = distance_queue_.pop();
      if (cancelled(n)) continue;
      visit(n);
    }
    flush_render_queue();
    return f_.end();
  }

 private:
  // Per node: triangle-weighted shading cost and object surface area (and,
  // with `rebuilt`, the temporal state carried over from the objects drawn
  // last frame).
  void describe_nodes(bool rebuilt = true) {
    const Bvh& bvh = index_.bvh;
    if (rebuilt || nodes_.size() != bvh.size()) carry_over(nodes_, bvh, seen_, frame_ - 1);
    for (NodeId n = NodeId(bvh.size()); n-- > 0;) {
      NodeInfo& info = nodes_[n];
      double weighted = 0.0;
      info.area = 0.0;
      for (ObjectId id : bvh.objects(n)) {
        const Object& o = index_.scene.object(id);
        info.area += index_.scene.object_surface_area(id);
        weighted += double(o.triangles) * double(index_.scene.material(o.material).shading_cost);
      }
      info.shading = bvh.node(n).triangles > 0 ? weighted / double(bvh.node(n).triangles) : 0.0;
    }
    levels_ = config_.levels > 0.0 ? config_.levels : std::log2(double(bvh.size()) + 1.0);
    layout_ = index_.scene.layout_revision();
  }

  struct NodeInfo {
    double area = 0.0;     // object surface area in the subtree
    double shading = 0.0;  // triangle-weighted mean shading cost
    std::uint32_t last_visited = kNever;
    std::uint32_t frames_since_query = 0;
    std::uint32_t cancelled = kNever;   // frame in which an ancestor was found occluded
    std::uint32_t cost_frame = kNever;  // frame of the cached c_bb
    double c_bb = 0.0;
    PreviousState state = PreviousState::outside;  // this frame's, once known
    bool visible = false;
  };
  struct Pending {
    QueryId id;
    NodeId node;
    bool wait;  // children held back until the answer
    PreviousState previous;  // of the node when queried, and the model's p_occl for it (uncorrected)
    double p_occl;
    std::uint32_t submission;  // QuerySubmitter tag: polled only once handed to the device
  };

  bool is_leaf(NodeId n) const { return index_.bvh.is_leaf(n, config_.common.virtual_leaf_triangles); }

  PreviousState previous_state(NodeId n) const {
    const NodeInfo& i = nodes_[n];
    if (i.last_visited == kNever || i.last_visited + 1 != frame_) return PreviousState::outside;
    return i.state;
  }

  // Whether an occluded answer of an ancestor cancelled `n`. A node waiting
  // in the distance queue has a parent visited this frame, and cancel()
  // marks every visited node below the occluded one, so looking at `n` and
  // its parent is enough (no walk to the root per popped node).
  bool cancelled(NodeId n) const {
    if (nodes_[n].cancelled == frame_) return true;
    const NodeId parent = index_.bvh.node(n).parent;
    return parent != kNoNode && nodes_[parent].cancelled == frame_;
  }

  // Marks `n` and its descendants visited this frame as cancelled.
  void cancel(NodeId n) {
    cancel_stack_.clear();
    cancel_stack_.push_back(n);
    while (!cancel_stack_.empty()) {
      const NodeId m = cancel_stack_.back();
      cancel_stack_.pop_back();
      nodes_[m].cancelled = frame_;
      if (index_.bvh.is_leaf(m)) continue;
      for (NodeId c : {Bvh::left(m), index_.bvh.right(m)})
        if (nodes_[c].last_visited == frame_ && nodes_[c].cancelled != frame_) cancel_stack_.push_back(c);
    }
  }

  double c_bb(NodeId n) {
    NodeInfo& i = nodes_[n];
    if (i.cost_frame != frame_) {
      const Aabb& box = index_.bvh.node(n).bounds;
      if (config_.exact_area) {
        i.c_bb = projected_area(box, f_.view->view_proj, f_.view->width, f_.view->height) /
                 (double(f_.view->width) * double(f_.view->height));
      } else {
        i.c_bb = bbox_screen_fraction(box.surface_area(), distance(f_.view->eye, box), *f_.view);
      }
      i.cost_frame = frame_;
    }
    return i.c_bb;
  }

  NodeEstimate estimate(NodeId n) {
    const BvhNode& node = index_.bvh.node(n);
    NodeCost cost;
    cost.draws = node.object_count;
    cost.triangles = node.triangles;
    cost.shading_cost = nodes_[n].shading;
    cost.c_bb = c_bb(n);
    cost.r_cov = coverage_ratio(nodes_[n].area, node.bounds.surface_area());
    NodeEstimate e;
    e.t_r = render_time(hw_, cost, f_.view->width, f_.view->height, config_.fragments_per_pixel);
    e.t_o = query_time(hw_, cost.c_bb, f_.view->width, f_.view->height);
    const PreviousState previous = previous_state(n);
    double p = occlusion_probability(previous, coverage_probability(c_scr_, cost.c_bb));
    if (previous == PreviousState::visible) p *= config_.visible_factor / 0.5;
    model_p_occl_ = std::clamp(p, 0.0, 1.0);
    e.p_occl = config_.learn ? calibration_.scale(previous, p) : model_p_occl_;
    e.leaves = node.object_count;
    return e;
  }

  void visit(NodeId n) {
    ++f_.nodes_visited;
    NodeInfo& info = nodes_[n];
    const PreviousState previous = previous_state(n);
    info.visible = false;
    info.last_visited = frame_;
    info.state = PreviousState::outside;
    const BvhNode& node = index_.bvh.node(n);
    if (node.object_count == 0 || frustum_.outside(index_.bvh, n)) return;
    info.state = PreviousState::visible;  // until a query says otherwise
    if (near_eye(node.bounds, *f_.view, f_.near_radius)) {
      process(n);
      return;
    }
    ReasonabilityInput in;
    in.node = estimate(n);
    const double model_p_occl = model_p_occl_;  // before the children's estimates replace it
    NodeEstimate kids[2];
    if (!is_leaf(n)) {
      kids[0] = child_estimate(Bvh::left(n));
      kids[1] = child_estimate(index_.bvh.right(n));
      in.children = std::span<const NodeEstimate>(kids, 2);
    }
    in.previous = previous;
    in.frames_since_query = info.frames_since_query;
    in.levels = levels_;
    in.query_overhead_ms = hw_.query_overhead_ms;
    if (query_reasonable(in)) {
      flush_render_queue();
      boxes_.clear();
      append_query_boxes(index_, n, {}, boxes_);
      const bool wait = previous == PreviousState::occluded;
      const QueryId q = f_.backend->issue_query(boxes_);
      query_queue_.push_back({q, n, wait, previous, model_p_occl, submitter_.issued(*f_.backend)});
      ++f_.counters.query_batches;
      info.frames_since_query = 0;
      if (!wait) process(n);
    } else {
      ++info.frames_since_query;
      process(n);
    }
  }

  // A child outside the frustum costs nothing to query (the granularity rule
  // then prefers querying the children).
  NodeEstimate child_estimate(NodeId c) {
    if (index_.bvh.node(c).object_count == 0 || frustum_.outside(index_.bvh, c)) return {0.0, 0.0, 0.0, 0};
    return estimate(c);
  }

  void process(NodeId n) {
    if (is_leaf(n)) {
      const std::size_t before = render_queue_.size();
      frustum_.append_objects(index_, n, render_queue_);
      if (render_queue_.size() > before) {
        NodeCost cost;
        cost.c_bb = c_bb(n);
        cost.r_cov = coverage_ratio(nodes_[n].area, index_.bvh.node(n).bounds.surface_area());
        c_scr_ = accumulate_coverage(c_scr_, object_screen_fraction(cost));
      }
      pull_up(n);
    } else {
      distance_queue_.push(index_.bvh, Bvh::left(n), f_.view->eye);
      distance_queue_.push(index_.bvh, index_.bvh.right(n), f_.view->eye);
    }
  }

  void pull_up(NodeId n) {
    for (; n != kNoNode && !nodes_[n].visible; n = index_.bvh.node(n).parent) {
      nodes_[n].visible = true;
      nodes_[n].state = PreviousState::visible;
    }
  }

  bool first_query_finished() {
    if (int(query_queue_.size()) >= max_parallel_) return true;  // the N_q rule
    if (!submitter_.submitted(query_queue_.front().submission)) return false;  // cannot be done yet
    return f_.backend->result_available(query_queue_.front().id);
  }

  void handle_returned_query() {
    const Pending q = query_queue_.front();
    query_queue_.pop_front();
    const bool visible = f_.backend->result(q.id) > config_.common.threshold;
    calibration_.record(q.previous, q.p_occl, !visible);
    if (cancelled(q.node)) return;  // an ancestor is occluded: nothing to do
    NodeInfo& info = nodes_[q.node];
    if (visible) {
      if (is_leaf(q.node)) pull_up(q.node);
      if (q.wait) process(q.node);
    } else {
      info.state = PreviousState::occluded;
      info.visible = false;
      if (!q.wait) cancel(q.node);  // drop the children queued meanwhile
    }
  }

  void flush_render_queue() {
    if (render_queue_.empty()) return;
    f_.backend->render(render_queue_);
    seen_.drawn(render_queue_, frame_);
    render_queue_.clear();
  }

  SceneIndex index_;
  NohcConfig config_;
  HardwareProfile hw_;
  std::vector<NodeInfo> nodes_;
  double levels_ = 1.0;
  int max_parallel_ = 1;
  std::uint32_t frame_ = 0;

  // Per frame.
  FrameContext f_;
  FrustumCache frustum_;
  ObjectVisibility seen_;  // what was drawn, for nodes_ after a rebuild of the hierarchy
  std::uint64_t layout_ = 0;      // Scene::layout_revision() of nodes_
  double c_scr_ = 0.0;
  double model_p_occl_ = 0.0;  // the model's p_occl of the last estimate, before calibration
  DistanceQueue distance_queue_;
  std::deque<Pending> query_queue_;
  std::vector<ObjectId> render_queue_;
  std::vector<Aabb> boxes_;
  std::vector<NodeId> cancel_stack_;
  QuerySubmitter submitter_;
  OcclusionCalibration calibration_;
};

}  // namespace

HardwareProfile nohc_profile(const CullerContext& context, const std::string& file) {
  if (!file.empty() && !context.hardware_profile)
    throw InputError(detail::format("nohc.profile={}: this program reads no profile files (CullerContext::hardware_profile "
                                    "is unset; occull::lab's load_profile reads them)",
                                    file));
  std::optional<HardwareProfile> profile = context.hardware_profile ? context.hardware_profile(file) : std::nullopt;
  if (profile) return std::move(*profile);
  if (!file.empty()) throw InputError(detail::format("nohc.profile: '{}' does not exist", file));
  throw InputError("nohc needs a hardware profile: run `occull calibrate` (occull bench does it for you), or pass "
                   "--opt nohc.profile=FILE (CullerContext::hardware_profile in a program)");
}

Registration nohc_registration() {
  using C = NohcConfig;
  static const ConfigTable<C> table =
      with_common_options(ConfigTable<C>(), &C::common)
          .text("profile", &C::profile, "hardware profile JSON; occull bench calibrates and caches one per renderer",
                "(calibrated)")
          .real("fragments_per_pixel", &C::fragments_per_pixel, 0.0, 100.0,
                "overdraw assumed when estimating shaded fragments")
          .real("visible_factor", &C::visible_factor, 0.0, 1.0,
                "p_occl = factor * p_cov^2 for nodes visible in the last frame")
          .real("levels", &C::levels, 0.0, 1000.0, "levels the benefit is spread over (0: log2(N_h + 1))")
          .integer("max_parallel", &C::max_parallel, 0, 100000,
                   "N_q: queries in flight before the oldest counts as finished (0: from the profile)")
          .flag("exact_area", &C::exact_area, "c_bb from the exact projected box area (off: the paper's approximation)")
          .flag("learn", &C::learn,
                "correct the occlusion probabilities by the share of queries that found nodes occluded, per previous "
                "state (off: the paper's model alone)")
          .integer("flush_every", &C::flush_every, 1, 1 << 20,
                   "hand queries to the device this many at a time, and poll only those handed over (1: each at once)");
  return registered(
      {"nohc", "near optimal hierarchical culling: occlusion probability + calibrated hardware cost model (Guthe et al. 2006)"},
      table, [](const SceneIndex& index, const C& c, const Options&, const CullerContext& context) {
        return std::make_unique<NohcCuller>(index, c, nohc_profile(context, c.profile));
      });
}

}  // namespace occull::detail
