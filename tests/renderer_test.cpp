// GL integration tests: the reference renderer on llvmpipe (or any GL 4.5
// driver), small frames.
#include "gl/gl.hpp"
#include "gl/renderer_impl.hpp"
#include "occull/error.hpp"
#include "occull/gl/context.hpp"
#include "occull/gl/renderer.hpp"
#include "occull/recording_backend.hpp"
#include "occull/lab.hpp"
#include "gl_test_util.hpp"
#include "test_util.hpp"

#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <set>

using namespace occull;

namespace {

constexpr int kSize = 128;

// Camera at the origin looking down -Z; a 6 x 6 wall 10 m ahead hides a
// small box 20 m ahead; another box 20 m ahead and 8 m right is in plain view.
struct WallScene {
  static constexpr ObjectId wall = 0, hidden = 1, beside = 2;
  Scene scene = test::box_scene({{{-3, -3, -11}, {3, 3, -10}},
                                 {{-1, -1, -21}, {1, 1, -19}},
                                 {{7, -1, -21}, {9, 1, -19}}});
  View view = make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.1f, 100.0f}, kSize, kSize);
};

class RendererTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { context_ = gl::Context::create(); }
  static void TearDownTestSuite() { context_.reset(); }
  static std::unique_ptr<gl::Context> context_;

  static gl::RendererOptions small() {
    gl::RendererOptions o;
    o.width = kSize;
    o.height = kSize;
    return o;
  }
};
std::unique_ptr<gl::Context> RendererTest::context_;

// Starts a frame of the wall scene with the wall already drawn.
void begin_with_wall(gl::Renderer& r, const WallScene& w) {
  r.begin_frame(w.view);
  const ObjectId wall[] = {WallScene::wall};
  r.render(wall);
}

using test::ids_in;

}  // namespace

TEST_F(RendererTest, ContextIsOpenGL45Core) {
  const auto info = context_->info();
  EXPECT_NE(info.version.find("4.5"), std::string::npos) << info.version;
  EXPECT_GT(info.samples_passed_bits, 0);
}

TEST_F(RendererTest, BoxBehindOccluderHasNoSamplesAndVisibleBoxHasSome) {
  WallScene w;
  gl::Renderer r(w.scene, small());
  begin_with_wall(r, w);
  const Aabb hidden[] = {w.scene.object(WallScene::hidden).bounds};
  const Aabb beside[] = {w.scene.object(WallScene::beside).bounds};
  const QueryId qh = r.issue_query(hidden);
  const QueryId qb = r.issue_query(beside);
  EXPECT_EQ(r.result(qh), 0u);
  EXPECT_GT(r.result(qb), 0u);
  r.end_frame();
  EXPECT_EQ(r.queries_in_flight(), 0u);
}

TEST_F(RendererTest, AQueryNotInFlightIsRefusedLoudly) {
  // Read twice, a query would go back to the pool twice and later be handed
  // to two users at once.
  WallScene w;
  gl::Renderer r(w.scene, small());
  begin_with_wall(r, w);
  const Aabb beside[] = {w.scene.object(WallScene::beside).bounds};
  const QueryId q = r.issue_query(beside);
  EXPECT_GT(r.result(q), 0u);
  EXPECT_THROW((void)r.result(q), std::logic_error);
  EXPECT_THROW((void)r.result_available(q), std::logic_error);
  EXPECT_THROW((void)r.result(q + 100), std::logic_error);  // never issued
  const QueryId a = r.issue_query(beside), b = r.issue_query(beside);
  EXPECT_NE(a, b);  // the pool still hands out distinct queries
  (void)r.result(a);
  (void)r.result(b);
  r.end_frame();
  EXPECT_EQ(r.queries_in_flight(), 0u);
}

TEST_F(RendererTest, MultiBoxQueryCountsTheUnion) {
  WallScene w;
  gl::Renderer r(w.scene, small());
  begin_with_wall(r, w);
  const Aabb both[] = {w.scene.object(WallScene::hidden).bounds, w.scene.object(WallScene::beside).bounds};
  const Aabb beside[] = {w.scene.object(WallScene::beside).bounds};
  const QueryId q2 = r.issue_query(both);
  const QueryId q1 = r.issue_query(beside);
  EXPECT_EQ(r.result(q2), r.result(q1));
  r.end_frame();
  EXPECT_EQ(r.stats().query_boxes, 3u);
}

TEST_F(RendererTest, ThousandQueriesAllReadBackCorrectly) {
  WallScene w;
  gl::Renderer r(w.scene, small());
  begin_with_wall(r, w);
  std::vector<QueryId> queries;
  std::vector<bool> expect_visible;
  for (int i = 0; i < 1000; ++i) {
    // Small boxes 20 m away: even ones behind the wall, odd ones beside it.
    const float x = (i % 2 == 0) ? -2.0f + 0.004f * float(i) : 6.0f + 0.002f * float(i);
    const Aabb box[] = {{{x - 0.2f, -0.2f, -20.5f}, {x + 0.2f, 0.2f, -19.5f}}};
    queries.push_back(r.issue_query(box));
    expect_visible.push_back(i % 2 == 1);
  }
  for (std::size_t i = 0; i < queries.size(); ++i)
    EXPECT_EQ(r.result(queries[i]) > 0, expect_visible[i]) << "query " << i;
  r.end_frame();
  EXPECT_EQ(r.stats().queries, 1000u);
}

TEST_F(RendererTest, QueryBoxesPastOneFillOfTheirStreamBufferAreDrawn) {
  // Frames with queries, then one without, then a query of more boxes than
  // two fills of the stream buffer (each fill fresh storage): hidden boxes
  // behind the wall and, last, one beside it.
  WallScene w;
  gl::Renderer r(w.scene, small());
  const Aabb hidden = w.scene.object(WallScene::hidden).bounds, beside = w.scene.object(WallScene::beside).bounds;
  for (int frame = 0; frame < 3; ++frame) {
    begin_with_wall(r, w);
    if (frame != 1) {
      const Aabb one[] = {beside};
      EXPECT_GT(r.result(r.issue_query(one)), 0u) << "frame " << frame;
    }
    r.end_frame();
  }
  begin_with_wall(r, w);
  std::vector<Aabb> boxes(std::size_t(2 * gl::detail::kBoxCapacity + 5), hidden);
  EXPECT_EQ(r.result(r.issue_query(boxes)), 0u);
  boxes.back() = beside;
  EXPECT_GT(r.result(r.issue_query(boxes)), 0u) << "the last box, in the third fill, is drawn";
  const Aabb one[] = {beside};
  EXPECT_GT(r.result(r.issue_query(one)), 0u);
  r.end_frame();
}

TEST_F(RendererTest, ResultAvailableTurnsTrueAfterFinish) {
  WallScene w;
  gl::Renderer r(w.scene, small());
  r.begin_frame(w.view);
  const Aabb beside[] = {w.scene.object(WallScene::beside).bounds};
  const QueryId q = r.issue_query(beside);
  r.end_frame();  // glFinish: everything done
  EXPECT_TRUE(r.result_available(q));
  EXPECT_GT(r.result(q), 0u);
}

TEST_F(RendererTest, FlushesCountSubmissionsIncludingPollsOfUnsubmittedQueries) {
  WallScene w;
  gl::Renderer r(w.scene, small());
  r.begin_frame(w.view);
  const Aabb beside[] = {w.scene.object(WallScene::beside).bounds};
  const auto flushes = [&] { return r.stats().flushes; };
  const QueryId a = r.issue_query(beside);
  const QueryId b = r.issue_query(beside);
  EXPECT_EQ(flushes(), 0u);
  (void)r.result_available(a);  // not yet submitted: the driver flushes
  EXPECT_EQ(flushes(), 1u);
  (void)r.result_available(b);  // submitted by that same flush
  (void)r.result_available(a);
  EXPECT_EQ(flushes(), 1u);
  const QueryId c = r.issue_query(beside);
  r.flush();
  EXPECT_EQ(flushes(), 2u);
  (void)r.result(c);  // submitted by the explicit flush
  EXPECT_EQ(flushes(), 2u);
  const QueryId d = r.issue_query(beside);
  (void)r.result(d);  // a read of an unsubmitted query flushes too
  EXPECT_EQ(flushes(), 3u);
  (void)r.result(a);
  (void)r.result(b);
  r.end_frame();
}

TEST_F(RendererTest, BoxCrossingTheNearPlaneIsVisible) {
  WallScene w;
  gl::Renderer r(w.scene, small());
  begin_with_wall(r, w);
  // In front of the wall, its near face behind the eye's near plane.
  const Aabb box[] = {{{-0.5f, -0.5f, -3.0f}, {0.5f, 0.5f, 0.05f}}};
  const QueryId q = r.issue_query(box);
  EXPECT_GT(r.result(q), 0u);
  r.end_frame();
}

TEST_F(RendererTest, StateChangesCountSwitchesBetweenRenderingAndQuerying) {
  WallScene w;
  gl::Renderer r(w.scene, small());
  r.begin_frame(w.view);
  const ObjectId wall[] = {WallScene::wall};
  const Aabb box[] = {w.scene.object(WallScene::beside).bounds};
  r.render(wall);                       // already in render state: no change
  const QueryId a = r.issue_query(box);  // 1
  const QueryId b = r.issue_query(box);  // still querying
  r.render(wall);                       // 2
  r.result(a);
  r.result(b);
  r.end_frame();
  EXPECT_EQ(r.stats().state_changes, 2u);
  EXPECT_EQ(r.stats().render_flushes, 2u);
  EXPECT_EQ(r.stats().draw_calls, 2u);
  EXPECT_EQ(r.stats().triangles, 24u);
}

TEST_F(RendererTest, IdBufferHoldsTheVisibleObjects) {
  WallScene w;
  gl::Renderer r(w.scene, small());
  r.begin_frame(w.view);
  const ObjectId all[] = {0, 1, 2};
  r.render(all);
  r.end_frame();
  const auto ids = r.read_ids();
  ASSERT_EQ(ids.size(), std::size_t(kSize * kSize));
  EXPECT_EQ(ids_in(ids), (std::set<ObjectId>{WallScene::wall, WallScene::beside}));
  // The centre pixel shows the wall.
  EXPECT_EQ(ids[std::size_t(kSize / 2 * kSize + kSize / 2)], WallScene::wall + 1);
}

// Conditional rendering. The box beside the wall, drawn on the condition of
// the hidden box's query, must not reach the image nor the frame's record
// (a RecordingBackend over the renderer, settled by unread_result where the
// query is still in flight at the frame's end); the hidden box, drawn on the
// visible query of the box beside, is drawn (and recorded) but stays behind
// the wall. Both wait modes, with the queries read before and after end_frame().
TEST_F(RendererTest, ConditionalDrawsTakeEffectOnlyWhereTheirQueryPassed) {
  WallScene w;
  gl::Renderer r(w.scene, small());
  RecordingBackend rec(r, w.scene);
  ASSERT_TRUE(rec.conditional_rendering());
  r.set_write_ids(true);
  for (const ConditionalWait wait : {ConditionalWait::wait, ConditionalWait::no_wait}) {
    for (const bool read_before_end : {true, false}) {
      const std::string where = fmt::format("wait {}, read before end {}", int(wait), read_before_end);
      const BackendStats before = r.stats();
      r.begin_frame(w.view);
      rec.start_frame();
      const ObjectId wall[] = {WallScene::wall};
      rec.render(wall);
      const ObjectId hidden[] = {WallScene::hidden}, beside[] = {WallScene::beside};
      const Aabb hidden_box[] = {w.scene.object(WallScene::hidden).bounds};
      const Aabb beside_box[] = {w.scene.object(WallScene::beside).bounds};
      const QueryId qh = rec.issue_query(hidden_box);
      const QueryId qb = rec.issue_query(beside_box);
      // no_wait draws while a result is unknown: wait for both first.
      for (int polls = 0; !(rec.result_available(qh) && rec.result_available(qb)); ++polls)
        ASSERT_LT(polls, 1000000) << where;
      rec.render_conditional(beside, qh, wait);
      rec.render_conditional(hidden, qb, wait);
      if (read_before_end) {
        EXPECT_EQ(rec.result(qh), 0u);
        EXPECT_GT(rec.result(qb), 0u);
      }
      r.end_frame();
      rec.finish_frame([&](QueryId q) { return r.unread_result(q); });
      const std::set<ObjectId> drawn(rec.objects().begin(), rec.objects().end());
      EXPECT_EQ(drawn, (std::set<ObjectId>{WallScene::wall, WallScene::hidden})) << where;
      EXPECT_EQ(ids_in(r.read_ids()), (std::set<ObjectId>{WallScene::wall})) << where;
      const BackendStats d = r.stats() - before;
      EXPECT_EQ(d.conditional_objects, 2u) << where;
      EXPECT_EQ(d.conditional_skipped, 1u) << where;
      if (!read_before_end) {
        EXPECT_EQ(rec.result(qh), 0u);
        EXPECT_GT(rec.result(qb), 0u);
      }
    }
  }
  EXPECT_EQ(r.queries_in_flight(), 0u);
}

TEST_F(RendererTest, ScreenshotHasTheObjectsOverTheBackground) {
  WallScene w;
  gl::RendererOptions o = small();
  o.background = {0.0f, 0.0f, 1.0f};
  gl::Renderer r(w.scene, o);
  r.begin_frame(w.view);
  const ObjectId all[] = {0, 1, 2};
  r.render(all);
  r.end_frame();
  const auto rgba = r.read_rgba();
  ASSERT_EQ(rgba.size(), std::size_t(kSize * kSize * 4));
  std::size_t background = 0, object = 0;
  for (std::size_t i = 0; i < rgba.size(); i += 4) {
    if (rgba[i] == 0 && rgba[i + 1] == 0 && rgba[i + 2] == 255) ++background; else ++object;
  }
  // The wall spans about atan(3/10) of a 30 degree half-angle: ~ 33% x 33%... of the frame.
  EXPECT_GT(object, std::size_t(kSize * kSize / 10));
  EXPECT_GT(background, std::size_t(kSize * kSize / 2));
  // Top-left corner is background; centre is an object (image rows start at the top).
  EXPECT_EQ(rgba[2], 255);
  const std::size_t centre = std::size_t((kSize / 2 * kSize + kSize / 2) * 4);
  EXPECT_FALSE(rgba[centre] == 0 && rgba[centre + 1] == 0 && rgba[centre + 2] == 255);
}

TEST_F(RendererTest, TranslucentObjectsNeitherOccludeNorWriteIds) {
  const Scene scene = test::glass_scene();
  const View view = make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.1f, 100.0f}, kSize, kSize);
  gl::Renderer r(scene, small());
  r.begin_frame(view);
  const ObjectId glass_pane[] = {0};
  r.render(glass_pane);
  const Aabb behind[] = {scene.object(1).bounds};
  const QueryId q = r.issue_query(behind);
  EXPECT_GT(r.result(q), 0u) << "glass must not hide what is behind it";
  const ObjectId box[] = {1};
  r.render(box);
  r.end_frame();
  EXPECT_EQ(ids_in(r.read_ids()), std::set<ObjectId>{1});
}

TEST_F(RendererTest, DynamicObjectsAreDrawnWhereTheyAreNow) {
  Scene scene("moving");
  const MaterialId grey = scene.add_material({"grey", {0.6f, 0.6f, 0.6f, 1.0f}, false, 0});
  const auto at = [](float x) { return glm::translate(glm::mat4(1.0f), {x, 0.0f, -20.0f}); };
  scene.add_dynamic_object(scene.add_mesh(test::box_mesh({{-1, -1, -1}, {1, 1, 1}})), grey, at(-30.0f),
                           OccluderClass::never);
  const View view = make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.1f, 100.0f}, kSize, kSize);
  for (const bool multi : {false, true}) {  // matrices as uniforms, and from the object buffer
    gl::RendererOptions o = small();
    o.draw = multi ? gl::DrawMode::multi : gl::DrawMode::single;
    gl::Renderer r(scene, o);
    const ObjectId obj[] = {0};
    scene.set_transform(0, at(-30.0f));  // far left: outside the view
    r.begin_frame(view);
    r.render(obj);
    r.end_frame();
    EXPECT_TRUE(ids_in(r.read_ids()).empty()) << "multi " << multi;
    scene.set_transform(0, at(0.0f));  // straight ahead
    r.begin_frame(view);
    r.render(obj);
    r.end_frame();
    EXPECT_EQ(ids_in(r.read_ids()), std::set<ObjectId>{0}) << "multi " << multi;
  }
}

TEST_F(RendererTest, QueryNamesAreReusedAfterResults) {
  WallScene w;
  gl::Renderer r(w.scene, small());
  const Aabb box[] = {w.scene.object(WallScene::beside).bounds};
  for (int frame = 0; frame < 3; ++frame) {
    r.begin_frame(w.view);
    for (int i = 0; i < 10; ++i) EXPECT_GT(r.result(r.issue_query(box)), 0u);
    r.end_frame();
  }
  EXPECT_EQ(r.queries_in_flight(), 0u);
}

TEST_F(RendererTest, GpuTimeOfAFrameThatDrawsIsPositiveWhereTheDeviceHasATimer) {
  WallScene w;
  gl::Renderer r(w.scene, small());
  r.begin_frame(w.view);
  const ObjectId all[] = {0, 1, 2};
  r.render(all);
  const double gpu_ms = r.end_frame();
  if (context_->info().time_elapsed_bits == 0) {
    EXPECT_EQ(gpu_ms, 0.0) << "no timer: reported as 0";
  } else {
    EXPECT_GT(gpu_ms, 0.0) << "a frame that drew has taken some GPU time";
    EXPECT_LT(gpu_ms, 60'000.0) << "a minute for three boxes: not a time in milliseconds";
  }
}

TEST_F(RendererTest, EveryDrawModeGivesTheSamePixels) {
  // Four boxes, then a row of 20 more: runs of one material both shorter and
  // longer than the renderer's shortest multi-draw (kMinMultiDrawRun, 16).
  std::vector<Aabb> boxes = {{{-3, -3, -11}, {3, 3, -10}},
                             {{-1, -1, -21}, {1, 1, -19}},
                             {{7, -1, -21}, {9, 1, -19}},
                             {{-9, -2, -30}, {-5, 2, -25}}};
  for (int i = 0; i < 20; ++i)
    boxes.push_back({{-10.0f + float(i), 14.0f, -40.0f}, {-9.5f + float(i), 14.5f, -39.0f}});
  Scene scene = test::box_scene(boxes);
  const View view = make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.1f, 100.0f}, kSize, kSize);
  std::vector<std::uint32_t> images[3];
  std::vector<std::uint8_t> colours[3];
  std::vector<float> depths[3];
  for (int multi = 0; multi < 3; ++multi) {  // single, multi, indirect
    gl::RendererOptions o = small();
    o.draw = gl::DrawMode(multi);
    gl::Renderer r(scene, o);
    std::vector<ObjectId> row;
    for (ObjectId id = 4; id < 24; ++id) row.push_back(id);
    for (int frame = 0; frame < 2; ++frame) {  // the second frame reuses the indirect buffer
      r.begin_frame(view);
      const ObjectId four[] = {3, 0, 2, 1};
      r.render(four);  // a short run
      r.render(row);   // a long one: one multi-draw
      r.end_frame();
    }
    images[multi] = r.read_ids();
    colours[multi] = r.read_rgba();
    depths[multi] = r.read_depth();
    EXPECT_EQ(r.stats().draw_calls, 48u);
  }
  // The three programs fetch per-draw data differently (uniforms / object
  // buffer / instanced attributes): the ids, colours and depths must not
  // differ by a bit.
  for (int mode : {1, 2}) {
    EXPECT_EQ(images[0], images[mode]) << "mode " << mode;
    EXPECT_EQ(colours[0], colours[mode]) << "mode " << mode;
    EXPECT_EQ(depths[0], depths[mode]) << "mode " << mode;
  }
  std::set<ObjectId> expected{0, 2, 3};
  for (ObjectId id = 4; id < 24; ++id) expected.insert(id);
  EXPECT_EQ(ids_in(images[1]), expected);
}

TEST_F(RendererTest, BoxAroundTheEyeIsVisible) {
  WallScene w;
  gl::Renderer r(w.scene, small());
  begin_with_wall(r, w);
  // The eye inside a big box whose far faces lie behind the wall.
  const Aabb around[] = {{{-50, -50, -50}, {50, 50, 50}}};
  const QueryId q = r.issue_query(around);
  EXPECT_GT(r.result(q), 0u);
  r.end_frame();
}

TEST_F(RendererTest, QueryCountsEachVisiblePixelOnce) {
  // Nothing drawn: a box face-on fills its projected area once (back faces culled).
  WallScene w;
  gl::Renderer r(w.scene, small());
  r.begin_frame(w.view);
  const Aabb box[] = {w.scene.object(WallScene::wall).bounds};
  const std::uint64_t samples = r.result(r.issue_query(box));
  r.end_frame();
  const double area = projected_area(box[0], w.view.view_proj, kSize, kSize);
  EXPECT_NEAR(double(samples), area, 0.1 * area);
}

// GL state belongs to whoever draws: a second renderer in the same context
// (as NOHC's calibration makes) binds its own buffers and, when destroyed,
// deletes them — which unbinds whatever binding points they held. The first
// renderer must establish its own state per frame and per pass.
TEST_F(RendererTest, AnotherRendererInTheSameContextChangesNothing) {
  WallScene w;
  gl::Renderer a(w.scene, small());
  const ObjectId all[] = {0, 1, 2};
  const auto frame_of_a = [&] {
    a.begin_frame(w.view);
    a.render(all);
    const Aabb hidden[] = {w.scene.object(WallScene::hidden).bounds};
    EXPECT_EQ(a.result(a.issue_query(hidden)), 0u);
    a.end_frame();
    return std::make_pair(a.read_ids(), a.read_rgba());
  };
  const auto truth_before = a.visible_pixels(w.view, all);
  const auto frame_before = frame_of_a();
  ASSERT_EQ(truth_before.size(), 2u);
  {
    // Another scene, size, query target and culling mode, used then destroyed.
    const Scene other = test::box_scene({{{-20, -20, -40}, {20, 20, -30}}});
    gl::RendererOptions o;
    o.width = 48;
    o.height = 32;
    o.query_mode = gl::QueryMode::any_samples_passed;
    o.cull_backfaces = false;
    o.draw = gl::DrawMode::multi;
    gl::Renderer b(other, o);
    const View v = make_view({{0, 0, 0}, 0.3f, 0.1f}, {90.0f, 0.5f, 50.0f}, 48, 32);
    b.begin_frame(v);
    const ObjectId obj[] = {0};
    b.render(obj);
    const Aabb box[] = {other.object(0).bounds};
    (void)b.result(b.issue_query(box));
    b.end_frame();
  }
  EXPECT_EQ(a.visible_pixels(w.view, all), truth_before);
  const auto frame_after = frame_of_a();
  EXPECT_TRUE(frame_after.first == frame_before.first) << "id image changed";
  EXPECT_TRUE(frame_after.second == frame_before.second) << "colour image changed";
}

// With back-face culling off, a closed box seen from inside shows its inner
// faces — also after a query pass, which culls the back faces of its boxes.
TEST_F(RendererTest, BackFacesStayDrawnAfterAQueryWhenCullingIsOff) {
  const Scene scene = test::box_scene({{{-5, -5, -5}, {5, 5, 5}}});
  gl::RendererOptions o = small();
  o.cull_backfaces = false;
  gl::Renderer r(scene, o);
  const View view = make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.1f, 100.0f}, kSize, kSize);
  r.begin_frame(view);
  const Aabb far_box[] = {{{-1, -1, -30}, {1, 1, -29}}};
  (void)r.result(r.issue_query(far_box));
  const ObjectId room[] = {0};
  r.render(room);
  r.end_frame();
  const auto ids = r.read_ids();
  EXPECT_EQ(std::count(ids.begin(), ids.end(), 1u), std::ptrdiff_t(ids.size()))
      << "every pixel shows the inside of the box";
}

namespace {

// 90 degrees on a 64 x 64 target: at 32 m, one metre is one pixel, so box
// faces there end exactly on pixel boundaries.
struct PixelGrid {
  static constexpr int kSide = 64;
  View view = make_view({{0, 0, 0}, 0, 0}, {90.0f, 0.5f, 100.0f}, kSide, kSide);
  // A 16 x 16 px box face-on at 32 m (pixels 24..40), 1 m deep.
  Aabb box{{-8, -8, -33}, {8, 8, -32}};
};

// Samples of `box`'s query with an occluder in front of it that spans
// `occluder_half` metres (= pixels) either side of the centre.
std::uint64_t samples_around_occluder(float margin, float occluder_half, gl::QueryRaster raster) {
  PixelGrid g;
  const Scene scene = test::box_scene({{{-occluder_half, -occluder_half, -31}, {occluder_half, occluder_half, -30.5f}}});
  gl::RendererOptions o;
  o.width = o.height = PixelGrid::kSide;
  o.query_margin_px = margin;
  o.query_raster = raster;
  gl::Renderer r(scene, o);
  r.begin_frame(g.view);
  const ObjectId occluder[] = {0};
  r.render(occluder);
  const Aabb box[] = {g.box};
  const std::uint64_t n = r.result(r.issue_query(box));
  r.end_frame();
  return n;
}

}  // namespace

TEST_F(RendererTest, QueryOutlineWidensByTheMarginSideways) {
  // The occluder hides exactly the box's 16 x 16 pixels. Pixel centres
  // outside lie half a pixel beyond its outline: a margin of 0.4 px does
  // not reach them, 0.6 px reaches the ring of 4 * 16 + 4 around it.
  EXPECT_EQ(samples_around_occluder(0.4f, 8.0f, gl::QueryRaster::margin), 0u);
  const std::uint64_t ring = samples_around_occluder(0.6f, 8.0f, gl::QueryRaster::margin);
  // 68 pixels; near each corner three of them lie in two bands (the bands
  // are lengthened by the margin too) and count twice: 80 samples.
  EXPECT_GE(ring, 68u);
  EXPECT_LE(ring, 80u);
  EXPECT_EQ(samples_around_occluder(0.6f, 8.0f, gl::QueryRaster::exact), 0u) << "exact boxes are not widened";
}

TEST_F(RendererTest, WidenedQueryBoxesStayHiddenBehindALargerOccluder) {
  // The bands keep the depth of the box's edges: an occluder one pixel
  // larger on every side still hides all of it.
  EXPECT_EQ(samples_around_occluder(0.6f, 9.0f, gl::QueryRaster::margin), 0u);
}

TEST_F(RendererTest, ZeroThicknessBoxIsWidenedAlongItsWholeOutline) {
  // A flat 16 x 16 px box face-on (zero depth), its own face hidden by an
  // occluder of the same size: only the bands around it can pass.
  PixelGrid g;
  const Scene scene = test::box_scene({{{-8, -8, -31}, {8, 8, -30.5f}}});
  gl::RendererOptions o;
  o.width = o.height = PixelGrid::kSide;
  o.query_margin_px = 0.6f;
  gl::Renderer r(scene, o);
  r.begin_frame(g.view);
  const ObjectId occluder[] = {0};
  r.render(occluder);
  const Aabb flat[] = {{{-8, -8, -32}, {8, 8, -32}}};
  const std::uint64_t n = r.result(r.issue_query(flat));
  r.end_frame();
  EXPECT_GE(n, 68u);  // as QueryOutlineWidensByTheMarginSideways
  EXPECT_LE(n, 80u);
}

// --gl-debug: a failing GL call becomes a GlError at the next check, naming
// the phase, the driver's report and the failing call's stack.
TEST(GlDebug, AFailingCallBecomesAGlErrorNamingThePhaseTheCallAndItsStack) {
  gl::ContextOptions options;
  options.debug = true;
  auto context = gl::Context::create(options);
  ASSERT_TRUE(context->debug());
  EXPECT_NO_THROW(context->check("a quiet phase"));
  glBindBuffer(GL_ARRAY_BUFFER, 0x7fffffffu);  // a name never generated: GL_INVALID_OPERATION
  glBindBuffer(GL_ARRAY_BUFFER, 0x7ffffffeu);
  try {
    context->check("the test's phase");
    FAIL() << "no GlError";
  } catch (const GlError& e) {
    const std::string text = e.what();
    EXPECT_NE(text.find("during the test's phase"), std::string::npos) << text;
    EXPECT_NE(text.find("glBindBuffer"), std::string::npos) << text;
    EXPECT_NE(text.find("(and 1 more)"), std::string::npos) << text;
    EXPECT_NE(text.find("AFailingCallBecomesAGlError"), std::string::npos) << "the stack names the caller: " << text;
  }
  // Reported once: the next check is quiet.
  EXPECT_NO_THROW(context->check("after"));
}

TEST(GlDebug, ABenchRunWithGlDebugReportsNoErrors) {
  BenchConfig config;
  config.scene = "city:blocks=3,traffic=3";
  config.algorithms = {"vfc", "chcpp", "grid", "oracle"};
  config.frames = 3;
  config.warmup = 1;
  config.width = 96;
  config.height = 54;
  config.gl_debug = true;
  EXPECT_NO_THROW((void)run_bench(config));
}

TEST_F(RendererTest, AnEmptySceneDrawsTheBackgroundAndItsTruthIsEmpty) {
  const Scene scene("empty");
  gl::Renderer r(scene, small());
  const View view = make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.1f, 100.0f}, kSize, kSize);
  r.begin_frame(view);
  const QueryId q = r.issue_query(std::vector<Aabb>{{{-1, -1, -6}, {1, 1, -5}}});
  EXPECT_GT(r.result(q), 0u) << "nothing in front of the box";
  r.end_frame();
  EXPECT_TRUE(ids_in(r.read_ids()).empty());
  EXPECT_TRUE(r.visible_pixels(view, {}).empty());
}

TEST_F(RendererTest, ATargetOfZeroOrMoreThanTheLimitIsAnErrorNamingIt) {
  const WallScene w;
  for (const auto& [width, height] : {std::pair{0, 64}, std::pair{64, 0}, std::pair{16385, 64}}) {
    gl::RendererOptions o = small();
    o.width = width;
    o.height = height;
    try {
      gl::Renderer r(w.scene, o);
      ADD_FAILURE() << width << "x" << height << " was accepted";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(fmt::format("render target {}x{}: each side must be in [1, 16384]", width,
                                                       height)),
                std::string::npos)
          << e.what();
    }
  }
}

// The depth error seen_only_through_depth_errors is for, on the field's
// glide at 30 fps, frame 30, 320x180: llvmpipe draws terrain tile 138 (528 m
// away, a sliver of triangles seen edge-on) into 5 pixels, one of them at
// the depth of 206 m, far in front of the tile's box. That pixel alone is
// the tile seen only through a depth error; its 4 others are its surface.
TEST(RendererDepthErrors, LlvmpipePutsOnePixelOfAFarSliverInFrontOfItsBox) {
  if (!test::on_llvmpipe()) GTEST_SKIP() << "pins llvmpipe's rasterisation";
  Session session("field", test::small_target(320, 180));
  session.set_sampling({30.0, 0.0});
  const View view = session.view_at(session.path("glide"), 30, 31);
  const std::vector<ObjectId> tile{138};
  gl::Renderer::PassImages image;
  ASSERT_EQ(session.renderer().visible_pixels(view, tile, &image).at(0).pixels, 5u);
  const std::size_t error_pixel = 105 * 320 + 159;
  ASSERT_EQ(image.ids[error_pixel], 139u);
  std::vector<std::uint32_t> only_error(image.ids.size(), 0), without_error = image.ids;
  only_error[error_pixel] = 139;
  without_error[error_pixel] = 0;
  const Scene& scene = session.scene();
  EXPECT_EQ(seen_only_through_depth_errors(scene, view, only_error, image.depth, 320, 180), tile);
  EXPECT_TRUE(seen_only_through_depth_errors(scene, view, without_error, image.depth, 320, 180).empty());
  EXPECT_TRUE(seen_only_through_depth_errors(scene, view, image.ids, image.depth, 320, 180).empty());
  // How far in front: the pixel's depth is that of a point nearer than half the box's distance.
  const glm::dmat4 to_world = glm::inverse(glm::dmat4(view.view_proj));
  const glm::dvec4 p = to_world * glm::dvec4((159.5 / 320.0) * 2.0 - 1.0, (105.5 / 180.0) * 2.0 - 1.0,
                                             2.0 * double(image.depth[error_pixel]) - 1.0, 1.0);
  const double to_pixel = glm::distance(glm::dvec3(p) / p.w, glm::dvec3(view.eye));
  EXPECT_LT(to_pixel, 0.5 * double(distance(view.eye, scene.object(138).bounds)));  // 206 m against 528 m
}
