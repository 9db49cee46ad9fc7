// Running untrusted work in a forked child: see child_process.hpp.
#include "child_process.hpp"

#include "occull/error.hpp"

#include <fmt/format.h>

#include <cerrno>
#include <chrono>
#include <csignal>
#include <cstring>
#include <fstream>
#include <new>
#include <stdexcept>

#include <fcntl.h>
#include <poll.h>
#include <sys/resource.h>
#include <sys/wait.h>
#include <unistd.h>

namespace occull {
namespace {

// The first byte the child writes says what the rest is.
constexpr char kResult = 'r';       // work's bytes
constexpr char kInputError = 'i';   // InputError's message
constexpr char kOutOfMemory = 'm';  // std::bad_alloc
constexpr char kOtherError = 'x';   // another exception's message

void write_all(int fd, const char* data, std::size_t size) noexcept {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return;  // the parent gave up on us; it reports why
    }
    data += n;
    size -= std::size_t(n);
  }
}

// The process's address space now (VmSize), bytes; 0 where unknown.
std::uint64_t address_space_bytes() {
  std::ifstream statm("/proc/self/statm");
  std::uint64_t pages = 0;
  statm >> pages;
  return pages * std::uint64_t(::sysconf(_SC_PAGESIZE));
}

[[noreturn]] void child_main(int fd, const std::function<std::string()>& work, const ChildLimits& limits) {
  // A crash ends the child and the parent reports it; handlers inherited
  // from the parent (a fuzzer's, a sanitizer's) would report it as a crash
  // of the parent's own.
  for (int s : {SIGSEGV, SIGBUS, SIGABRT, SIGILL, SIGFPE, SIGTRAP, SIGXCPU, SIGPIPE}) std::signal(s, SIG_DFL);
  const rlimit cpu{rlim_t(limits.cpu_seconds), rlim_t(limits.cpu_seconds) + 1};
  ::setrlimit(RLIMIT_CPU, &cpu);
  if (limits.memory_bytes > 0) {
    const rlim_t as = rlim_t(address_space_bytes() + limits.memory_bytes);
    const rlimit memory{as, as};
    ::setrlimit(RLIMIT_AS, &memory);
  }
  char tag = kResult;
  std::string bytes;
  try {
    bytes = work();
  } catch (const InputError& e) {
    tag = kInputError;
    bytes = e.what();
  } catch (const std::bad_alloc&) {
    tag = kOutOfMemory;
    bytes.clear();
  } catch (const std::exception& e) {
    tag = kOtherError;
    bytes = e.what();
  } catch (...) {
    tag = kOtherError;
    bytes = "an exception of unknown type";
  }
  write_all(fd, &tag, 1);
  write_all(fd, bytes.data(), bytes.size());
  ::_exit(0);
}

std::string mib(std::uint64_t bytes) { return fmt::format("{} MiB", bytes >> 20); }

}  // namespace

std::string describe_child_end(int wait_status, bool killed_for_time, const ChildLimits& limits) {
  if (killed_for_time) return fmt::format("did not finish within {:g} s", limits.wall_seconds);
  if (WIFSIGNALED(wait_status)) {
    const int s = WTERMSIG(wait_status);
    if (s == SIGXCPU) return fmt::format("used its {} s of CPU time", limits.cpu_seconds);
    if (s == SIGKILL)
      return fmt::format("was killed (signal {}): past its {} s of CPU time, or the system ran out of memory", s,
                         limits.cpu_seconds);
    return fmt::format("crashed (signal {}, {})", s, ::strsignal(s));
  }
  if (WIFEXITED(wait_status)) return fmt::format("ended with exit status {} and no result", WEXITSTATUS(wait_status));
  return fmt::format("ended with wait status {:#x} and no result", unsigned(wait_status));
}

std::string run_in_child(const std::function<std::string()>& work, const ChildLimits& limits, std::string_view what) {
  int fds[2];
  if (::pipe2(fds, O_CLOEXEC) != 0) throw std::runtime_error(fmt::format("pipe: {}", std::strerror(errno)));
  const pid_t pid = ::fork();
  if (pid < 0) {
    const int e = errno;
    ::close(fds[0]);
    ::close(fds[1]);
    throw std::runtime_error(fmt::format("fork: {}", std::strerror(e)));
  }
  if (pid == 0) {
    ::close(fds[0]);
    child_main(fds[1], work, limits);
  }
  ::close(fds[1]);

  using Clock = std::chrono::steady_clock;
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(limits.wall_seconds));
  std::string out;
  bool killed_for_time = false;
  char buffer[1 << 16];
  for (;;) {
    const auto left = std::chrono::ceil<std::chrono::milliseconds>(deadline - Clock::now()).count();
    if (left <= 0) {
      ::kill(pid, SIGKILL);
      killed_for_time = true;
      break;
    }
    pollfd p{fds[0], POLLIN, 0};
    const int ready = ::poll(&p, 1, int(std::min<long long>(left, 1000)));
    if (ready < 0 && errno != EINTR) break;
    if (ready <= 0) continue;
    const ssize_t n = ::read(fds[0], buffer, sizeof buffer);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;  // end of file: the child is done (or gone)
    out.append(buffer, std::size_t(n));
  }
  ::close(fds[0]);
  int status = 0;
  while (::waitpid(pid, &status, 0) < 0 && errno == EINTR) {
  }

  if (!killed_for_time && WIFEXITED(status) && WEXITSTATUS(status) == 0 && !out.empty()) {
    const char tag = out[0];
    out.erase(0, 1);
    switch (tag) {
      case kResult: return out;
      case kInputError: throw InputError(out);
      case kOutOfMemory:
        throw InputError(limits.memory_bytes > 0
                             ? fmt::format("{} ran out of its {} memory limit", what, mib(limits.memory_bytes))
                             : fmt::format("{} ran out of memory", what));
      default: throw InputError(fmt::format("{} failed: {}", what, out));
    }
  }
  throw InputError(fmt::format("{} {}", what, describe_child_end(status, killed_for_time, limits)));
}

}  // namespace occull
