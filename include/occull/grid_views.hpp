// occull — split screen with the uniform-grid culler (Seletsky, seed 003,
// chapter 4.4): one `grid` culler per view, sharing one UniformGrid (the
// scene is indexed once, dynamic objects move in it once per frame) and one
// per-frame query cap, which a QueryBudget splits between the views. Each
// view keeps its own cell answers and durations.
#pragma once

#include "occull/culler.hpp"
#include "occull/grid.hpp"

#include <cstdint>
#include <memory>
#include <vector>

namespace occull {

/// Splits a per-frame query cap between views. The thesis leaves this open.
///
/// What the cap decides: the grid culler queries the cells it draws (visible
/// by their answer, new, or around the eye) past any cap, so the cap only
/// bounds the re-queries of cells hidden by their last answer. Such a
/// re-query changes nothing when the cell is still hidden (its stale answer
/// would have culled it as well); it pays only when it finds the cell
/// visible again, for then the cell is drawn and does not pop. So a view's
/// claim on the cap is its *reveal rate*: the share of its hidden
/// re-queries that found the cell visible and drew an object no other cell
/// had drawn (with grid.latency=1: found it visible), counting only the
/// re-queries the cap had deferred before when there are any, since those
/// are the ones the split decides. A view turning fast or moving past
/// occluders reveals many; one standing behind a wall reveals few.
///
/// Measured (city, street beside turn, 640x180, 150 frames at 30 fps): with
/// the default durations Policy::reveal popped more than Policy::even (35 vs
/// 23 missed object-frames, same frame time), because allowances close to
/// the demands cap both views in most frames, and capped frames lengthen
/// the durations of hidden answers (grid.invis_growth); with
/// grid.invis_growth=0 it popped less (3 vs 11). Two variants did worse
/// and were dropped: all of the rest to the view with the higher rate (42
/// missed), and growing durations only when the views' total demand
/// exceeded the total rather than at each view's allowance (58 vs 23 for
/// even, longest miss 5 frames, 16 % more queries). The misses are all in
/// the turning view (path turn); a guess not yet checked: cells at the
/// frustum's sides, hidden only because their visible part was outside it,
/// whose answers the cap keeps stale while the view turns, so ordering a
/// view's re-queries within its allowance may matter more than the split.
/// Policy::even is therefore GridViews' default.
///
/// Policy, once per frame (split()), from each view's last report:
///  - forced: the queries of drawn cells, which run past the cap anyway;
///  - optional demand: hidden re-queries issued plus those deferred;
///  - rate: the reveal rate, smoothed over frames (exponential, weight 1/4
///    for the newest), at least 1 %;
///  - if all demands fit in the total, each view gets its demand and the
///    slack is shared evenly;
///  - otherwise the total less the forced queries is split: each view first
///    gets min(optional demand, floor · that / views), the rest goes in
///    proportion to remaining optional demand × rate, capped at each one's
///    remaining demand, leftovers passed on. A view's allowance is its
///    forced queries plus its share; at least 1.
/// The allowance counts every query of the view (as grid.cap does), so it
/// is exact when the forced ones are as many as in the last frame.
/// Policy::even: total / views each, whatever was reported.
class QueryBudget {
 public:
  enum class Policy { reveal, even };

  /// Preconditions: views >= 1, total >= views, 0 <= floor <= 1.
  QueryBudget(int total, int views, double floor = 0.25, Policy policy = Policy::reveal);

  [[nodiscard]] int views() const noexcept { return int(allowance_.size()); }
  [[nodiscard]] int total() const noexcept { return total_; }
  /// This frame's cap of view `view` (0-based), >= 1. Before the first
  /// split(): an even share.
  [[nodiscard]] int allowance(int view) const { return allowance_.at(std::size_t(view)); }
  /// The smoothed share of the view's hidden re-queries that found the cell visible.
  [[nodiscard]] double reveal_rate(int view) const { return rate_.at(std::size_t(view)); }

  /// What one frame of view `view` asked: `forced` queries of cells it drew,
  /// `rechecked` queries of cells hidden by their last answer, `revealed` of
  /// those that found the cell visible, `deferred` re-queries that were due
  /// but over its allowance. Precondition: revealed <= rechecked.
  void report(int view, std::uint64_t forced, std::uint64_t rechecked, std::uint64_t revealed,
              std::uint64_t deferred);

  /// Sets every view's allowance for the next frame from the latest reports.
  void split();

 private:
  int total_;
  double floor_;
  Policy policy_;
  std::vector<int> allowance_;
  std::vector<double> rate_;
  std::vector<std::uint64_t> forced_, optional_;
};

/// One grid culler per view over one shared grid and query budget.
class GridViews {
 public:
  /// A `grid` culler per view, with `options` (grid.*; grid.cap is the
  /// total of all views, grid.split the QueryBudget's policy, reveal or
  /// even, grid.split_floor its floor).
  /// Preconditions: index.scene outlives this object; 1 <= views <= 16.
  /// Throws InputError for a bad option.
  GridViews(const SceneIndex& index, int views, const Options& options = {});
  ~GridViews();
  GridViews(const GridViews&) = delete;
  GridViews& operator=(const GridViews&) = delete;

  [[nodiscard]] int size() const noexcept { return int(views_.size()); }
  /// The culler of view `k` (0-based); render each view's frame with it.
  [[nodiscard]] Culler& view(int k) { return *views_.at(std::size_t(k)); }

  /// Call once per frame before the views render: splits the query cap
  /// from what the views' queries found.
  void begin_frame() { budget_->split(); }

  [[nodiscard]] const QueryBudget& budget() const noexcept { return *budget_; }
  [[nodiscard]] const UniformGrid& grid() const noexcept { return *grid_; }

 private:
  std::shared_ptr<UniformGrid> grid_;
  std::shared_ptr<QueryBudget> budget_;
  std::vector<std::unique_ptr<Culler>> views_;
};

}  // namespace occull
