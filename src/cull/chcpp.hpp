// Internal: the parts of CHC++ that unit tests check on their own — the
// visibility-persistence statistics behind p_keep, the multiquery grouping
// and the jittered first re-query. The culler itself is in chcpp.cpp.
#pragma once

#include "traversal.hpp"

#include <array>
#include <cstdint>
#include <span>

namespace occull::detail {

struct ChcppConfig {
  std::uint32_t batch = 50;       ///< b: i-queue nodes per query batch
  bool v_queue = true;            ///< defer visible-leaf queries to fill idle time
  bool multiquery = true;         ///< group i-queue nodes into multiqueries
  bool jitter = true;             ///< randomise the first re-query of a newly visible leaf
  std::uint32_t n_av = 6;         ///< frames between queries of a visible leaf
  QueryShape shape{true, 3, 1.4f};
  CommonOptions common{0, 1500};  ///< threshold 0; virtual leaves up to 1500 triangles
  std::uint32_t leaf_objects = 0; ///< ... and at most this many objects (0: any number)
  std::uint32_t pkeep_min_samples = 20;  ///< tests at one i before the measured p_keep(i) is used
  std::uint64_t seed = 1;                ///< of the jitter
  bool flush_batches = true;             ///< Backend::flush() after each query batch
  std::uint64_t render_batch_triangles = 20000;  ///< hand the render queue over at this size (0: only before queries)
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
