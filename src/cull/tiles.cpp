// `tiles`: tile queries with the common box and per-tile CHC++ over a tiled
// world (Gomez et al. 2013, Algorithms 1-4; occull/tiles.hpp).
//
// Each frame starts at the nearest cell whose common box is in the frustum
// (nothing is drawn yet, so it is visible: closestVisibleTileInFrustum),
// renders it with its CHC++ context, queries its neighbours with the
// common box offset to each (queryNeighbors: only those in the frustum and
// not queried yet this frame, each query kept in a FIFO), and goes on with
// the next neighbour whose query comes back positive (getNextPositiveQuery).
// A neighbour seen visible in the previous frame whose result is not ready
// is rendered at once and its result read at the frame's end
// (updatePostponedQueryQueue), as the prediction for the next frame.
//
// Why a negative query may stop propagation: every cell's query draws the
// same box, the union of all tiles' boxes, so a cell whose common box is
// hidden hides whatever tile it holds; and a ray from the eye to a visible
// point of a farther cell crosses the columns of a chain of neighbouring
// cells (8-neighbours take the chains through corners) inside their common
// boxes while it runs inside the boxes' height range, so each of those has a
// visible point too (Gomez et al. 2013, Section III-C); from above the boxes, every
// box top in the frustum is seen over whatever lies below it. The verifier
// checks it (and catches tiles.box=tile, which queries each tile's own box).
//
// Beyond the paper: the eye-inside rule (a neighbour's box around the eye is
// visible without a query, which the near plane could clip) and
// tiles.requery=N (a visible tile's query only every N-th frame).
#include "cullers.hpp"
#include "tile_cache.hpp"
#include "traversal.hpp"

#include <deque>
#include <map>
#include <optional>

namespace occull::detail {
namespace {

class TilesCuller final : public Culler {
 public:
  TilesCuller(const SceneIndex& index, const TilesConfig& c, const Options& o)
      : world_(tiled_world(index, "tiles")),
        cache_(index, c.local, o, c.evict),
        neighbors_(c.neighbors),
        common_box_(c.common_box),
        requery_(c.requery) {}

  void visit_counters(const CounterVisitor& visit) const override { cache_.visit_counters(visit); }

  FrameResult cull(const View& view, Backend& backend) override {
    backend_ = &backend;
    view_ = &view;
    near_radius_ = near_plane_radius(view);
    cache_.begin_frame(++frame_);
    release(backend);  // the queries whose results were not ready at the last frame's end

    pending_.clear();
    postponed_.clear();
    std::optional<TileCoord> t = closest_visible_tile_in_frustum();
    if (t) state(*t).queried_frame = frame_;
    while (t) {
      cache_.render(cache_.fetch(*t), view, backend);  // renderWithCHC++(fetchBVHInstance(T))
      query_neighbors(*t);
      t = next_positive_query();
    }
    update_postponed_queries();
    cache_.end_frame();
    prune();
    backend_ = nullptr;  // this frame's only: queries left over are in stale_
    view_ = nullptr;
    return cache_.result();
  }
  [[nodiscard]] std::span<const CullRegion> regions() const override { return cache_.regions(); }

  // The postponed queries given up on at the last frame's end (their cells
  // were already taken as hidden): read and dropped, as the next frame would.
  void release(Backend& backend) override {
    for (QueryId q : stale_) (void)backend.result(q);
    stale_.clear();
  }
  [[nodiscard]] std::size_t queries_held() const override { return stale_.size(); }

 private:
  struct CellState {
    std::uint64_t queried_frame = 0;  // last frame its query was issued or it was passed over
    std::uint64_t visible_for = 0;    // the frame it is predicted visible in (0: none)
  };
  struct Pending {
    QueryId query;
    TileCoord cell;
    bool queried;  // false: visible by the eye-inside rule, no query issued
    Aabb box;      // what was queried
  };

  CellState& state(TileCoord c) { return cells_[c]; }
  [[nodiscard]] static std::uint64_t phase(TileCoord c) noexcept {
    return std::uint64_t(std::uint32_t(c.x) * 73856093u ^ std::uint32_t(c.z) * 19349663u);
  }

  // closestVisibleTileInFrustum (Algorithm 1, line 3)
  std::optional<TileCoord> closest_visible_tile_in_frustum() { return nearest_cell_in_frustum(world_, *view_); }

  // queryNeighbors (Algorithm 2)
  void query_neighbors(TileCoord t) {
    static constexpr int kOffsets[8][2] = {{1, 0}, {-1, 0}, {0, 1}, {0, -1}, {1, 1}, {1, -1}, {-1, 1}, {-1, -1}};
    for (int i = 0; i < neighbors_; ++i) {
      const TileCoord n{t.x + kOffsets[i][0], t.z + kOffsets[i][1]};
      CellState& s = state(n);
      if (s.queried_frame == frame_) continue;
      s.queried_frame = frame_;
      if (!world_.in_window(n)) continue;
      const Aabb box = common_box_ ? world_.common_box_at(n) : world_.tile_box_at(n);  // commonBboxAtOffset(n)
      if (view_->frustum.classify(box) == Containment::outside) continue;
      // The eye-inside rule: the near plane may clip the faces of a box
      // around the camera, so such a box is visible without a query. With
      // tiles.requery=N, a tile seen visible is drawn again without a query
      // except every N-th frame (phase by cell, as CHC++ jitters its
      // re-queries), which only ever draws more: conservative.
      const bool skip = requery_ > 1 && s.visible_for == frame_ && (frame_ + phase(n)) % requery_ != 0;
      if (skip || near_eye(box, *view_, near_radius_)) {
        pending_.push_back({0, n, false, box});
        continue;
      }
      pending_.push_back({backend_->issue_query(std::span<const Aabb>(&box, 1)), n, true, box});
      ++cache_.counters().tile_queries;
    }
  }

  // getNextPositiveQuery (Algorithm 3)
  std::optional<TileCoord> next_positive_query() {
    while (!pending_.empty()) {
      const Pending p = pending_.front();
      pending_.pop_front();
      CellState& s = state(p.cell);
      if (!p.queried) {
        s.visible_for = frame_ + 1;
        return p.cell;
      }
      if (!backend_->result_available(p.query) && s.visible_for == frame_) {
        postponed_.push_back(p);
        ++cache_.counters().tile_postponed;
        return p.cell;
      }
      if (backend_->result(p.query) > 0) {
        s.visible_for = frame_ + 1;
        return p.cell;
      }
      s.visible_for = 0;
      cache_.note(p.box, false);
    }
    return std::nullopt;
  }

  // updatePostponedQueryQueue (Algorithm 4)
  void update_postponed_queries() {
    for (const Pending& p : postponed_) {
      CellState& s = state(p.cell);
      if (backend_->result_available(p.query)) {
        s.visible_for = backend_->result(p.query) > 0 ? frame_ + 1 : 0;
      } else {
        s.visible_for = 0;
        ++cache_.counters().tile_prediction_failures;
        stale_.push_back(p.query);
      }
    }
    postponed_.clear();
  }

  // Forgets cells not queried for the eviction time (their prediction is
  // long stale) and cells that left the window.
  void prune() {
    for (auto it = cells_.begin(); it != cells_.end();) {
      if (frame_ - it->second.queried_frame >= std::uint64_t(cache_.evict_after()) || !world_.in_window(it->first))
        it = cells_.erase(it);
      else
        ++it;
    }
  }

  const TiledWorld& world_;
  TileCache cache_;
  int neighbors_;
  bool common_box_;  // false: each tile's own box (tiles.box=tile, not conservative)
  std::uint64_t requery_;  // a visible tile's query every this many frames (1: every frame, as the paper)
  std::uint64_t frame_ = 0;
  std::map<TileCoord, CellState> cells_;
  std::deque<Pending> pending_;    // Q: queries in issue order (results come back in order)
  std::vector<Pending> postponed_; // P
  std::vector<QueryId> stale_;     // postponed queries given up on at the last frame's end
  Backend* backend_ = nullptr;  // during render_frame only
  const View* view_ = nullptr;  // during render_frame only
  float near_radius_ = 0.0f;
};

}  // namespace

Registration tiles_registration() {
  using C = TilesConfig;
  static const ConfigTable<C> table =
      ConfigTable<C>()
          .choice("local", &C::local, std::vector<std::pair<std::string, std::string>>{{"chcpp", "chcpp"}, {"none", ""}},
                  "culling inside a visible tile: chcpp (its own CHC++ context) or none (draw the whole tile)")
          .integer("evict", &C::evict, 1, 1000000,
                   "frames a tile instance may go unused before its BVH instance and CHC++ context are freed")
          .choice("neighbors", &C::neighbors, {{"4", 4}, {"8", 8}},
                  "neighbours a visible tile queries: 4 (edges) or 8 (edges and corners)")
          .integer("requery", &C::requery, 1, 1000,
                   "a tile found visible is queried again every N frames and drawn without a query in between (1: "
                   "every frame, as the paper; N > 1 as CHC++ re-queries visible nodes)")
          .choice("box", &C::common_box, {{"common", true}, {"tile", false}},
                  "box a tile query draws: common (the union of every tile's box) or tile (the queried tile's own box: "
                  "not conservative, Gomez et al. 2013's Figure 7, kept to show why)")
          .approximate_unless_default();
  Registration r = registered({"tiles",
                     "tiled worlds: visibility propagated tile to tile by queries of the common box, front to back, "
                     "with temporal prediction; each visible tile culled by its own CHC++ (Gomez et al. 2013, Algorithms 1-4)",
                     true, {}, false, SceneKind::tiled},
                    table, [](const SceneIndex& index, const C& c, const Options& o, const CullerContext&) {
                      return std::make_unique<TilesCuller>(index, c, o);
                    });
  r.bench_variants = {"tiles:local=none"};  // the paper's "tile query alone"
  return r;
}

}  // namespace occull::detail
