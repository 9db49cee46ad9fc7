// Internal: the parts of CHC++ that unit tests check on their own — the
// visibility-persistence statistics behind p_keep, the multiquery grouping
// and the jittered first re-query. The culler itself is in chcpp.cpp.
#pragma once

#include "traversal.hpp"

#include <array>
#include <cstdint>
#include <span>
#include <vector>

namespace occull::detail {

/// Whether queries of *entering* nodes pay: nodes that were not found
/// occluded in the previous frame and were not visible either (outside the
/// frustum, or not reached). CHC queries every one; where few of them turn
/// out occluded (open ground, small maps) those queries, their waits and the
/// cascade down the hierarchy of nodes that come back visible only cost.
/// The gate learns, per subtree (region) of the BVH, the share of entering
/// nodes found occluded — from the queries of entering nodes, and from the
/// first re-query of a leaf that was drawn without one — and says to query
/// where that share is at least p_min. Recent outcomes weigh most (counts
/// are halved as they grow); a region with few outcomes leans on the global
/// share, which starts at 1/2 so a new scene begins with plain CHC++.
class EnteringGate {
 public:
  /// `regions`: how many subtrees keep their own counts; `p_min` 0 always queries.
  EnteringGate(std::size_t regions, double p_min) : regions_(regions), p_min_(p_min) {}
  /// An entering node of `region` was found occluded (or not).
  void record(std::size_t region, bool occluded);
  /// The estimated share of entering nodes of `region` found occluded.
  [[nodiscard]] double p_occluded(std::size_t region) const;
  /// Whether an entering node of `region` should be queried.
  [[nodiscard]] bool query(std::size_t region) const { return p_min_ <= 0.0 || p_occluded(region) >= p_min_; }

 private:
  struct Counts {
    double occluded = 0.0;
    double tests = 0.0;
  };
  static void add(Counts& c, bool occluded, double window);
  std::vector<Counts> regions_;
  Counts global_{4.0, 8.0};  // prior: 1/2, worth 8 outcomes
  double p_min_;
};

/// p_keep(i): the probability that a node found invisible in i consecutive
/// tests stays invisible in the next, learned from the tests so far
/// (n_i^keep / n_i^all), propagated piecewise-constantly to higher i where
/// data is missing, and 0.99 - 0.7 e^-i before there is any.
class VisibilityPersistence {
 public:
  static constexpr std::uint32_t kMaxPersistence = 63;  ///< higher i share the last bucket

  explicit VisibilityPersistence(std::uint32_t min_samples = 20) : min_samples_(min_samples) {}
  /// A node invisible for `i` tests was tested again; `kept` if still invisible.
  void record(std::uint32_t i, bool kept);
  [[nodiscard]] double p_keep(std::uint32_t i) const;
  [[nodiscard]] static double analytic(std::uint32_t i);
  [[nodiscard]] std::uint32_t samples(std::uint32_t i) const { return all_[std::min(i, kMaxPersistence)]; }

 private:
  std::uint32_t min_samples_;
  std::array<std::uint32_t, kMaxPersistence + 1> keep_{};
  std::array<std::uint32_t, kMaxPersistence + 1> all_{};
};

/// Size j of the multiquery made of the first j nodes (sorted by p_keep,
/// descending) that maximises V = j / (1 + (1 - prod p_keep) j) — or 1 when
/// no group beats V = 1, the value of querying each node alone (for
/// hopeless nodes V only creeps towards 1 as the group grows).
/// Precondition: non-empty.
std::size_t best_multiquery_size(std::span<const double> p_keep_sorted);

/// The random first re-query delay r, 0 < r < n_av, from a random number
/// (for n_av <= 1: n_av).
std::uint32_t first_requery_delay(std::uint32_t n_av, std::uint64_t random);

}  // namespace occull::detail
