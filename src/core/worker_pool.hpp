// occull — a few threads that one owner (an occlusion buffer, for its
// culler) runs a job on, all lanes at once: lane 0 on the caller's thread,
// lanes 1..workers on the pool's. No global state: each owner makes its own.
#pragma once

#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

namespace occull::detail {

class WorkerPool {
 public:
  /// Starts `workers` threads (0: none; run() then calls the job on the
  /// caller's thread alone).
  explicit WorkerPool(int workers);
  /// Stops and joins the threads. Precondition: no run() in progress.
  ~WorkerPool();
  WorkerPool(const WorkerPool&) = delete;
  WorkerPool& operator=(const WorkerPool&) = delete;

  /// Lanes a job runs on: the workers and the caller.
  [[nodiscard]] int lanes() const noexcept { return int(threads_.size()) + 1; }

  /// Calls job(lane) once for each lane in [0, lanes()), lane 0 on the
  /// calling thread, and returns when every call has returned; what the
  /// calls wrote is then visible to the caller. `job` must not throw. Not
  /// reentrant, one caller at a time.
  template <class Job>
  void run(Job& job) {
    run(&call<Job>, &job);
  }

 private:
  template <class Job>
  static void call(void* job, int lane) {
    (*static_cast<Job*>(job))(lane);
  }
  void run(void (*fn)(void*, int), void* job);
  void work(int lane);

  std::vector<std::thread> threads_;
  void (*fn_)(void*, int) = nullptr;  // the job of the current run, written before generation_ moves
  void* job_ = nullptr;
  std::atomic<std::uint32_t> generation_{0};  // one step a run
  std::atomic<int> busy_{0};                  // workers still in the current run
  std::atomic<bool> stop_{false};
};

}  // namespace occull::detail
