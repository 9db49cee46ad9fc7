#include "occull/error.hpp"
#include "occull/scene.hpp"
#include "occull/motion.hpp"
#include "test_util.hpp"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

using namespace occull;

namespace {
Mesh unit_quad_mesh() {
  Mesh m;
  m.positions = {{0, 0, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
  m.normals.assign(4, glm::vec3(0, 0, 1));
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}
}  // namespace

TEST(Mesh, BoundsAndSurfaceArea) {
  const Mesh m = unit_quad_mesh();
  EXPECT_EQ(m.triangle_count(), 2u);
  EXPECT_EQ(m.bounds().max, glm::vec3(1, 1, 0));
  EXPECT_NEAR(m.surface_area(), 1.0, 1e-9);
}

TEST(Scene, ObjectBoundsFollowTheTransform) {
  Scene s("t");
  const MeshId mesh = s.add_mesh(unit_quad_mesh());
  const MaterialId mat = s.add_material({});
  const ObjectId id = s.add_object(mesh, mat, glm::translate(glm::mat4(1), {5, 0, 0}),
                                   OccluderClass::always);
  EXPECT_EQ(s.object(id).bounds.min, glm::vec3(5, 0, 0));
  EXPECT_EQ(s.object(id).triangles, 2u);
  EXPECT_FALSE(s.object(id).dynamic());
  EXPECT_EQ(s.triangle_count(), 2u);
}

TEST(Motion, LoopsAroundItsWaypointsAtItsSpeed) {
  Motion m;
  m.waypoints = {{0, 0, 0}, {10, 0, 0}, {10, 0, 10}, {0, 0, 10}};
  m.speed = 5.0f;
  EXPECT_NEAR(glm::vec3(m.transform_at(1.0)[3]).x, 5.0f, 1e-4f);
  EXPECT_NEAR(glm::vec3(m.transform_at(3.0)[3]).z, 5.0f, 1e-4f);   // on the second side
  EXPECT_NEAR(glm::vec3(m.transform_at(9.0)[3]).x, 5.0f, 1e-4f);   // 45 m: once round plus 5
}

TEST(Motion, ObjectFacesItsDirectionOfTravel) {
  Motion m;
  m.waypoints = {{0, 0, 0}, {0, 0, 10}};
  const glm::vec3 forward = glm::vec3(m.transform_at(0.5) * glm::vec4(1, 0, 0, 0));
  EXPECT_NEAR(forward.z, 1.0f, 1e-5f);
}

TEST(Motion, AnimateMovesScriptedObjectsAndTheirBounds) {
  Scene s("t");
  const MeshId mesh = s.add_mesh(unit_quad_mesh());
  const MaterialId mat = s.add_material({});
  Motion m;
  m.waypoints = {{0, 0, 0}, {100, 0, 0}};
  m.speed = 10.0f;
  std::vector<ScriptedObject> scripted;
  const ObjectId id = add_scripted_object(s, scripted, mesh, mat, m, OccluderClass::never);
  ASSERT_TRUE(s.object(id).dynamic());
  ASSERT_EQ(s.dynamic_objects().size(), 1u);
  EXPECT_EQ(s.dynamic_range(id), (Aabb{{0, 0, 0}, {100, 0, 0}})) << "where it goes";
  animate(s, scripted, 2.0);
  EXPECT_NEAR(s.object(id).bounds.min.x, 20.0f, 1e-4f);
  animate(s, scripted, 0.0);
  EXPECT_NEAR(s.object(id).bounds.min.x, 0.0f, 1e-4f);
  m.speed = 0.0f;
  EXPECT_THROW((void)add_scripted_object(s, scripted, mesh, mat, m, OccluderClass::never), InputError);
  EXPECT_EQ(scripted.size(), 1u);
}

TEST(Scene, ADynamicObjectMovesUnlistedWithinItsRange) {
  Scene s("t");
  const MeshId mesh = s.add_mesh(unit_quad_mesh());
  const MaterialId mat = s.add_material({});
  const ObjectId still = s.add_object(mesh, mat, glm::mat4(1.0f), OccluderClass::never);
  const ObjectId car = s.add_dynamic_object(mesh, mat, glm::mat4(1.0f), OccluderClass::never, {{0, 0, 0}, {50, 0, 0}});
  const std::uint64_t revision = s.placement_revision();
  s.set_transform(car, glm::translate(glm::mat4(1.0f), {7, 0, 0}));
  EXPECT_NEAR(s.object(car).bounds.min.x, 7.0f, 1e-5f);
  EXPECT_EQ(s.placement_revision(), revision) << "consumers follow every dynamic object each frame";
  s.set_transform(still, glm::translate(glm::mat4(1.0f), {7, 0, 0}));
  EXPECT_EQ(s.placement_revision(), revision + 1);
  EXPECT_EQ(s.dynamic_range(car), (Aabb{{0, 0, 0}, {50, 0, 0}}));
  EXPECT_TRUE(s.dynamic_range(still).empty());
  s.set_dynamic_range(car, {{10, 0, 0}, {60, 0, 0}});
  EXPECT_EQ(s.dynamic_range(car), (Aabb{{10, 0, 0}, {60, 0, 0}}));
  EXPECT_THROW(s.set_dynamic_range(still, {{0, 0, 0}, {1, 1, 1}}), UsageError);
  EXPECT_THROW(s.set_dynamic_range(car, {{0, 0, 0}, {std::nanf(""), 1, 1}}), InputError);
  EXPECT_EQ(s.dynamic_range(car), (Aabb{{10, 0, 0}, {60, 0, 0}})) << "unchanged by a refused call";
}

TEST(Scene, SetTransformMovesAnyObjectAndCountsAPlacement) {
  Scene s = test::box_scene({{{0, 0, 0}, {1, 1, 1}}, {{5, 0, 0}, {6, 1, 1}}});
  const std::uint64_t before = s.placement_revision();
  s.set_transform(0, glm::translate(glm::mat4(1.0f), {10, 0, 0}));
  EXPECT_EQ(s.object(0).bounds, (Aabb{{10, 0, 0}, {11, 1, 1}}));
  EXPECT_EQ(s.placement_revision(), before + 1);
  std::vector<ObjectId> changed;
  EXPECT_EQ(s.for_each_changed_since(before, [&](ObjectId id) { changed.push_back(id); }), before + 1);
  EXPECT_NE(std::find(changed.begin(), changed.end(), 0u), changed.end());
}

TEST(Scene, RemovedIdsAreEmptyAndReusedMostRecentFirst) {
  Scene s = test::box_scene({{{0, 0, 0}, {1, 1, 1}}, {{5, 0, 0}, {6, 1, 1}}, {{9, 0, 0}, {10, 1, 1}}});
  const MeshId mesh = s.object(0).mesh;
  const std::uint64_t layout = s.layout_revision();
  s.remove_object(0);
  s.remove_object(2);
  EXPECT_FALSE(s.alive(0));
  EXPECT_TRUE(s.object(2).bounds.empty());
  EXPECT_EQ(s.object(2).triangles, 0u);
  EXPECT_EQ(s.layout_revision(), layout + 2);
  EXPECT_EQ(s.add_object(mesh, 0, glm::mat4(1.0f), OccluderClass::never), 2u);
  EXPECT_EQ(s.add_object(mesh, 0, glm::mat4(1.0f), OccluderClass::never), 0u);
  EXPECT_EQ(s.add_object(mesh, 0, glm::mat4(1.0f), OccluderClass::never), 3u);
  EXPECT_TRUE(s.alive(2));
  EXPECT_EQ(s.object(2).bounds, (Aabb{{0, 0, 0}, {1, 1, 1}}));
}

TEST(Scene, RemovingADynamicObjectStopsItsMotion) {
  Scene s("dyn");
  const MeshId mesh = s.add_mesh(test::box_mesh({{-0.5f, -0.5f, -0.5f}, {0.5f, 0.5f, 0.5f}}));
  const MaterialId mat = s.add_material({});
  Motion m;
  m.waypoints = {{0, 0, 0}, {10, 0, 0}};
  std::vector<ScriptedObject> scripted;
  const ObjectId id = add_scripted_object(s, scripted, mesh, mat, m, OccluderClass::never);
  s.remove_object(id);
  animate(s, scripted, 1.0);
  EXPECT_TRUE(s.object(id).bounds.empty());
  EXPECT_TRUE(s.dynamic_range(id).empty());
  EXPECT_TRUE(s.dynamic_objects().empty());
}

TEST(Scene, BadEngineCallsAreRefusedAndChangeNothing) {
  Scene s = test::box_scene({{{0, 0, 0}, {1, 1, 1}}});
  const Object before = s.object(0);
  const std::uint64_t revision = s.placement_revision();
  glm::mat4 nan = glm::mat4(1.0f);
  nan[3][0] = std::nanf("");
  EXPECT_THROW(s.set_transform(0, nan), InputError);
  EXPECT_THROW(s.set_transform(7, glm::mat4(1.0f)), UsageError);
  EXPECT_THROW(s.remove_object(7), UsageError);
  EXPECT_THROW((void)s.add_object(9, 0, glm::mat4(1.0f), OccluderClass::never), UsageError);
  EXPECT_THROW((void)s.add_object(0, 9, glm::mat4(1.0f), OccluderClass::never), UsageError);
  EXPECT_THROW((void)s.add_object(0, 0, nan, OccluderClass::never), InputError);
  s.remove_object(0);
  try {
    s.set_transform(0, glm::mat4(1.0f));
    FAIL() << "a removed object moved";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("object 0: it was removed"), std::string::npos) << e.what();
  }
  EXPECT_THROW(s.remove_object(0), UsageError);
  EXPECT_THROW(s.place_object(0, 0, 0, glm::mat4(1.0f), OccluderClass::never), UsageError);  // removed
  Mesh past_its_positions = test::box_mesh({{0, 0, 0}, {1, 1, 1}});
  past_its_positions.indices.back() = std::uint32_t(past_its_positions.positions.size());
  EXPECT_THROW((void)s.add_mesh(past_its_positions), UsageError);
  EXPECT_EQ(s.meshes().size(), 1u);
  EXPECT_EQ(s.objects().size(), 1u);
  EXPECT_EQ(s.placement_revision(), revision + 1);  // the one removal
  (void)before;
}

TEST(Scene, MeshesWithoutVerticesCarryBoundsTrianglesAndArea) {
  Scene s("engine");
  const MeshId mesh = s.add_mesh(MeshInfo{{{-1, -1, -1}, {1, 1, 1}}, 5000, 24.0});
  const ObjectId id = s.add_object(mesh, s.add_material({}), glm::scale(glm::mat4(1.0f), glm::vec3(2.0f)),
                                   OccluderClass::always);
  EXPECT_EQ(s.object(id).bounds, (Aabb{{-2, -2, -2}, {2, 2, 2}}));
  EXPECT_EQ(s.object(id).triangles, 5000u);
  EXPECT_NEAR(s.object_surface_area(id), 96.0, 1e-4);
  EXPECT_TRUE(s.mesh(mesh).positions.empty());
  EXPECT_THROW((void)s.add_mesh(MeshInfo{{{0, 0, 0}, {std::nanf(""), 1, 1}}, 1, 1.0}), InputError);
  EXPECT_THROW((void)s.add_mesh(MeshInfo{{{0, 0, 0}, {1, 1, 1}}, 1, -1.0}), InputError);
}

TEST(Scene, TheListOfMovedObjectsStaysBoundedAndConsumersStillSeeEverything) {
  Scene s = test::box_scene({{{0, 0, 0}, {1, 1, 1}}, {{5, 0, 0}, {6, 1, 1}}});
  const std::uint64_t start = s.placement_revision();
  for (int k = 0; k < 1000; ++k) s.set_transform(ObjectId(k % 2), glm::translate(glm::mat4(1.0f), {float(k), 0, 0}));
  EXPECT_LE(s.moved_objects().size(), 64u);
  std::vector<int> seen(2, 0);
  (void)s.for_each_changed_since(start, [&](ObjectId id) { ++seen[id]; });
  EXPECT_GT(seen[0], 0);
  EXPECT_GT(seen[1], 0);
}
