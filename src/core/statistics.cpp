#include "occull/statistics.hpp"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace occull {

Summary summarize(std::vector<double> v) {
  Summary s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  s.mean = std::accumulate(v.begin(), v.end(), 0.0) / double(v.size());
  const std::size_t n = v.size();
  s.median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  const auto rank = std::size_t(std::ceil(0.95 * double(n)));
  s.p95 = v[std::min(n, std::max<std::size_t>(rank, 1)) - 1];
  s.min = v.front();
  s.max = v.back();
  return s;
}

}  // namespace occull
