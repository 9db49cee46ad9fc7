// The CPU first test (CpuTestBackend) and `soc` with a scripted Backend:
// what they answer, forward and draw.
#include "occull/bvh.hpp"
#include "occull/cpu_test_backend.hpp"
#include "occull/culler.hpp"
#include "test_util.hpp"

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <string>
#include <string_view>

using namespace occull;
using test::ScriptedBackend;

namespace {

// A wall 10 m down -Z filling the view, a box behind it, a box beside the
// eye in front of it; the camera at the origin looking down -Z.
Scene wall_scene() {
  return test::box_scene({{{-40, -40, -11}, {40, 40, -10}},   // 0: the wall
                          {{-1, -1, -30}, {1, 1, -28}},       // 1: behind it
                          {{-1, -1, -6}, {1, 1, -5}}});        // 2: in front of it
}

View camera() { return make_view(CameraPose{}, Lens{60.0f, 0.1f, 100.0f}, 320, 180); }

// Moves object `id` as an engine does between frames: the hierarchy refitted, the moves taken.
void move(Scene& scene, Bvh& bvh, ObjectId id, const glm::mat4& transform) {
  scene.set_transform(id, transform);
  bvh.refit(scene);
  scene.clear_moved();
}

// What `culler` draws of a frame seen through `view`, sorted.
std::vector<ObjectId> drawn_in_frame(Culler& culler, const View& view, ScriptedBackend& device) {
  device.rendered.clear();
  (void)culler.render_frame(view, device);
  std::sort(device.rendered.begin(), device.rendered.end());
  return device.rendered;
}

TEST(CpuTestBackend, AQueryOfBoxesBehindADrawnOccluderIsAnsweredWithoutTheDevice) {
  const Scene scene = wall_scene();
  const View view = camera();
  ScriptedBackend device;
  CpuTestBackend test(scene);
  test.begin_frame(device, view);
  const ObjectId wall = 0;
  test.render(std::span(&wall, 1));
  EXPECT_EQ(device.rendered, std::vector<ObjectId>{0});
  const Aabb behind[] = {scene.object(1).bounds};
  const QueryId q = test.issue_query(behind);
  EXPECT_TRUE(device.queried.empty());
  EXPECT_TRUE(test.result_available(q));
  EXPECT_EQ(test.result(q), 0u);
  EXPECT_EQ(test.answered(), 1u);
  // In front of the wall, or with one box in front: the device is asked.
  const Aabb mixed[] = {scene.object(1).bounds, scene.object(2).bounds};
  const QueryId r = test.issue_query(mixed);
  ASSERT_EQ(device.queried.size(), 1u);
  EXPECT_EQ(device.queried[0].size(), 2u);
  EXPECT_EQ(test.result(r), 2u);  // the scripted device's answer, passed on
  test.end_frame();
  std::map<std::string_view, double> counters;
  test.visit_counters([&](std::string_view name, double value) { counters[name] = value; });
  EXPECT_GT(counters.at("occluder_triangles"), 0.0);
  EXPECT_EQ(counters.at("boxes_tested"), 3.0);  // the hidden one, then the first of the two
  EXPECT_EQ(counters.at("buffer_texels"), 80.0 * 45.0);
}

TEST(CpuTestBackend, NothingDrawnYetMeansEveryQueryGoesToTheDevice) {
  const Scene scene = wall_scene();
  const View view = camera();
  ScriptedBackend device;
  CpuTestBackend test(scene);
  test.begin_frame(device, view);
  const Aabb behind[] = {scene.object(1).bounds};
  (void)test.result(test.issue_query(behind));
  EXPECT_EQ(device.queried.size(), 1u);
  // Drawn under a condition, the wall may not be drawn at all: it occludes nothing.
  device.conditional = true;
  const QueryId q = test.issue_query(behind);
  const ObjectId wall = 0;
  test.render_conditional(std::span(&wall, 1), q, ConditionalWait::wait);
  (void)test.result(q);
  (void)test.result(test.issue_query(behind));
  EXPECT_EQ(device.queried.size(), 3u);
  EXPECT_EQ(test.answered(), 0u);
}

TEST(CpuTestBackend, EachFrameStartsWithAnEmptyBuffer) {
  const Scene scene = wall_scene();
  const View view = camera();
  ScriptedBackend device;
  CpuTestBackend test(scene);
  test.begin_frame(device, view);
  const ObjectId wall = 0;
  test.render(std::span(&wall, 1));
  const Aabb behind[] = {scene.object(1).bounds};
  (void)test.result(test.issue_query(behind));
  EXPECT_EQ(test.answered(), 1u);
  test.end_frame();
  test.begin_frame(device, view);
  (void)test.result(test.issue_query(behind));
  EXPECT_EQ(test.answered(), 0u);
  EXPECT_EQ(device.queried.size(), 1u);
}

TEST(CpuTestBackend, ChcppWithTheFirstTestIssuesFewerQueriesAndDrawsTheSame) {
  // The wall, and 40 boxes behind it in a row: a hierarchy of hidden nodes.
  std::vector<Aabb> boxes = {{{-40, -40, -11}, {40, 40, -10}}};
  for (int i = 0; i < 40; ++i) boxes.push_back({{-20.0f + float(i), -1, -30}, {-19.5f + float(i), 1, -28}});
  const Scene scene = test::box_scene(boxes);
  const Bvh bvh = Bvh::build(scene);
  const View view = camera();
  std::vector<ObjectId> drawn[2];
  std::size_t queries[2];
  for (int on = 0; on < 2; ++on) {
    ScriptedBackend device;
    // The device reports no sample for the box behind the wall, as a GPU would.
    device.visible_samples = [&](std::span<const Aabb> boxes) {
      std::uint64_t n = 0;
      for (const Aabb& b : boxes) n += b.max.z > -12.0f ? 1 : 0;
      return n;
    };
    // (virtual_leaf=0: the whole scene is under chcpp's default virtual leaf size)
    auto culler = make_culler(on ? "chcpp:virtual_leaf=0:cpu_test=on" : "chcpp:virtual_leaf=0", {scene, bvh});
    for (int frame = 0; frame < 6; ++frame) {
      device.rendered.clear();
      (void)culler->render_frame(view, device);
    }
    drawn[on] = device.rendered;
    queries[on] = device.queried.size();
    std::sort(drawn[on].begin(), drawn[on].end());
  }
  EXPECT_EQ(drawn[0], drawn[1]);
  EXPECT_LT(queries[1], queries[0]);
}

TEST(CpuTestBackend, TheQueryCullersCpuScaleSizesItsBuffer) {
  const Scene scene = wall_scene();
  const Bvh bvh = Bvh::build(scene);
  for (const auto& [spec, width] : {std::pair{"chcpp:cpu_test=on", 80}, std::pair{"chcpp:cpu_test=on:cpu_scale=1", 320},
                                    std::pair{"chc:cpu_test=on:cpu_scale=2", 160}}) {
    ScriptedBackend device;
    auto culler = make_culler(spec, {scene, bvh});
    (void)culler->render_frame(camera(), device);
    ASSERT_NE(culler->occlusion_buffer(), nullptr) << spec;
    EXPECT_EQ(culler->occlusion_buffer()->width(), width) << spec;
    // A single-sampled view of 320 x 180 pixels: the buffer covers its pixel centres (rule 10).
    EXPECT_EQ(culler->occlusion_buffer()->pixels_per_texel(), 320 / width) << spec;
  }
}

TEST(Soc, DrawsTheWallAndWhatIsInFrontOfItButNotWhatIsBehind) {
  const Scene scene = wall_scene();
  const Bvh bvh = Bvh::build(scene);
  ScriptedBackend device;
  auto soc = make_culler("soc", {scene, bvh});
  (void)soc->render_frame(camera(), device);
  std::sort(device.rendered.begin(), device.rendered.end());
  EXPECT_EQ(device.rendered, (std::vector<ObjectId>{0, 2}));
  EXPECT_TRUE(device.queried.empty());
  EXPECT_GT(test::counter(*soc, "occluder_triangles"), 0.0);
  EXPECT_GT(test::counter(*soc, "boxes_tested"), 0.0);
}

// soc leaves untested an interior node that held a drawn object in the last
// frame: the next frame of the same view tests fewer boxes and draws the
// same; when the wall then moves in front of what was shown, the objects'
// own tests hide them, as a fresh soc does.
TEST(Soc, AnInteriorNodeShownLastFrameIsNotTestedAgainButItsObjectsAre) {
  std::vector<Aabb> boxes = {{{-40, -40, -11}, {40, 40, -10}}};  // 0: the wall
  for (int i = 0; i < 16; ++i) {
    const float x = -8.0f + float(i);
    boxes.push_back({{x, -0.4f, -6.0f}, {x + 0.8f, 0.4f, -5.0f}});    // in front of it
    boxes.push_back({{x, -0.4f, -30.0f}, {x + 0.8f, 0.4f, -29.0f}});  // behind it
  }
  Scene scene = test::box_scene(boxes);
  Bvh bvh = Bvh::build(scene);
  ScriptedBackend device;
  auto soc = make_culler("soc", {scene, bvh});
  const auto frame = [&](Culler& culler) {
    device.rendered.clear();
    (void)culler.render_frame(camera(), device);
    std::sort(device.rendered.begin(), device.rendered.end());
    return std::pair{device.rendered, test::counter(culler, "boxes_tested")};
  };
  const auto [first, first_tests] = frame(*soc);
  ASSERT_GT(first.size(), 8u);  // the wall and the row in front of it (odd ids), in the frustum
  for (ObjectId id : first) EXPECT_TRUE(id == 0 || id % 2 == 1) << id;
  const auto [second, second_tests] = frame(*soc);
  EXPECT_EQ(second, first);
  EXPECT_LT(second_tests, first_tests);
  // The wall moves in front of the row: every node over the row was shown.
  scene.set_transform(0, glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 0.0f, 6.5f)));
  bvh.refit(scene);
  scene.clear_moved();
  const auto [third, third_tests] = frame(*soc);
  auto fresh = make_culler("soc", {scene, bvh});
  const auto [expected, fresh_tests] = frame(*fresh);
  EXPECT_EQ(expected, std::vector<ObjectId>{0});
  EXPECT_EQ(third, expected);
}

// 144 boxes of varied heights in 12 rows down -Z: rows hide rows.
std::vector<Aabb> rows_of_boxes() {
  std::vector<Aabb> boxes;
  for (int i = 0; i < 12; ++i)
    for (int j = 0; j < 12; ++j) {
      const float x = -30.0f + 5.0f * float(i), z = -8.0f - 5.0f * float(j), h = float((i * 7 + j * 3) % 5);
      boxes.push_back({{x, -2.0f, z}, {x + 3.0f, h, z + 1.0f}});
    }
  return boxes;
}

// The camera of frame `frame`, moving sideways.
View moving_camera(int frame) {
  CameraPose pose;
  pose.position = glm::vec3(0.5f * float(frame), 0.0f, 0.0f);
  return make_view(pose, Lens{60.0f, 0.1f, 100.0f}, 320, 180);
}

// The query cullers' CPU test on threads (cpu_threads) rasterizes each batch
// drawn among them: chcpp asks the device the same queries and draws the
// same as with one thread, and fewer than without the test (the CPU answered
// some). The scene and device of ChcppWithTheFirstTestIssuesFewerQueriesAndDrawsTheSame.
TEST(CpuTestBackend, ThreadsAnswerAsOneThreadDoes) {
  std::vector<Aabb> boxes = {{{-40, -40, -11}, {40, 40, -10}}};
  for (int i = 0; i < 40; ++i) boxes.push_back({{-20.0f + float(i), -1, -30}, {-19.5f + float(i), 1, -28}});
  const Scene scene = test::box_scene(boxes);
  const Bvh bvh = Bvh::build(scene);
  std::map<std::string, std::pair<std::vector<ObjectId>, std::size_t>> runs;  // drawn, device queries
  for (const std::string spec : {"chcpp:virtual_leaf=0", "chcpp:virtual_leaf=0:cpu_test=on",
                                 "chcpp:virtual_leaf=0:cpu_test=on:cpu_threads=3"}) {
    ScriptedBackend device;
    device.visible_samples = [&](std::span<const Aabb> b) {
      std::uint64_t n = 0;
      for (const Aabb& box : b) n += box.max.z > -12.0f ? 1 : 0;
      return n;
    };
    auto culler = make_culler(spec, {scene, bvh});
    for (int frame = 0; frame < 6; ++frame) (void)culler->render_frame(camera(), device);
    std::sort(device.rendered.begin(), device.rendered.end());
    runs[spec] = {device.rendered, device.queried.size()};
  }
  EXPECT_EQ(runs["chcpp:virtual_leaf=0:cpu_test=on:cpu_threads=3"], runs["chcpp:virtual_leaf=0:cpu_test=on"]);
  EXPECT_LT(runs["chcpp:virtual_leaf=0:cpu_test=on"].second, runs["chcpp:virtual_leaf=0"].second);
}

// soc's prepass (on by default) rasterizes last frame's occluders before its walk, so it
// must draw them whatever the walk finds (a rasterized occluder that is not
// drawn could hide what lies behind it on screen), and carries into the next
// prepass only those its walk found visible again. A back wall is seen,
// then a front wall moves in front of it: the back wall is drawn once more
// (prepassed), then no longer. Without the prepass it is not drawn at once.
TEST(Soc, ThePrepassDrawsLastFramesOccludersAndCarriesOnlyThoseFoundVisible) {
  Scene scene = test::box_scene({{{-40, -40, -11}, {40, 40, -10}},   // 0: the front wall, moved aside at first
                                 {{-20, -20, -31}, {20, 20, -30}}});  // 1: the back wall
  const glm::mat4 aside = glm::translate(glm::mat4(1.0f), glm::vec3(500.0f, 0.0f, 0.0f));
  Bvh bvh = Bvh::build(scene);
  std::map<std::string, std::vector<std::vector<ObjectId>>> frames;
  for (const char* spec : {"soc", "soc:prepass=off"}) {
    move(scene, bvh, 0, aside);
    auto soc = make_culler(spec, {scene, bvh});
    ScriptedBackend device;
    for (int frame = 0; frame < 3; ++frame) {
      if (frame == 1) move(scene, bvh, 0, glm::mat4(1.0f));  // the front wall back in front of the back wall
      frames[spec].push_back(drawn_in_frame(*soc, camera(), device));
    }
  }
  using Ids = std::vector<ObjectId>;
  EXPECT_EQ(frames["soc"], (std::vector<Ids>{{1}, {0, 1}, {0}}));
  EXPECT_EQ(frames["soc:prepass=off"], (std::vector<Ids>{{1}, {0}, {0}}));
}

// soc's threads (soc:threads, the buffer's own) share its prepass and its
// occluders of many polygons: it draws what one thread draws, frame by frame.
TEST(Soc, ThreadsDrawWhatOneThreadDraws) {
  const std::vector<Aabb> boxes = rows_of_boxes();
  const Scene scene = test::box_scene(boxes);
  const Bvh bvh = Bvh::build(scene);
  for (const char* scale : {"", ":scale=4"}) {
    std::map<std::string, std::vector<std::vector<ObjectId>>> frames;
    const std::string one = std::string("soc:threads=1") + scale, three = std::string("soc:threads=3") + scale;
    for (const std::string& spec : {one, three}) {
      auto soc = make_culler(spec, {scene, bvh});
      ScriptedBackend device;
      for (int frame = 0; frame < 6; ++frame) frames[spec].push_back(drawn_in_frame(*soc, moving_camera(frame), device));
    }
    EXPECT_EQ(frames[three], frames[one]) << scale;
    EXPECT_LT(frames[one].back().size(), boxes.size() / 2) << scale;  // it culls: rows hide rows
  }
}

// A prepassed occluder that the prepass's other occluders hide is not drawn:
// its own texels lie no nearer than its box, behind what hides the box, so
// rasterizing it changed no texel. The back wall is half hidden (drawn,
// carried), then the front wall moves over all of it: with both in the
// prepass, the back wall is found hidden there and not drawn.
TEST(Soc, APrepassedOccluderFoundHiddenAfterThePrepassIsNotDrawn) {
  Scene scene = test::box_scene({{{-40, -40, -11}, {40, 40, -10}},   // 0: the front wall, half over the back one at first
                                 {{-20, -20, -31}, {20, 20, -30}}});  // 1: the back wall
  Bvh bvh = Bvh::build(scene);
  move(scene, bvh, 0, glm::translate(glm::mat4(1.0f), glm::vec3(40.0f, 0.0f, 0.0f)));
  auto soc = make_culler("soc", {scene, bvh});
  ScriptedBackend device;
  std::vector<std::vector<ObjectId>> frames;
  for (int frame = 0; frame < 2; ++frame) {
    if (frame == 1) move(scene, bvh, 0, glm::mat4(1.0f));
    frames.push_back(drawn_in_frame(*soc, camera(), device));
  }
  EXPECT_EQ(frames, (std::vector<std::vector<ObjectId>>{{0, 1}, {0}}));
}

// soc:rest: an occluder that hides nothing for `rest` frames rests (is not
// rasterized, but still drawn), tried again one frame in `rest`; one that
// hides something does not. The wall hides the box behind it every frame; a
// box in front of the wall, off to the side, hides nothing.
TEST(Soc, AnOccluderThatHidesNothingRestsAndOneThatHidesDoesNot) {
  const Scene scene = test::box_scene({{{-40, -40, -11}, {40, 40, -10}},  // 0: the wall
                                       {{-1, -1, -30}, {1, 1, -28}},      // 1: behind it
                                       {{3, -1, -6}, {4, 1, -5}}});       // 2: in front of it, aside
  const Bvh bvh = Bvh::build(scene);
  ScriptedBackend device;
  auto soc = make_culler("soc:rest=2:rest_triangles=0", {scene, bvh});
  std::vector<double> resting, triangles;
  for (int frame = 0; frame < 12; ++frame) {
    EXPECT_EQ(drawn_in_frame(*soc, camera(), device), (std::vector<ObjectId>{0, 2})) << "frame " << frame;
    resting.push_back(test::counter(*soc, "occluders_resting"));
    triangles.push_back(test::counter(*soc, "occluder_triangles"));
  }
  // On trial for its first frames, then resting but for a try now and then.
  EXPECT_EQ(std::vector<double>(resting.begin(), resting.begin() + 4), (std::vector<double>{0, 0, 0, 1}));
  EXPECT_EQ(*std::max_element(resting.begin(), resting.end()), 1.0);  // the aside box alone, never the wall
  EXPECT_GE(std::count(resting.begin() + 3, resting.end(), 1.0), 6) << "it rests most frames";
  EXPECT_NE(std::find(resting.begin() + 4, resting.end(), 0.0), resting.end()) << "and is tried again";
  for (std::size_t f = 3; f < resting.size(); ++f)
    if (resting[f] > 0.0) EXPECT_LT(triangles[f], triangles[0]) << "frame " << f;
  // Off (the default): every occluder every frame.
  auto plain = make_culler("soc", {scene, bvh});
  for (int frame = 0; frame < 4; ++frame) {
    EXPECT_EQ(drawn_in_frame(*plain, camera(), device), (std::vector<ObjectId>{0, 2}));
    EXPECT_EQ(test::counter(*plain, "occluders_resting"), 0.0);
  }
}

TEST(Soc, AnOccluderWithoutVerticesOnTheCpuHidesNothing) {
  Scene scene("info");
  const MaterialId mat = scene.add_material({"grey", {0.7f, 0.7f, 0.7f, 1.0f}, false, 0});
  const MeshId wall = scene.add_mesh(MeshInfo{{{-40, -40, -11}, {40, 40, -10}}, 12, 6400.0});
  const MeshId box = scene.add_mesh(MeshInfo{{{-1, -1, -30}, {1, 1, -28}}, 12, 24.0});
  scene.add_object(wall, mat, glm::mat4(1.0f), OccluderClass::always);
  scene.add_object(box, mat, glm::mat4(1.0f), OccluderClass::always);
  const Bvh bvh = Bvh::build(scene);
  ScriptedBackend device;
  auto soc = make_culler("soc", {scene, bvh});
  (void)soc->render_frame(camera(), device);
  EXPECT_EQ(device.rendered.size(), 2u);
}

}  // namespace
