#include "occull/geometry.hpp"
#include "occull/view.hpp"

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

using namespace occull;

TEST(Aabb, DefaultIsEmptyAndExtendsToExactlyWhatIsAdded) {
  Aabb b;
  EXPECT_TRUE(b.empty());
  EXPECT_EQ(b.surface_area(), 0.0f);
  b.extend(glm::vec3(1, 2, 3));
  EXPECT_FALSE(b.empty());
  EXPECT_EQ(b.min, glm::vec3(1, 2, 3));
  EXPECT_EQ(b.max, glm::vec3(1, 2, 3));
  b.extend(Aabb{{0, 0, 0}, {2, 4, 6}});
  EXPECT_EQ(b.min, glm::vec3(0, 0, 0));
  EXPECT_EQ(b.max, glm::vec3(2, 4, 6));
}

TEST(Aabb, SurfaceAreaAndVolumeOfABox) {
  const Aabb b{{0, 0, 0}, {1, 2, 3}};
  EXPECT_FLOAT_EQ(b.surface_area(), 2.0f * (2 + 6 + 3));
  EXPECT_FLOAT_EQ(b.volume(), 6.0f);
}

TEST(Aabb, ContainsPointsOnTheBoundary) {
  const Aabb b{{0, 0, 0}, {1, 1, 1}};
  EXPECT_TRUE(b.contains(glm::vec3(1, 1, 1)));
  EXPECT_TRUE(b.contains(glm::vec3(0.5f)));
  EXPECT_FALSE(b.contains(glm::vec3(1.01f, 0.5f, 0.5f)));
}

TEST(Aabb, CornersEnumerateAllEightCombinations) {
  const Aabb b{{0, 0, 0}, {1, 2, 3}};
  EXPECT_EQ(b.corner(0), glm::vec3(0, 0, 0));
  EXPECT_EQ(b.corner(7), glm::vec3(1, 2, 3));
  EXPECT_EQ(b.corner(5), glm::vec3(1, 0, 3));
}

TEST(Geometry, TransformBoxIsExactForQuarterTurns) {
  const Aabb b{{0, 0, 0}, {4, 1, 2}};
  const glm::mat4 m = glm::rotate(glm::translate(glm::mat4(1), {10, 0, 0}), glm::radians(90.0f),
                                  glm::vec3(0, 1, 0));
  const Aabb t = transform_box(b, m);
  // Rotating +X by 90 degrees about +Y maps it to -Z.
  EXPECT_NEAR(t.min.x, 10.0f, 1e-5f);
  EXPECT_NEAR(t.max.x, 12.0f, 1e-5f);
  EXPECT_NEAR(t.min.z, -4.0f, 1e-5f);
  EXPECT_NEAR(t.max.z, 0.0f, 1e-5f);
  EXPECT_NEAR(t.max.y, 1.0f, 1e-5f);
}

TEST(Geometry, DistanceFromPointToBox) {
  const Aabb b{{0, 0, 0}, {1, 1, 1}};
  EXPECT_FLOAT_EQ(distance(glm::vec3(0.5f), b), 0.0f);
  EXPECT_FLOAT_EQ(distance(glm::vec3(3, 0.5f, 0.5f), b), 2.0f);
  EXPECT_FLOAT_EQ(distance(glm::vec3(4, 5, 1), b), 5.0f);
}

TEST(Geometry, PolygonAreaOfASquareEitherWinding) {
  const std::vector<glm::dvec2> ccw{{0, 0}, {2, 0}, {2, 2}, {0, 2}};
  const std::vector<glm::dvec2> cw{{0, 0}, {0, 2}, {2, 2}, {2, 0}};
  EXPECT_DOUBLE_EQ(polygon_area(ccw), 4.0);
  EXPECT_DOUBLE_EQ(polygon_area(cw), 4.0);
}

namespace {
View looking_down_minus_z(int w = 100, int h = 100) {
  return make_view(CameraPose{{0, 0, 0}, 0.0f, 0.0f}, Lens{90.0f, 0.1f, 100.0f}, w, h);
}
}  // namespace

TEST(Frustum, ClassifiesBoxesInsideOutsideAndStraddling) {
  const View v = looking_down_minus_z();
  EXPECT_EQ(v.frustum.classify({{-1, -1, -11}, {1, 1, -9}}), Containment::inside);
  EXPECT_EQ(v.frustum.classify({{-1, -1, 9}, {1, 1, 11}}), Containment::outside);        // behind
  EXPECT_EQ(v.frustum.classify({{-1, -1, -200}, {1, 1, -150}}), Containment::outside);   // past far
  EXPECT_EQ(v.frustum.classify({{50, -1, -11}, {60, 1, -9}}), Containment::outside);     // right of it
  EXPECT_EQ(v.frustum.classify({{5, -1, -11}, {20, 1, -9}}), Containment::intersecting);  // on the edge
  EXPECT_EQ(v.frustum.classify({{-1, -1, -1}, {1, 1, 1}}), Containment::intersecting);    // around the eye
}

TEST(Frustum, PlaneMaskDropsPlanesTheBoxIsFullyInside) {
  const View v = looking_down_minus_z();
  std::uint32_t mask = Frustum::all_planes;
  // Straddles only the right plane (x = -z).
  EXPECT_EQ(v.frustum.classify({{5, -1, -11}, {20, 1, -9}}, mask), Containment::intersecting);
  EXPECT_EQ(mask, 1u << Frustum::right);
}

// Far from the origin a float holds positions to millimetres (10 km): a
// box that float arithmetic cannot tell from touching a plane is not
// outside it; a box clearly past it is. (At 1,000 km the planes themselves,
// taken from a float view-projection matrix, are metres off: that is why
// coordinates are kept near a floating origin, docs/library.md.)
TEST(Frustum, ABoxWithinTheRoundingOfAPlaneIsNotOutside) {
  const glm::vec3 eye(1e4f, 0.0f, 1e4f);
  const View v = make_view(CameraPose{eye, 0.0f, 0.0f}, Lens{90.0f, 0.1f, 100.0f}, 100, 100);
  // The right plane is x - eye.x = -(z - eye.z); at z = eye.z - 11 it is at x = eye.x + 11.
  const float z0 = eye.z - 11.0f, z1 = eye.z - 9.0f;
  const Aabb touching{{eye.x + 11.0f, -1.0f, z0}, {eye.x + 12.0f, 1.0f, z1}};  // its corner on the plane
  const Aabb cm_past{{eye.x + 11.01f, -1.0f, z0}, {eye.x + 12.0f, 1.0f, z1}};  // within the rounding here
  const Aabb clearly_past{{eye.x + 21.0f, -1.0f, z0}, {eye.x + 30.0f, 1.0f, z1}};
  EXPECT_NE(v.frustum.classify(touching), Containment::outside);
  EXPECT_NE(v.frustum.classify(cm_past), Containment::outside);
  EXPECT_EQ(v.frustum.classify(clearly_past), Containment::outside);
  // Near the origin the same centimetre decides.
  const View home = looking_down_minus_z();
  EXPECT_EQ(home.frustum.classify({{11.01f, -1.0f, -11.0f}, {12.0f, 1.0f, -9.0f}}), Containment::outside);
}

TEST(Frustum, PlanesPointInwards) {
  const View v = looking_down_minus_z();
  for (int i = 0; i < Frustum::count; ++i)
    EXPECT_GT(v.frustum.plane(i).signed_distance({0, 0, -10}), 0.0f) << "plane " << i;
}

TEST(ProjectedArea, OrthographicSquareCoversItsPixels) {
  const glm::mat4 proj = glm::ortho(-1.0f, 1.0f, -1.0f, 1.0f, 0.1f, 10.0f);
  const Aabb b{{-0.5f, -0.5f, -6}, {0.5f, 0.5f, -5}};
  EXPECT_NEAR(projected_area(b, proj, 100, 100), 2500.0, 1e-6);
}

TEST(ProjectedArea, ClippedToTheViewport) {
  const glm::mat4 proj = glm::ortho(-1.0f, 1.0f, -1.0f, 1.0f, 0.1f, 10.0f);
  const Aabb b{{0.5f, 0.5f, -6}, {3, 3, -5}};
  EXPECT_NEAR(projected_area(b, proj, 100, 100), 25.0 * 25.0, 1e-6);
}

TEST(ProjectedArea, PerspectiveFaceOnBoxMatchesHandComputedArea) {
  // 90 degree fov: at distance 10 the viewport spans [-10, 10]; a 2 x 2 face
  // there covers 1/100 of a 200 x 200 viewport = 400 px.
  const View v = looking_down_minus_z(200, 200);
  const Aabb b{{-1, -1, -12}, {1, 1, -10}};
  EXPECT_NEAR(projected_area(b, v.view_proj, 200, 200), 400.0, 1.0);
}

TEST(ProjectedArea, BoxBehindTheEyeCoversNothing) {
  const View v = looking_down_minus_z();
  EXPECT_EQ(projected_area({{-1, -1, 5}, {1, 1, 7}}, v.view_proj, 100, 100), 0.0);
}

TEST(ProjectedArea, BoxAroundTheEyeCoversTheWholeViewport) {
  const View v = looking_down_minus_z();
  EXPECT_NEAR(projected_area({{-5, -5, -5}, {5, 5, 5}}, v.view_proj, 100, 100), 10000.0, 1e-6);
}

TEST(ProjectedArea, BoxCrossingTheNearPlaneIsClippedNotLost) {
  const View v = looking_down_minus_z();
  const double a = projected_area({{0.5f, -1, -3}, {2, 1, 1}}, v.view_proj, 100, 100);
  EXPECT_GT(a, 0.0);
  EXPECT_LE(a, 10000.0);
}

TEST(CameraPath, InterpolatesAndHoldsBeforeACut) {
  CameraPath path("p", "", {{0.0, {{0, 0, 0}, 0, 0}, false},
                            {2.0, {{2, 0, 0}, 0, 0}, false},
                            {4.0, {{100, 0, 0}, 0, 0}, true}});
  EXPECT_FLOAT_EQ(path.sample(1.0).position.x, 1.0f);
  EXPECT_FLOAT_EQ(path.sample(3.9).position.x, 2.0f);  // held until the jump
  EXPECT_FLOAT_EQ(path.sample(4.0).position.x, 100.0f);
  EXPECT_DOUBLE_EQ(path.frame_time(0, 5), 0.0);
  EXPECT_DOUBLE_EQ(path.frame_time(4, 5), 4.0);
}

TEST(CameraPath, YawTakesTheShorterArc) {
  CameraPath path("p", "", {{0.0, {{0, 0, 0}, glm::radians(170.0f), 0}, false},
                            {1.0, {{0, 0, 0}, glm::radians(-170.0f), 0}, false}});
  EXPECT_NEAR(glm::degrees(path.sample(0.5).yaw), 180.0f, 1e-3f);
}

TEST(CameraPath, FramesAtAFixedRateFromAStartTime) {
  CameraPath path("p", "", {{1.0, {{0, 0, 0}, 0, 0}, false}, {5.0, {{4, 0, 0}, 0, 0}, false}});
  const FrameSampling at_10fps{10.0, 0.5};
  EXPECT_DOUBLE_EQ(path.frame_time(0, 100, at_10fps), 1.5);  // 0.5 s after the first key
  EXPECT_DOUBLE_EQ(path.frame_time(7, 100, at_10fps), 2.2);
  EXPECT_EQ(path.frames_that_fit(at_10fps), 36);              // 1.5 .. 5.0 s
  EXPECT_EQ(path.frames_that_fit({10.0, 4.0}), 1);
  EXPECT_EQ(path.frames_that_fit({10.0, 4.5}), 0);
  EXPECT_EQ(path.frames_that_fit({}), std::numeric_limits<int>::max());  // spread: any number
  EXPECT_DOUBLE_EQ(path.frame_time(2, 5), 3.0);  // spread: 1, 2, 3, 4, 5
}
