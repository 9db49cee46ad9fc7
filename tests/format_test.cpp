// The culling core's message formatting (src/core/format.hpp): what fmt's
// "{}" and "{:.Nf}" would write, without fmt.
#include "core/format.hpp"

#include <gtest/gtest.h>

#include <cstdint>
#include <string>

namespace occull {
namespace {

TEST(CoreFormat, FieldsTakeTheArgumentsInOrder) {
  EXPECT_EQ(detail::format("option {}: {} is outside [{}, {}]", std::string("chcpp.batch"), 0, 1, 1000),
            "option chcpp.batch: 0 is outside [1, 1000]");
  EXPECT_EQ(detail::format("no fields"), "no fields");
  EXPECT_EQ(detail::format("{}{}", 'a', "b"), "ab");
}

TEST(CoreFormat, NumbersAreWrittenAsFmtWritesThem) {
  EXPECT_EQ(detail::format("{}", 0.5), "0.5");
  EXPECT_EQ(detail::format("{}", 0.1f), "0.1");  // a float's shortest form, not the double's
  EXPECT_EQ(detail::format("{}", 1e-7), "1e-07");
  EXPECT_EQ(detail::format("{}", std::uint64_t(18446744073709551615u)), "18446744073709551615");
  EXPECT_EQ(detail::format("{}", -3), "-3");
  EXPECT_EQ(detail::format("{} {}", true, false), "true false");
  EXPECT_EQ(detail::format("{:.0f} cells", 2.5e9), "2500000000 cells");
  EXPECT_EQ(detail::format("{:.2f}", 1.0 / 3.0), "0.33");
}

TEST(CoreFormat, DoubledBracesWriteOneBrace) {
  EXPECT_EQ(detail::format("{{{}}}", 7), "{7}");
}

}  // namespace
}  // namespace occull
