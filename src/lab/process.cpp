#include "occull/process.hpp"

#include "occull/error.hpp"

#include <fmt/format.h>

#include <cstdio>

#include <sys/resource.h>
#include <unistd.h>

#if defined(__GLIBC__)
#include <malloc.h>
#endif

namespace occull {
namespace {

double to_ms(const timeval& t) { return double(t.tv_sec) * 1e3 + double(t.tv_usec) * 1e-3; }

}  // namespace

ProcessUsage process_usage() noexcept {
  rusage u{};
  if (getrusage(RUSAGE_SELF, &u) != 0) return {};
  return {std::uint64_t(u.ru_minflt), std::uint64_t(u.ru_majflt), to_ms(u.ru_stime), to_ms(u.ru_utime)};
}

MemoryUsage memory_usage() noexcept {
  MemoryUsage m;
  if (std::FILE* f = std::fopen("/proc/self/statm", "r")) {
    unsigned long long size = 0, resident = 0;
    if (std::fscanf(f, "%llu %llu", &size, &resident) == 2)
      m.resident_bytes = std::uint64_t(resident) * std::uint64_t(sysconf(_SC_PAGESIZE));
    std::fclose(f);
  }
#if defined(__GLIBC__) && (__GLIBC__ > 2 || __GLIBC_MINOR__ >= 33)
  const struct mallinfo2 mi = mallinfo2();
  m.heap_bytes = std::uint64_t(mi.uordblks) + std::uint64_t(mi.hblkhd);
  m.heap_held_bytes = std::uint64_t(mi.arena) + std::uint64_t(mi.hblkhd);
#endif
  return m;
}

AllocatorPolicy parse_allocator_policy(std::string_view name) {
  if (name == "engine") return AllocatorPolicy::engine;
  if (name == "system") return AllocatorPolicy::system;
  throw InputError(fmt::format("unknown allocator policy '{}'; valid policies: engine, system", name));
}

std::string apply_allocator_policy(AllocatorPolicy policy) {
  if (policy == AllocatorPolicy::system) return "system (the C library's defaults; --malloc system)";
#if defined(__GLIBC__)
  constexpr int kTrim = 1 << 30;      // 1 GiB of free memory at the top before trimming
  constexpr int kMmap = 32 << 20;     // glibc's largest allowed mmap threshold on 64-bit
  const bool ok = mallopt(M_TRIM_THRESHOLD, kTrim) == 1 && mallopt(M_MMAP_THRESHOLD, kMmap) == 1;
  if (!ok) return "system (glibc refused the engine policy's mallopt settings)";
  return "engine (glibc keeps freed memory: trim threshold 1 GiB, mmap threshold 32 MiB; --malloc system "
         "for glibc's defaults)";
#else
  return "system (no allocator controls in this C library)";
#endif
}

}  // namespace occull
