// Internal: the decision at the heart of NOHC — is a query for this node
// reasonable? (Guthe et al. 2006, Sections 4.1–4.2, Figure 5) — as a pure function,
// so unit tests can walk its branches. The culler is in nohc.cpp.
#pragma once

#include "occull/cost_model.hpp"

#include <cstdint>
#include <span>

namespace occull::detail {

/// A node's estimates in the current view.
struct NodeEstimate {
  double t_r = 0.0;        ///< rendering time, ms
  double t_o = 0.0;        ///< query time, ms
  double p_occl = 0.0;     ///< occlusion probability
  std::uint32_t leaves = 1;  ///< N_l: leaves of its subtree
};

/// B(H) = p_occl (t_r - t_o) / levels, levels = log2(N_h + 1) by default.
[[nodiscard]] double query_benefit(const NodeEstimate& n, double levels);

struct ReasonabilityInput {
  NodeEstimate node;
  std::span<const NodeEstimate> children;  ///< empty for a leaf
  PreviousState previous = PreviousState::outside;
  std::uint32_t frames_since_query = 0;   ///< n: frames rendered without a query
  double levels = 1.0;                    ///< the benefit is spread over this many levels
  double query_overhead_ms = 0.0;         ///< T_o^o
};

/// Figure 5, with Section 4.1's rule for nodes that were outside the
/// frustum (query only if t_o + (1 - p_occl) t_r < t_r):
///  - never when rendering is cheaper than querying, or querying the
///    children is cheaper than querying the node;
///  - always when the node was occluded;
///  - for a previously visible node only when its cost is paid back by n
///    frames of benefit, C <= n B;
///  - then at this level only if a child is too cheap to query, or the node's
///    benefit exceeds its children's and querying every leaf during
///    rendering (T_o^o N_l) would cost more than this one query.
[[nodiscard]] bool query_reasonable(const ReasonabilityInput& in);

/// The occlusion probabilities of the model against what the queries found.
/// Per previous state (visible, outside; an occluded node's p_occl is 1 by
/// definition), it sums the predicted p_occl of the queried nodes and counts
/// those found occluded; scale() multiplies a prediction by their ratio.
/// Where the model overrates occlusion (open ground: coverage says a node
/// may be hidden, the query finds it visible) its queries stop paying and
/// the ratio falls, so fewer queries pass query_reasonable; where it
/// underrates it, more do. Older outcomes weigh less (sums halve past 256
/// queries); two queries' worth of prior keep the ratio at 1 until there
/// are outcomes, and it stays within [1/16, 4].
class OcclusionCalibration {
 public:
  void record(PreviousState previous, double predicted, bool occluded);
  [[nodiscard]] double ratio(PreviousState previous) const;
  /// `p` corrected by ratio(previous), within [0, 1].
  [[nodiscard]] double scale(PreviousState previous, double p) const;

 private:
  struct Sums {
    double predicted = 1.0;  // prior: two queries at p = 1/2, one of them occluded
    double occluded = 1.0;
    double queries = 2.0;
  };
  Sums sums_[3];
};

}  // namespace occull::detail
