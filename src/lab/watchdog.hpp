// Internal: the lab's bound on its own waits. A GL call that never
// returns (a hung device or driver) cannot be interrupted, so when a step
// runs past its time the watchdog says which step hung and ends the
// process (exit 1) rather than leaving a benchmark hanging forever.
#pragma once

#include <chrono>
#include <condition_variable>
#include <functional>
#include <mutex>
#include <string>
#include <thread>

namespace occull::detail {

class Watchdog {
 public:
  /// What happens when a step runs past its time: given the message.
  using Expiry = std::function<void(const std::string& message)>;
  /// The default expiry: the message on stderr, then exit 1 (std::_Exit:
  /// the thread of the hung call cannot be unwound).
  static void exit_process(const std::string& message);

  /// seconds: the time of each step; 0 turns the watchdog off.
  explicit Watchdog(double seconds, Expiry expiry = &Watchdog::exit_process);
  ~Watchdog();
  Watchdog(const Watchdog&) = delete;
  Watchdog& operator=(const Watchdog&) = delete;

  /// Arms the watchdog for one step until the returned object goes.
  class Step {
   public:
    explicit Step(Watchdog* dog) : dog_(dog) {}
    ~Step() {
      if (dog_) dog_->disarm();
    }
    Step(const Step&) = delete;
    Step& operator=(const Step&) = delete;

   private:
    Watchdog* dog_;
  };
  /// `what` names the step in the message ("frame 12 of chcpp").
  [[nodiscard]] Step step(std::string what);

  [[nodiscard]] double seconds() const noexcept { return seconds_; }

 private:
  void disarm();
  void run();

  double seconds_;
  Expiry expiry_;
  std::mutex mutex_;
  std::condition_variable wake_;
  bool armed_ = false;
  bool stop_ = false;
  std::uint64_t generation_ = 0;  // steps armed so far
  std::string what_;
  std::chrono::steady_clock::time_point deadline_;
  std::thread thread_;
};

}  // namespace occull::detail
