// Query ownership: a culler hands back every query it holds (Culler::release)
// and keeps no backend between frames; the test backend enforces the query
// contract of occull/backend.hpp.
#include "occull/motion.hpp"
#include "occull/culler.hpp"
#include "occull/error.hpp"
#include "occull/profile_io.hpp"
#include "occull/scenes.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <map>
#include <memory>

#include <unistd.h>

using namespace occull;

namespace {

// 80 boxes in front of the camera, 8 of them moving across the others
// (on `scripted`).
Scene moving_boxes(std::vector<ScriptedObject>& scripted) {
  std::vector<Aabb> boxes;
  for (int i = 0; i < 80; ++i) {
    const float x = float((i * 37) % 21) - 10.0f, y = float((i * 11) % 13) - 6.0f;
    const float z = -8.0f - float((i * 7) % 40);
    boxes.push_back({{x, y, z}, {x + 0.8f + float(i % 3), y + 0.8f, z + 0.8f}});
  }
  Scene scene = test::box_scene(boxes);
  const MeshId cube = scene.add_mesh(test::box_mesh({{-0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, 0.5f}}));
  for (int i = 0; i < 8; ++i) {
    Motion m;
    m.waypoints = {{-12.0f, float(i) - 4.0f, -10.0f - 4.0f * float(i)}, {12.0f, float(i) - 4.0f, -12.0f - 4.0f * float(i)}};
    m.speed = 3.0f + float(i);
    add_scripted_object(scene, scripted, cube, 0, m, OccluderClass::sometimes);
  }
  return scene;
}

// Answers come late (a query polls as available only from the frame after
// the one it was first polled in, as on a busy device; result() still
// answers) and say a box is visible when its hash says so, changing every
// few frames.
void make_slow_and_changing(test::ScriptedBackend& backend, const int& frame) {
  auto first_poll = std::make_shared<std::map<QueryId, int>>();
  backend.available = [first_poll, &frame](QueryId q) { return first_poll->try_emplace(q, frame).first->second < frame; };
  backend.visible_samples = [&frame](std::span<const Aabb> boxes) {
    std::uint64_t samples = 0;
    for (const Aabb& b : boxes)
      samples += (std::uint32_t(b.min.x * 7.0f + b.min.z * 3.0f) + std::uint32_t(frame / 5)) % 3 == 0 ? 4 : 0;
    return samples;
  };
}

}  // namespace

TEST(ScriptedBackend, ReadingAQueryTwiceFailsLoudly) {
  test::ScriptedBackend backend;
  const Aabb box{{0, 0, 0}, {1, 1, 1}};
  const QueryId q = backend.issue_query(std::span<const Aabb>(&box, 1));
  EXPECT_EQ(backend.in_flight(), 1u);
  (void)backend.result(q);
  EXPECT_EQ(backend.in_flight(), 0u);
  EXPECT_THROW((void)backend.result(q), std::logic_error);
  EXPECT_THROW((void)backend.result_available(q), std::logic_error);
}

TEST(ScriptedBackend, AQueryOfAnotherDeviceFailsLoudly) {
  test::ScriptedBackend a(0), b(1000);
  const Aabb box{{0, 0, 0}, {1, 1, 1}};
  const QueryId q = a.issue_query(std::span<const Aabb>(&box, 1));
  EXPECT_THROW((void)b.result(q), std::logic_error);
  EXPECT_THROW((void)b.result(QueryId(7)), std::logic_error);  // never issued anywhere
  EXPECT_EQ(a.result(q), 1u);
}

// Every algorithm that runs on a scene with a BVH, through frames with
// moving objects and late, changing answers: what it says it holds is what
// the backend has in flight, and after release() nothing is.
TEST(QueryOwnership, EveryBvhAlgorithmHandsBackEveryQuery) {
  std::vector<ScriptedObject> scripted;
  Scene scene = moving_boxes(scripted);
  Bvh bvh = Bvh::build(scene);
  Options base;
  const test::ProfileFile profile("occull-ownership-" + std::to_string(::getpid()) + ".json");
  base.set("nohc.profile", profile.path());
  const View view = make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.1f, 500.0f}, 64, 64);
  std::size_t held_somewhere = 0;
  for (const AlgorithmInfo& info : algorithms()) {
    if (info.lab_only || !runs_on(info, false)) continue;
    if (info.device) continue;  // culls on the device: hiz_gl_test.cpp
    Options options;
    for (const auto& [k, v] : base.values())
      if (k.rfind(info.name + ".", 0) == 0 || info.name == "auto") options.set(k, v);
    auto culler = make_culler(info.name, {scene, bvh}, options, test::reading_profiles());
    test::ScriptedBackend backend;
    int frame = 0;
    make_slow_and_changing(backend, frame);
    for (frame = 0; frame < 24; ++frame) {
      animate(scene, scripted, frame / 30.0);
      bvh.refit(scene);
      (void)culler->render_frame(view, backend);
      EXPECT_EQ(culler->queries_held(), backend.in_flight()) << info.name << " frame " << frame;
      held_somewhere += culler->queries_held();
    }
    culler->release(backend);
    EXPECT_EQ(culler->queries_held(), 0u) << info.name;
    EXPECT_EQ(backend.in_flight(), 0u) << info.name;
    // Still usable after release, and releasing again reads nothing twice.
    (void)culler->render_frame(view, backend);
    culler->release(backend);
    culler->release(backend);
    EXPECT_EQ(backend.in_flight(), 0u) << info.name;
  }
  // The test means something only if some culler kept queries across frames.
  EXPECT_GT(held_somewhere, 0u);
}

TEST(QueryOwnership, EveryTiledWorldAlgorithmHandsBackEveryQuery) {
  SceneBundle bundle = make_scene("tiles_city:far=150");
  const Bvh none = Bvh::build(std::span<const Aabb>{}, std::span<const std::uint32_t>{});
  std::size_t held_somewhere = 0;
  for (const AlgorithmInfo& info : algorithms()) {
    if (info.lab_only || !runs_on(info, true)) continue;
    auto culler = make_culler(info.name, {bundle.scene, none, bundle.world.get()});
    test::ScriptedBackend backend;
    int frame = 0;
    make_slow_and_changing(backend, frame);
    // Tiles found visible stay predicted visible, so their late queries are
    // postponed and, at the frame's end, given up on and held (tiles).
    backend.visible_samples = [](std::span<const Aabb> boxes) { return std::uint64_t(boxes.size()); };
    for (frame = 0; frame < 24; ++frame) {
      const glm::vec3 eye{1.0f + 3.0f * float(frame), 1.7f, -20.0f};
      bundle.world->follow(bundle.scene, eye);
      const View view = make_view({eye, 0.3f, 0.0f}, bundle.lens, 64, 36);
      (void)culler->render_frame(view, backend);
      EXPECT_EQ(culler->queries_held(), backend.in_flight()) << info.name << " frame " << frame;
      held_somewhere += culler->queries_held();
    }
    culler->release(backend);
    EXPECT_EQ(culler->queries_held(), 0u) << info.name;
    EXPECT_EQ(backend.in_flight(), 0u) << info.name;
  }
  EXPECT_GT(held_somewhere, 0u);
}
