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

/// Splits a per-frame query cap between views. The thesis leaves this open;
/// an even split starves a view that looks at many cells and gives a view
/// that sees everything (whose queries never cull) queries it cannot use.
///
/// Policy, once per frame (split()):
///  - demand of a view: the queries it issued plus those its cap deferred,
///    in the last frame it reported;
///  - benefit of a view: the share of its queries that found a cell hidden,
///    smoothed over frames (exponential, weight 1/4 for the newest), at
///    least 1 %; a hidden cell is what a query buys;
///  - if the demands fit in the total, each view gets its demand and the
///    slack is shared evenly;
///  - otherwise each view first gets min(demand, floor · total / views),
///    and the rest goes to the views in proportion to demand × benefit,
///    capped at each one's remaining demand, leftovers passed on.
/// Every allowance is at least 1. Views visible by their last answer are
/// queried past their allowance anyway (the grid culler's blinking fix), so
/// an allowance bounds the re-queries of hidden and new cells.
class QueryBudget {
 public:
  /// Preconditions: views >= 1, total >= views, 0 <= floor <= 1.
  QueryBudget(int total, int views, double floor = 0.25);

  [[nodiscard]] int views() const noexcept { return int(allowance_.size()); }
  [[nodiscard]] int total() const noexcept { return total_; }
  /// This frame's cap of view `view` (0-based), >= 1. Before the first
  /// split(): an even share.
  [[nodiscard]] int allowance(int view) const { return allowance_.at(std::size_t(view)); }
  /// The smoothed share of the view's queries that found a cell hidden.
  [[nodiscard]] double benefit(int view) const { return benefit_.at(std::size_t(view)); }

  /// What the queries of one frame of view `view` found: `issued` queries,
  /// `hidden` of them with no samples (the cell was culled), `deferred`
  /// queries that were due but over its allowance. Precondition: hidden <= issued.
  void report(int view, std::uint64_t issued, std::uint64_t hidden, std::uint64_t deferred);

  /// Sets every view's allowance for the next frame from the latest reports.
  void split();

 private:
  int total_;
  double floor_;
  std::vector<int> allowance_;
  std::vector<double> benefit_;
  std::vector<std::uint64_t> demand_;
};

/// One grid culler per view over one shared grid and query budget.
class GridViews {
 public:
  /// A `grid` culler per view, with `options` (grid.*; grid.cap is the
  /// total of all views, grid.split_floor the QueryBudget's floor).
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
