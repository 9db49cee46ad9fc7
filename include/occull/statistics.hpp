// occull — summary statistics of a series of measurements (frame times,
// calibration rounds, upkeep timings): the one definition of median and p95
// the library, the lab and the tool share.
#pragma once

#include <vector>

namespace occull {

/// A series in a few figures, in the series' unit. All 0 for an empty one.
struct Summary {
  double mean = 0.0;
  double median = 0.0;  ///< the middle value; the mean of the two middle ones for an even count
  double p95 = 0.0;     ///< nearest-rank 95th percentile: the smallest value at least 95 % of the series reach
  double min = 0.0;
  double max = 0.0;
};

[[nodiscard]] Summary summarize(std::vector<double> values);

}  // namespace occull
