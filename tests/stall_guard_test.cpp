// StallGuard: a result not there in time counts as visible; what it gave up
// on is read once it arrives. Timeout 0 (the first poll decides), so no test
// depends on how long anything takes.
#include "occull/culler.hpp"
#include "occull/stall_guard.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>

using namespace occull;

TEST(StallGuard, AResultNotThereInTimeCountsAsVisibleAndIsReadOnceItArrives) {
  test::ScriptedBackend backend;
  backend.visible_samples = [](std::span<const Aabb>) { return std::uint64_t(0); };  // all hidden
  bool arrived = false;
  backend.available = [&](QueryId q) { return q != 1 || arrived; };
  StallGuard guard(backend, 0.0);
  const Aabb box{{0, 0, 0}, {1, 1, 1}};

  const QueryId q0 = guard.issue_query({&box, 1});
  EXPECT_EQ(guard.result(q0), 0u);  // there: passed through
  const QueryId q1 = guard.issue_query({&box, 1});
  EXPECT_EQ(guard.result(q1), StallGuard::kStalledSamples);
  EXPECT_EQ(guard.stats().stalled_results, 1u);
  EXPECT_EQ(guard.stats().blocking_waits, 1u);
  EXPECT_EQ(guard.abandoned(), 1u);
  EXPECT_EQ(std::count(backend.read.begin(), backend.read.end(), q1), 0) << "not read while it is not there";

  arrived = true;
  (void)guard.issue_query({&box, 1});  // collects what arrived
  EXPECT_EQ(guard.abandoned(), 0u);
  EXPECT_EQ(std::count(backend.read.begin(), backend.read.end(), q1), 1) << "read (freed) once there";
}

TEST(StallGuard, QueriesStillOutstandingAreReadWhenTheGuardGoes) {
  test::ScriptedBackend backend;
  backend.available = [](QueryId) { return false; };
  const Aabb box{{0, 0, 0}, {1, 1, 1}};
  {
    StallGuard guard(backend, 0.0);
    for (int i = 0; i < 3; ++i) (void)guard.result(guard.issue_query({&box, 1}));
    EXPECT_EQ(guard.abandoned(), 3u);
    EXPECT_TRUE(backend.read.empty());
  }
  EXPECT_EQ(backend.read.size(), 3u);
}

// A driver that never answers: a conservative culler behind the guard draws
// every object in the frustum (each unanswered query counts as visible) and
// the frame ends.
TEST(StallGuard, AConservativeCullerBehindItDrawsWhatANeverAnsweringDriverHid) {
  std::vector<Aabb> boxes;
  for (int i = 0; i < 20; ++i) boxes.push_back({{-1.0f + 0.1f * float(i), -1, -5.0f - 3.0f * float(i)},
                                               {0.0f + 0.1f * float(i), 1, -4.0f - 3.0f * float(i)}});
  const Scene scene = test::box_scene(boxes);
  const Bvh bvh = Bvh::build(scene);
  const View view = make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.1f, 200.0f}, 64, 64);
  for (const char* algo : {"stopwait", "chc", "chcpp"}) {
    auto culler = make_culler(algo, {scene, bvh});
    test::ScriptedBackend backend;
    backend.visible_samples = [](std::span<const Aabb>) { return std::uint64_t(0); };
    backend.available = [](QueryId) { return false; };
    StallGuard guard(backend, 0.0);
    for (int frame = 0; frame < 3; ++frame) {
      backend.rendered.clear();
      (void)culler->render_frame(view, guard);
      culler->frame_finished({});
    }
    std::vector<ObjectId> drawn = backend.rendered;
    std::sort(drawn.begin(), drawn.end());
    drawn.erase(std::unique(drawn.begin(), drawn.end()), drawn.end());
    EXPECT_EQ(drawn.size(), boxes.size()) << algo;
    EXPECT_GT(guard.stats().stalled_results, 0u) << algo;
  }
}
