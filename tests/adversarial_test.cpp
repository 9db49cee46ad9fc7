// Conservativeness under attack: on scenes built to break it (tiny meshes,
// zero-thickness boxes, coplanar objects, the camera through boxes,
// one-pixel objects kilometres away), every conservative culler — also with
// virtual leaves off — misses nothing, in every query mode.
#include "conservative_walk.hpp"
#include "gl_test_util.hpp"
#include "occull/lab.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

using namespace occull;

namespace {

// Half as many under the sanitizers (tests/CMakeLists.txt).
#ifdef OCCULL_TEST_SANITIZED
constexpr int kFrames = 12;
#else
constexpr int kFrames = 24;
#endif
// Bounded in what they draw over the attacks' walks but for nohc and auto
// (they may decide by cost to draw without queries) and chcpp with its
// virtual leaves of 1,500 triangles: a leaf holds a hundred of these small
// meshes and is drawn whole when one is seen (0.93-0.97 of vfc's objects on
// the far and thin kinds); chcpp:virtual_leaf=0 is bounded.
const std::vector<std::string_view> kUnbounded = {"nohc", "auto", "chcpp", "chcpp:cpu_test=on"};

const char* const kCullers[] = {"stopwait", "chc",  "chcpp", "chcpp:virtual_leaf=0", "nohc", "auto:trial=1:period=2",
                                "hiz",      "hiz:texels=2", "soc", "soc:scale=1", "soc:width=64:height=36",
                                "soc:width=173:height=61", "chcpp:cpu_test=on", "nohc:cpu_test=on"};

Options fixed_profile() {
  Options o;
  o.set("nohc.profile", OCCULL_TEST_PROFILE);
  return o;
}

// One attack in one query mode. Sized from measurements: with exact query
// boxes (no margin), 320 x 180 and 24 frames over these seeds and paths
// produce misses on the far and thin kinds in several cullers; 160 x 90 and
// 12 frames produced none (a test that cannot fail proves nothing).
struct Attack {
  const char* kind;
  gl::QueryMode mode;
};

std::string attack_text(const Attack& a) {
  const char* mode = a.mode == gl::QueryMode::samples_passed ? "samples"
                     : a.mode == gl::QueryMode::any_samples_passed ? "any"
                                                                   : "any_conservative";
  return std::string(a.kind) + "_" + mode;
}
std::string attack_name(const ::testing::TestParamInfo<Attack>& info) { return attack_text(info.param); }
void PrintTo(const Attack& a, std::ostream* os) { *os << attack_text(a); }

class Adversarial : public ::testing::TestWithParam<Attack> {};

}  // namespace

TEST_P(Adversarial, ConservativeCullersMissNothing) {
  gl::RendererOptions ro = test::small_target(320, 180);
  ro.query_mode = GetParam().mode;
  test::CullingTally tally;
  for (int seed : {1, 2}) {
    Session session(std::string("adversarial:kind=") + GetParam().kind + ",seed=" + std::to_string(seed), ro);
    for (const CameraPath& path : session.bundle().paths)
      test::run_walk(session, path, kFrames, kCullers, fixed_profile(), tally,
                     attack_text(GetParam()) + " seed " + std::to_string(seed) + " / " + path.name());
  }
  tally.expect_culling(kUnbounded);
}

INSTANTIATE_TEST_SUITE_P(
    Attacks, Adversarial,
    ::testing::Values(Attack{"far", gl::QueryMode::samples_passed}, Attack{"thin", gl::QueryMode::samples_passed},
                      Attack{"farout", gl::QueryMode::samples_passed},
                      Attack{"tiny", gl::QueryMode::samples_passed}, Attack{"near", gl::QueryMode::samples_passed},
                      Attack{"coplanar", gl::QueryMode::samples_passed}, Attack{"mixed", gl::QueryMode::samples_passed},
                      Attack{"far", gl::QueryMode::any_samples_passed}, Attack{"thin", gl::QueryMode::any_samples_passed},
                      Attack{"far", gl::QueryMode::any_samples_passed_conservative},
                      Attack{"thin", gl::QueryMode::any_samples_passed_conservative}),
    attack_name);

namespace {

// An attack placed far from the world's origin: the kind, and the scene's
// offset along x and z (metres).
struct FarAttack {
  const char* kind;
  double offset;
};
std::string far_attack_text(const FarAttack& a) {
  return std::string(a.kind) + "_at_" + std::to_string(std::lround(a.offset / 1000.0)) + "km";
}
std::string far_attack_name(const ::testing::TestParamInfo<FarAttack>& info) { return far_attack_text(info.param); }
void PrintTo(const FarAttack& a, std::ostream* os) { *os << far_attack_text(a); }

class FarFromTheOrigin : public ::testing::TestWithParam<FarAttack> {};

}  // namespace

// Every kind 10 km and 1,000 km out, the session's floating origin near the
// camera (Session::origin): nothing missed, culling kept. At 1,000 km a float
// holds positions to 6 cm; the frame occull works in holds them to a tenth
// of a millimetre.
TEST_P(FarFromTheOrigin, ConservativeCullersMissNothing) {
  const FarAttack a = GetParam();
  Session session(std::string("adversarial:kind=") + a.kind + ",offset=" + std::to_string(a.offset),
                  test::small_target(320, 180));
  ASSERT_GT(glm::length(session.origin()), 0.5 * a.offset);  // the frame is out there too
  test::CullingTally tally;
  for (const CameraPath& path : session.bundle().paths)
    test::run_walk(session, path, kFrames, kCullers, fixed_profile(), tally, far_attack_text(a) + " / " + path.name());
  tally.expect_culling(kUnbounded);
}

INSTANTIATE_TEST_SUITE_P(
    Offsets, FarFromTheOrigin,
    ::testing::Values(FarAttack{"mixed", 1e4}, FarAttack{"tiny", 1e4}, FarAttack{"thin", 1e4},
                      FarAttack{"coplanar", 1e4}, FarAttack{"near", 1e4}, FarAttack{"far", 1e4},
                      FarAttack{"farout", 1e4}, FarAttack{"mixed", 1e6}, FarAttack{"tiny", 1e6},
                      FarAttack{"thin", 1e6}, FarAttack{"coplanar", 1e6}, FarAttack{"near", 1e6},
                      FarAttack{"far", 1e6}, FarAttack{"farout", 1e6}),
    far_attack_name);

namespace {

// Misses of `spec` on one of the adversarial kinds, 320 x 180, 40 frames.
std::uint64_t misses(const std::string& scene, const std::string& path, const std::string& spec,
                     gl::QueryRaster raster, float margin) {
  gl::RendererOptions ro = test::small_target(320, 180);
  ro.query_raster = raster;
  ro.query_margin_px = margin;
  Session session(scene, ro);
  const CameraPath& p = session.path(path);
  const auto truth = session.ground_truth(p, 40);
  auto culler = session.make(spec, fixed_profile());
  std::uint64_t missed = 0;
  for (const FrameStats& f : session.run_path(spec, *culler, p, 40, &truth).frames) missed += f.missed_objects;
  return missed;
}

}  // namespace

// Not vacuous: the same scenes make exact query boxes miss one-pixel objects
// 2-3 km away (their boxes snap to a neighbouring pixel that a wall covers),
// and the default query geometry catches them. stopwait waits for every
// answer, so the outcome depends only on the rasteriser: llvmpipe's.
TEST(QueryGeometry, ExactQueryBoxesMissOnePixelObjectsThatTheDefaultGeometryCatches) {
  if (!test::on_llvmpipe()) GTEST_SKIP() << "pins llvmpipe's rasterisation";
  const std::string scene = "adversarial:kind=far";
  EXPECT_GT(misses(scene, "far", "stopwait", gl::QueryRaster::exact, 0.0f), 0u);
  EXPECT_EQ(misses(scene, "far", "stopwait", gl::QueryRaster::margin, gl::RendererOptions{}.query_margin_px), 0u);
}

// A decal lying exactly on the ground wins a few pixels of its z-fight; its
// query box face, coplanar with the ground, must pass there too. A sideways
// margin alone (1/64 px) did not make it; the depth slope term does.
TEST(QueryGeometry, CoplanarDecalIsSeenByItsQuery) {
  if (!test::on_llvmpipe()) GTEST_SKIP() << "pins llvmpipe's rasterisation";
  EXPECT_EQ(misses("adversarial:kind=thin", "far", "stopwait", gl::QueryRaster::margin, 1.0f / 64.0f), 0u);
}
