#include "occull/cost_model.hpp"
#include "occull/error.hpp"

#include <algorithm>
#include <cassert>
#include <cmath>

namespace occull {

double HardwareProfile::fragment_cost(int shading_cost) const {
  if (fragment_ms.empty()) throw UsageError("HardwareProfile::fragment_cost: the profile has no fragment costs");
  const auto hit = fragment_ms.find(shading_cost);
  if (hit != fragment_ms.end()) return hit->second;
  if (fragment_ms.size() == 1) return fragment_ms.begin()->second;
  // The two measured classes around it (or the two nearest at one end).
  auto hi = fragment_ms.upper_bound(shading_cost);
  if (hi == fragment_ms.end()) --hi;
  if (hi == fragment_ms.begin()) ++hi;
  const auto lo = std::prev(hi);
  const double t = double(shading_cost - lo->first) / double(hi->first - lo->first);
  return std::max(0.0, lo->second + t * (hi->second - lo->second));
}

int HardwareProfile::max_parallel_queries() const {
  const double step = std::min(query_setup_ms, query_overhead_ms + draw_setup_ms);
  if (step <= 0.0) return 1;
  return int(std::ceil(query_latency_ms / step)) + 1;
}

double bbox_screen_fraction(double box_area, double distance, int width, int height, double fov_y) {
  if (distance <= 0.0) return 1.0;
  const double k = 1.0 / (distance * std::sqrt(double(width) / double(height)) * 2.0 * std::tan(fov_y / 2.0));
  return std::clamp(k * k * box_area / 6.0, 0.0, 1.0);
}

double bbox_screen_fraction(double box_area, double distance, const View& view) {
  const double scale = std::abs(double(view.proj[0][0]) * double(view.proj[1][1])) / 4.0;
  if (view.orthographic) return std::clamp(scale * box_area / 6.0, 0.0, 1.0);
  if (distance <= 0.0) return 1.0;
  return std::clamp(scale * box_area / (6.0 * distance * distance), 0.0, 1.0);
}

double coverage_ratio(double object_area, double box_area) {
  return box_area > 0.0 ? 1.5 * object_area / box_area : 1.0;
}

double object_screen_fraction(const NodeCost& n) { return std::min(1.0, n.r_cov) * n.c_bb; }

double accumulate_coverage(double c_scr, double c_object) {
  return std::clamp(c_scr + (1.0 - c_scr) * c_object, 0.0, 1.0);
}

double coverage_probability(double c_scr, double c_bb) {
  if (c_bb >= c_scr) return 0.0;
  const double d = std::sqrt(c_scr) - std::sqrt(c_bb);
  return d * d;
}

double occlusion_probability(PreviousState previous, double p_cov) {
  switch (previous) {
    case PreviousState::visible: return 0.5 * p_cov * p_cov;
    case PreviousState::occluded: return 1.0;
    case PreviousState::outside: break;
  }
  return p_cov;
}

double render_time(const HardwareProfile& hw, const NodeCost& n, int width, int height,
                   double fragments_per_pixel) {
  const double setup = double(n.draws) * hw.draw_setup_ms;
  const double vertex = double(n.triangles) * hw.triangle_ms;
  const double fragments = fragments_per_pixel * double(width) * double(height) * object_screen_fraction(n);
  const double fragment = fragments * hw.fragment_cost(int(std::lround(n.shading_cost)));
  return std::max({setup, vertex, fragment});
}

double query_time(const HardwareProfile& hw, double c_bb, int width, int height) {
  return hw.query_setup_ms + double(width) * double(height) * c_bb * hw.query_fragment_ms;
}

}  // namespace occull
