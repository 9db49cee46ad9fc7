// Internal: the adaptive culler's schedule, as a class tests can drive
// frame by frame (the culler is in auto.cpp).
#pragma once

#include "occull/configs.hpp"

#include <cstdint>
#include <string>
#include <vector>

namespace occull::detail {

/// Which candidate runs each frame, from the measured cost of the frames
/// run so far (any unit, the same for every frame; auto passes
/// milliseconds per unit of frame content).
///
/// Start: the first frame runs candidate 0 and is not counted (a temporal
/// culler starts cold; no_cold_frame() says candidate 0 does not, and its
/// try begins there); then each candidate is tried in order, and the
/// cheapest is kept ("the current"). So with fixed costs the schedule runs
/// the cheapest from frame 1 + trial x candidates on (trial x candidates
/// after no_cold_frame()).
///
/// A try of a challenger runs `trial` frames, or fewer when every one
/// costs more than `cut` x the current's: one, when that frame is within
/// twice the candidate's last measured cost (a loser tried again) or above
/// 8 x the current's (in the start's round: the cheapest measured), else
/// two. No try costs more than `trial` frames of a loser. Its cost is the
/// mean of its frames but spikes: a frame above twice the try's lowest is
/// the machine's (a page fault storm, a descheduled driver thread: measured
/// on llvmpipe, 4-5 ms frames among 1 ms ones, most in a run's first
/// frames), not the candidate's. The current's
/// running cost takes each frame at most at twice its value. A try is
/// skipped (no loss: see below) while the challenger's estimate (estimate();
/// auto gives one for vfc, whose frame is predictable: it draws the
/// frustum) exceeds `skip` x the current's; an estimate of this frame's
/// view below (1 - margin) x the current's cost of the same frame (and its
/// running cost) takes over without a try (such an estimate errs high:
/// below the current's cost by the margin, the candidate is cheaper). The
/// challenger takes over when
/// its try's cost is below (1 - margin) x the current's running cost; two
/// candidates of equal cost therefore do not alternate. A challenger that
/// loses waits period frames for its next try, twice as long after each
/// further loss, up to 16 x period; a try that cost more than `cut` x the
/// current's (in the start's round too) counts as three losses (4 x period
/// at least). A try skipped as hopeless is no loss: the estimate is checked
/// again every frame, at no cost, and the try runs once it is not.
///
/// The budget of tries. After the start's round a try is paid from a
/// credit, in milliseconds of frame time (finished()'s `ms`): every measured
/// frame adds budget / 2 x its time, up to budget / 2 x 1000 ms; every
/// frame of a try takes what it cost above the current's predicted cost of
/// it (the current's cost x this frame's content). A due try starts only
/// when the credit covers what its first frame is expected to cost above
/// the current's (the candidate's last measured cost, or cut x the
/// current's when never measured), and ends when the credit runs out. So
/// over any run of frames the tries spend at most budget / 2 x 1000 ms +
/// budget / 2 x their time: at most `budget` of any second's frame time,
/// but for the error of the last frame's expectation. The start's round is
/// outside it (every candidate is tried once: trial frames each at most).
/// So after the costs change, a challenger that became cheaper is kept
/// within trial + 16 x period frames once the credit covers its try: a try
/// expected to cost E ms above the current's waits at most E / (budget / 2
/// x the frame's ms) frames for it, and never where E is above the cap.
class AutoSchedule {
 public:
  AutoSchedule(AutoConfig config, std::size_t candidates);

  /// The candidate to run in the next frame.
  [[nodiscard]] std::size_t next() const noexcept { return running_; }
  /// Whether next() runs the first frame of a try (the start's round
  /// included: every candidate's first measured frame).
  [[nodiscard]] bool starts_try() const noexcept { return in_trial_ && !cold_ && trial_frame_ == 0 && !restarted_; }
  /// Whether the last finished() made a challenger the current.
  [[nodiscard]] bool just_switched() const noexcept { return switched_; }
  /// Reports the cost of the frame just run by next() and chooses the next
  /// frame's candidate. `ms`: the frame's time, ms (the budget's unit);
  /// without it the cost is taken as the frame's time.
  void finished(double cost, double ms);
  void finished(double cost) { finished(cost, cost); }
  /// The frame just run by next() is not a measure (it followed a camera
  /// cut: every temporal culler starts over there): it is not counted; a try
  /// in progress goes on and is judged on its measured frames.
  void unmeasured();
  /// The first frame's candidate keeps no state across frames (soc, vfc):
  /// its first frame is measured like any other, the first of its try.
  /// Call before the first finished(); after disable() of the first.
  void no_cold_frame();
  /// Never runs candidate `c` again (it cannot run here: hiz on a backend
  /// without device culling). Precondition: some other candidate remains.
  void disable(std::size_t c);
  /// Candidate `c`'s first frame may hold one-off costs (hiz: the device's
  /// buffers made, its programs compiled by the driver; docs/performance.md
  /// has the figures): until it was measured once, one frame above 8 x the
  /// reference does not end its try.
  void starts_up(std::size_t c);
  /// An estimate of candidate `c`'s cost of the frame finished() counts
  /// next, in finished()'s unit (0: none). `of_this_view`: made from this
  /// frame's view (it may then switch to `c` when below (1 - margin) x both
  /// the current's running cost and its cost of this frame; otherwise, or
  /// later, it only skips tries). Precondition: an estimate of this view
  /// errs high, if at all.
  void estimate(std::size_t c, double cost, bool of_this_view);

  [[nodiscard]] std::size_t current() const noexcept { return current_; }  ///< the one kept between tries
  [[nodiscard]] std::uint64_t switches() const noexcept { return switches_; }
  [[nodiscard]] std::uint64_t tries() const noexcept { return tries_; }     ///< tries of challengers run
  [[nodiscard]] double cost(std::size_t c) const { return cost_[c]; }      ///< 0 until measured
  /// What the tries spent above the current's predicted cost since the
  /// start's round, ms.
  [[nodiscard]] double spent_ms() const noexcept { return spent_ms_; }

 private:
  void start_trial(std::size_t c);
  void end_trial();  // a try that cost more than cut x the current's lost by far
  [[nodiscard]] double try_cost() const;  // the mean of the try's frames, spikes left out
  void after_initial(std::size_t c);  // the try of candidate c in the initial round ended
  void choose_next();
  void take_over(std::size_t c, double cost);  // c becomes the current, at this cost
  // the candidate estimated for this frame below `than` x (1 - margin), or count_
  [[nodiscard]] std::size_t estimated_cheaper(double than) const;
  void lost(std::size_t c, std::uint32_t by = 1);  // c lost a try: its next comes later
  [[nodiscard]] double reference(std::size_t c) const;  // the cost a try of c is measured against
  [[nodiscard]] bool hopeless(std::size_t c) const;  // its estimate skips its try
  [[nodiscard]] bool affordable(std::size_t c) const;  // the credit covers its try's first frame
  double pay(double cost, double ms);  // the budget after a measured frame; returns a try frame's excess, ms
  [[nodiscard]] double cap_ms() const;  // the most credit there is

  AutoConfig config_;
  std::size_t count_;
  std::vector<double> cost_;       // running cost of the current one; last try's mean of the others
  std::vector<double> estimate_;   // 0: none
  std::vector<std::uint64_t> estimated_in_;  // the frame whose measure the estimate came with
  std::vector<std::uint32_t> losses_;
  std::vector<std::uint64_t> next_try_;
  std::vector<bool> disabled_;
  std::vector<bool> starts_up_;    // see starts_up()
  std::vector<double> samples_;    // the try's frames
  std::size_t current_ = 0;
  std::size_t running_ = 0;
  bool in_trial_ = true;
  bool initial_ = true;            // the first round: every candidate once
  bool cold_ = true;               // the very first frame: not counted
  bool switched_ = false;
  bool restarted_ = false;         // the try in progress ran its first frame, unmeasured
  int trial_frame_ = 0;
  std::uint64_t frame_ = 0;
  std::uint64_t switches_ = 0;
  std::uint64_t tries_ = 0;
  double credit_ms_ = 0.0;         // the budget's credit (see the class comment)
  double spent_ms_ = 0.0;
  double ms_per_cost_ = 0.0;       // the last measured frame's ms per unit of cost (its content)
};

}  // namespace occull::detail
