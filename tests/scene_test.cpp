#include "occull/scene.hpp"

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

TEST(Scene, UpdateMovesDynamicObjectsAndTheirBounds) {
  Scene s("t");
  const MeshId mesh = s.add_mesh(unit_quad_mesh());
  const MaterialId mat = s.add_material({});
  Motion m;
  m.waypoints = {{0, 0, 0}, {100, 0, 0}};
  m.speed = 10.0f;
  const ObjectId id = s.add_dynamic_object(mesh, mat, m, OccluderClass::never);
  ASSERT_TRUE(s.object(id).dynamic());
  ASSERT_EQ(s.dynamic_objects().size(), 1u);
  s.update(2.0);
  EXPECT_NEAR(s.object(id).bounds.min.x, 20.0f, 1e-4f);
  s.update(0.0);
  EXPECT_NEAR(s.object(id).bounds.min.x, 0.0f, 1e-4f);
}
