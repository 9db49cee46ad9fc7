#include "occull/stall_guard.hpp"

#include <algorithm>
#include <chrono>
#include <thread>

namespace occull {

StallGuard::StallGuard(Backend& inner, double timeout_ms) : inner_(inner), timeout_ms_(std::max(0.0, timeout_ms)) {}

StallGuard::~StallGuard() {
  for (QueryId q : abandoned_) (void)inner_.result(q);
}

QueryId StallGuard::issue_query(std::span<const Aabb> boxes) {
  collect_abandoned();
  return inner_.issue_query(boxes);
}

std::uint64_t StallGuard::result(QueryId q) {
  if (inner_.result_available(q)) return inner_.result(q);
  // Waiting: poll until the deadline. The time between polls is this
  // backend's wait (the wrapped one only sees the polls).
  using Clock = std::chrono::steady_clock;
  const auto start = Clock::now();
  const double inner_before = inner_.stats().backend_ms;
  const auto deadline = start + std::chrono::duration<double, std::milli>(timeout_ms_);
  ++waits_;
  bool arrived = false;
  while (!arrived && Clock::now() < deadline) {
    std::this_thread::yield();
    arrived = inner_.result_available(q);
  }
  spin_ms_ += std::max(0.0, std::chrono::duration<double, std::milli>(Clock::now() - start).count() -
                                (inner_.stats().backend_ms - inner_before));
  if (arrived) return inner_.result(q);
  ++stalled_;
  abandoned_.push_back(q);
  return kStalledSamples;
}

void StallGuard::collect_abandoned() {
  std::erase_if(abandoned_, [&](QueryId q) {
    if (!inner_.result_available(q)) return false;
    (void)inner_.result(q);
    return true;
  });
}

BackendStats StallGuard::stats() const {
  BackendStats s = inner_.stats();
  s.stalled_results = stalled_;
  s.blocking_waits += waits_;
  s.wait_ms += spin_ms_;
  s.backend_ms += spin_ms_;
  return s;
}

}  // namespace occull
