// Every algorithm under a scene the engine drives: objects moved by
// set_transform, removed, and added (ids reused, and past the count the
// hierarchy was built over, which rebuilds it) between frames.
#include "occull/culler.hpp"
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

std::vector<Aabb> scattered_boxes(int n) {
  std::vector<Aabb> boxes;
  for (int i = 0; i < n; ++i) {
    const float x = float((i * 37) % 23) - 11.0f, y = float((i * 11) % 13) - 6.0f;
    const float z = -6.0f - float((i * 7) % 45);
    boxes.push_back({{x, y, z}, {x + 0.7f + float(i % 3), y + 0.8f, z + 0.9f}});
  }
  return boxes;
}

}  // namespace

TEST(EngineDrivenScene, EveryAlgorithmFollowsMovesAdditionsAndRemovals) {
  const test::ProfileFile profile("occull-engine-" + std::to_string(::getpid()) + ".json");
  const View view = make_view({{0, 0, 0}, 0, 0}, {70.0f, 0.1f, 500.0f}, 64, 64);
  std::size_t rebuilds = 0, removed_seen = 0;
  for (const AlgorithmInfo& info : algorithms()) {
    if (info.harness_only || !runs_on(info, false)) continue;
    Scene scene = test::box_scene(scattered_boxes(120));
    Bvh bvh = Bvh::build(scene);
    Options options;
    if (info.name == "nohc" || info.name == "auto") options.set("nohc.profile", profile.path());
    auto culler = make_culler(info.name, {scene, bvh}, options);
    test::RecordingBackend backend;
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
  EXPECT_EQ(removed_seen, 0u);
}
