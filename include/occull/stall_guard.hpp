// occull — a bound on how long a culler waits for a query result.
//
// A driver that never answers a query (a lost device, a hung GPU, a bug)
// would stall the frame forever inside Backend::result(). Shipped engines
// guard against it: after a few milliseconds a pending result is taken as
// "visible", which is always safe for a conservative culler (it draws what
// the query was about), and the frame goes on.
#pragma once

#include "occull/backend.hpp"

#include <vector>

namespace occull {

/// A Backend that forwards to another and bounds result(): when the result
/// is not available within `timeout_ms` of the call, it returns
/// kStalledSamples (counted as visible by every threshold) and counts a
/// stall in BackendStats::stalled_results. The query it gave up on stays in
/// flight in the wrapped backend; later calls read and free such queries
/// once their results arrive, and the destructor reads the rest (waiting).
/// Its stats() are the wrapped backend's plus its own waits (blocking_waits,
/// wait_ms, backend_ms) and stalls.
///
/// Use it in engines (a driver that never answers costs timeout_ms per
/// query, not the frame); leave it out of conservative benchmarks, where a
/// stall answered "visible" changes what is drawn (occull bench
/// --stall-guard MS measures it). Not thread-safe, as Backend.
class StallGuard final : public Backend {
 public:
  /// Samples reported for a result given up on.
  static constexpr std::uint64_t kStalledSamples = ~std::uint64_t(0);

  /// Preconditions: `inner` outlives this object; timeout_ms >= 0 (0: any
  /// result not available at the first poll counts as stalled).
  explicit StallGuard(Backend& inner, double timeout_ms = 4.0);
  ~StallGuard() override;
  StallGuard(const StallGuard&) = delete;
  StallGuard& operator=(const StallGuard&) = delete;

  [[nodiscard]] double timeout_ms() const noexcept { return timeout_ms_; }
  /// Queries given up on whose results have not arrived yet.
  [[nodiscard]] std::size_t abandoned() const noexcept { return abandoned_.size(); }

  void render(std::span<const ObjectId> objects) override { inner_.render(objects); }
  QueryId issue_query(std::span<const Aabb> boxes) override;
  bool result_available(QueryId q) override { return inner_.result_available(q); }
  std::uint64_t result(QueryId q) override;
  [[nodiscard]] bool conditional_rendering() const override { return inner_.conditional_rendering(); }
  void render_conditional(std::span<const ObjectId> objects, QueryId q, ConditionalWait wait) override {
    inner_.render_conditional(objects, q, wait);
  }
  void flush() override { inner_.flush(); }
  [[nodiscard]] DeviceCulling* device_culling() override { return inner_.device_culling(); }
  [[nodiscard]] ResultReads result_reads() const override { return inner_.result_reads(); }
  [[nodiscard]] BackendStats stats() const override;

 private:
  void collect_abandoned();

  Backend& inner_;
  double timeout_ms_;
  std::uint64_t stalled_ = 0;
  std::uint64_t waits_ = 0;   // result() calls whose result was not available at once
  double spin_ms_ = 0.0;      // time waiting between polls, milliseconds
  std::vector<QueryId> abandoned_;
};

}  // namespace occull
