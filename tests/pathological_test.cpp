// Pathological input, defined behaviour: a non-finite camera, a near plane
// of 0, zero or huge viewports are InputErrors naming the value; empty
// scenes, one object, objects of zero size or with no triangles, a path of
// one key and a million instances are rendered by every culler.
#include "occull/bvh.hpp"
#include "occull/culler.hpp"
#include "occull/error.hpp"
#include "occull/scene.hpp"
#include "occull/view.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

using namespace occull;

namespace {

constexpr Lens kLens{60.0f, 0.1f, 500.0f};
const View kView = test::unsampled(make_view({{0, 0, 0}, 0, 0}, kLens, 64, 64));

std::string error_of(const CameraPose& pose, const Lens& lens, int w, int h) {
  try {
    (void)make_view(pose, lens, w, h);
  } catch (const InputError& e) {
    return e.what();
  }
  return "(no error)";
}

// Every registered culler of scenes with a BVH (the tiled-world ones have
// their own tests: tiles_test.cpp), with the options it needs without a GL device.
std::vector<std::pair<std::string, Options>> every_culler() {
  std::vector<std::pair<std::string, Options>> out;
  for (const AlgorithmInfo& a : algorithms()) {
    if (a.name == "oracle" || !runs_on(a, false)) continue;  // oracle: fed by the lab's truth
    if (a.device) continue;  // culls on the device: hiz_gl_test.cpp
    Options o;
    o.set(std::string("nohc.profile=") + OCCULL_SOURCE_DIR + "/tests/data/profile-llvmpipe-320x180.json");
    out.emplace_back(a.name, o);
  }
  return out;
}

// Runs every culler over `frames` frames of `view`; the test double finds
// every query visible. Returns, per culler, the objects of the last frame.
std::map<std::string, std::vector<ObjectId>> render_with_every_culler(const Scene& scene, const View& view,
                                                                       int frames = 4) {
  const Bvh bvh = Bvh::build(scene);
  std::map<std::string, std::vector<ObjectId>> out;
  for (const auto& [name, options] : every_culler()) {
    auto culler = make_culler(name, {scene, bvh}, options, test::reading_profiles());
    test::ScriptedBackend backend;
    for (int f = 0; f < frames; ++f) {
      backend.rendered.clear();
      culler->render_frame(view, backend);
    }
    for (const auto& boxes : backend.queried)
      for (const Aabb& b : boxes)
        EXPECT_TRUE(std::isfinite(b.min.x) && std::isfinite(b.max.z) && !b.empty()) << name << " queried a box "
                                                                                       "that is not one";
    std::vector<ObjectId> r = backend.rendered;
    std::sort(r.begin(), r.end());
    r.erase(std::unique(r.begin(), r.end()), r.end());
    out[name] = r;
  }
  return out;
}

}  // namespace

TEST(Pathological, ANonFiniteCameraIsAnErrorNamingIt) {
  const float nan = std::numeric_limits<float>::quiet_NaN(), inf = std::numeric_limits<float>::infinity();
  EXPECT_NE(error_of({{nan, 0, 0}, 0, 0}, kLens, 64, 64).find("camera at (nan, 0, 0)"), std::string::npos);
  EXPECT_NE(error_of({{0, 0, 0}, inf, 0}, kLens, 64, 64).find("yaw inf"), std::string::npos);
  EXPECT_NE(error_of({{0, 0, 0}, 0, 1.6f}, kLens, 64, 64).find("camera pitch 1.6 rad"), std::string::npos);
  EXPECT_EQ(error_of({{0, 0, 0}, 0, 1.5f}, kLens, 64, 64), "(no error)");
}

TEST(Pathological, ANearPlaneOfZeroOrAFarPlaneNotBeyondItIsAnError) {
  EXPECT_NE(error_of({}, {60.0f, 0.0f, 500.0f}, 64, 64).find("lens near 0 far 500: needs 0 < near < far"),
            std::string::npos);
  EXPECT_NE(error_of({}, {60.0f, 1.0f, 1.0f}, 64, 64).find("lens near 1 far 1"), std::string::npos);
  EXPECT_NE(error_of({}, {60.0f, 1.0f, std::numeric_limits<float>::infinity()}, 64, 64).find("far inf"),
            std::string::npos);
  EXPECT_NE(error_of({}, {180.0f, 1.0f, 10.0f}, 64, 64).find("field of view 180"), std::string::npos);
  EXPECT_EQ(error_of({}, {60.0f, 1e-6f, 1e6f}, 64, 64), "(no error)");
}

TEST(Pathological, AZeroOrHugeViewportIsAnError) {
  EXPECT_NE(error_of({}, kLens, 0, 64).find("viewport 0x64: each side must be in [1, 16384]"), std::string::npos);
  EXPECT_NE(error_of({}, kLens, 64, -1).find("viewport 64x-1"), std::string::npos);
  EXPECT_NE(error_of({}, kLens, 16385, 64).find("viewport 16385x64"), std::string::npos);
  EXPECT_EQ(error_of({}, kLens, 1, 1), "(no error)");
}

TEST(Pathological, EveryCullerRendersAnEmptySceneDrawingNothing) {
  Scene scene("empty");
  for (const auto& [name, rendered] : render_with_every_culler(scene, kView))
    EXPECT_TRUE(rendered.empty()) << name;
}

TEST(Pathological, EveryCullerRendersTheOneObjectOfASceneInView) {
  const Scene scene = test::box_scene({{{-1, -1, -10}, {1, 1, -8}}});
  for (const auto& [name, rendered] : render_with_every_culler(scene, kView))
    EXPECT_EQ(rendered, std::vector<ObjectId>{0}) << name;
}

TEST(Pathological, ObjectsOfZeroSizeOrWithoutTrianglesAreHandledByEveryCuller) {
  // Object 0: a box in view. 1: a mesh of one degenerate triangle at a
  // point in view (a zero-size box). 2: a mesh with no triangles (an empty,
  // inverted box). 3: a flat panel (zero thickness) in view.
  Scene scene("degenerate");
  const MaterialId m = scene.add_material({});
  scene.add_object(scene.add_mesh(test::box_mesh({{-1, -1, -10}, {1, 1, -8}})), m, glm::mat4(1.0f),
                   OccluderClass::always);
  Mesh point;
  point.positions = {{3, 0, -12}, {3, 0, -12}, {3, 0, -12}};
  point.normals = {{0, 0, 1}, {0, 0, 1}, {0, 0, 1}};
  point.indices = {0, 1, 2};
  scene.add_object(scene.add_mesh(point), m, glm::mat4(1.0f), OccluderClass::sometimes);
  scene.add_object(scene.add_mesh(Mesh{}), m, glm::mat4(1.0f), OccluderClass::never);
  scene.add_object(scene.add_mesh(test::box_mesh({{-4, 2, -15}, {-2, 4, -15}})), m, glm::mat4(1.0f),
                   OccluderClass::sometimes);
  ASSERT_TRUE(scene.object(2).bounds.empty());
  for (const auto& [name, rendered] : render_with_every_culler(scene, kView)) {
    for (ObjectId id : {0u, 1u, 3u})
      EXPECT_TRUE(std::count(rendered.begin(), rendered.end(), id)) << name << " left out object " << id;
  }
}

TEST(Pathological, APathOfOneKeyHoldsItsPoseForEveryFrame) {
  const CameraPath path("one", "one key", {{2.0, {{1, 2, 3}, 0.5f, 0.1f}, false}});
  EXPECT_EQ(path.duration(), 0.0);
  for (int k : {0, 5, 9}) {
    const double t = path.frame_time(k, 10);
    EXPECT_TRUE(std::isfinite(t)) << k;
    EXPECT_EQ(path.sample(t).position, glm::vec3(1, 2, 3)) << k;
  }
  EXPECT_EQ(path.frame_time(0, 1), 2.0);
  EXPECT_EQ(path.frames_that_fit({30.0, 0.0}), 1);
}

TEST(Pathological, AMillionInstancesBuildABvhThatVfcCulls) {
  // One box mesh instanced 10^6 times on a 1000 x 1000 grid in front of the
  // camera: the scene stores 12 triangles, the BVH covers every object.
  Scene scene("million");
  const MaterialId m = scene.add_material({});
  const MeshId mesh = scene.add_mesh(test::box_mesh({{0, 0, 0}, {0.5f, 0.5f, 0.5f}}));
  for (int i = 0; i < 1000; ++i)
    for (int j = 0; j < 1000; ++j)
      scene.add_object(mesh, m, glm::translate(glm::mat4(1.0f), glm::vec3(float(i) - 500.0f, -2.0f, -float(j) - 1.0f)),
                       OccluderClass::sometimes);
  const Bvh bvh = Bvh::build(scene);
  EXPECT_EQ(scene.objects().size(), 1000000u);
  EXPECT_GT(bvh.size(), 1000000u / BvhOptions{}.max_leaf_objects);
  auto culler = make_culler("vfc", {scene, bvh});
  test::ScriptedBackend backend;
  culler->render_frame(kView, backend);
  std::size_t in_frustum = 0;
  for (const Object& o : scene.objects()) in_frustum += kView.frustum.classify(o.bounds) != Containment::outside;
  EXPECT_EQ(backend.rendered.size(), in_frustum);
  EXPECT_GT(in_frustum, 1000u);
  EXPECT_LT(in_frustum, 1000000u);
}
