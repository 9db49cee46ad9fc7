// The one median and p95 of the library, the lab and the tool.
#include "occull/statistics.hpp"

#include <gtest/gtest.h>

#include <vector>

namespace occull {
namespace {

TEST(Summarize, MeanMedianPercentileMinMax) {
  std::vector<double> v;
  for (int i = 100; i >= 1; --i) v.push_back(i);  // unsorted
  const Summary s = summarize(v);
  EXPECT_DOUBLE_EQ(s.mean, 50.5);
  EXPECT_DOUBLE_EQ(s.median, 50.5);  // even count: the mean of the middle two
  EXPECT_DOUBLE_EQ(s.p95, 95.0);     // nearest rank
  EXPECT_DOUBLE_EQ(s.min, 1.0);
  EXPECT_DOUBLE_EQ(s.max, 100.0);
}

TEST(Summarize, AnOddCountsMedianIsItsMiddleValueAndAnEmptySeriesIsZero) {
  const Summary s = summarize({3.0, 1.0, 2.0});
  EXPECT_DOUBLE_EQ(s.median, 2.0);
  EXPECT_DOUBLE_EQ(s.p95, 3.0);
  const Summary none = summarize({});
  EXPECT_DOUBLE_EQ(none.median, 0.0);
  EXPECT_DOUBLE_EQ(none.max, 0.0);
}

}  // namespace
}  // namespace occull
