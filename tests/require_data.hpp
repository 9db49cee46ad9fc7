// Tests that need data made by others (the OpenArena maps, `make data`):
// skipped where it is missing, failed under CI.
#pragma once

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string_view>

namespace occull::test {

/// Whether the tests run under CI (CI=true, as CI services set it): there a
/// test's missing data is a failure, not a reason to skip.
inline bool in_ci() {
  const char* ci = std::getenv("CI");
  return ci != nullptr && std::string_view(ci) == "true";
}

/// In a test body: when `file` (a path) is missing, skips the test — or,
/// under CI, fails it — naming the file and the command that fetches it.
#define OCCULL_REQUIRE_DATA(file)                                                                   \
  do {                                                                                              \
    if (!std::filesystem::exists(file)) {                                                           \
      if (::occull::test::in_ci())                                                                  \
        FAIL() << (file) << " missing (CI=true: data is required): run make data (scripts/fetch-data.sh)"; \
      GTEST_SKIP() << (file) << " missing: run make data (scripts/fetch-data.sh)";                  \
    }                                                                                               \
  } while (false)

}  // namespace occull::test
