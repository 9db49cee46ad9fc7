// occull — what the process costs the operating system, and how its heap
// allocator behaves.
//
// Page faults and kernel time are not algorithm costs, but they can swamp
// them: on Mesa llvmpipe every glFlush (and every availability poll of a
// query not yet flushed) ends a batch whose memory is freed; glibc then trims
// the heap back to the OS and the next batch faults it in again. A culler
// that flushes more often than another pays for that churn, so the lab
// counts faults and kernel time per frame, and the tools set an allocator
// policy an engine would use (no trimming of a heap it is about to reuse).
#pragma once

#include <cstdint>
#include <string>
#include <string_view>

namespace occull {

/// Resource use of the whole process (every thread, the driver's included)
/// since it started: getrusage(RUSAGE_SELF).
struct ProcessUsage {
  std::uint64_t minor_faults = 0;  ///< page faults served without I/O (memory given back and taken again)
  std::uint64_t major_faults = 0;  ///< page faults that needed I/O
  double kernel_ms = 0.0;          ///< CPU time in the kernel, milliseconds
  double user_ms = 0.0;            ///< CPU time in user space, milliseconds
};

/// The process's usage now. Never fails (zeros where the OS says nothing).
[[nodiscard]] ProcessUsage process_usage() noexcept;

/// The process's memory now.
struct MemoryUsage {
  std::uint64_t resident_bytes = 0;  ///< resident set (/proc/self/statm), bytes; 0 where unknown
  std::uint64_t heap_bytes = 0;      ///< bytes malloc has handed out and not had back (glibc mallinfo2); 0 where unknown
  /// Bytes malloc holds from the OS, in use or free (mallinfo2 arena + hblkhd,
  /// every arena); 0 where unknown. Under the engine policy this is the heap's
  /// high-water mark.
  std::uint64_t heap_held_bytes = 0;
};

/// Never fails (zeros where the OS or C library says nothing).
[[nodiscard]] MemoryUsage memory_usage() noexcept;

/// How the process's heap allocator returns memory to the OS.
enum class AllocatorPolicy {
  /// Keep freed memory for reuse, as engines do: glibc trims the heap only
  /// above 1 GiB of free top memory, and blocks up to 32 MiB come from the
  /// heap instead of their own mmap (which munmap would hand straight back).
  engine,
  /// glibc's defaults (trim above 128 KiB, a dynamic mmap threshold).
  system,
};

/// "engine" or "system". Throws InputError listing the valid names.
[[nodiscard]] AllocatorPolicy parse_allocator_policy(std::string_view name);

/// Sets the policy for the whole process (call it once, at start-up, before
/// the GL context exists) and returns a one-line description for reports.
/// Where the C library has no such controls, says so and changes nothing.
std::string apply_allocator_policy(AllocatorPolicy policy);

}  // namespace occull
