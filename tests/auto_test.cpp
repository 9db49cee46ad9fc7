// The adaptive culler: its schedule on scripted costs, and the culler
// switching when a scripted backend's costs change.
#include "cull/auto.hpp"
#include "occull/culler.hpp"
#include "occull/error.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

using namespace occull;

namespace {

detail::AutoConfig config() {
  detail::AutoConfig c;
  c.trial = 2;
  c.period = 10;
  c.margin = 0.05;
  return c;
}

// Runs the schedule for `frames` frames with a fixed cost per candidate;
// returns which candidate ran in each frame.
std::vector<std::size_t> run(detail::AutoSchedule& s, const std::vector<double>& cost, int frames) {
  std::vector<std::size_t> ran;
  for (int k = 0; k < frames; ++k) {
    ran.push_back(s.next());
    s.finished(cost[s.next()]);
  }
  return ran;
}

}  // namespace

TEST(AutoSchedule, TriesEveryCandidateThenKeepsTheCheapest) {
  detail::AutoSchedule s(config(), 3);
  const auto ran = run(s, {5.0, 2.0, 3.0}, 6);
  EXPECT_EQ(ran, (std::vector<std::size_t>{0, 0, 1, 1, 2, 2}));
  EXPECT_EQ(s.current(), 1u);
  EXPECT_EQ(s.next(), 1u);
}

TEST(AutoSchedule, ATryMoreThanTwiceTheBestCostEndsAfterOneFrame) {
  detail::AutoSchedule s(config(), 3);
  const auto ran = run(s, {2.0, 9.0, 3.0}, 5);
  EXPECT_EQ(ran, (std::vector<std::size_t>{0, 0, 1, 2, 2}));
  EXPECT_EQ(s.current(), 0u);
}

TEST(AutoSchedule, SwitchesWhenAChallengerBecomesCheaperByTheMargin) {
  detail::AutoSchedule s(config(), 2);
  run(s, {2.0, 5.0}, 4);
  ASSERT_EQ(s.current(), 0u);
  // Candidate 1 gets cheaper: at its next try it takes over.
  const auto ran = run(s, {2.0, 1.0}, 20);
  EXPECT_EQ(s.current(), 1u);
  EXPECT_EQ(s.switches(), 1u);
  EXPECT_EQ(ran.back(), 1u);
}

TEST(AutoSchedule, KeepsTheCurrentWithinTheMargin) {
  detail::AutoSchedule s(config(), 2);
  run(s, {2.0, 5.0}, 4);
  run(s, {2.0, 1.95}, 60);  // 2.5 % cheaper: not enough
  EXPECT_EQ(s.current(), 0u);
  EXPECT_EQ(s.switches(), 0u);
}

TEST(AutoSchedule, ALosingChallengerIsTriedLessAndLessOften) {
  detail::AutoSchedule s(config(), 2);
  run(s, {1.0, 9.0}, 4);
  const auto ran = run(s, {1.0, 9.0}, 400);
  std::vector<int> tries;  // frame of each try's first frame
  for (std::size_t k = 1; k < ran.size(); ++k)
    if (ran[k] == 1 && ran[k - 1] == 0) tries.push_back(int(k));
  ASSERT_GE(tries.size(), 3u);
  for (std::size_t i = 2; i < tries.size(); ++i)
    EXPECT_GE(tries[i] - tries[i - 1], tries[i - 1] - tries[i - 2]) << "gaps between tries never shrink";
  EXPECT_GE(tries[2] - tries[1], 2 * (tries[1] - tries[0]) - 2);
}

TEST(AutoCuller, SwitchesWhenTheBackendsCostsChange) {
  // Boxes in a row in front of the camera; vfc never queries, chcpp does.
  std::vector<Aabb> boxes;
  for (int i = 0; i < 20; ++i) boxes.push_back({{-1.0f, -1.0f, -5.0f - 3.0f * float(i)}, {1.0f, 1.0f, -4.0f - 3.0f * float(i)}});
  const Scene scene = test::box_scene(boxes);
  const Bvh bvh = Bvh::build(scene);
  Options o;
  o.set("auto.candidates", "vfc+chcpp");
  o.set("auto.period", "5");
  o.set("chcpp.virtual_leaf", "0");
  o.set("chcpp.enter_p_min", "0");  // chcpp keeps querying these always-visible boxes: frames with queries are its
  o.set("chcpp.backoff", "0");
  const auto culler = make_culler("auto", {scene, bvh}, o);
  const View view = make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.1f, 200.0f}, 64, 64);
  test::ScriptedBackend backend;
  // A frame with queries costs `query_frame` ms, one without `plain_frame`.
  const auto fly = [&](double query_frame, double plain_frame, int frames) {
    int with_queries = 0;
    for (int k = 0; k < frames; ++k) {
      const std::uint64_t before = backend.stats().queries;
      (void)culler->render_frame(view, backend);
      const bool queried = backend.stats().queries > before;
      with_queries += queried ? 1 : 0;
      FrameStats measured;
      measured.frame_ms = queried ? query_frame : plain_frame;
      culler->frame_finished(measured);
    }
    return with_queries;
  };
  (void)fly(10.0, 5.0, 10);                     // queries are expensive here
  EXPECT_LE(fly(10.0, 5.0, 40), 12) << "auto should mostly run vfc";
  (void)fly(2.0, 5.0, 60);                      // now querying pays
  EXPECT_GE(fly(2.0, 5.0, 40), 30) << "auto should have switched to chcpp";
}

TEST(AutoCuller, RejectsItselfAndTheOracleAsCandidates) {
  const Scene scene = test::box_scene({{{-1, -1, -5}, {1, 1, -4}}});
  const Bvh bvh = Bvh::build(scene);
  for (const char* bad : {"vfc+auto", "oracle"}) {
    Options o;
    o.set("auto.candidates", bad);
    EXPECT_THROW((void)make_culler("auto", {scene, bvh}, o), InputError) << bad;
  }
}
