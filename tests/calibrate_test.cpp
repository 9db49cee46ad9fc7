// Calibration of the NOHC cost model: what it measures and how it reports
// it. Never the timings themselves — those are noisy on a shared machine and
// belong in `occull calibrate --check`, a report for people.
#include "occull/gl/calibrate.hpp"
#include "occull/gl/context.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <set>

using namespace occull;

namespace {

gl::CalibrationResult small_calibration() {
  gl::CalibrationOptions o;
  o.width = 160;
  o.height = 90;
  o.repeats = 2;
  o.shading_classes = {0, 16};
  return gl::calibrate(o);
}

// A calibration with chosen values, for the checks.
gl::CalibrationResult synthetic(double draw, double triangle, double frag0, double frag16, double latency) {
  gl::CalibrationResult r;
  HardwareProfile& p = r.profile;
  p.draw_setup_ms = draw;
  p.triangle_ms = triangle;
  p.fragment_ms = {{0, frag0}, {16, frag16}};
  p.query_setup_ms = 0.01;
  p.query_fragment_ms = 1e-7;
  p.query_latency_ms = latency;
  p.query_overhead_ms = 0.002;
  r.values = {{"T_r^s", "", draw, 0.0},        {"T_r^tri", "", triangle, 0.0},
              {"T_r^f[0]", "", frag0, 0.0},   {"T_r^f[16]", "", frag16, 0.0},
              {"T_o^l", "", latency, 0.0}};
  return r;
}

bool verdict(const std::vector<gl::CalibrationCheck>& checks, const std::string& name_start) {
  for (const auto& c : checks)
    if (c.name.rfind(name_start, 0) == 0) return c.ok;
  ADD_FAILURE() << "no check named " << name_start;
  return false;
}

}  // namespace

TEST(Calibration, MeasuresEveryQuantityAsAFiniteNonNegativeTime) {
  auto context = gl::Context::create();
  const gl::CalibrationResult r = small_calibration();
  std::set<std::string> names;
  for (const auto& v : r.values) {
    names.insert(v.name);
    EXPECT_TRUE(std::isfinite(v.value_ms) && v.value_ms >= 0.0) << v.name << " " << v.value_ms;
    EXPECT_TRUE(std::isfinite(v.spread) && v.spread >= 0.0) << v.name << " spread " << v.spread;
    EXPECT_FALSE(v.meaning.empty()) << v.name;
  }
  EXPECT_EQ(names, (std::set<std::string>{"T_r^s", "T_r^tri", "T_r^f[0]", "T_r^f[16]", "T_o^s", "T_o^f",
                                          "T_o^l", "T_o^o"}));
  const HardwareProfile& p = r.profile;
  EXPECT_EQ(p.width, 160);
  EXPECT_EQ(p.height, 90);
  ASSERT_EQ(p.fragment_ms.size(), 2u);
  // The profile holds exactly the reported values.
  for (const auto& v : r.values) {
    double field = -1.0;
    if (v.name == "T_r^s") field = p.draw_setup_ms;
    if (v.name == "T_r^tri") field = p.triangle_ms;
    if (v.name == "T_r^f[0]") field = p.fragment_ms.at(0);
    if (v.name == "T_r^f[16]") field = p.fragment_ms.at(16);
    if (v.name == "T_o^s") field = p.query_setup_ms;
    if (v.name == "T_o^f") field = p.query_fragment_ms;
    if (v.name == "T_o^l") field = p.query_latency_ms;
    if (v.name == "T_o^o") field = p.query_overhead_ms;
    EXPECT_EQ(field, v.value_ms) << v.name;
  }
  EXPECT_GE(p.max_parallel_queries(), 1);
}

TEST(CalibrationCheck, SaneCalibrationsPassEveryCheck) {
  const auto a = synthetic(0.01, 1e-6, 1e-6, 5e-6, 0.2);
  const auto b = synthetic(0.015, 1.5e-6, 1.2e-6, 4e-6, 0.3);
  for (const auto& c : gl::check_calibrations(a, b)) EXPECT_TRUE(c.ok) << c.name << ": " << c.detail;
}

TEST(CalibrationCheck, FlagsWrongOrderingsAndPoorRepeatability) {
  const auto sane = synthetic(0.01, 1e-6, 1e-6, 5e-6, 0.2);
  // A triangle dearer than a draw call, in one of the two runs.
  EXPECT_FALSE(verdict(gl::check_calibrations(sane, synthetic(0.01, 0.1, 1e-6, 5e-6, 0.2)), "a triangle"));
  // Heavier shading measured cheaper.
  EXPECT_FALSE(verdict(gl::check_calibrations(sane, synthetic(0.01, 1e-6, 5e-6, 1e-6, 0.2)), "fragments"));
  // No latency measured.
  EXPECT_FALSE(verdict(gl::check_calibrations(sane, synthetic(0.01, 1e-6, 1e-6, 5e-6, 0.0)), "a query"));
  // A negative or infinite time.
  EXPECT_FALSE(verdict(gl::check_calibrations(sane, synthetic(-1.0, 1e-6, 1e-6, 5e-6, 0.2)), "every time"));
  EXPECT_FALSE(verdict(gl::check_calibrations(sane, synthetic(INFINITY, 1e-6, 1e-6, 5e-6, 0.2)), "every time"));
  // The per-draw time three times as large in the second run.
  const auto checks = gl::check_calibrations(sane, synthetic(0.03, 1e-6, 1e-6, 5e-6, 0.2));
  EXPECT_FALSE(verdict(checks, "T_r^s repeats"));
  EXPECT_TRUE(verdict(checks, "T_r^tri repeats"));
}
