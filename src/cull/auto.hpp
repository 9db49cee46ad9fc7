// Internal: the adaptive culler's schedule, as a class tests can drive
// frame by frame (the culler is in auto.cpp).
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace occull::detail {

struct AutoConfig {
  // Tried in this order at the start: chcpp first, so that a candidate far
  // worse than it (vfc in a dense city) is dropped after one frame.
  std::string candidates = "chcpp+vfc+nohc";  ///< joined by +
  int trial = 2;          ///< frames a candidate runs when tried (its cost: their median)
  int period = 50;        ///< frames between tries of a challenger
  double margin = 0.15;   ///< a challenger must be this much cheaper to take over (hysteresis)
  double smoothing = 0.15;  ///< weight of the newest frame in the running cost of the current culler
};

/// Which candidate runs each frame, from the measured cost of the frames
/// run so far. Starts by trying each candidate in order; then keeps the
/// cheapest, tries another one every `period` frames for `trial` frames and
/// switches when it was cheaper by `margin`. A try whose frame costs more
/// than twice the best known cost ends after that frame. A challenger that loses waits
/// twice as long before its next try (up to 16 periods), so a candidate
/// that never pays costs almost nothing to keep watching.
class AutoSchedule {
 public:
  AutoSchedule(AutoConfig config, std::size_t candidates);

  /// The candidate to run in the next frame.
  [[nodiscard]] std::size_t next() const noexcept { return running_; }
  /// Reports the cost of the frame just run by next() (any unit, the same
  /// for every frame: auto passes milliseconds per unit of frame content)
  /// and chooses the next frame's candidate.
  void finished(double cost_ms);

  [[nodiscard]] std::size_t current() const noexcept { return current_; }  ///< the one kept between tries
  [[nodiscard]] std::uint64_t switches() const noexcept { return switches_; }
  [[nodiscard]] double cost(std::size_t c) const { return cost_[c]; }      ///< 0 until measured

 private:
  void start_trial(std::size_t c);
  void end_trial();

  AutoConfig config_;
  std::size_t count_;
  std::vector<double> cost_;       // running cost of the current one; last trial's median of others
  std::vector<std::uint32_t> losses_;
  std::vector<std::uint64_t> next_try_;
  std::vector<double> samples_;    // the trial's counted frames
  std::size_t current_ = 0;
  std::size_t running_ = 0;
  bool in_trial_ = true;
  bool initial_ = true;            // trying every candidate once at the start
  int trial_frame_ = 0;
  std::uint64_t frame_ = 0;
  std::uint64_t switches_ = 0;
};

}  // namespace occull::detail
