// Calibration of the NOHC cost model on the real renderer (llvmpipe here).
#include "occull/gl/calibrate.hpp"
#include "occull/gl/context.hpp"

#include <gtest/gtest.h>

#include <cmath>

using namespace occull;

namespace {

gl::CalibrationResult small_calibration() {
  gl::CalibrationOptions o;
  o.width = 320;
  o.height = 180;
  o.repeats = 3;
  o.shading_classes = {0, 16};
  return gl::calibrate(o);
}

}  // namespace

TEST(Calibration, TimesArePositiveAndATriangleCostsLessThanADraw) {
  auto context = gl::Context::create();
  const gl::CalibrationResult r = small_calibration();
  const HardwareProfile& p = r.profile;
  EXPECT_GT(p.draw_setup_ms, 0.0);
  EXPECT_GT(p.triangle_ms, 0.0);
  EXPECT_GT(p.query_setup_ms, 0.0);
  EXPECT_GT(p.query_fragment_ms, 0.0);
  EXPECT_GT(p.query_latency_ms, 0.0);
  ASSERT_EQ(p.fragment_ms.size(), 2u);
  EXPECT_GT(p.fragment_ms.at(0), 0.0);
  EXPECT_GT(p.fragment_ms.at(16), p.fragment_ms.at(0)) << "16 lights per fragment cost more than none";
  EXPECT_LT(p.triangle_ms, p.draw_setup_ms);
  EXPECT_LT(r.seconds, 10.0);
}

// Repeat calibrations agree within a factor of 2 on the quantities the
// model leans on most (the others — per-draw setup, latency — are dominated
// by scheduling noise on a shared machine; their spread is printed instead).
TEST(Calibration, RepeatCalibrationsAgreeWithinAFactorOfTwo) {
  auto context = gl::Context::create();
  const HardwareProfile a = small_calibration().profile;
  const HardwareProfile b = small_calibration().profile;
  const auto close = [](double x, double y) { return std::abs(std::log2(x / y)) <= 1.0; };
  EXPECT_TRUE(close(a.triangle_ms, b.triangle_ms)) << a.triangle_ms << " vs " << b.triangle_ms;
  EXPECT_TRUE(close(a.fragment_ms.at(0), b.fragment_ms.at(0)));
  EXPECT_TRUE(close(a.fragment_ms.at(16), b.fragment_ms.at(16)));
  EXPECT_TRUE(close(a.query_setup_ms, b.query_setup_ms)) << a.query_setup_ms << " vs " << b.query_setup_ms;
}
