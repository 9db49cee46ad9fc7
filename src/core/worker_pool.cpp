#include "core/worker_pool.hpp"

#if defined(__x86_64__) || defined(__i386__)
#include <immintrin.h>
#endif

namespace occull::detail {
namespace {

// How long a thread spins on a flag before it sleeps on it: 4,000 pauses,
// about 90 us on this machine's CPU (an AMD EPYC), several times what a
// wake-up from sleep costs. A culler's jobs come in bursts within a frame,
// and between frames the workers sleep. 500 pauses cost soc:scale=1:threads=2
// 0.9 ms of CPU a frame more on field/glide (docs/performance.md).
constexpr int kSpins = 4000;

void pause() noexcept {
#if defined(__x86_64__) || defined(__i386__)
  _mm_pause();
#endif
}

// Waits until `flag` no longer holds `value`: spinning first, then asleep.
template <class T>
T wait_while(const std::atomic<T>& flag, T value) {
  for (int i = 0; i < kSpins; ++i) {
    const T now = flag.load(std::memory_order_acquire);
    if (now != value) return now;
    pause();
  }
  for (;;) {
    flag.wait(value, std::memory_order_acquire);
    const T now = flag.load(std::memory_order_acquire);
    if (now != value) return now;
  }
}

}  // namespace

WorkerPool::WorkerPool(int workers) {
  threads_.reserve(std::size_t(workers > 0 ? workers : 0));
  for (int lane = 1; lane <= workers; ++lane) threads_.emplace_back([this, lane] { work(lane); });
}

WorkerPool::~WorkerPool() {
  stop_.store(true, std::memory_order_relaxed);
  generation_.fetch_add(1, std::memory_order_release);
  generation_.notify_all();
  for (std::thread& t : threads_) t.join();
}

void WorkerPool::run(void (*fn)(void*, int), void* job) {
  if (threads_.empty()) {
    fn(job, 0);
    return;
  }
  fn_ = fn;
  job_ = job;
  busy_.store(int(threads_.size()), std::memory_order_relaxed);
  generation_.fetch_add(1, std::memory_order_release);  // publishes fn_, job_ and busy_
  generation_.notify_all();
  fn(job, 0);
  for (int left = busy_.load(std::memory_order_acquire); left != 0; left = busy_.load(std::memory_order_acquire))
    (void)wait_while(busy_, left);
}

void WorkerPool::work(int lane) {
  std::uint32_t seen = 0;
  for (;;) {
    seen = wait_while(generation_, seen);
    if (stop_.load(std::memory_order_relaxed)) return;
    fn_(job_, lane);
    if (busy_.fetch_sub(1, std::memory_order_acq_rel) == 1) busy_.notify_one();
  }
}

}  // namespace occull::detail
