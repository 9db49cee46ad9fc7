// perobject (the engine notes' per-object asynchronous queries) against a Backend
// test double whose answers and their timing the test controls.
#include "occull/culler.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>

using namespace occull;

namespace {

// Camera at the origin looking down -Z. Object 0: a wall 10 m ahead
// (occluder class always); 1: a box behind it; 2: a box beside it; 3: a
// small box half a metre from the eye (within the near-plane radius);
// 1..3 are occludees (class never).
struct Stage {
  Scene scene{"perobject"};
  Bvh bvh;
  View view = make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.5f, 100.0f}, 64, 64);
  Stage() {
    const MaterialId grey = scene.add_material({"grey", {0.6f, 0.6f, 0.6f, 1}, false, 0});
    const auto add = [&](const Aabb& b, OccluderClass c) {
      scene.add_object(scene.add_mesh(test::box_mesh(b)), grey, glm::mat4(1.0f), c);
    };
    add({{-3, -3, -11}, {3, 3, -10}}, OccluderClass::always);
    add({{-1, -1, -21}, {1, 1, -19}}, OccluderClass::never);
    add({{7, -1, -21}, {9, 1, -19}}, OccluderClass::never);
    add({{-0.1f, -0.1f, -0.7f}, {0.1f, 0.1f, -0.5f}}, OccluderClass::never);
    bvh = Bvh::build(scene);
  }
  std::unique_ptr<Culler> make(std::vector<std::string> options = {}) {
    Options o;
    for (const auto& s : options) o.set(s);
    return make_culler("perobject", {scene, bvh}, o);
  }
};

// Queries whose (single) box is object `id`'s.
std::size_t queries_of(const test::ScriptedBackend& b, const Scene& scene, ObjectId id) {
  return std::size_t(std::count_if(b.queried.begin(), b.queried.end(), [&](const std::vector<Aabb>& q) {
    return q.size() == 1 && q[0] == scene.object(id).bounds;
  }));
}

std::size_t times_drawn(const test::ScriptedBackend& b, ObjectId id) {
  return std::size_t(std::count(b.rendered.begin(), b.rendered.end(), id));
}

}  // namespace

TEST(PerObject, OccludersArePrepassedFirstAndNeverQueried) {
  Stage s;
  auto culler = s.make();
  test::ScriptedBackend backend;
  for (int f = 0; f < 6; ++f) {
    backend.rendered.clear();
    culler->render_frame(s.view, backend);
    ASSERT_FALSE(backend.rendered.empty());
    EXPECT_EQ(backend.rendered.front(), 0u) << "the wall comes first, frame " << f;
  }
  EXPECT_EQ(queries_of(backend, s.scene, 0), 0u);
}

TEST(PerObject, VisibleObjectIsRetestedOnlyEveryIntervalFrames) {
  Stage s;
  auto culler = s.make({"perobject.interval=5"});
  test::ScriptedBackend backend;  // everything visible, answers at once
  for (int f = 0; f < 30; ++f) culler->render_frame(s.view, backend);
  // Tested in frames 1, 7, 13, 19, 25: a query, then 5 frames drawn untested.
  EXPECT_EQ(queries_of(backend, s.scene, 2), 5u);
  EXPECT_EQ(times_drawn(backend, 2), 30u);
}

TEST(PerObject, OccludedObjectIsDroppedOnceAnsweredAndRetestedEveryFrame) {
  Stage s;
  auto culler = s.make();
  test::ScriptedBackend backend;
  backend.visible_samples = [&](std::span<const Aabb> b) {
    return std::uint64_t(b[0] == s.scene.object(1).bounds ? 0 : 9);  // object 1 is hidden
  };
  for (int f = 0; f < 12; ++f) culler->render_frame(s.view, backend);
  EXPECT_EQ(queries_of(backend, s.scene, 1), 12u);
  EXPECT_EQ(times_drawn(backend, 1), 0u);
  EXPECT_EQ(times_drawn(backend, 2), 12u);
}

TEST(PerObject, PendingObjectIsDrawnOnlyWithRenderPending) {
  for (const bool render_pending : {true, false}) {
    Stage s;
    auto culler = s.make({std::string("perobject.render_pending=") + (render_pending ? "on" : "off")});
    test::ScriptedBackend backend;
    bool answered = false;
    backend.available = [&](QueryId) { return answered; };
    for (int f = 0; f < 3; ++f) culler->render_frame(s.view, backend);  // answers late
    EXPECT_EQ(queries_of(backend, s.scene, 2), 1u) << "one query, still running";
    EXPECT_EQ(times_drawn(backend, 2), render_pending ? 3u : 0u) << render_pending;
    answered = true;
    backend.rendered.clear();
    culler->render_frame(s.view, backend);
    EXPECT_EQ(times_drawn(backend, 2), 1u) << "answered visible: drawn";
  }
}

TEST(PerObject, ObjectNearTheEyeIsDrawnWithoutAQuery) {
  Stage s;
  auto culler = s.make();
  test::ScriptedBackend backend;
  backend.visible_samples = [](std::span<const Aabb>) { return std::uint64_t(0); };
  for (int f = 0; f < 4; ++f) culler->render_frame(s.view, backend);
  EXPECT_EQ(queries_of(backend, s.scene, 3), 0u);
  EXPECT_EQ(times_drawn(backend, 3), 4u);
}
