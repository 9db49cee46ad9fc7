// Internal to the renderers (occull_gl, occull_vk): wall time of a scope,
// added to a BackendStats counter (backend_ms, wait_ms).
#pragma once

#include <chrono>

namespace occull::render {

using Clock = std::chrono::steady_clock;

inline double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

/// Adds the wall time of the enclosing scope to `sink`, milliseconds.
class ScopedTimer {
 public:
  explicit ScopedTimer(double& sink) : sink_(sink), t0_(Clock::now()) {}
  ~ScopedTimer() { sink_ += ms_since(t0_); }
  ScopedTimer(const ScopedTimer&) = delete;
  ScopedTimer& operator=(const ScopedTimer&) = delete;

 private:
  double& sink_;
  Clock::time_point t0_;
};

}  // namespace occull::render
