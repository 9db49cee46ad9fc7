#include "watchdog.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <cstdlib>

namespace occull::detail {

void Watchdog::exit_process(const std::string& message) {
  std::fputs(message.c_str(), stderr);
  std::fputc('\n', stderr);
  std::fflush(stderr);
  std::_Exit(1);
}

Watchdog::Watchdog(double seconds, Expiry expiry) : seconds_(seconds), expiry_(std::move(expiry)) {
  if (seconds_ > 0.0) thread_ = std::thread([this] { run(); });
}

Watchdog::~Watchdog() {
  {
    const std::lock_guard lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (thread_.joinable()) thread_.join();
}

Watchdog::Step Watchdog::step(std::string what) {
  if (seconds_ <= 0.0) return Step(nullptr);
  {
    const std::lock_guard lock(mutex_);
    armed_ = true;
    ++generation_;
    what_ = std::move(what);
    deadline_ = std::chrono::steady_clock::now() +
                std::chrono::duration_cast<std::chrono::steady_clock::duration>(std::chrono::duration<double>(seconds_));
  }
  wake_.notify_all();
  return Step(this);
}

void Watchdog::disarm() {
  const std::lock_guard lock(mutex_);
  armed_ = false;
}

void Watchdog::run() {
  std::unique_lock lock(mutex_);
  while (!stop_) {
    if (!armed_) {
      wake_.wait(lock);
      continue;
    }
    const std::uint64_t generation = generation_;
    if (wake_.wait_until(lock, deadline_, [&] { return stop_ || !armed_ || generation_ != generation; }))
      continue;
    // The same step, still armed, past its deadline.
    const std::string message = fmt::format(
        "occull: watchdog: {} has not finished after {:g} s; the GL driver or device does not return "
        "(a hung or lost device?). Stopping the run (exit 1); --watchdog SECONDS sets the limit (0: off).",
        what_, seconds_);
    armed_ = false;
    lock.unlock();
    expiry_(message);
    lock.lock();
  }
}

}  // namespace occull::detail
