// The run-time invariants of the instrument, each broken on purpose through
// a fault hook: a check that has never been seen failing is not trusted.
#include "lab/fault_hooks.hpp"
#include "lab/invariants.hpp"
#include "gl_test_util.hpp"
#include "occull/error.hpp"
#include "occull/lab.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>

using namespace occull;

namespace {

constexpr const char* kScene = "city:blocks=3,traffic=6";

// The run's fault hooks, made on first use.
detail::FaultHooks& hooks(BenchConfig& c) {
  if (!c.hooks) c.hooks = std::make_shared<detail::FaultHooks>();
  return *c.hooks;
}

BenchConfig small_bench(std::vector<std::string> algorithms) {
  BenchConfig c;
  c.scene = kScene;
  c.path = "street";
  c.algorithms = std::move(algorithms);
  c.frames = 3;
  c.warmup = 0;
  c.width = 96;
  c.height = 54;
  return c;
}

// Runs the bench and returns the violation's message ("" when none).
std::string violation_of(const BenchConfig& c) {
  try {
    (void)run_bench(c);
  } catch (const InvariantViolation& e) {
    return e.what();
  }
  return "";
}

// The message names the invariant, the scene, the path and a frame.
void expect_violation(const std::string& message, const std::string& invariant) {
  ASSERT_FALSE(message.empty()) << invariant << " was not detected";
  EXPECT_NE(message.find("invariant " + invariant + " violated"), std::string::npos) << message;
  EXPECT_NE(message.find(std::string("scene ") + kScene), std::string::npos) << message;
  EXPECT_NE(message.find("path street"), std::string::npos) << message;
  EXPECT_NE(message.find("frame 0"), std::string::npos) << message;
}

}  // namespace

TEST(Invariants, HoldOnAnUnbrokenRun) {
  EXPECT_EQ(violation_of(small_bench({"vfc", "chcpp", "oracle", "oracle:set=boxes"})), "");
}

TEST(Invariants, TruthWithAnObjectOutsideTheFrustumStopsTheRun) {
  BenchConfig c = small_bench({"vfc"});
  auto drawn = std::make_shared<std::vector<ObjectId>>();
  hooks(c).truth_objects = [drawn](std::vector<ObjectId>& objects) { *drawn = objects; };
  hooks(c).truth_images = [drawn](std::vector<gl::Renderer::ObjectPixels>& visible, gl::Renderer::PassImages&) {
    ObjectId outside = 0;
    while (std::find(drawn->begin(), drawn->end(), outside) != drawn->end()) ++outside;
    visible.push_back({outside, 3});
    std::sort(visible.begin(), visible.end(), [](auto& a, auto& b) { return a.id < b.id; });
  };
  expect_violation(violation_of(c), "truth-in-frustum");
}

TEST(Invariants, IdImageThatDisagreesWithTheDepthImageStopsTheRun) {
  BenchConfig c = small_bench({"vfc"});
  hooks(c).truth_images = [](std::vector<gl::Renderer::ObjectPixels>&, gl::Renderer::PassImages& images) {
    const auto covered = std::find_if(images.ids.begin(), images.ids.end(), [](std::uint32_t v) { return v != 0; });
    ASSERT_NE(covered, images.ids.end());
    *covered = 0;  // an id write lost
  };
  expect_violation(violation_of(c), "truth-covers-full-render");
}

TEST(Invariants, ObjectLeftOutOfTheTruthPassStopsTheRun) {
  // As a frustum test that wrongly calls everything outside would.
  BenchConfig c = small_bench({"vfc"});
  hooks(c).truth_objects = [](std::vector<ObjectId>& objects) { objects.clear(); };
  expect_violation(violation_of(c), "truth-covers-full-render");
}

TEST(Invariants, EmptyTruthOfACoveredFrameStopsTheRun) {
  BenchConfig c = small_bench({"vfc"});
  hooks(c).truth_images = [](std::vector<gl::Renderer::ObjectPixels>& visible, gl::Renderer::PassImages&) {
    visible.clear();
  };
  expect_violation(violation_of(c), "truth-not-empty");
}

TEST(Invariants, TruthPassThatDrewNothingIsCaughtByTheCpuProbe) {
  // The original failure: every draw of the truth pass landed nowhere, so
  // the images are empty and consistent with each other and with the list.
  BenchConfig c = small_bench({"vfc"});
  hooks(c).truth_images = [](std::vector<gl::Renderer::ObjectPixels>& visible, gl::Renderer::PassImages& images) {
    visible.clear();
    std::fill(images.ids.begin(), images.ids.end(), 0u);
    std::fill(images.depth.begin(), images.depth.end(), 1.0f);
  };
  expect_violation(violation_of(c), "truth-probe");
}

TEST(Invariants, FrameCoveringMoreThanTheTruthStopsTheRun) {
  BenchConfig c = small_bench({"vfc"});
  hooks(c).frame_depth = [](std::vector<float>& depth) { std::fill(depth.begin(), depth.end(), 0.5f); };
  const std::string message = violation_of(c);
  expect_violation(message, "frame-within-truth");
  EXPECT_NE(message.find("vfc covers"), std::string::npos) << message;
}

TEST(Invariants, OracleLeavingOutATruthObjectStopsTheRun) {
  BenchConfig c = small_bench({"oracle"});
  hooks(c).oracle_objects = [](std::vector<ObjectId>& visible) {
    ASSERT_FALSE(visible.empty());
    visible.pop_back();
  };
  const std::string message = violation_of(c);
  expect_violation(message, "oracle-draws-truth");
  EXPECT_NE(message.find("1 missing"), std::string::npos) << message;
}

TEST(Invariants, OracleFrameWithOtherDepthStopsTheRun) {
  BenchConfig c = small_bench({"oracle"});
  hooks(c).frame_depth = [](std::vector<float>& depth) {
    const auto covered = std::find_if(depth.begin(), depth.end(), [](float z) { return z < 1.0f; });
    ASSERT_NE(covered, depth.end());
    *covered = 1.0f;
  };
  expect_violation(violation_of(c), "oracle-draws-truth");
}

TEST(Invariants, BoxReachLeavingOutAVisibleObjectStopsTheRun) {
  BenchConfig c = small_bench({"oracle:set=boxes"});
  hooks(c).box_reach = [](std::vector<ObjectId>& reach) {
    ASSERT_FALSE(reach.empty());
    reach.erase(reach.begin());  // the truth's objects are most of the reach: the first is one of them
  };
  expect_violation(violation_of(c), "box-reach-holds-truth");
}

TEST(Invariants, OracleOfBoxesLeavingOutAnObjectOfTheReachStopsTheRun) {
  BenchConfig c = small_bench({"oracle:set=boxes"});
  hooks(c).oracle_objects = [](std::vector<ObjectId>& reach) {
    ASSERT_FALSE(reach.empty());
    reach.pop_back();
  };
  const std::string message = violation_of(c);
  expect_violation(message, "oracle-draws-truth");
  EXPECT_NE(message.find("1 missing"), std::string::npos) << message;
}

TEST(Invariants, CpuProbeFindsTrianglesToTestOnAPlainView) {
  // Not vacuous: on a wall in plain view the probe does test triangles, and
  // it accepts the truth the renderer drew.
  auto context = gl::Context::create();
  const Scene scene = test::box_scene({{{-3, -3, -11}, {3, 3, -10}}, {{7, -1, -21}, {9, 1, -19}}});
  gl::Renderer r(scene, test::small_target(128, 128));
  const View view = make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.1f, 100.0f}, 128, 128);
  const ObjectId all[] = {0, 1};
  gl::Renderer::PassImages images;
  (void)r.visible_pixels(view, all, &images);
  const detail::FrameLabel where{"boxes", "none", 0};
  EXPECT_EQ(detail::check_truth_probes(where, scene, view, all, images.depth, true), 2u);
}

TEST(Invariants, SubpixelRuleCullingAVisibleObjectStopsTheRun) {
  // A box a fifth of a pixel across over a pixel centre is in the truth; a
  // box a pixel across lying between centres is not. The sub-pixel rule
  // keeps the first (the invariant holds and counts the second); a size
  // threshold in its place would cull a visible object, and the invariant
  // says so.
  auto context = gl::Context::create();
  const Scene scene = test::box_scene({{{-7.2f, -7.2f, -10.01f}, {-6.8f, -6.8f, -10.0f}},
                                       {{-4.9f, -4.9f, -10.01f}, {-3.1f, -3.1f, -10.0f}}});
  gl::Renderer r(scene, test::small_target(10, 10));
  const View view = make_view({{0, 0, 0}, 0, 0}, {90.0f, 0.1f, 100.0f}, 10, 10);
  const ObjectId all[] = {0, 1};
  const auto visible = r.visible_pixels(view, all);
  ASSERT_EQ(visible.size(), 1u);
  EXPECT_EQ(visible[0].id, 0u);
  const detail::FrameLabel where{"boxes", "none", 0};
  EXPECT_EQ(detail::check_truth_holds_samples(where, visible, scene, view), 1u);
  SubpixelRules size_threshold;
  size_threshold.pixel_centres = false;
  try {
    (void)detail::check_truth_holds_samples(where, visible, scene, view, size_threshold);
    ADD_FAILURE() << "a size threshold culling a visible object passed the invariant";
  } catch (const InvariantViolation& e) {
    EXPECT_NE(std::string(e.what()).find("truth-holds-samples"), std::string::npos) << e.what();
  }
}
