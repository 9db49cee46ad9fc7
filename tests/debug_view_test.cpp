// The debug views without GL: the frame log, the query outcomes, and what
// each picture holds.
#include "occull/debug_view.hpp"
#include "occull/error.hpp"
#include "occull/frame_log.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

using namespace occull;

namespace {

// Three unit boxes down -Z: objects 0, 1, 2 at z = -5, -10, -15.
Scene three_boxes() {
  return test::box_scene({{{-0.5f, -0.5f, -5.5f}, {0.5f, 0.5f, -4.5f}},
                          {{-0.5f, -0.5f, -10.5f}, {0.5f, 0.5f, -9.5f}},
                          {{-0.5f, -0.5f, -15.5f}, {0.5f, 0.5f, -14.5f}}});
}

Aabb around(const Scene& s, ObjectId id) { return s.object(id).bounds.grown(0.1f); }

View front_view() { return make_view({{0, 0, 0}, 0, 0}, {60, 0.1f, 100}, 64, 36); }

}  // namespace

TEST(FrameLog, LogsCallsInOrderWithAnswersAndConditionalDraws) {
  test::ScriptedBackend inner;
  inner.conditional = true;
  inner.visible_samples = [](std::span<const Aabb>) { return std::uint64_t(7); };
  FrameLog log;
  LoggingBackend b(inner);
  b.log_into(&log);
  const ObjectId first[] = {0, 1};
  b.render(first);
  const Aabb box{{0, 0, 0}, {1, 1, 1}};
  const QueryId q = b.issue_query(std::span<const Aabb>(&box, 1));
  const ObjectId second[] = {2};
  b.render_conditional(second, q, ConditionalWait::wait);
  EXPECT_EQ(b.result(q), 7u);
  ASSERT_EQ(log.draws.size(), 2u);
  ASSERT_EQ(log.queries.size(), 1u);
  EXPECT_EQ(log.draws[0].objects, (std::vector<ObjectId>{0, 1}));
  EXPECT_EQ(log.draws[0].event, 0u);
  EXPECT_EQ(log.draws[0].query, -1);
  EXPECT_EQ(log.queries[0].issued, 1u);
  EXPECT_EQ(log.draws[1].query, 0);
  EXPECT_EQ(log.draws[1].event, 2u);
  ASSERT_TRUE(log.queries[0].samples.has_value());
  EXPECT_EQ(*log.queries[0].samples, 7u);
  EXPECT_EQ(log.queries[0].answered, 3u);
  EXPECT_EQ(log.events, 4u);
  EXPECT_EQ(inner.rendered, (std::vector<ObjectId>{0, 1, 2}));  // everything forwarded
}

TEST(FrameLog, AQueryOfAnEarlierFrameIsForwardedButNotLogged) {
  test::ScriptedBackend inner;
  const Aabb box{{0, 0, 0}, {1, 1, 1}};
  const QueryId old = inner.issue_query(std::span<const Aabb>(&box, 1));
  FrameLog log;
  LoggingBackend b(inner);
  b.log_into(&log);
  EXPECT_EQ(b.result(old), 1u);
  EXPECT_TRUE(log.queries.empty());
  EXPECT_EQ(inner.read, (std::vector<QueryId>{old}));
}

TEST(FrameLog, WithoutALogItOnlyForwardsAndANewLogStartsEmpty) {
  test::ScriptedBackend inner;
  LoggingBackend b(inner);
  const Aabb box{{0, 0, 0}, {1, 1, 1}};
  const QueryId q = b.issue_query(std::span<const Aabb>(&box, 1));  // not logged
  FrameLog log;
  b.log_into(&log);
  EXPECT_EQ(b.result(q), 1u);
  const ObjectId one[] = {1};
  b.render(one);
  EXPECT_TRUE(log.queries.empty());
  ASSERT_EQ(log.draws.size(), 1u);
  b.log_into(nullptr);
  b.render(one);
  EXPECT_EQ(log.draws.size(), 1u);
  EXPECT_EQ(inner.rendered, (std::vector<ObjectId>{1, 1}));
}

TEST(DebugView, QueryOutcomesFollowTheOrderOfAnswersAndDraws) {
  const Scene s = three_boxes();
  FrameLog log;
  // q0: hidden. q1: visible, its object drawn before the answer (wasted).
  // q2: visible, its object drawn after the answer (visible). q3: never read.
  log.queries.push_back({{around(s, 0)}, 0, 0, 1});
  log.draws.push_back({{1}, 2, -1});
  log.queries.push_back({{around(s, 1)}, 3, 5, 4});
  log.queries.push_back({{around(s, 2)}, 5, 9, 6});
  log.draws.push_back({{2}, 7, -1});
  log.queries.push_back({{around(s, 0)}, 8, std::nullopt, 0});
  EXPECT_EQ(classify_queries(s, log), (std::vector<QueryOutcome>{QueryOutcome::occluded, QueryOutcome::wasted,
                                                                  QueryOutcome::visible, QueryOutcome::unanswered}));
}

TEST(DebugView, ADrawConditionalOnAQueryMakesItVisible) {
  const Scene s = three_boxes();
  FrameLog log;
  log.queries.push_back({{around(s, 2)}, 0, 3, 2});
  log.draws.push_back({{2}, 1, 0});  // before the answer, but on the device's answer
  EXPECT_EQ(classify_queries(s, log), (std::vector<QueryOutcome>{QueryOutcome::visible}));
}

TEST(DebugView, AnObjectOutsideAVisibleQuerysBoxesDoesNotMakeItUseful) {
  const Scene s = three_boxes();
  FrameLog log;
  log.queries.push_back({{around(s, 2)}, 0, 3, 1});
  log.draws.push_back({{0, 1}, 2, -1});  // after the answer, but other objects
  EXPECT_EQ(classify_queries(s, log), (std::vector<QueryOutcome>{QueryOutcome::wasted}));
}

TEST(DebugView, QueriesPictureLayersOccludedBoxesOverTheRest) {
  const Scene s = three_boxes();
  const View v = front_view();
  FrameLog log;
  log.queries.push_back({{around(s, 2)}, 0, 0, 1});
  log.queries.push_back({{around(s, 1)}, 2, 1, 3});
  const DebugFrame f{s, v, log, {}, {}, {}};
  const Picture p = make_picture(DebugView::queries, f, 16.0f / 9.0f);
  ASSERT_EQ(p.boxes.size(), 2u);
  EXPECT_TRUE(p.frame_background);
  EXPECT_EQ(p.boxes.back().color, palette::occluded);
  EXPECT_GT(p.boxes.back().layer, p.boxes.front().layer);
  EXPECT_EQ(p.boxes.front().color, palette::wasted);
}

TEST(DebugView, BatchesCountTheStateChangesOfTheLog) {
  const Scene s = three_boxes();
  const View v = front_view();
  FrameLog log;
  // render, query, query, render, query: 3 changes, 2 render and 2 query batches.
  log.draws.push_back({{0}, 0, -1});
  log.queries.push_back({{around(s, 1)}, 1, 1, 5});
  log.queries.push_back({{around(s, 2)}, 2, 1, 6});
  log.draws.push_back({{1}, 3, -1});
  log.queries.push_back({{around(s, 2)}, 4, 1, 7});
  const DebugFrame f{s, v, log, {}, {}, {}};
  const Picture p = make_picture(DebugView::batches, f, 1.0f);
  ASSERT_EQ(p.legend.size(), 3u);
  EXPECT_EQ(p.legend[0].count, 2u);
  EXPECT_EQ(p.legend[1].count, 2u);
  EXPECT_EQ(p.legend[2].count, 3u);
  ASSERT_EQ(p.objects.size(), 2u);
  EXPECT_NE(p.objects[0].color, p.objects[1].color);  // different batches
  EXPECT_EQ(p.lines.size(), 3u * 12u);                 // every queried box's edges
}

TEST(DebugView, OverviewColoursEachObjectByWhatHappenedToIt) {
  Scene s = three_boxes();
  s.add_object(s.add_mesh(test::box_mesh({{-0.5f, -0.5f, 4.5f}, {0.5f, 0.5f, 5.5f}})), 0, glm::mat4(1.0f),
               OccluderClass::always);  // object 3: behind the eye
  const View v = front_view();
  const FrameLog log;
  const ObjectId drawn[] = {0};
  const ObjectId truth[] = {0, 1};  // 1 visible but not drawn: missed
  const DebugFrame f{s, v, log, {}, drawn, truth};
  const Picture p = make_picture(DebugView::overview, f, 1.0f);
  EXPECT_FALSE(p.frame_background);
  std::map<ObjectId, glm::vec3> color;
  for (const auto& o : p.objects) color[o.id] = o.color;
  EXPECT_EQ(color.at(0), palette::drawn);
  EXPECT_EQ(color.at(1), palette::missed);
  EXPECT_EQ(color.at(2), palette::occlusion_culled);
  EXPECT_EQ(color.at(3), palette::frustum_culled);
  EXPECT_EQ(p.objects.back().id, 1u);  // missed ones are drawn last
  EXPECT_EQ(p.lines.size(), 12u);      // the frustum's edges
}

TEST(DebugView, RegionsAreFootprintsFromAboveGreenWhenDrawnOverRedWhenHidden) {
  const Scene s = three_boxes();
  const View v = front_view();
  const FrameLog log;
  const CullRegion regions[] = {{around(s, 0), false}, {around(s, 1), true}};
  const DebugFrame f{s, v, log, regions, {}, {}};
  const Picture p = make_picture(DebugView::cells, f, 1.0f);
  ASSERT_EQ(p.boxes.size(), 2u);
  EXPECT_EQ(p.boxes[0].color, palette::occluded);
  EXPECT_EQ(p.boxes[1].color, palette::visible);
  EXPECT_LT(p.boxes[0].layer, p.boxes[1].layer);  // drawn over hidden
  EXPECT_EQ(p.boxes[0].box.min.y, p.boxes[0].box.max.y);  // footprints, seen from above
  EXPECT_FALSE(p.frame_background);
  EXPECT_EQ(p.legend.at(0).count, 1u);
  EXPECT_EQ(p.legend.at(1).count, 1u);
}

TEST(DebugView, UnknownViewNamesListTheValidOnes) {
  EXPECT_EQ(parse_debug_view("overview"), DebugView::overview);
  try {
    (void)parse_debug_view("wireframe");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("color, queries, multiqueries, batches, overview, cells, tiles"),
              std::string::npos)
        << e.what();
  }
}
