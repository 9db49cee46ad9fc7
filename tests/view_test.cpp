// Views from an engine's matrices: every clip convention (OpenGL's [-1, 1],
// [0, 1], reversed-Z), infinite far planes, asymmetric and orthographic
// projections, and the refusals of bad matrices.
#include "occull/cost_model.hpp"
#include "occull/error.hpp"
#include "occull/view.hpp"

#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

using namespace occull;

namespace {

constexpr float kFov = 1.0f;  // radians
constexpr float kAspect = 16.0f / 9.0f;
constexpr float kNear = 0.5f, kFar = 300.0f;
const glm::mat4 kCamera = glm::lookAt(glm::vec3(3, 2, 1), glm::vec3(10, 1, -20), glm::vec3(0, 1, 0));

// The same lens in four clip conventions.
glm::mat4 gl_standard() { return glm::perspectiveRH_NO(kFov, kAspect, kNear, kFar); }
glm::mat4 zero_to_one() { return glm::perspectiveRH_ZO(kFov, kAspect, kNear, kFar); }
glm::mat4 gl_reversed() {
  glm::mat4 p = gl_standard();
  for (int c = 0; c < 4; ++c) p[c][2] = -p[c][2];  // depth negated: near 1, far -1
  return p;
}
glm::mat4 zero_to_one_reversed() { return glm::perspectiveRH_ZO(kFov, kAspect, kFar, kNear); }
glm::mat4 infinite_reversed() { return perspective_reversed_infinite(kFov, kAspect, kNear); }

void expect_same_planes(const Frustum& a, const Frustum& b, int sides, const char* what) {
  for (int i = 0; i < sides; ++i) {
    EXPECT_NEAR(glm::length(a.plane(i).n - b.plane(i).n), 0.0f, 1e-4f) << what << " plane " << i;
    EXPECT_NEAR(a.plane(i).d, b.plane(i).d, 1e-3f * std::max(1.0f, std::abs(b.plane(i).d))) << what << " plane " << i;
  }
}

}  // namespace

TEST(ViewFromMatrices, EqualsThePoseViewForOpenGLMatrices) {
  const CameraPose pose{{3, 2, 1}, 0.4f, -0.1f};
  const Lens lens{60.0f, 0.1f, 800.0f};
  const View a = make_view(pose, lens, 320, 180);
  const View b = make_view(a.view, a.proj, 320, 180);
  EXPECT_NEAR(glm::length(a.eye - b.eye), 0.0f, 1e-4f);
  EXPECT_NEAR(b.near, lens.near, 1e-5f);
  EXPECT_NEAR(b.far, lens.far, 1e-3f * lens.far);  // far is ill-conditioned in a float matrix
  EXPECT_FLOAT_EQ(a.near_radius, b.near_radius);
  EXPECT_FALSE(b.orthographic);
  expect_same_planes(a.frustum, b.frustum, 6, "pose");
  // The near-plane radius is the distance to a corner of the near rectangle.
  const float half_h = lens.near * std::tan(glm::radians(lens.fov_y_degrees) / 2.0f);
  const float half_w = half_h * 320.0f / 180.0f;
  EXPECT_NEAR(a.near_radius, std::sqrt(lens.near * lens.near + half_w * half_w + half_h * half_h), 1e-5f);
}

TEST(ViewFromMatrices, EveryClipConventionGivesTheSameFrustumNearAndFar) {
  const View reference = make_view(kCamera, gl_standard(), 640, 360);
  EXPECT_NEAR(reference.near, kNear, 1e-5f);
  EXPECT_NEAR(reference.far, kFar, 0.05f);
  struct Case {
    const char* name;
    glm::mat4 proj;
    ClipSpace clip;
  };
  const Case cases[] = {
      {"[0, 1]", zero_to_one(), {DepthRange::zero_to_one, false}},
      {"[-1, 1] reversed", gl_reversed(), {DepthRange::negative_one_to_one, true}},
      {"[0, 1] reversed", zero_to_one_reversed(), {DepthRange::zero_to_one, true}},
  };
  for (const Case& c : cases) {
    const View v = make_view(kCamera, c.proj, 640, 360, c.clip);
    EXPECT_NEAR(v.near, kNear, 1e-4f) << c.name;
    EXPECT_NEAR(v.far, kFar, 0.1f) << c.name;
    EXPECT_NEAR(v.near_radius, reference.near_radius, 1e-4f) << c.name;
    expect_same_planes(v.frustum, reference.frustum, 6, c.name);
  }
}

TEST(ViewFromMatrices, WrongConventionsAreRefusedNotMisread) {
  // A [0, 1] reversed matrix read as OpenGL's puts the near plane behind the eye.
  EXPECT_THROW((void)make_view(kCamera, zero_to_one_reversed(), 640, 360), InputError);
  try {
    (void)make_view(kCamera, gl_standard(), 640, 360, {DepthRange::zero_to_one, true});
    FAIL() << "accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("reversed"), std::string::npos) << e.what();
  }
}

TEST(ViewFromMatrices, InfiniteFarPlaneKeepsEveryBoxInFrontInside) {
  const View v = make_view(kCamera, infinite_reversed(), 640, 360, {DepthRange::zero_to_one, true});
  EXPECT_TRUE(std::isinf(v.far));
  EXPECT_NEAR(v.near, kNear, 1e-5f);
  const View finite = make_view(kCamera, zero_to_one_reversed(), 640, 360, {DepthRange::zero_to_one, true});
  expect_same_planes(v.frustum, finite.frustum, 5, "infinite");  // all but the far plane
  // Far beyond any finite far plane, straight ahead: inside.
  const glm::vec3 ahead = v.eye + 1e6f * glm::normalize(glm::vec3(10, 1, -20) - v.eye);
  const Aabb far_box{ahead - glm::vec3(10.0f), ahead + glm::vec3(10.0f)};
  EXPECT_NE(v.frustum.classify(far_box), Containment::outside);
  EXPECT_EQ(finite.frustum.classify(far_box), Containment::outside);
  // Behind the eye: still outside.
  const glm::vec3 behind = v.eye - 50.0f * glm::normalize(glm::vec3(10, 1, -20) - v.eye);
  EXPECT_EQ(v.frustum.classify({behind - glm::vec3(1.0f), behind + glm::vec3(1.0f)}), Containment::outside);
}

TEST(ViewFromMatrices, AsymmetricFrustumSeesOnlyItsSide) {
  // An eye of a stereo pair: the frustum leans right (left 0.1, right 0.5 at near 0.5).
  const glm::mat4 proj = glm::frustum(-0.1f, 0.5f, -0.2f, 0.2f, 0.5f, 100.0f);
  const View v = make_view(glm::mat4(1.0f), proj, 400, 200);
  EXPECT_NEAR(v.near, 0.5f, 1e-5f);
  // At 10 m the view spans x in [-2, 10].
  EXPECT_NE(v.frustum.classify({{8.0f, -0.5f, -10.5f}, {9.0f, 0.5f, -9.5f}}), Containment::outside);
  EXPECT_EQ(v.frustum.classify({{-4.0f, -0.5f, -10.5f}, {-3.0f, 0.5f, -9.5f}}), Containment::outside);
  // Its near-plane radius reaches the farther corner (0.5, +-0.2, -0.5).
  EXPECT_NEAR(v.near_radius, std::sqrt(0.25f + 0.04f + 0.25f), 1e-4f);
  // The screen fraction follows the lens's real width: half that of a
  // symmetric lens twice as wide.
  const View wide = make_view(glm::mat4(1.0f), glm::frustum(-1.2f, 1.2f, -0.2f, 0.2f, 0.5f, 100.0f), 400, 200);
  EXPECT_NEAR(bbox_screen_fraction(6.0, 10.0, v) / bbox_screen_fraction(6.0, 10.0, wide), 4.0, 1e-6);
}

TEST(ViewFromMatrices, OrthographicViewsHaveNoPerspective) {
  const glm::mat4 proj = glm::ortho(-20.0f, 20.0f, -10.0f, 10.0f, -5.0f, 200.0f);
  const View v = make_view(kCamera, proj, 400, 200);
  EXPECT_TRUE(v.orthographic);
  EXPECT_NEAR(v.near, -5.0f, 1e-4f);  // behind the camera: allowed in an orthographic view
  EXPECT_NEAR(v.far, 200.0f, 1e-3f);
  EXPECT_NEAR(v.near_radius, std::sqrt(25.0f + 400.0f + 100.0f), 1e-3f);
  // Size on screen does not depend on distance.
  EXPECT_DOUBLE_EQ(bbox_screen_fraction(6.0, 1.0, v), bbox_screen_fraction(6.0, 100.0, v));
  EXPECT_NEAR(bbox_screen_fraction(6.0, 1.0, v), 1.0 / 800.0, 1e-9);  // a 1 m^2 face of a 40 x 20 screen
  // A [0, 1] orthographic projection reads the same.
  const View zo = make_view(kCamera, glm::orthoRH_ZO(-20.0f, 20.0f, -10.0f, 10.0f, -5.0f, 200.0f), 400, 200,
                            {DepthRange::zero_to_one, false});
  EXPECT_NEAR(zo.near, -5.0f, 1e-4f);
  expect_same_planes(zo.frustum, v.frustum, 6, "orthographic [0, 1]");
}

TEST(ViewFromMatrices, SymmetricPerspectiveScreenFractionIsThePapers) {
  const View v = make_view(kCamera, gl_standard(), 640, 360);
  const double fov = 2.0 * std::atan(1.0 / double(v.proj[1][1]));
  for (const double d : {1.0, 7.5, 120.0})
    EXPECT_NEAR(bbox_screen_fraction(24.0, d, v) / bbox_screen_fraction(24.0, d, 640, 360, fov), 1.0, 1e-6) << d;
}

TEST(ViewFromMatrices, BadMatricesAreRefusedNamingTheValue) {
  const auto refused = [](const glm::mat4& view, const glm::mat4& proj, const std::string& says, int w = 64,
                          int h = 64) {
    try {
      (void)make_view(view, proj, w, h);
      ADD_FAILURE() << "accepted; expected: " << says;
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  };
  glm::mat4 nan_view = kCamera;
  nan_view[3][1] = std::numeric_limits<float>::quiet_NaN();
  refused(nan_view, gl_standard(), "view matrix: entry [column 3][row 1] is nan");
  glm::mat4 inf_proj = gl_standard();
  inf_proj[0][0] = std::numeric_limits<float>::infinity();
  refused(kCamera, inf_proj, "projection matrix: entry [column 0][row 0] is inf");
  refused(glm::mat4(0.0f), gl_standard(), "cannot be inverted");
  glm::mat4 flat = gl_standard();
  flat[0][0] = 0.0f;
  refused(kCamera, flat, "singular");
  glm::mat4 tilted = gl_standard();
  tilted[0][3] = 0.3f;
  refused(kCamera, tilted, "neither perspective");
  refused(kCamera, gl_standard(), "viewport", 0, 64);
}

// Exact sub-pixel culling (holds_no_sample): a 10 × 10 viewport, 90 degrees,
// looking down -Z from the origin. At a distance of 10 a pixel is 2 units
// and pixel centres lie at odd coordinates (-9, -7, ..., 9).
namespace {
View ten_by_ten(glm::vec3 eye = glm::vec3(0.0f)) { return make_view({eye, 0, 0}, {90.0f, 0.1f, 100.0f}, 10, 10); }
Aabb flat_box(float x0, float x1, float y0, float y1, glm::vec3 eye = glm::vec3(0.0f)) {
  return {eye + glm::vec3(x0, y0, -10.0f), eye + glm::vec3(x1, y1, -10.0f)};
}
}  // namespace

TEST(Subpixel, ABoxBetweenPixelCentresHoldsNoSample) {
  EXPECT_TRUE(holds_no_sample(flat_box(-8.9f, -7.1f, -8.9f, -7.1f), ten_by_ten()));
  // Between centres on one axis only is enough.
  EXPECT_TRUE(holds_no_sample(flat_box(-8.9f, -7.1f, -9.5f, 9.5f), ten_by_ten()));
  EXPECT_FALSE(holds_no_sample(flat_box(-9.5f, 9.5f, -9.5f, 9.5f), ten_by_ten()));
}

TEST(Subpixel, ABoxSmallerThanAPixelOverACentreHoldsOne) {
  // A fifth of a pixel across, over the centre (-7, -7): it makes a fragment.
  const Aabb box = flat_box(-7.2f, -6.8f, -7.2f, -6.8f);
  EXPECT_FALSE(holds_no_sample(box, ten_by_ten()));
  // A size threshold (engines' small-feature culling) culls it: it pops.
  SubpixelRules size_threshold;
  size_threshold.pixel_centres = false;
  EXPECT_TRUE(holds_no_sample(box, ten_by_ten(), size_threshold));
}

TEST(Subpixel, AnEdgeWithinTheSnappingMarginOfACentreKeepsTheBox) {
  // Ends 1/128 pixel before the centre at -7: snapping may move it across.
  const float before = -7.0f - 2.0f / 128.0f;
  const Aabb box = flat_box(-8.9f, before, -8.9f, -7.1f + 2.0f);
  EXPECT_FALSE(holds_no_sample(box, ten_by_ten()));
  SubpixelRules no_margin;
  no_margin.snapping_margin = false;
  EXPECT_TRUE(holds_no_sample(box, ten_by_ten(), no_margin));
  // A centre exactly on the edge is inside (ties keep the box).
  EXPECT_FALSE(holds_no_sample(flat_box(-8.9f, -7.0f, -8.9f, -5.0f), ten_by_ten(), no_margin));
}

TEST(Subpixel, FarFromTheOriginTheBoxIsGrownForFloatRounding) {
  // At 1e6 a float holds 1/16 of a unit: the device's vertices may lie that
  // far outside their box. 2^-20 of 1e6 (0.95 units, half a pixel here)
  // keeps a box ending 0.3 pixel before a centre.
  const glm::vec3 eye(1.0e6f, 0.0f, 0.0f);
  const Aabb box = flat_box(-8.9f, -7.6f, -8.9f, -5.0f, eye);
  EXPECT_FALSE(holds_no_sample(box, ten_by_ten(eye)));
  SubpixelRules exact;
  exact.grow_for_rounding = false;
  EXPECT_TRUE(holds_no_sample(box, ten_by_ten(eye), exact));
}

TEST(Subpixel, ABoxReachingTheNearPlaneOrTheEyeIsKept) {
  const View view = ten_by_ten();
  EXPECT_FALSE(holds_no_sample({{0.01f, 0.01f, -10.0f}, {0.02f, 0.02f, 0.05f}}, view));  // through the near plane
  EXPECT_FALSE(holds_no_sample({{0.01f, 0.01f, 1.0f}, {0.02f, 0.02f, 2.0f}}, view));     // behind the eye
}

TEST(Subpixel, OnlyASingleSampledViewSkipsAnything) {
  View view = ten_by_ten();
  view.samples = 0;  // MSAA, or rendered at another size
  EXPECT_FALSE(holds_no_sample(flat_box(-8.9f, -7.1f, -8.9f, -7.1f), view));
  EXPECT_FALSE(holds_no_sample(Aabb{}, ten_by_ten()));  // empty
}

// The test reads the view's eye_projection, made by make_view; a View put
// together by hand (all zero there) skips nothing rather than guessing.
TEST(Subpixel, TheProjectionIsMakeViewsAndAHandMadeViewSkipsNothing) {
  const View view = ten_by_ten();
  EXPECT_EQ(view.eye_projection, eye_relative_projection(view));
  const View from_matrices = make_view(view.view, view.proj, 10, 10);
  EXPECT_EQ(from_matrices.eye_projection, eye_relative_projection(from_matrices));
  const Aabb between = flat_box(-8.9f, -7.1f, -8.9f, -7.1f);
  EXPECT_TRUE(holds_no_sample(between, from_matrices));
  View by_hand = view;
  by_hand.eye_projection = glm::dmat4(0.0);
  EXPECT_FALSE(holds_no_sample(between, by_hand));
}

// holds_no_sample projects two corners, then the rest, and sums matrix
// columns instead of multiplying each corner: it must decide as projecting
// all 8 corners one by one does (the rules' definition, written out here).
namespace {
bool corner_by_corner(const Aabb& box, const View& view) {
  glm::dvec3 lo(box.min), hi(box.max);
  double magnitude = 0.0;
  for (int a = 0; a < 3; ++a) magnitude = std::max({magnitude, std::abs(lo[a]), std::abs(hi[a])});
  lo -= magnitude / 1048576.0;
  hi += magnitude / 1048576.0;
  double x0 = 1e300, x1 = -1e300, y0 = 1e300, y1 = -1e300;
  for (int k = 0; k < 8; ++k) {
    const glm::dvec3 p((k & 1) ? hi.x : lo.x, (k & 2) ? hi.y : lo.y, (k & 4) ? hi.z : lo.z);
    const glm::dvec4 c = view.eye_projection * glm::dvec4(p - glm::dvec3(view.eye), 1.0);
    if (c.w <= 0.0 || c.z <= double(view.clip.near_depth()) * c.w) return false;
    const double x = (c.x / c.w * 0.5 + 0.5) * view.width, y = (c.y / c.w * 0.5 + 0.5) * view.height;
    x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
  }
  const auto centre_in = [](double from, double to, int size) {
    for (int i = 0; i < size; ++i)
      if (from - 1.0 / 64.0 <= i + 0.5 && i + 0.5 <= to + 1.0 / 64.0) return true;
    return false;
  };
  return !centre_in(x0, x1, view.width) || !centre_in(y0, y1, view.height);
}
}  // namespace

TEST(Subpixel, AgreesWithProjectingEveryCornerOnRandomBoxes) {
  const View view = make_view({glm::vec3(3.0f, 2.0f, 1.0f), 0.4f, -0.2f}, {70.0f, 0.5f, 500.0f}, 64, 36);
  std::mt19937 random(46);
  const auto uniform = [&](float a, float b) { return std::uniform_real_distribution<float>(a, b)(random); };
  int culled = 0, kept = 0;
  for (int i = 0; i < 20000; ++i) {
    // Around the eye, most of them in front, from far away to through the near plane.
    const glm::vec3 at = view.eye + glm::vec3(uniform(-20, 20), uniform(-12, 12), uniform(-40, 1));
    const glm::vec3 size(uniform(0.0f, 0.4f), uniform(0.0f, 0.4f), uniform(0.0f, 0.4f));
    const Aabb box{at, at + size};
    const bool expected = corner_by_corner(box, view);
    ASSERT_EQ(holds_no_sample(box, view), expected) << "box " << i;
    (expected ? culled : kept) += 1;
  }
  // Both answers are common: the comparison says something.
  EXPECT_GT(culled, 2000);
  EXPECT_GT(kept, 2000);
}
