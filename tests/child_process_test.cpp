// run_in_child: whatever the work does in the child, the caller gets its
// bytes or an InputError saying how it ended, and goes on.
#include "scenes/child_process.hpp"
#include "occull/error.hpp"

#include <gtest/gtest.h>

#include <csignal>
#include <cstdlib>
#include <new>
#include <string>
#include <unistd.h>
#include <vector>

namespace occull {
namespace {

// The message of the InputError `f` throws; fails the test when it throws none.
template <class F>
std::string input_error_of(F&& f) {
  try {
    f();
  } catch (const InputError& e) {
    return e.what();
  }
  ADD_FAILURE() << "no InputError";
  return {};
}

const ChildLimits kQuick{5, 30.0, 0};

TEST(ChildProcess, ReturnsTheChildsBytesWholeEvenPastAPipesBuffer) {
  std::string expected(3 << 20, '\0');
  for (std::size_t i = 0; i < expected.size(); ++i) expected[i] = char(i * 7 + i / 251);
  EXPECT_EQ(run_in_child([&] { return expected; }, kQuick, "work"), expected);
  EXPECT_EQ(run_in_child([] { return std::string(); }, kQuick, "work"), "");
}

TEST(ChildProcess, AnInputErrorInTheChildReachesTheCallerWithItsMessage) {
  const std::string m = input_error_of(
      [] { (void)run_in_child([]() -> std::string { throw InputError("x.ply: damaged"); }, kQuick, "x.ply: import"); });
  EXPECT_EQ(m, "x.ply: damaged");
}

TEST(ChildProcess, AnotherExceptionInTheChildIsAnInputErrorNamingTheWork) {
  const std::string m = input_error_of(
      [] { (void)run_in_child([]() -> std::string { throw std::out_of_range("vector::at"); }, kQuick, "x.obj: import"); });
  EXPECT_EQ(m, "x.obj: import failed: vector::at");
}

TEST(ChildProcess, AChildThatCrashesIsAnInputErrorNamingTheSignalAndTheCallerGoesOn) {
  const std::string m = input_error_of([] {
    (void)run_in_child([]() -> std::string { std::abort(); }, kQuick, "x.off: import");
  });
  EXPECT_NE(m.find("x.off: import crashed (signal 6"), std::string::npos) << m;
  const std::string segv = input_error_of([] {
    (void)run_in_child([]() -> std::string { std::raise(SIGSEGV); return "unreached"; }, kQuick, "import");
  });
  EXPECT_NE(segv.find("crashed (signal 11"), std::string::npos) << segv;
  EXPECT_EQ(run_in_child([] { return std::string("still here"); }, kQuick, "work"), "still here");
}

TEST(ChildProcess, AChildThatNeverReturnsIsKilledAtItsWallClockLimit) {
  const ChildLimits limits{5, 0.2, 0};
  const std::string m = input_error_of([&] {
    (void)run_in_child([]() -> std::string { for (;;) ::pause(); }, limits, "x.stl: import");
  });
  EXPECT_EQ(m, "x.stl: import did not finish within 0.2 s");
}

TEST(ChildProcess, AChildThatSpinsIsStoppedAtItsCpuTimeLimit) {
  const ChildLimits limits{1, 60.0, 0};
  const std::string m = input_error_of([&] {
    (void)run_in_child([]() -> std::string { volatile unsigned long spins = 0;  // volatile: the loop is not optimised away
      for (;;) spins = spins + 1; }, limits, "import");
  });
  EXPECT_EQ(m, "import used its 1 s of CPU time");
}

TEST(ChildProcess, AChildPastItsMemoryLimitIsAnInputErrorNamingTheLimit) {
  const ChildLimits limits{5, 30.0, std::uint64_t(64) << 20};
  const std::string m = input_error_of([&] {
    (void)run_in_child([]() -> std::string {
      std::vector<char> big(std::size_t(1) << 30, 'x');
      return std::string(1, big[12345]);
    }, limits, "x.gltf: import");
  });
#if defined(__SANITIZE_ADDRESS__)
  // AddressSanitizer's allocator reports the failed mapping and ends the
  // child itself (abort or exit, by ASAN_OPTIONS).
  EXPECT_EQ(m.rfind("x.gltf: import ", 0), 0u) << m;
#else
  EXPECT_EQ(m, "x.gltf: import ran out of its 64 MiB memory limit");
#endif
}

}  // namespace
}  // namespace occull
