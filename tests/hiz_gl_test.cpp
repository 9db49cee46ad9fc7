// GL integration: `hiz` and the renderer's DeviceCulling on llvmpipe, small
// frames. Every scene kind through the verifier is in culling_gl_test.cpp
// and adversarial_test.cpp (hiz is among their conservative cullers).
#include "gl/gl.hpp"
#include "cull/cullers.hpp"
#include "occull/culler.hpp"
#include "occull/depth_pyramid.hpp"
#include "occull/error.hpp"
#include "occull/gl/context.hpp"
#include "occull/gl/renderer.hpp"
#include "occull/recording_backend.hpp"
#include "occull/scenes.hpp"
#include "gl_test_util.hpp"
#include "test_util.hpp"

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <set>

using namespace occull;

namespace {

constexpr int kSize = 96;

class Hiz : public ::testing::Test {
 protected:
  static void SetUpTestSuite() { context_ = gl::Context::create(); }
  static void TearDownTestSuite() { context_.reset(); }
  static std::unique_ptr<gl::Context> context_;

  static gl::RendererOptions target(int width = kSize, int height = kSize) {
    gl::RendererOptions o;
    o.width = width;
    o.height = height;
    return o;
  }
};
std::unique_ptr<gl::Context> Hiz::context_;

// Camera at the origin looking down -Z; a 6 x 6 wall 10 m ahead hides a box
// 20 m ahead; another box 20 m ahead and 8 m right is in plain view.
struct WallScene {
  static constexpr ObjectId wall = 0, hidden = 1, beside = 2;
  Scene scene = test::box_scene({{{-3, -3, -11}, {3, 3, -10}}, {{-1, -1, -21}, {1, 1, -19}}, {{7, -1, -21}, {9, 1, -19}}});
  Bvh bvh = Bvh::build(scene);
  View view = make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.1f, 100.0f}, kSize, kSize);
};

// One frame of `culler` through a RecordingBackend over `r`: what the device
// drew, ascending, as the lab reads it back.
std::vector<ObjectId> frame(Culler& culler, gl::Renderer& r, const Scene& scene, const View& view) {
  RecordingBackend recorder(r, scene);
  r.begin_frame(view);
  recorder.start_frame();
  culler.render_frame(view, recorder);
  r.end_frame();
  recorder.finish_frame([&](QueryId q) { return r.unread_result(q); });
  std::vector<ObjectId> drawn(recorder.objects().begin(), recorder.objects().end());
  return drawn;
}

using test::ids_in;

}  // namespace

TEST_F(Hiz, ABoxBehindAWallIsNotDrawnOnceItsDepthIsKnown) {
  WallScene w;
  gl::Renderer r(w.scene, target());
  auto hiz = make_culler("hiz", {w.scene, w.bvh});
  // Frame 1: nothing visible yet, an empty pyramid: all three drawn.
  EXPECT_EQ(frame(*hiz, r, w.scene, w.view), (std::vector<ObjectId>{0, 1, 2}));
  // Frame 2: phase 1 draws all three; phase 2 finds the hidden box behind the wall.
  (void)frame(*hiz, r, w.scene, w.view);
  // Frame 3: it is not drawn in phase 1, and phase 2 finds it hidden again.
  EXPECT_EQ(frame(*hiz, r, w.scene, w.view), (std::vector<ObjectId>{WallScene::wall, WallScene::beside}));
  EXPECT_EQ(ids_in(r.read_ids()), (std::set<ObjectId>{WallScene::wall, WallScene::beside}));
  hiz->release(r);
}

TEST_F(Hiz, AnObjectUncoveredByAMovingOccluderIsDrawnInTheSameFrame) {
  WallScene w;
  gl::Renderer r(w.scene, target());
  auto hiz = make_culler("hiz", {w.scene, w.bvh});
  for (int f = 0; f < 3; ++f) (void)frame(*hiz, r, w.scene, w.view);
  ASSERT_EQ(frame(*hiz, r, w.scene, w.view), (std::vector<ObjectId>{WallScene::wall, WallScene::beside}));
  // The wall slides 20 m left between frames: the box behind it shows now.
  w.scene.set_transform(WallScene::wall, glm::translate(glm::mat4(1.0f), glm::vec3(-20.0f, 0.0f, 0.0f)));
  w.bvh.refit(w.scene);
  const std::vector<ObjectId> drawn = frame(*hiz, r, w.scene, w.view);
  EXPECT_TRUE(std::binary_search(drawn.begin(), drawn.end(), WallScene::hidden));
  EXPECT_TRUE(ids_in(r.read_ids()).count(WallScene::hidden));
  hiz->release(r);
}

// Each object drawn once: the triangles the device made (a primitives
// query around the frame's device draws) are exactly those of the objects
// read back, each counted once; and every object in the id image was read
// back as drawn.
TEST_F(Hiz, TheReadBackIsExactlyWhatTheDeviceDrewEachOnce) {
  Scene scene = test::box_scene({{{-3, -3, -11}, {3, 3, -10}}, {{-1, -1, -21}, {1, 1, -19}},
                                 {{7, -1, -21}, {9, 1, -19}}, {{-9, -1, -31}, {-7, 1, -29}},
                                 {{2, 2, -41}, {4, 4, -39}}, {{-2, -8, -15}, {2, -6, -14}}});
  const Bvh bvh = Bvh::build(scene);
  gl::Renderer r(scene, target());
  auto hiz = make_culler("hiz", {scene, bvh});
  GLuint primitives = 0;
  glCreateQueries(GL_PRIMITIVES_GENERATED, 1, &primitives);
  for (int f = 0; f < 6; ++f) {
    // The camera turns a little each frame, so phase 2 finds new objects.
    const View view = make_view({{0, 0, 0}, 0.08f * float(f), 0}, {60.0f, 0.1f, 100.0f}, kSize, kSize);
    RecordingBackend recorder(r, scene);
    r.begin_frame(view);
    recorder.start_frame();
    glBeginQuery(GL_PRIMITIVES_GENERATED, primitives);
    hiz->render_frame(view, recorder);
    glEndQuery(GL_PRIMITIVES_GENERATED);
    r.end_frame();
    recorder.finish_frame([&](QueryId q) { return r.unread_result(q); });
    GLuint64 made = 0;
    glGetQueryObjectui64v(primitives, GL_QUERY_RESULT, &made);
    std::uint64_t expected = 0;
    const std::set<ObjectId> drawn(recorder.objects().begin(), recorder.objects().end());
    EXPECT_EQ(drawn.size(), recorder.objects().size()) << "an object read back twice, frame " << f;
    for (ObjectId id : drawn) expected += scene.object(id).triangles;
    EXPECT_EQ(made, expected) << "frame " << f;
    for (ObjectId id : ids_in(r.read_ids())) EXPECT_TRUE(drawn.count(id)) << id << " shown, not read back, frame " << f;
    EXPECT_EQ(recorder.stats().objects_rendered, drawn.size());
  }
  glDeleteQueries(1, &primitives);
  hiz->release(r);
}

TEST_F(Hiz, CompactedAndPerObjectCommandsDrawTheSame) {
  Scene city = make_scene("city:blocks=3,traffic=10").scene;
  const Bvh bvh = Bvh::build(city);
  gl::RendererOptions compacted = target(160, 90), per_object = target(160, 90);
  per_object.device_draw_count = false;
  gl::Renderer a(city, compacted), b(city, per_object);
  auto ha = make_culler("hiz", {city, bvh});
  auto hb = make_culler("hiz", {city, bvh});
  const View view = make_view({{0, 1.7f, 0}, 0.3f, 0}, {70.0f, 0.1f, 500.0f}, 160, 90);
  for (int f = 0; f < 3; ++f) {
    EXPECT_EQ(frame(*ha, a, city, view), frame(*hb, b, city, view)) << "frame " << f;
    EXPECT_EQ(a.read_ids(), b.read_ids()) << "frame " << f;
  }
  EXPECT_FALSE(b.device_draws_compacted());
  ha->release(a);
  hb->release(b);
}

// The device's pyramid is the reference's (occull/depth_pyramid.hpp, whose
// rules the unit tests break one by one) bit for bit, built from the same
// depth, with an odd-sized target, in both depth conventions.
TEST_F(Hiz, TheDevicesPyramidIsTheReferenceBuiltFromTheSameDepth) {
  Scene city = make_scene("city:blocks=3,traffic=10").scene;
  const Bvh bvh = Bvh::build(city);
  for (const DepthMode depth : {DepthMode::standard, DepthMode::reversed}) {
    gl::Renderer r(city, target(157, 91));
    auto hiz = make_culler("hiz", {city, bvh});
    Lens lens{70.0f, 0.1f, 500.0f};
    lens.depth = depth;
    const View view = make_view({{0, 1.7f, 0}, 0.3f, 0}, lens, 157, 91);
    for (int f = 0; f < 2; ++f) (void)frame(*hiz, r, city, view);
    // The last frame drew nothing new in phase 2 (the view did not move), so
    // the final depth is the one its pyramid was built from.
    const std::vector<float> stored = r.read_stored_depth();
    const auto [nearest, farthest] = std::minmax_element(stored.begin(), stored.end());
    ASSERT_LT(*nearest, *farthest) << "the view should see something in front of the background";
    const DepthPyramid reference(stored, 157, 91, view.clip.reversed_z);
    for (int level = 1; level < reference.levels(); ++level) {
      const std::vector<float> device = r.read_depth_pyramid(level);
      const auto expected = reference.level(level);
      ASSERT_EQ(device.size(), expected.size()) << "level " << level;
      EXPECT_TRUE(std::equal(device.begin(), device.end(), expected.begin()))
          << "level " << level << (depth == DepthMode::reversed ? " reversed" : "");
    }
    hiz->release(r);
  }
}

// The device's box test decides as the reference's (occull/depth_pyramid.hpp,
// rules 1-10) on the same depth: over the field at an odd size,
// every object inside the frustum is found visible by the device exactly
// when the reference cannot hide it (pixel centres, the view being
// single-sampled at the target's size; octants). And the last two rules
// hide some there that whole pixels and whole boxes keep.
TEST_F(Hiz, TheDevicesTestDecidesAsTheReference) {
  SceneBundle bundle = make_scene("field");
  const Scene& field = bundle.scene;
  const Bvh bvh = Bvh::build(field);
  gl::Renderer r(field, target(157, 91));
  auto hiz = make_culler("hiz:texels=8", {field, bvh});
  const View view = make_view(bundle.path("glide").sample(3.0), bundle.lens, 157, 91);
  for (int f = 0; f < 3; ++f) (void)frame(*hiz, r, field, view);
  // The last frame drew nothing new in phase 2 (the view did not move): the
  // final depth is the one its pyramid was built from.
  const std::vector<float> stored = r.read_stored_depth();
  const DepthPyramid reference(stored, 157, 91, view.clip.reversed_z);
  detail::PyramidRules earlier;
  earlier.octants_tested = 0;
  const DepthPyramid whole_boxes(stored, 157, 91, view.clip.reversed_z, earlier);
  auto* resumable = dynamic_cast<detail::Resumable*>(hiz.get());
  ASSERT_NE(resumable, nullptr);
  std::vector<ObjectId> visible;
  resumable->last_visible(r, visible);
  const std::set<ObjectId> device(visible.begin(), visible.end());
  int compared = 0, hidden = 0, hidden_by_new_rules = 0;
  for (ObjectId id = 0; id < field.objects().size(); ++id) {
    const Aabb& box = field.object(id).bounds;
    if (view.frustum.classify(box) == Containment::outside || holds_no_sample(box, view)) continue;
    ++compared;
    const bool occluded = reference.occluded(box, view.view_proj, view.clip, 8, true);
    EXPECT_EQ(device.count(id) == 0, occluded) << "object " << id;
    if (!occluded) continue;
    ++hidden;
    if (!whole_boxes.occluded(box, view.view_proj, view.clip, 8, false)) ++hidden_by_new_rules;
  }
  EXPECT_GT(compared, 1000);  // 2,552 here, 1,341 hidden, 697 of them by rules 9 and 10
  EXPECT_GT(hidden, 500);
  EXPECT_GT(hidden_by_new_rules, 0) << "pixel centres and octants should hide some that the earlier test kept";
  hiz->release(r);
}

TEST_F(Hiz, FollowsObjectsRemovedAndAddedBack) {
  WallScene w;
  gl::Renderer r(w.scene, target());
  auto hiz = make_culler("hiz", {w.scene, w.bvh});
  for (int f = 0; f < 2; ++f) (void)frame(*hiz, r, w.scene, w.view);
  w.scene.remove_object(WallScene::beside);
  w.bvh.refit(w.scene);
  EXPECT_EQ(frame(*hiz, r, w.scene, w.view), (std::vector<ObjectId>{WallScene::wall}));
  // The slot comes back as the hidden box's mesh moved in front of the wall
  // (the renderer keeps the meshes it was made with).
  const glm::mat4 in_front = glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.0f, 14.0f));
  ASSERT_EQ(w.scene.add_object(w.scene.object(WallScene::hidden).mesh, 0, in_front, OccluderClass::always),
            WallScene::beside);
  w.bvh.refit(w.scene);
  EXPECT_EQ(frame(*hiz, r, w.scene, w.view), (std::vector<ObjectId>{WallScene::wall, WallScene::beside}));
  hiz->release(r);
}

TEST_F(Hiz, AnEmptySceneAndObjectsWithoutTrianglesDrawNothing) {
  Scene empty("empty");
  const Bvh none = Bvh::build(empty);
  gl::Renderer r(empty, target());
  auto hiz = make_culler("hiz", {empty, none});
  const View view = make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.1f, 100.0f}, kSize, kSize);
  for (int f = 0; f < 2; ++f) EXPECT_TRUE(frame(*hiz, r, empty, view).empty());
  hiz->release(r);

  WallScene w;
  w.scene.remove_object(WallScene::hidden);  // empty bounds, no triangles
  w.bvh.refit(w.scene);
  gl::Renderer r2(w.scene, target());
  auto hiz2 = make_culler("hiz", {w.scene, w.bvh});
  for (int f = 0; f < 2; ++f)
    EXPECT_EQ(frame(*hiz2, r2, w.scene, w.view), (std::vector<ObjectId>{WallScene::wall, WallScene::beside}));
  hiz2->release(r2);
}

TEST_F(Hiz, AVisibleSetHandedOverIsDrawnInPhaseOne) {
  // auto's hand-over (detail::Resumable, DeviceCulling::set_visible): the set
  // handed over is the device's visibility for the next phase 1.
  WallScene w;
  gl::Renderer r(w.scene, target());
  auto fresh = make_culler("hiz", {w.scene, w.bvh});
  EXPECT_EQ(frame(*fresh, r, w.scene, w.view),
            (std::vector<ObjectId>{WallScene::wall, WallScene::hidden, WallScene::beside}))
      << "from nothing, phase 2 tests against an empty pyramid";
  fresh->release(r);
  auto hiz = make_culler("hiz", {w.scene, w.bvh});
  auto* resumable = dynamic_cast<detail::Resumable*>(hiz.get());
  ASSERT_NE(resumable, nullptr);
  const std::vector<ObjectId> handed{WallScene::wall};
  resumable->resume_from(handed);
  EXPECT_EQ(frame(*hiz, r, w.scene, w.view), (std::vector<ObjectId>{WallScene::wall, WallScene::beside}))
      << "phase 1 drew the wall handed over, so the box behind it is culled in the first frame";
  hiz->release(r);
}

TEST_F(Hiz, AVisibilityHandedBackCannotBeUsedAgain) {
  WallScene w;
  gl::Renderer r(w.scene, target());
  const DeviceCulling::Visibility v = r.create_visibility();
  r.destroy_visibility(v);
  r.begin_frame(w.view);
  EXPECT_THROW(r.draw_previously_visible(v), std::logic_error);
  EXPECT_THROW(r.draw_newly_visible(v, 4), std::logic_error);
  r.end_frame();
  EXPECT_THROW(r.destroy_visibility(v), std::logic_error);
}

TEST_F(Hiz, PhaseTwoWithoutAPyramidIsRefused) {
  WallScene w;
  gl::Renderer r(w.scene, target());
  const DeviceCulling::Visibility v = r.create_visibility();
  r.begin_frame(w.view);
  r.draw_previously_visible(v);
  EXPECT_THROW(r.draw_newly_visible(v, 4), std::logic_error);
  r.end_frame();
  r.destroy_visibility(v);
}

TEST_F(Hiz, ReleaseHandsBackTheCullersVisibility) {
  WallScene w;
  gl::Renderer r(w.scene, target());
  auto hiz = make_culler("hiz", {w.scene, w.bvh});
  (void)frame(*hiz, r, w.scene, w.view);  // makes the device's buffers and the culler's visibility
  const std::size_t holding = r.resources().buffers;
  hiz->release(r);
  EXPECT_EQ(r.resources().buffers, holding - 1);
  (void)frame(*hiz, r, w.scene, w.view);  // usable after release: a new visibility, from nothing visible
  EXPECT_EQ(r.resources().buffers, holding);
  hiz->release(r);
  hiz->release(r);  // twice is harmless
  EXPECT_EQ(r.resources().buffers, holding - 1);
}

TEST_F(Hiz, TheVisibilityReadBackIsWhatPhaseTwoFoundVisibleOrWhatWasSet) {
  WallScene w;
  gl::Renderer r(w.scene, target());
  auto hiz = make_culler("hiz", {w.scene, w.bvh});
  for (int f = 0; f < 3; ++f) (void)frame(*hiz, r, w.scene, w.view);
  auto* resumable = dynamic_cast<detail::Resumable*>(hiz.get());
  ASSERT_NE(resumable, nullptr);
  std::vector<ObjectId> visible;
  resumable->last_visible(r, visible);
  EXPECT_EQ(visible, (std::vector<ObjectId>{WallScene::wall, WallScene::beside})) << "the box behind the wall is hidden";
  const DeviceCulling::Visibility v = r.create_visibility();
  const std::vector<ObjectId> set{WallScene::hidden};
  r.set_visible(v, set);
  visible.clear();
  r.read_visible(v, visible);
  EXPECT_EQ(visible, set);
  r.destroy_visibility(v);
  hiz->release(r);
}

// auto's switch from hiz to a query culler hands over hiz's visible set,
// read back from the device: the query culler's first frame draws what hiz
// found visible without querying it, and queries only what hiz found hidden
// (started cold, it queries every leaf: 3 here).
TEST_F(Hiz, AutoHandsHizsVisibleSetToTheQueryCullerItTriesNext) {
  WallScene w;
  gl::Renderer r(w.scene, target());
  Options options;
  options.set("chcpp.virtual_leaf=0");  // one object per leaf: the scene is one virtual leaf otherwise
  auto culler = make_culler("auto:candidates=hiz+chcpp", {w.scene, w.bvh}, options);
  bool tried = false;
  for (int f = 0; f < 12 && !tried; ++f) {
    RecordingBackend recorder(r, w.scene);
    r.begin_frame(w.view);
    recorder.start_frame();
    (void)culler->render_frame(w.view, recorder);
    r.end_frame();
    recorder.finish_frame([&](QueryId q) { return r.unread_result(q); });
    if (culler->counter("auto_choice") != 2.0) continue;  // hiz's frames
    tried = true;
    std::vector<ObjectId> drawn(recorder.objects().begin(), recorder.objects().end());
    std::sort(drawn.begin(), drawn.end());
    EXPECT_EQ(drawn, (std::vector<ObjectId>{WallScene::wall, WallScene::beside}));
    EXPECT_EQ(recorder.stats().queries, 1u) << "chcpp's first frame queries only the box hiz found hidden";
  }
  EXPECT_TRUE(tried) << "auto never tried chcpp";
  culler->release(r);
}
