// Every algorithm under a scene the engine drives: objects moved by
// set_transform, removed, and added (ids reused, and past the count the
// hierarchy was built over, which rebuilds it) between frames.
#include "occull/culler.hpp"
#include "occull/depth_pyramid.hpp"
#include "occull/profile_io.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <random>
#include <set>

#include <unistd.h>

using namespace occull;

namespace {

// What a culler deciding from the geometry (soc's CPU buffer) must draw: the
// objects in the frustum that no other box can hide any part of (every other
// live box misses their screen rectangle or lies wholly behind them). The
// scripted truth below is the test double's, which only queries read; a
// buffer of one pixel a texel hides what lies behind other boxes whatever
// the double says.
std::set<ObjectId> unobstructed(const Scene& scene, const View& view) {
  std::vector<std::pair<ObjectId, BoxFootprint>> in;
  for (ObjectId id = 0; id < scene.objects().size(); ++id)
    if (scene.alive(id) && view.frustum.classify(scene.object(id).bounds) != Containment::outside)
      in.emplace_back(id, project_box(scene.object(id).bounds, view.view_proj, view.clip, view.width, view.height));
  std::set<ObjectId> out;
  for (const auto& [x, fx] : in) {
    bool clear = true;
    for (const auto& [y, fy] : in) {
      if (y == x || fx.reaches_eye) continue;
      const bool overlaps = fy.reaches_eye || (fy.min_x <= fx.max_x + 1.0f && fx.min_x <= fy.max_x + 1.0f &&
                                               fy.min_y <= fx.max_y + 1.0f && fx.min_y <= fy.max_y + 1.0f);
      if (overlaps && !(fy.min_depth > fx.max_depth)) clear = false;
    }
    if (clear) out.insert(x);
  }
  return out;
}

}  // namespace


TEST(EngineDrivenScene, EveryAlgorithmFollowsMovesAdditionsAndRemovals) {
  const test::ProfileFile profile("occull-engine-" + std::to_string(::getpid()) + ".json");
  const View view = test::unsampled(make_view({{0, 0, 0}, 0, 0}, {70.0f, 0.1f, 500.0f}, 64, 64));
  std::size_t rebuilds = 0, removed_seen = 0, geometric_truth = 0;
  for (const AlgorithmInfo& info : algorithms()) {
    if (info.lab_only || !runs_on(info, false)) continue;
    if (info.device) continue;  // culls on the device: hiz_gl_test.cpp
    Scene scene = test::box_scene(test::scattered_boxes(120));
    Bvh bvh = Bvh::build(scene);
    Options options;
    if (info.name == "nohc" || info.name == "auto") options.set("nohc.profile", profile.path());
    auto culler = make_culler(info.name, {scene, bvh}, options, test::reading_profiles());
    test::ScriptedBackend backend;
    std::vector<Aabb> visible;
    backend.visible_samples = [&visible](std::span<const Aabb> boxes) {
      std::uint64_t samples = 0;
      for (const Aabb& b : boxes)
        for (const Aabb& v : visible) samples += b.overlaps(v) ? 1 : 0;
      return samples;
    };
    std::mt19937 rng(7);
    const MeshId mesh = scene.object(0).mesh;
    for (int frame = 0; frame < 40; ++frame) {
      // The engine's changes for this frame.
      std::uniform_int_distribution<ObjectId> any(0, ObjectId(scene.objects().size() - 1));
      std::uniform_real_distribution<float> at(-10.0f, 10.0f);
      for (int k = 0; k < 12; ++k) {
        const ObjectId id = any(rng);
        if (scene.alive(id)) scene.set_transform(id, glm::translate(glm::mat4(1.0f), {at(rng), at(rng) * 0.5f, at(rng) - 20.0f}));
      }
      for (int k = 0; k < 2; ++k) {
        const ObjectId id = any(rng);
        if (scene.alive(id)) scene.remove_object(id);
      }
      scene.add_object(mesh, 0, glm::translate(glm::mat4(1.0f), {at(rng), 0.0f, -15.0f}), OccluderClass::sometimes);
      if (frame % 5 == 0) {  // past every removed id: a new slot, so the hierarchy is rebuilt
        const std::size_t count = scene.objects().size();
        ObjectId id = 0;
        do {
          id = scene.add_object(mesh, 0, glm::translate(glm::mat4(1.0f), {0, at(rng), -25.0f}), OccluderClass::always);
        } while (id < count);
      }
      const std::uint64_t generation = bvh.generation();
      bvh.refit(scene);
      rebuilds += bvh.generation() != generation ? 1 : 0;
      scene.clear_moved();

      // The truth of the test double: two thirds of what is in the frustum.
      visible.clear();
      std::set<ObjectId> truth;
      for (ObjectId id = 0; id < scene.objects().size(); ++id) {
        const Aabb& b = scene.object(id).bounds;
        if (!scene.alive(id) || view.frustum.classify(b) == Containment::outside) continue;
        if ((id + ObjectId(frame / 4)) % 3 == 0) continue;
        visible.push_back(b);
        truth.insert(id);
      }
      if (info.name == "soc") {  // decides from the geometry, not from the double's answers
        truth = unobstructed(scene, view);
        geometric_truth += truth.size();
      }
      backend.rendered.clear();
      (void)culler->render_frame(view, backend);
      const std::set<ObjectId> rendered(backend.rendered.begin(), backend.rendered.end());
      for (ObjectId id : rendered) {
        EXPECT_TRUE(scene.alive(id)) << info.name << " drew removed object " << id << " in frame " << frame;
        removed_seen += scene.alive(id) ? 0 : 1;
      }
      if (info.conservative)
        for (ObjectId id : truth)
          EXPECT_TRUE(rendered.count(id)) << info.name << " missed object " << id << " in frame " << frame;
      // The visible set out: what the backend was asked to draw, each once.
      const auto drawn = culler->drawn_objects();
      EXPECT_TRUE(std::is_sorted(drawn.begin(), drawn.end()));
      EXPECT_EQ(std::set<ObjectId>(drawn.begin(), drawn.end()), rendered) << info.name << " frame " << frame;
      EXPECT_EQ(std::size_t(drawn.size()), rendered.size()) << info.name << " frame " << frame;
      for (ObjectId id : objects_not_drawn(scene, view, drawn)) {
        EXPECT_FALSE(rendered.count(id));
        if (info.conservative) EXPECT_FALSE(truth.count(id)) << info.name << " found visible object " << id << " occluded";
      }
    }
    culler->release(backend);
    EXPECT_EQ(backend.in_flight(), 0u) << info.name;
  }
  EXPECT_GT(rebuilds, 0u);  // the hierarchy was rebuilt under the cullers
  EXPECT_GT(geometric_truth, 40u);  // soc was checked against something
  EXPECT_EQ(removed_seen, 0u);
}

// A rebuilt hierarchy does not send a coherent culler back to a cold start:
// its new nodes begin from what it drew last frame. The work of the frame
// after a rebuild (queries issued + objects drawn) is never more than a fresh
// culler's first frame over the same hierarchy, and less in one of two
// worlds: every query finding its boxes visible (a fresh chc or chcpp
// queries its way down from the root), or hidden. The scene is a wall of heavy objects (200k
// triangles each, no vertices, so that queries pay in nohc's cost model)
// with as many behind it.
TEST(EngineDrivenScene, HierarchicalCullersKeepTheirStateAcrossARebuild) {
  const HardwareProfile profile = test::hardware_profile();
  const CullerContext context = with_profile(profile);
  const View view = test::unsampled(make_view({{0, 0, 0}, 0, 0}, {70.0f, 0.1f, 500.0f}, 64, 64));
  for (const char* name : {"chc", "chcpp", "nohc"}) {
    SCOPED_TRACE(name);
    std::size_t less = 0;
    for (const bool visible : {true, false}) {
      Scene scene("wall");
      const MaterialId material = scene.add_material({});
      const MeshId mesh = scene.add_mesh(MeshInfo{{glm::vec3(-1.0f), glm::vec3(1.0f)}, 200000, 24.0});
      const auto place = [&](float x, float y, float z) {
        return scene.add_object(mesh, material, glm::translate(glm::mat4(1.0f), {x, y, z}), OccluderClass::sometimes);
      };
      for (int layer = 0; layer < 2; ++layer)
        for (int i = 0; i < 12; ++i)
          for (int j = 0; j < 12; ++j) (void)place(-11.0f + 2.0f * float(i), -11.0f + 2.0f * float(j), -8.0f - 20.0f * float(layer));
      Bvh bvh = Bvh::build(scene);
      const auto answer = [visible](std::span<const Aabb> boxes) { return visible ? std::uint64_t(boxes.size()) : 0; };
      const auto work = [](const test::ScriptedBackend& b) { return b.queried.size() + b.rendered.size(); };

      auto culler = make_culler(name, {scene, bvh}, {}, context);
      test::ScriptedBackend backend;
      backend.visible_samples = answer;
      for (int frame = 0; frame < 8; ++frame) (void)culler->render_frame(view, backend);
      culler->release(backend);
      const std::uint64_t generation = bvh.generation();
      (void)place(0.0f, 0.0f, -300.0f);
      bvh.refit(scene);
      ASSERT_NE(bvh.generation(), generation) << "an object past the built count rebuilds the hierarchy";
      test::ScriptedBackend after;
      after.visible_samples = answer;
      (void)culler->render_frame(view, after);
      culler->release(after);

      auto fresh = make_culler(name, {scene, bvh}, {}, context);
      test::ScriptedBackend first;
      first.visible_samples = answer;
      (void)fresh->render_frame(view, first);
      fresh->release(first);
      EXPECT_LE(work(after), work(first)) << (visible ? "visible" : "hidden");
      less += work(after) < work(first) ? 1 : 0;
    }
    // nohc decides from its cost model, and on this scene the carried
    // states lead it to the same choices as a fresh start: no worse is all
    // that is asked of it.
    if (std::string_view(name) != "nohc") EXPECT_GT(less, 0u);
  }
}
