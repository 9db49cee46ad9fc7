// The culling core's message formatting (src/core/format.hpp): what fmt's
// "{}" and "{:.Nf}" would write, without fmt.
#include "core/format.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <random>
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
  EXPECT_EQ(detail::format("{}", 1e-5), "1e-05");
  EXPECT_EQ(detail::format("{}", 1e-4), "0.0001");
  EXPECT_EQ(detail::format("{}", 1e9), "1000000000");  // fixed below 1e16, as fmt
  EXPECT_EQ(detail::format("{}", 1e15), "1000000000000000");
  EXPECT_EQ(detail::format("{}", 1e16), "1e+16");
  EXPECT_EQ(detail::format("{}", 1.5e16f), "1.5e+16");
  EXPECT_EQ(detail::format("{}", 123456789.0f), "123456790");  // a float's shortest digits
  EXPECT_EQ(detail::format("{}", -0.0), "-0");
  EXPECT_EQ(detail::format("{}", 0.0), "0");
  EXPECT_EQ(detail::format("{}", std::uint64_t(18446744073709551615u)), "18446744073709551615");
  EXPECT_EQ(detail::format("{}", -3), "-3");
  EXPECT_EQ(detail::format("{} {}", true, false), "true false");
  EXPECT_EQ(detail::format("{:.0f} cells", 2.5e9), "2500000000 cells");
  EXPECT_EQ(detail::format("{:.2f}", 1.0 / 3.0), "0.33");
}

// The core's messages and `occull algos`' ranges read as they did when fmt wrote them.
TEST(CoreFormat, NumbersOfEveryMagnitudeReadAsFmtWritesThem) {
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> mantissa(-10.0, 10.0);
  std::uniform_int_distribution<int> exponent(-30, 30);
  int compared = 0;
  for (int i = 0; i < 20000; ++i) {
    const double d = mantissa(rng) * std::pow(10.0, exponent(rng));
    const float f = float(d);
    const double whole = std::round(d);
    ASSERT_EQ(detail::format("{}", d), fmt::format("{}", d)) << i;
    ASSERT_EQ(detail::format("{}", f), fmt::format("{}", f)) << i;
    ASSERT_EQ(detail::format("{}", whole), fmt::format("{}", whole)) << i;
    compared += 3;
  }
  for (const double special : {0.0, -0.0, 1.0, 1e16, 1e-5, std::numeric_limits<double>::infinity(),
                               std::numeric_limits<double>::max(), std::numeric_limits<double>::denorm_min()})
    EXPECT_EQ(detail::format("{}", special), fmt::format("{}", special));
  EXPECT_EQ(compared, 60000);
}

TEST(CoreFormat, DoubledBracesWriteOneBrace) {
  EXPECT_EQ(detail::format("{{{}}}", 7), "{7}");
}

}  // namespace
}  // namespace occull
