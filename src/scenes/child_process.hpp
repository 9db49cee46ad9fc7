// Internal: running code we cannot trust with our process (a third-party
// importer fed files made by others) in a forked child, under limits.
//
// assimp's readers have hung, aborted the process and allocated 16 GB on
// inputs of a few hundred bytes (fuzz_model). Checks in front of assimp
// catch the forms found so far; the child catches the rest: whatever the
// code does in there, the caller gets its result or an InputError saying
// how it ended, and its own process is untouched. POSIX only (fork, pipes,
// setrlimit).
#pragma once

#include <cstdint>
#include <functional>
#include <string>
#include <string_view>

namespace occull {

/// What the child may use.
struct ChildLimits {
  unsigned cpu_seconds = 60;       ///< CPU time (RLIMIT_CPU), seconds, >= 1
  double wall_seconds = 120.0;     ///< wall-clock time before the parent kills it, seconds, > 0
  std::uint64_t memory_bytes = 0;  ///< address space it may add to what it inherits (RLIMIT_AS), bytes; 0: no limit
};

/// How a child that gave no result ended, for a message: "did not finish
/// within 120 s", "used its 60 s of CPU time", "crashed (signal 11,
/// Segmentation fault)", "ended with exit status 3". `wait_status` is what
/// waitpid reported; `killed_for_time` says the parent killed it at
/// limits.wall_seconds.
[[nodiscard]] std::string describe_child_end(int wait_status, bool killed_for_time, const ChildLimits& limits);

/// Runs `work` in a forked child under `limits` and returns the bytes it
/// returned, copied through a pipe. Throws InputError:
/// - with the child's own message when `work` threw InputError there;
/// - "WHAT ran out of the N MiB memory limit" when it threw std::bad_alloc;
/// - "WHAT failed: MESSAGE" for any other exception;
/// - "WHAT " + describe_child_end(...) when it crashed, hung or passed a
///   limit, e.g. "PATH: assimp's import did not finish within 120 s".
/// Throws std::runtime_error when the child cannot be started (fork, pipe).
/// Preconditions: `work` must not rely on other threads of this process
/// (the child has only the calling one) or on the caller's open files.
/// The child ends with _exit: no destructors or atexit handlers of the
/// parent's objects run there.
[[nodiscard]] std::string run_in_child(const std::function<std::string()>& work, const ChildLimits& limits,
                                       std::string_view what);

}  // namespace occull
