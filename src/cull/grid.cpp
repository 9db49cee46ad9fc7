// `grid`: uniform-grid occlusion culling with a per-frame query cap
// (Seletsky 2013, chapter 4.3).
//
// The scene lives in a UniformGrid (occull/grid.hpp), not the BVH. Each frame:
//  1. read every cell query of the last frame (they are a frame old, so done)
//     and store per cell whether it was visible and until which frame that
//     answer holds: visibility lasts `vis_duration` frames, invisibility
//     `invis_duration`, both longer by `*_growth` per consecutive frame that
//     hit the query cap, plus a random 0..2·(those frames) (query starvation,
//     thesis 4.3.5);
//  2. walk the cells the frustum meets in occlusion order (GridTraversal).
//     A cell whose answer expired is queried again while fewer than `cap`
//     queries ran this frame — a cell that was visible always is (the
//     blinking fix). A cell whose answer says visible has its objects drawn:
//     occluders of class `always`, and `sometimes` while fewer than
//     `prepass` of them were drawn this frame, at once so that they occlude
//     the cells behind (the thesis' depth pre-pass), the rest at the end,
//     sorted by material (the colour pass);
//  3. (latency=0) read the queries of the cells not drawn and draw those
//     found visible.
//
// Deviations, each for a reason:
//  - The queries of cells not drawn this frame are waited for after the
//    colour pass, and the cells they find visible drawn in the same frame
//    (`latency=0`): in the thesis (`latency=1`) every cell that comes into
//    sight from behind an occluder pops in a frame late, 0.16% to 0.29% of
//    the visible object-frames on OpenArena maps. The wait is for queries
//    flushed before the colour pass, as CHC++ waits for those of hidden
//    nodes; the answers of drawn cells are still read a frame later.
//  - A cell the frustum did not meet in the last frame has no current
//    answer; it is drawn while its first query runs (`unknown=visible`),
//    where the thesis leaves it hidden (`unknown=hidden`) and every cell
//    entering the view pops in a frame late.
//  - The pre-pass draws in colour, once, instead of depth-only followed by
//    a second colour draw: occull's Backend has one draw call, and drawing
//    each object once is never slower.
//  - The pre-pass of a cell queried this frame runs under conditional
//    rendering on that query (`conditional`, where the Backend has it),
//    as in the thesis, but only for objects inside the cell: an object
//    that reaches into other cells is drawn once per frame, and the device
//    skipping it here would leave its parts in the other cells undrawn.
//  - Queries use the box of what a cell holds (its objects clipped to the
//    cell, `tight`), which covers every object part in the cell, instead of
//    the whole cell box.
//
// Results are a frame late and capped: this culler is not conservative;
// the verifier measures its popping.
#include "cullers.hpp"
#include "traversal.hpp"

#include "occull/error.hpp"
#include "occull/grid.hpp"
#include "occull/grid_views.hpp"
#include "core/format.hpp"

#include <algorithm>
#include <memory>
#include <optional>
#include <random>

namespace occull::detail {
namespace {

class GridCuller final : public Culler {
 public:
  // `grid` and `budget` may be shared with the cullers of other views
  // (GridViews); without a budget the cap is config.cap.
  GridCuller(const SceneIndex& index, const GridConfig& config, std::shared_ptr<UniformGrid> grid,
             std::shared_ptr<QueryBudget> budget = nullptr, int view = 0)
      : scene_(index.scene), config_(config), grid_(std::move(grid)), budget_(std::move(budget)), view_(view),
        drawn_(index.scene.objects().size(), ~std::uint64_t(0)),
        seen_placement_(index.scene.placement_revision()), rng_(config.seed) {}

  void visit_counters(const CounterVisitor& visit) const override {
    visit("query_batches", double(counters_.query_batches));
    visit("capped", double(counters_.capped));
    visit("over_cap", double(counters_.over_cap));
    visit("result_age", counters_.result_age);
    visit("revealed", double(counters_.revealed));
  }

  FrameResult cull(const View& view, Backend& backend) override {
    FrameResult result;
    Counters& stats = counters_ = {};
    for (ObjectId id : scene_.dynamic_objects()) grid_->update(id, scene_.object(id).bounds);
    // What the engine moved, added or removed (the grid may be shared: updates are idempotent).
    seen_placement_ = scene_.for_each_changed_since(
        seen_placement_, [&](ObjectId id) { grid_->update(id, scene_.object(id).bounds); });
    if (drawn_.size() < scene_.objects().size()) drawn_.resize(scene_.objects().size(), ~std::uint64_t(0));
    if (cells_.size() < grid_->occupied()) cells_.resize(grid_->occupied());
    gather(backend);
    ++frame_;

    const float near_radius = near_plane_radius(view);
    const int cap = budget_ ? budget_->allowance(view_) : config_.cap;
    int queries = 0, prepass = 0;
    bool capped = false;
    std::uint64_t answers = 0, age = 0;
    colour_.clear();
    regions_.clear();
    for (const CellRun& run : traversal_.traverse(grid_->geometry(), view, config_.traversal)) {
      for (int i = 0; i < run.count; ++i) {
        ++result.nodes_visited;
        const std::uint32_t c = grid_->find(run.start + run.step * i);
        if (c == UniformGrid::kNoCell || grid_->objects(c).empty()) continue;
        Cell& cell = cells_[c];
        const bool seen_last_frame = cell.seen + 1 == frame_;
        cell.seen = frame_;
        const Aabb box = config_.tight ? grid_->content_box(c) : grid_->geometry().cell_box(grid_->coord(c));
        bool draw = cell.visible && cell.until >= frame_;
        bool requery = cell.until <= frame_;
        const bool unknown = !seen_last_frame && !draw;
        if (unknown && config_.unknown_visible) draw = requery = true;
        if (near_eye(box, view, near_radius)) {
          // Around the eye: visible, and its query could miss the faces around the camera.
          draw = true;
          requery = false;
          cell.visible = true;
          cell.until = cell.asked = frame_;
        } else if (!unknown) {
          ++answers;
          age += frame_ - cell.asked;
        }
        regions_.push_back({grid_->geometry().cell_box(grid_->coord(c)), draw});
        QueryId query = 0;
        bool queried = false;
        if (requery) {
          if (queries >= cap && !capped) {
            capped = true;
            ++capped_frames_;
          }
          if (queries < cap || draw) {
            query = backend.issue_query(std::span<const Aabb>(&box, 1));
            queried = true;
            pending_.push_back({query, c, draw, cell.until < frame_, regions_.size() - 1});
            ++queries;
            ++stats.query_batches;
          } else {
            ++stats.over_cap;
          }
        }
        if (!draw) continue;
        // The pre-pass of a cell queried now is conditional on that query,
        // except for objects that reach into other cells: the device may
        // skip them here, where they count as drawn for this frame.
        const bool conditional = queried && config_.conditional && backend.conditional_rendering();
        prepass_.clear();
        inside_.clear();
        for (ObjectId id : grid_->objects(c)) {
          if (drawn_[id] == frame_) continue;
          drawn_[id] = frame_;
          // The cell meets the frustum; the object may reach it only outside.
          if (view.frustum.classify(scene_.object(id).bounds) == Containment::outside ||
            holds_no_sample(scene_.object(id).bounds, view))
          continue;
          if (occludes(id, prepass)) {
            (conditional && in_one_cell(id) ? inside_ : prepass_).push_back(id);
            ++prepass;
          } else {
            colour_.push_back(id);
          }
        }
        if (!prepass_.empty()) backend.render(prepass_);
        if (!inside_.empty()) backend.render_conditional(inside_, query, *config_.conditional);
      }
    }
    if (!capped) capped_frames_ = 0;
    stats.capped = capped ? 1 : 0;
    deferred_ = stats.over_cap;
    stats.result_age = answers > 0 ? double(age) / double(answers) : 0.0;
    backend.flush();  // the queries run while the colour pass is drawn
    if (!colour_.empty()) backend.render(colour_);
    if (config_.latency == 0) reveal(view, backend, stats);
    return result;
  }

 private:
  // The frame's counters beyond FrameResult: the query cap's (whether the
  // frame reached it, how many cells due a query it deferred, how old the
  // answers used were) and latency=0's reveals.
  struct Counters {
    std::uint64_t query_batches = 0;  // queries issued (one cell each)
    std::uint64_t capped = 0;         // 1 when the frame reached the query cap
    std::uint64_t over_cap = 0;       // queries due but deferred by the cap
    double result_age = 0.0;          // mean frames since the query behind each answer used was issued
    std::uint64_t revealed = 0;       // hidden cells found visible by this frame's query and drawn in it
  };

  struct Cell {
    std::uint64_t until = 0;       // the last frame the stored answer holds (expiry)
    std::uint64_t seen = ~std::uint64_t(0);  // last frame the traversal met the cell
    std::uint64_t asked = 0;       // the frame whose query gave the stored answer
    bool visible = false;
  };
  struct Pending {
    QueryId query;
    std::uint32_t cell;
    bool drawn;             // the cell's objects were drawn in the frame of the query
    bool overdue;           // its answer had expired before that frame: the cap deferred it
    std::size_t region;     // its entry in regions_ of that frame
    bool settled = false;   // result read in that frame already (reveal), kept in `visible`
    bool visible = false;
    bool useful = false;    // settled, visible, and it drew an object no other cell had drawn
  };

  // `latency=0`: waits for the queries of this frame's undrawn cells and
  // draws the cells they find visible now, not a frame late. The queries
  // were flushed before the colour pass, so on a device that works while
  // the CPU submits, most answers are in by now. The answers are kept for
  // gather(), which treats them as every other.
  void reveal(const View& view, Backend& backend, Counters& stats) {
    colour_.clear();
    for (Pending& p : pending_) {
      if (p.drawn) continue;
      p.settled = true;
      p.visible = backend.result(p.query) > config_.threshold;
      if (!p.visible) continue;
      ++stats.revealed;
      regions_[p.region].visible = true;
      for (ObjectId id : grid_->objects(p.cell)) {
        if (drawn_[id] == frame_) continue;
        drawn_[id] = frame_;
        if (view.frustum.classify(scene_.object(id).bounds) == Containment::outside ||
            holds_no_sample(scene_.object(id).bounds, view))
          continue;
        colour_.push_back(id);
        p.useful = true;
      }
    }
    if (!colour_.empty()) backend.render(colour_);
  }

  // Last frame's answers. The frame number is still last frame's here, as
  // in the thesis' pseudo-code.
  void gather(Backend& backend) {
    const int grow = capped_frames_;
    std::uniform_int_distribution<int> offset(0, 2 * grow);
    // Re-queries of hidden cells, all and those the cap had deferred.
    std::uint64_t forced = 0, rechecked[2] = {0, 0}, revealed[2] = {0, 0};
    for (const Pending& p : pending_) {
      Cell& cell = cells_[p.cell];
      cell.visible = p.settled ? p.visible : backend.result(p.query) > config_.threshold;
      forced += p.drawn ? 1 : 0;
      if (!p.drawn) {
        for (int k = 0; k < (p.overdue ? 2 : 1); ++k) {
          ++rechecked[k];
          revealed[k] += (p.settled ? p.useful : cell.visible) ? 1 : 0;
        }
      }
      cell.asked = frame_;
      const int base = cell.visible ? config_.vis_duration + config_.vis_growth * grow
                                    : config_.invis_duration + config_.invis_growth * grow;
      cell.until = frame_ + std::uint64_t(base) + std::uint64_t(grow > 0 ? offset(rng_) : 0);
    }
    // The budget wants the odds that a deferred re-query would find its
    // cell visible: those of the deferred ones that ran, if any did.
    const int k = rechecked[1] > 0 ? 1 : 0;
    if (budget_) budget_->report(view_, forced, rechecked[k], revealed[k], deferred_);
    pending_.clear();
  }

  [[nodiscard]] std::span<const CullRegion> regions() const override { return regions_; }

  // The last frame's queries are read now and kept as the next frame's
  // gather() would keep them.
  void release(Backend& backend) override { gather(backend); }
  [[nodiscard]] std::size_t queries_held() const override {
    return std::size_t(std::count_if(pending_.begin(), pending_.end(), [](const Pending& p) { return !p.settled; }));
  }

  bool in_one_cell(ObjectId id) const {
    const Aabb& b = scene_.object(id).bounds;
    return grid_->geometry().cell_of(b.min) == grid_->geometry().cell_of(b.max);
  }

  // Whether object `id` goes to the pre-pass, given `drawn` pre-pass objects so far.
  bool occludes(ObjectId id, int drawn) const {
    const Object& o = scene_.object(id);
    if (scene_.material(o.material).translucent) return false;
    return o.occluder == OccluderClass::always ||
           (o.occluder == OccluderClass::sometimes && drawn < config_.prepass);
  }

  const Scene& scene_;
  GridConfig config_;
  std::shared_ptr<UniformGrid> grid_;
  std::shared_ptr<QueryBudget> budget_;
  int view_;
  std::uint64_t deferred_ = 0;          // queries the cap deferred in the last frame
  GridTraversal traversal_;
  std::vector<Cell> cells_;             // per occupied cell
  std::vector<std::uint64_t> drawn_;    // per object: last frame it was drawn (once per frame)
  std::uint64_t seen_placement_;        // Scene::placement_revision() the grid follows
  std::vector<Pending> pending_;        // this frame's queries, read next frame
  std::vector<ObjectId> prepass_, inside_, colour_;
  std::vector<CullRegion> regions_;     // this frame's cells (Culler::regions)
  Counters counters_;                   // of the last frame
  std::uint64_t frame_ = 0;
  int capped_frames_ = 0;               // consecutive frames that hit the cap
  std::mt19937 rng_;
};

}  // namespace

namespace {

const ConfigTable<GridConfig>& grid_table() {
  using C = GridConfig;
  static const ConfigTable<C> table =
      ConfigTable<C>()
          .real("cell", &C::cell, 0.0, 1e9,
                "cell edge, scene units (0: twice the median object size, at most 256 cells along the scene)")
          .choice("traversal", &C::traversal,
                  {{"frustum", GridTraversal::Mode::frustum}, {"box", GridTraversal::Mode::box}},
                  "frustum: rasterize the frustum slice by slice; box: every cell of its bounding box")
          .integer("cap", &C::cap, 1, 1 << 24, "queries per frame; cells visible by their last answer are queried past it")
          .integer("vis_duration", &C::vis_duration, 1, 1 << 16, "frames a visible answer holds")
          .integer("vis_growth", &C::vis_growth, 0, 1 << 16, "... longer by this per consecutive frame that hit the cap")
          .integer("invis_duration", &C::invis_duration, 1, 1 << 16,
                   "frames an occluded answer holds (1: query again next frame)")
          .integer("invis_growth", &C::invis_growth, 0, 1 << 16,
                   "... longer by this per consecutive frame that hit the cap")
          .integer("prepass", &C::prepass, 0, 1 << 24,
                   "occluders of class sometimes drawn in the pre-pass per frame (class always: all)")
          .choice("unknown", &C::unknown_visible, {{"visible", true}, {"hidden", false}},
                  "a cell the frustum did not meet last frame: visible (draw it while its query runs) or hidden (the "
                  "thesis: it pops in a frame late)")
          .flag("tight", &C::tight, "query the box of what a cell holds instead of the whole cell")
          .integer("latency", &C::latency, 0, 1,
                   "frames before a hidden cell's answer is used: 0 waits for it after the colour pass and draws the "
                   "cells found visible in the same frame; 1 uses it next frame (the thesis: they pop in a frame "
                   "late)")
          .choice("conditional", &C::conditional,
                  std::vector<std::pair<std::string, std::optional<ConditionalWait>>>{
                      {"wait", ConditionalWait::wait}, {"no_wait", ConditionalWait::no_wait}, {"off", std::nullopt}},
                  "pre-pass of a cell queried this frame under conditional rendering on its query: wait (the device "
                  "waits for the result), no_wait (draws while it is unknown) or off")
          .integer("threshold", &C::threshold, 0, 1 << 24, "a cell is visible when more samples (pixels) pass")
          .approximate_unless_default()
          .integer("seed", &C::seed, 0, 1 << 30, "random seed of the answers' extra duration when capped")
          .choice("split", &C::split, {{"reveal", SplitPolicy::reveal}, {"even", SplitPolicy::even}},
                  "split screen (bench --views): how the views share the cap; reveal: an even split of what the "
                  "queries of drawn cells leave, capped at each view's recent peak demand, and what a view does not "
                  "need lent in proportion to demand x share of its re-queries of hidden cells that found them "
                  "visible (measured: less popping than even); even: cap / views each")
          .real("split_floor", &C::split_floor, 0.0, 1.0,
                "with split=reveal: share of an even split of what the queries of drawn cells leave each view is "
                "sure of (below 1, more goes by reveal rate)");
  return table;
}

}  // namespace

Registration grid_registration() {
  Registration r = registered(
      {"grid",
       "uniform grid in occlusion order, cell queries read a frame later, occluder pre-pass, per-frame query cap "
       "(Seletsky 2013); may pop",
       false, {}, false, SceneKind::bvh, /*shares_views=*/true},
      grid_table(), [](const SceneIndex& index, const GridConfig& c, const Options&, const CullerContext&) {
        return std::make_unique<GridCuller>(index, c,
                                            std::make_shared<UniformGrid>(UniformGrid::of_scene(index.scene, c.cell)));
      });
  r.make_views = [](const SceneIndex& index, int views, const Options& o, const CullerContext&) {
    return std::make_unique<GridViews>(index, views, o);
  };
  return r;
}

}  // namespace occull::detail

namespace occull {

namespace {
constexpr double kPriorReveals = 0.01;           // per query, as if one query had been seen
constexpr std::size_t kDemandWindow = 8;         // frames of reports a view's optional demand is the peak of
}  // namespace

QueryBudget::QueryBudget(int total, int views, double floor, Policy policy)
    : total_(total), floor_(floor), policy_(policy), allowance_(std::size_t(views)), rate_(std::size_t(views), kPriorReveals),
      revealed_(std::size_t(views), 0.0), rechecked_(std::size_t(views), 0.0),
      reports_(std::size_t(views), 0), forced_(std::size_t(views), 0),
      optional_(std::size_t(views) * kDemandWindow, 0) {
  if (views < 1 || total < views || !(floor >= 0.0 && floor <= 1.0))
    throw InputError(detail::format("query budget: {} queries for {} views (floor {}) cannot be split", total, views,
                                 floor));
  for (int& a : allowance_) a = total / views;
}

void QueryBudget::report(int view, std::uint64_t forced, std::uint64_t rechecked, std::uint64_t revealed,
                         std::uint64_t deferred) {
  const std::size_t k = std::size_t(view);
  forced_.at(k) = forced;
  optional_[k * kDemandWindow + reports_[k]++ % kDemandWindow] = rechecked + deferred;
  // Counts, not shares, are smoothed: a frame of 2000 re-queries weighs
  // more than one of 20, and rates far below 1 % stay apart (one view's
  // re-queries may reveal ten times as often as another's).
  revealed_[k] = 0.9 * revealed_[k] + double(std::min(revealed, rechecked));
  rechecked_[k] = 0.9 * rechecked_[k] + double(rechecked);
  rate_[k] = (revealed_[k] + kPriorReveals) / (rechecked_[k] + 1.0);
}

void QueryBudget::split() {
  if (policy_ == Policy::even) return;  // the constructor's even shares
  const std::size_t n = allowance_.size();
  // Each view's demand: the queries of the cells it drew last frame, and
  // the most re-queries of hidden cells it asked for in one of its recent
  // frames (hidden answers expire together, so that demand comes in bursts).
  std::vector<std::uint64_t> forced_of(forced_), optional_of(n, 0);
  std::uint64_t wanted = 0, forced = 0;
  for (std::size_t k = 0; k < n; ++k) {
    for (std::size_t i = k * kDemandWindow; i < (k + 1) * kDemandWindow; ++i)
      optional_of[k] = std::max(optional_of[k], optional_[i]);
    wanted += forced_of[k] + optional_of[k];
    forced += forced_of[k];
  }
  if (wanted <= std::uint64_t(total_)) {
    // Everyone gets what it asked for; the slack is shared evenly.
    const std::uint64_t slack = (std::uint64_t(total_) - wanted) / n;
    for (std::size_t k = 0; k < n; ++k) allowance_[k] = int(forced_of[k] + optional_of[k] + slack);
  } else {
    // What the forced queries leave: a floor each, then the rest by
    // remaining optional demand x reveal rate.
    const std::uint64_t free = forced < std::uint64_t(total_) ? std::uint64_t(total_) - forced : 0;
    const auto floor_each = std::uint64_t(floor_ * double(free) / double(n));
    std::vector<std::uint64_t> grant(n), rest(n);
    std::uint64_t left = free;
    for (std::size_t k = 0; k < n; ++k) {
      grant[k] = std::min(optional_of[k], floor_each);
      rest[k] = optional_of[k] - grant[k];
      left -= grant[k];
    }
    // Proportional shares; a view that needs less than its share passes the remainder on.
    for (int round = 0; round < int(n) && left > 0; ++round) {
      double weight = 0.0;
      for (std::size_t k = 0; k < n; ++k)
        if (rest[k] > 0) weight += double(rest[k]) * rate_[k];
      if (weight <= 0.0) break;
      std::uint64_t given = 0;
      for (std::size_t k = 0; k < n; ++k) {
        if (rest[k] == 0) continue;
        const auto share = std::uint64_t(double(left) * double(rest[k]) * rate_[k] / weight);
        const std::uint64_t g = std::min(rest[k], share);
        grant[k] += g;
        rest[k] -= g;
        given += g;
      }
      left -= given;
      if (given == 0) break;
    }
    for (std::size_t k = 0; k < n; ++k) allowance_[k] = int(forced_of[k] + grant[k]);
  }
  for (int& a : allowance_) a = std::max(a, 1);
}

GridViews::GridViews(const SceneIndex& index, int views, const Options& options)
    : GridViews(index, views, (check_options(options), detail::grid_table().parse(options, "grid"))) {}

GridViews::GridViews(const SceneIndex& index, int views, const GridConfig& c) {
  if (views < 1 || views > 16) throw InputError(detail::format("{} views: must be in [1, 16]", views));
  detail::grid_table().check(c, "grid");
  grid_ = std::make_shared<UniformGrid>(UniformGrid::of_scene(index.scene, c.cell));
  budget_ = std::make_shared<QueryBudget>(std::max(c.cap, views), views, c.split_floor, c.split);
  for (int k = 0; k < views; ++k) {
    GridConfig view_config = c;
    view_config.seed = c.seed + std::uint32_t(k);
    views_.push_back(std::make_unique<detail::GridCuller>(index, view_config, grid_, budget_, k));
  }
}

GridViews::~GridViews() = default;

std::unique_ptr<SplitScreen> make_split_screen(const GridConfig& config, const SceneIndex& index, int views,
                                               const CullerContext&) {
  return std::make_unique<GridViews>(index, views, config);
}

}  // namespace occull
