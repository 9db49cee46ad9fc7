// What the instrument reports of the operating system: page faults are
// counted, and the allocator policy names are checked.
#include "occull/error.hpp"
#include "occull/process.hpp"

#include <gtest/gtest.h>

#include <sys/mman.h>

namespace {

TEST(ProcessUsage, TouchingFreshPagesCountsAsPageFaults) {
  constexpr std::size_t kPages = 256;
  constexpr std::size_t kPage = 4096;
  void* p = mmap(nullptr, kPages * kPage, PROT_READ | PROT_WRITE, MAP_PRIVATE | MAP_ANONYMOUS, -1, 0);
  ASSERT_NE(p, MAP_FAILED);
  const occull::ProcessUsage before = occull::process_usage();
  auto* bytes = static_cast<volatile unsigned char*>(p);
  for (std::size_t i = 0; i < kPages; ++i) bytes[i * kPage] = 1;
  const occull::ProcessUsage after = occull::process_usage();
  munmap(p, kPages * kPage);
  // Each first write to an anonymous page faults (a huge page could serve
  // many at once, so ask for at least one, not for 256).
  EXPECT_GE(after.minor_faults + after.major_faults, before.minor_faults + before.major_faults + 1);
  EXPECT_GE(after.kernel_ms, before.kernel_ms);
}

TEST(AllocatorPolicy, UnknownNameListsTheValidOnes) {
  EXPECT_EQ(occull::parse_allocator_policy("engine"), occull::AllocatorPolicy::engine);
  EXPECT_EQ(occull::parse_allocator_policy("system"), occull::AllocatorPolicy::system);
  try {
    (void)occull::parse_allocator_policy("jemalloc");
    FAIL() << "accepted an unknown policy";
  } catch (const occull::InputError& e) {
    EXPECT_NE(std::string(e.what()).find("engine, system"), std::string::npos) << e.what();
  }
}

TEST(AllocatorPolicy, SystemChangesNothingAndSaysSo) {
  EXPECT_NE(occull::apply_allocator_policy(occull::AllocatorPolicy::system).find("system"), std::string::npos);
}

}  // namespace
