// `grid` (Seletsky 2013's uniform-grid culling) against a Backend test double
// whose answers the test controls.
#include "occull/culler.hpp"
#include "occull/error.hpp"
#include "occull/grid.hpp"
#include "occull/grid_views.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>

using namespace occull;

namespace {

// Camera at the origin looking down -Z through a grid of 2 m cells. Object
// 0: a wall 10 m ahead (class always); 1: a box behind it (never); 2: a
// long kerb beside the path spanning many cells (sometimes); 3: a box 30 m
// to the left, outside the frustum (never).
struct Stage {
  Scene scene{"grid"};
  Bvh bvh;
  View view = make_view({{0, 1, 0}, 0, 0}, {60.0f, 0.5f, 100.0f}, 64, 64);
  Stage() {
    const MaterialId grey = scene.add_material({"grey", {0.6f, 0.6f, 0.6f, 1}, false, 0});
    const auto add = [&](const Aabb& b, OccluderClass c) {
      scene.add_object(scene.add_mesh(test::box_mesh(b)), grey, glm::mat4(1.0f), c);
    };
    add({{-3, 0, -11}, {3, 6, -10}}, OccluderClass::always);
    add({{-1, 0, -21}, {1, 2, -19}}, OccluderClass::never);
    add({{3, 0, -30}, {4, 0.5f, -2}}, OccluderClass::sometimes);
    add({{-31, 0, -11}, {-30, 1, -10}}, OccluderClass::never);
    bvh = Bvh::build(scene);
  }
  std::unique_ptr<Culler> make(std::vector<std::string> options = {}) {
    Options o;
    o.set("grid.cell=2");
    for (const auto& s : options) o.set(s);
    return make_culler("grid", {scene, bvh}, o);
  }
};

// Occluded: boxes entirely behind the wall's plane and within its width.
std::uint64_t behind_wall(std::span<const Aabb> boxes) {
  std::uint64_t samples = 0;
  for (const Aabb& b : boxes) {
    const bool hidden = b.max.z < -11.0f && b.min.x > -3.0f && b.max.x < 3.0f && b.max.y < 6.0f;
    samples += hidden ? 0 : 1;
  }
  return samples;
}

std::size_t times_drawn(const test::ScriptedBackend& b, ObjectId id) {
  return std::size_t(std::count(b.rendered.begin(), b.rendered.end(), id));
}

}  // namespace

TEST(Grid, HidesAnOccludedCellFromTheFrameAfterItsQueryAndQueriesItAgainEachFrame) {
  Stage s;
  test::ScriptedBackend backend;
  auto culler = s.make();
  backend.visible_samples = behind_wall;
  for (int frame = 1; frame <= 4; ++frame) {
    backend.rendered.clear();
    const std::size_t queries_before = backend.queried.size();
    culler->render_frame(s.view, backend);
    // Frame 1 has no answers yet: a cell the frustum did not meet is drawn.
    EXPECT_EQ(times_drawn(backend, 1), frame == 1 ? 1u : 0u) << "frame " << frame;
    EXPECT_EQ(times_drawn(backend, 0), 1u) << "frame " << frame;
    EXPECT_EQ(times_drawn(backend, 3), 0u) << "outside the frustum, frame " << frame;
    EXPECT_GT(backend.queried.size(), queries_before) << "frame " << frame;
  }
  // The occluded box's cell is queried every frame (invis_duration 1).
  const Aabb hidden = s.scene.object(1).bounds;
  const auto queries_of_hidden = std::count_if(backend.queried.begin(), backend.queried.end(), [&](const auto& q) {
    return q.size() == 1 && hidden.contains(q[0].center());
  });
  EXPECT_GE(queries_of_hidden, 4);
}

TEST(Grid, TheThesisLeavesCellsWithoutAnAnswerHidden) {
  Stage s;
  test::ScriptedBackend backend;
  auto culler = s.make({"grid.unknown=hidden", "grid.latency=1"});
  culler->render_frame(s.view, backend);
  EXPECT_TRUE(backend.rendered.empty());
  culler->render_frame(s.view, backend);
  EXPECT_EQ(times_drawn(backend, 0), 1u);
}

TEST(Grid, AHiddenCellWhoseQueryFindsItVisibleIsDrawnInTheFrameOfTheQueryWithLatencyZero) {
  for (int latency : {0, 1}) {
    Stage s;
    test::ScriptedBackend backend;
    auto culler = s.make({"grid.latency=" + std::to_string(latency)});
    backend.visible_samples = behind_wall;
    for (int frame = 1; frame <= 2; ++frame) culler->render_frame(s.view, backend);
    // The wall goes: the box behind it is hidden by its last answer, and
    // this frame's query of its cell finds it visible.
    backend.visible_samples = [](std::span<const Aabb> boxes) { return std::uint64_t(boxes.size()); };
    backend.rendered.clear();
    (void)culler->render_frame(s.view, backend);
    EXPECT_EQ(times_drawn(backend, 1), latency == 0 ? 1u : 0u) << "latency " << latency;
    EXPECT_EQ(test::counter(*culler, "revealed") > 0, latency == 0) << "latency " << latency;
    backend.rendered.clear();
    culler->render_frame(s.view, backend);
    EXPECT_EQ(times_drawn(backend, 1), 1u) << "next frame, latency " << latency;
    EXPECT_EQ(times_drawn(backend, 3), 0u) << "outside the frustum, latency " << latency;
  }
}

TEST(Grid, VisibleAnswersHoldForVisDurationFrames) {
  Stage s;
  test::ScriptedBackend backend;
  auto culler = s.make({"grid.vis_duration=5", "grid.vis_growth=0"});
  std::vector<std::size_t> per_frame;
  for (int frame = 1; frame <= 12; ++frame) {
    const std::size_t before = backend.queried.size();
    culler->render_frame(s.view, backend);
    per_frame.push_back(backend.queried.size() - before);
  }
  // Every cell is visible: queried in frame 1, then again 5 frames later.
  EXPECT_GT(per_frame[0], 0u);
  for (int f : {1, 2, 3, 4, 6, 7, 8, 9, 11}) EXPECT_EQ(per_frame[std::size_t(f)], 0u) << "frame " << f + 1;
  EXPECT_EQ(per_frame[5], per_frame[0]);
  EXPECT_EQ(per_frame[10], per_frame[0]);
}

TEST(Grid, CapsQueriesExceptForCellsThatWereVisible) {
  Stage s;
  test::ScriptedBackend backend;
  {
    // Without answers every cell is hidden: the cap holds.
    auto culler = s.make({"grid.cap=2", "grid.unknown=hidden"});
    culler->render_frame(s.view, backend);
    EXPECT_EQ(backend.queried.size(), 2u);
  }
  {
    // Cells visible by their answer are queried past the cap (the blinking fix).
    auto culler = s.make({"grid.cap=2", "grid.vis_duration=1", "grid.vis_growth=0"});
    culler->render_frame(s.view, backend);
    const std::size_t before = backend.queried.size();
    culler->render_frame(s.view, backend);
    EXPECT_GT(backend.queried.size() - before, 2u);
  }
}

TEST(Grid, DrawsAnObjectOncePerFrameOccludersFirst) {
  Stage s;
  test::ScriptedBackend backend;
  auto culler = s.make();
  for (int frame = 1; frame <= 3; ++frame) {
    backend.rendered.clear();
    culler->render_frame(s.view, backend);
    EXPECT_EQ(times_drawn(backend, 2), 1u) << "the kerb spans many cells, frame " << frame;
    // The wall (class always) is drawn in the pre-pass, before the box of class never.
    const auto wall = std::find(backend.rendered.begin(), backend.rendered.end(), 0u);
    const auto box = std::find(backend.rendered.begin(), backend.rendered.end(), 1u);
    ASSERT_NE(wall, backend.rendered.end());
    if (box != backend.rendered.end()) EXPECT_LT(wall, box);
  }
}

TEST(Grid, CountsCappedFramesDeferredQueriesAndTheAgeOfItsAnswers) {
  Stage s;
  test::ScriptedBackend backend;
  std::size_t due = 0;  // cells due a query in the first frame: every non-empty one in view
  {
    auto culler = s.make({"grid.unknown=hidden"});
    (void)culler->render_frame(s.view, backend);
    due = backend.queried.size();
    EXPECT_EQ(test::counter(*culler, "capped"), 0.0);
    EXPECT_EQ(test::counter(*culler, "over_cap"), 0.0);
  }
  ASSERT_GT(due, 2u);
  {
    auto culler = s.make({"grid.cap=2", "grid.unknown=hidden"});
    (void)culler->render_frame(s.view, backend);
    EXPECT_EQ(test::counter(*culler, "capped"), 1.0);
    EXPECT_EQ(test::counter(*culler, "over_cap"), double(due - 2));
  }
  {
    // Answers come from frame 1's queries and hold 5 frames: 1, 2, 3 frames old.
    auto culler = s.make({"grid.vis_duration=5", "grid.vis_growth=0"});
    (void)culler->render_frame(s.view, backend);
    EXPECT_EQ(test::counter(*culler, "result_age"), 0.0) << "no answers yet";
    for (int frame = 2; frame <= 4; ++frame) {
      (void)culler->render_frame(s.view, backend);
      EXPECT_DOUBLE_EQ(test::counter(*culler, "result_age"), double(frame - 1)) << "frame " << frame;
    }
  }
}

TEST(Grid, PrePassOfACellQueriedThisFrameIsConditionalOnItsQueryUnlessAnObjectLeavesTheCell) {
  Stage s;
  // Object 4: an occluder inside one 2 m cell, in view.
  const MaterialId grey = s.scene.object(0).material;
  const Aabb small{{3.2f, 0.2f, -7.8f}, {4.8f, 1.8f, -6.2f}};
  s.scene.add_object(s.scene.add_mesh(test::box_mesh(small)), grey, glm::mat4(1.0f), OccluderClass::always);
  s.bvh = Bvh::build(s.scene);
  const GridGeometry g = UniformGrid::of_scene(s.scene, 2.0f).geometry();
  ASSERT_EQ(g.cell_of(small.min), g.cell_of(small.max)) << "the test's object must lie in one cell";

  const auto conditional_ids = [](const test::ScriptedBackend& b) {
    std::vector<ObjectId> ids;
    for (const auto& [id, q] : b.rendered_conditionally) ids.push_back(id);
    return ids;
  };
  {
    test::ScriptedBackend backend;
    backend.conditional = true;
    auto culler = s.make();
    culler->render_frame(s.view, backend);
    // The small occluder depends on the query of its own cell, issued this frame.
    ASSERT_EQ(conditional_ids(backend), std::vector<ObjectId>{4});
    const QueryId q = backend.rendered_conditionally[0].second;
    ASSERT_LT(q, backend.queried.size());
    ASSERT_EQ(backend.queried[q].size(), 1u);
    EXPECT_TRUE(backend.queried[q][0].contains(small.center()));
    // The wall reaches into other cells: drawn unconditionally, once.
    EXPECT_EQ(times_drawn(backend, 0), 1u);
  }
  {
    test::ScriptedBackend backend;
    backend.conditional = true;
    auto culler = s.make({"grid.conditional=off"});
    culler->render_frame(s.view, backend);
    EXPECT_TRUE(backend.rendered_conditionally.empty());
    EXPECT_EQ(times_drawn(backend, 4), 1u);
  }
  {
    test::ScriptedBackend backend;  // no conditional rendering: drawn as usual
    auto culler = s.make();
    culler->render_frame(s.view, backend);
    EXPECT_EQ(times_drawn(backend, 4), 1u);
  }
}

TEST(Grid, DrawsNoObjectOutsideTheFrustumThoughACellOfItMeetsTheFrustum) {
  Stage s;
  // Object 4: left of the frustum (at z = -3 it spans x -6..-2.5; the view
  // reaches x = -1.73 there), in a cell (x -3..-1, z -4..-2) that the
  // frustum meets.
  const Aabb beside{{-6.0f, 0.0f, -3.0f}, {-2.5f, 1.0f, -2.8f}};
  s.scene.add_object(s.scene.add_mesh(test::box_mesh(beside)), s.scene.object(0).material, glm::mat4(1.0f),
                     OccluderClass::never);
  s.bvh = Bvh::build(s.scene);
  ASSERT_EQ(s.view.frustum.classify(beside), Containment::outside);
  test::ScriptedBackend backend;
  auto culler = s.make();
  for (int frame = 1; frame <= 2; ++frame) {
    backend.rendered.clear();
    culler->render_frame(s.view, backend);
    EXPECT_EQ(times_drawn(backend, 4), 0u) << "frame " << frame;
    EXPECT_EQ(times_drawn(backend, 0), 1u) << "frame " << frame;
  }
}

TEST(QueryBudget, SplitsEvenlyFirstThenGrantsDemandsThatFitAndSharesTheSlack) {
  QueryBudget b(100, 2);
  EXPECT_EQ(b.allowance(0), 50);
  EXPECT_EQ(b.allowance(1), 50);
  b.report(0, 20, 10, 2, 0);
  b.report(1, 5, 10, 0, 5);
  b.split();
  EXPECT_EQ(b.allowance(0), 30 + 25);
  EXPECT_EQ(b.allowance(1), 20 + 25);
}

TEST(QueryBudget, OverTheCapAViewWhoseHiddenCellsComeIntoSightGetsMoreThanOneWhoseStayHidden) {
  QueryBudget b(100, 2, 0.25);
  for (int frame = 0; frame < 12; ++frame) {
    b.report(0, 20, 40, 20, 60);  // half of its re-queries find a hidden cell visible again
    b.report(1, 20, 40, 0, 60);   // none do: its stale answers were right
    b.split();
  }
  EXPECT_GT(b.reveal_rate(0), 0.45);
  EXPECT_LT(b.reveal_rate(1), 0.05);
  EXPECT_LE(b.allowance(0) + b.allowance(1), 100);
  EXPECT_GE(b.allowance(1), 20 + 7) << "its drawn cells' queries and the floor: a quarter of an even share of 60";
  EXPECT_GT(b.allowance(0) - 20, 3 * (b.allowance(1) - 20));
  // The drawn cells' queries come first: a view that draws more gets more.
  QueryBudget drawn(100, 2);
  drawn.report(0, 50, 40, 10, 40);
  drawn.report(1, 10, 40, 10, 40);
  drawn.split();
  EXPECT_EQ(drawn.allowance(0) - 50, drawn.allowance(1) - 10);
  EXPECT_EQ(drawn.allowance(0) + drawn.allowance(1), 100);
  // The baseline ignores every report.
  QueryBudget even(100, 2, 0.25, QueryBudget::Policy::even);
  even.report(0, 20, 40, 20, 60);
  even.report(1, 20, 40, 0, 60);
  even.split();
  EXPECT_EQ(even.allowance(0), 50);
  EXPECT_EQ(even.allowance(1), 50);
  EXPECT_THROW(QueryBudget(1, 2), InputError);
}

TEST(QueryBudget, ByDefaultEachViewIsSureOfAnEvenShareAndWhatOneDoesNotNeedGoesToTheOthers) {
  QueryBudget lend(100, 2);
  lend.report(0, 10, 20, 0, 0);     // needs 30 of its 50
  lend.report(1, 10, 100, 0, 100);  // needs 210
  lend.split();
  EXPECT_EQ(lend.allowance(0), 30);
  EXPECT_EQ(lend.allowance(1), 70);
  // Both need more than an even share: even shares, whatever their rates.
  QueryBudget both(100, 2);
  for (int frame = 0; frame < 10; ++frame) {
    both.report(0, 10, 100, 50, 100);
    both.report(1, 10, 100, 0, 100);
    both.split();
  }
  EXPECT_GT(both.reveal_rate(0), 10 * both.reveal_rate(1));
  EXPECT_EQ(both.allowance(0), 50);
  EXPECT_EQ(both.allowance(1), 50);
}

TEST(QueryBudget, RevealRatesFarBelowOnePercentStillDecideTheSplit) {
  // City street beside turn: the turning view's re-queries find a hidden
  // cell visible about 4 times in 1000, the street view's about 4 in 10000.
  QueryBudget b(4000, 2, 0.25);
  for (int frame = 0; frame < 40; ++frame) {
    b.report(0, 500, 1000, 4, 600);
    b.report(1, 500, 2000, frame % 3 == 0 ? 1 : 0, 2000);
    b.split();
  }
  EXPECT_GT(b.reveal_rate(0), 5 * b.reveal_rate(1));
  EXPECT_EQ(b.allowance(0), 500 + 1600) << "view 0 gets all it asks for";
  EXPECT_EQ(b.allowance(0) + b.allowance(1), 4000);
}

TEST(QueryBudget, AViewWhoseDemandComesInBurstsKeepsAnAllowanceForItsRecentPeak) {
  // Hidden answers expire together, so a view asks for many re-queries every
  // few frames and few in between; last frame's demand would cap the burst.
  QueryBudget b(4000, 2, 0.25);
  for (int frame = 0; frame < 40; ++frame) {
    const bool burst = frame % 4 == 0;
    b.report(0, 300, burst ? 1700 : 100, burst ? 7 : 0, 0);
    b.report(1, 500, 2000, 1, 3000);
    b.split();
    EXPECT_GE(b.allowance(0), 2000) << "after frame " << frame;
  }
}

TEST(GridViews, ViewsShareOneGridAndTheViewWhoseHiddenCellsComeIntoSightGetsTheLargerShare) {
  Stage s;
  Options o;
  o.set("grid.cell=2");
  o.set("grid.cap=6");
  o.set("grid.vis_duration=1");
  o.set("grid.split=reveal");
  o.set("grid.split_floor=0.25");  // both views ask for more than half the cap: let the rate split most of it
  // Both views look past the wall. In view 0 the wall comes and goes (every
  // other frame everything is visible), so re-queries of its hidden cells
  // find them visible again; in view 1 the wall stands.
  int frame = 0;
  test::ScriptedBackend flicker, steady;
  flicker.visible_samples = [&frame](std::span<const Aabb> boxes) {
    return frame % 2 == 0 ? std::uint64_t(boxes.size()) : behind_wall(boxes);
  };
  steady.visible_samples = behind_wall;
  GridViews views({s.scene, s.bvh}, 2, o);
  EXPECT_EQ(views.grid().occupied(), UniformGrid::of_scene(s.scene, 2.0f).occupied());
  for (frame = 1; frame <= 20; ++frame) {
    views.begin_frame();
    steady.rendered.clear();
    views.view(0).render_frame(s.view, flicker);
    views.view(1).render_frame(s.view, steady);
    EXPECT_EQ(times_drawn(steady, 0), 1u) << "frame " << frame;
    EXPECT_EQ(times_drawn(steady, 3), 0u) << "frame " << frame;
  }
  // Of view 0's re-queries, those that drew the box behind the wall count
  // (its other cells hold nothing undrawn); view 1's reveal nothing.
  EXPECT_GT(views.budget().reveal_rate(0), 2 * views.budget().reveal_rate(1));
  EXPECT_LT(views.budget().reveal_rate(1), 0.02);
  EXPECT_GT(views.budget().allowance(0), views.budget().allowance(1));
  EXPECT_LE(views.budget().allowance(0) + views.budget().allowance(1), 6);
}
