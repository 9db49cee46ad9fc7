#include "occull/error.hpp"
#include "occull/scenes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include <glm/trigonometric.hpp>

using namespace occull;

namespace {

void expect_identical(const Scene& a, const Scene& b) {
  ASSERT_EQ(a.objects().size(), b.objects().size());
  ASSERT_EQ(a.meshes().size(), b.meshes().size());
  for (std::size_t i = 0; i < a.meshes().size(); ++i) {
    EXPECT_EQ(a.meshes()[i].positions, b.meshes()[i].positions);
    EXPECT_EQ(a.meshes()[i].indices, b.meshes()[i].indices);
  }
  for (std::size_t i = 0; i < a.objects().size(); ++i) {
    EXPECT_EQ(a.objects()[i].transform, b.objects()[i].transform);
    EXPECT_EQ(a.objects()[i].material, b.objects()[i].material);
  }
}

std::string error_of(std::string_view spec) {
  try {
    (void)make_scene(spec);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(Scenes, SameSpecGivesTheSameScene) {
  for (const char* spec : {"city:blocks=4,traffic=10", "field:objects=500"}) {
    const SceneBundle a = make_scene(spec);
    const SceneBundle b = make_scene(spec);
    expect_identical(a.scene, b.scene);
  }
}

TEST(Scenes, SeedChangesTheScene) {
  const SceneBundle a = make_scene("field:objects=200,seed=1");
  const SceneBundle b = make_scene("field:objects=200,seed=2");
  EXPECT_NE(a.scene.objects().back().transform, b.scene.objects().back().transform);
}

TEST(Scenes, DynamicObjectsMoveDeterministically) {
  SceneBundle a = make_scene("city:blocks=3,traffic=5");
  SceneBundle b = make_scene("city:blocks=3,traffic=5");
  animate(a.scene, a.scripted, 3.25);
  animate(b.scene, b.scripted, 3.25);
  ASSERT_EQ(a.scene.dynamic_objects().size(), 5u);
  for (ObjectId id : a.scene.dynamic_objects())
    EXPECT_EQ(a.scene.object(id).bounds, b.scene.object(id).bounds);
}

TEST(Scenes, DefaultCityIsLargeAndHasEveryIngredient) {
  const SceneBundle city = make_scene("city");
  EXPECT_GT(city.scene.triangle_count(), 800'000u);
  EXPECT_GT(city.scene.dynamic_objects().size(), 0u);
  bool translucent = false;
  for (const auto& o : city.scene.objects())
    translucent = translucent || city.scene.material(o.material).translucent;
  EXPECT_TRUE(translucent);
  for (const char* p : {"street", "flyover", "turn"}) EXPECT_NO_THROW((void)city.path(p));
}

TEST(Scenes, CityPathsStayOutOfStaticObjects) {
  const SceneBundle city = make_scene("city:blocks=5");
  for (const auto& path : city.paths) {
    for (int k = 0; k < 200; ++k) {
      const glm::vec3 eye = path.sample(path.frame_time(k, 200)).position;
      for (const auto& o : city.scene.objects())
        if (!o.dynamic()) ASSERT_FALSE(o.bounds.contains(eye)) << path.name() << " frame " << k;
    }
  }
}

TEST(Scenes, PathsGiveFinitePoses) {
  for (const auto& info : embedded_scenes()) {
    const SceneBundle b = make_scene(info.name);
    ASSERT_EQ(b.paths.size(), info.paths.size());
    for (const auto& path : b.paths) {
      EXPECT_GT(path.duration(), 0.0);
      for (int k = 0; k < 50; ++k) {
        const CameraPose p = path.sample(path.frame_time(k, 50));
        EXPECT_TRUE(std::isfinite(p.position.x) && std::isfinite(p.yaw) && std::isfinite(p.pitch));
        EXPECT_LT(std::abs(p.pitch), 1.5f);
      }
    }
  }
}

TEST(Scenes, UnknownSceneListsTheValidOnes) {
  EXPECT_NE(error_of("town").find("city, field"), std::string::npos);
}

TEST(Scenes, UnknownParameterListsTheSceneParameters) {
  const std::string e = error_of("city:bloks=3");
  EXPECT_NE(e.find("bloks"), std::string::npos);
  EXPECT_NE(e.find("blocks, floors"), std::string::npos);
}

TEST(Scenes, BadParameterValuesAreRejected) {
  EXPECT_NE(error_of("city:blocks=2").find("outside"), std::string::npos);
  EXPECT_NE(error_of("city:blocks=4.5").find("whole number"), std::string::npos);
  EXPECT_NE(error_of("city:blocks=abc").find("not a number"), std::string::npos);
  EXPECT_NE(error_of("city:blocks").find("key=value"), std::string::npos);
}

TEST(Scenes, UnknownPathListsTheValidOnes) {
  const SceneBundle f = make_scene("field:objects=10");
  try {
    (void)f.path("street");
    FAIL();
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("overview, glide"), std::string::npos);
  }
}

TEST(Scenes, TrackIsThousandsOfSmallMeshesAlongARoadTheLapFollows) {
  const SceneBundle track = make_scene("track");
  const auto objects = track.scene.objects();
  ASSERT_GT(objects.size(), 5000u);
  std::vector<std::uint32_t> triangles;
  for (const auto& o : objects) triangles.push_back(o.triangles);
  std::nth_element(triangles.begin(), triangles.begin() + std::ptrdiff_t(triangles.size() / 2), triangles.end());
  EXPECT_LE(triangles[triangles.size() / 2], 64u) << "the median object is a small mesh";
  const CameraPath& lap = track.path("lap");
  float previous_yaw = lap.sample(0.0).yaw;
  for (int k = 0; k < 400; ++k) {
    const CameraPose p = lap.sample(lap.frame_time(k, 400));
    EXPECT_NEAR(p.position.y, 1.2f, 0.01f) << "frame " << k;  // on the flat road, at eye height
    bool on_road = false;
    for (const auto& o : objects)
      on_road = on_road || (track.scene.material(o.material).name == "asphalt" &&
                            o.bounds.grown(0.5f).contains({p.position.x, 0.0f, p.position.z}));
    EXPECT_TRUE(on_road) << "frame " << k << " is off the road";
    EXPECT_LT(std::abs(p.yaw - previous_yaw), glm::radians(15.0f)) << "frame " << k << ": the lap spins";
    previous_yaw = p.yaw;
  }
}
