// The Quake 3 reader on a tiny map written by the test, and on real
// OpenArena maps when `make data` has fetched them.
#include "occull/bvh.hpp"
#include "occull/error.hpp"
#include "occull/q3bsp.hpp"
#include "require_data.hpp"
#include "tiny_bsp.hpp"

#include <gtest/gtest.h>

#include <filesystem>

using namespace occull;

TEST(Q3Bsp, TinyMapReadsBackExactly) {
  const auto b = test::TinyBsp::example();
  const q3::Map m = q3::read_bsp(b.bytes(), "tiny.bsp");
  ASSERT_EQ(m.textures.size(), 1u);
  EXPECT_EQ(m.textures[0].name, "textures/base_wall/concrete");
  EXPECT_EQ(m.textures[0].contents, 1);
  ASSERT_EQ(m.vertices.size(), 13u);
  EXPECT_EQ(m.vertices[2].position, glm::vec3(64, 64, 0));
  EXPECT_EQ(m.vertices[4].normal, glm::vec3(0, 0, 1));
  EXPECT_EQ(m.meshverts, (std::vector<std::int32_t>{0, 1, 2, 0, 2, 3}));
  ASSERT_EQ(m.faces.size(), 2u);
  EXPECT_EQ(m.faces[0].type, q3::FaceType::polygon);
  EXPECT_EQ(m.faces[0].meshvert_count, 6);
  EXPECT_EQ(m.faces[1].type, q3::FaceType::patch);
  EXPECT_EQ(m.faces[1].patch_width, 3);
  ASSERT_EQ(m.leaves.size(), 1u);
  EXPECT_EQ(m.leaves[0].face_count, 2);
  ASSERT_EQ(m.entities.size(), 2u);
  EXPECT_EQ(m.entities[1].at("classname"), "info_player_deathmatch");
  EXPECT_EQ(m.entities[1].at("origin"), "32 32 24");
}

TEST(Q3Bsp, PatchTessellationCountsAndStaysInTheControlHull) {
  std::vector<q3::Vertex> control;
  for (int j = 0; j < 5; ++j)
    for (int i = 0; i < 3; ++i)  // a curved 3 x 5 patch: two sub-patches
      control.push_back({{float(i) * 10.0f, float(j) * 10.0f, (i == 1 ? 8.0f : 0.0f) + float(j % 2) * 3.0f}, {0, 0, 1}});
  for (int level : {1, 4, 9}) {
    std::vector<q3::Vertex> v;
    std::vector<std::uint32_t> idx;
    q3::tessellate_patch(control, 3, 5, level, v, idx);
    EXPECT_EQ(v.size(), std::size_t(2 * (level + 1) * (level + 1))) << level;
    EXPECT_EQ(idx.size(), std::size_t(2 * 2 * level * level * 3)) << level;
    Aabb hull;
    for (const auto& c : control) hull.extend(c.position);
    for (const auto& p : v) EXPECT_TRUE(hull.grown(1e-4f).contains(p.position));
    // The corners are interpolated exactly.
    EXPECT_EQ(v.front().position, control.front().position);
  }
}

TEST(Q3Bsp, SceneConvertsToMetresAndYUp) {
  const auto b = test::TinyBsp::example();
  const SceneBundle s = q3::build_scene(q3::read_bsp(b.bytes(), "tiny.bsp"), "tiny", {2, 1500});
  // Quad (2 triangles) + patch at level 2 (8 triangles).
  EXPECT_EQ(s.scene.triangle_count(), 10u);
  const Aabb box = s.scene.bounds();
  EXPECT_NEAR(box.max.x, 164.0f / 32.0f, 1e-4f);  // x stays x
  EXPECT_NEAR(box.min.z, -64.0f / 32.0f, 1e-4f);  // y becomes -z
  EXPECT_NEAR(box.max.y, 0.0f, 1e-4f);            // z becomes y
  ASSERT_FALSE(s.paths.empty());
  EXPECT_EQ(s.paths.front().name(), "tour");
  EXPECT_NEAR(s.paths.front().keys().front().pose.position.y, 50.0f / 32.0f, 1e-4f);  // eye height
}

TEST(Q3Bsp, SkyIsOpaqueNoDrawIsLeftOutAndWaterIsTranslucent) {
  // Sky surfaces are drawn in the game (the sky box is painted on them) and
  // hide what lies behind them; no-draw surfaces are invisible.
  auto b = test::TinyBsp::example();
  b.textures = {{"textures/skies/blue", 1}, {"textures/liquids/water", 32}, {"textures/common/nodraw", 1}};
  b.faces[0][0] = 0;  // the quad: sky
  b.faces[1][0] = 1;  // the patch: water
  b.faces.push_back(b.faces[0]);
  b.faces.back()[0] = 2;  // the quad again: no-draw
  auto bytes = b.bytes();
  // Surface flags sit at byte 64 of each 72-byte texture record.
  const std::size_t textures_at = std::size_t(std::to_integer<int>(bytes[16])) |
                                  std::size_t(std::to_integer<int>(bytes[17])) << 8;
  test::TinyBsp::put(bytes, textures_at + 64, q3::kSurfSky);
  test::TinyBsp::put(bytes, textures_at + 2 * 72 + 64, q3::kSurfNoDraw);
  const SceneBundle s = q3::build_scene(q3::read_bsp(bytes, "sky.bsp"), "sky", {2, 1500});
  EXPECT_EQ(s.scene.triangle_count(), 10u);  // the sky quad and the patch, not the no-draw quad
  std::size_t opaque = 0, translucent = 0;
  for (const auto& o : s.scene.objects()) {
    const Material& m = s.scene.material(o.material);
    if (m.translucent) {
      ++translucent;
      EXPECT_EQ(o.occluder, OccluderClass::never);
      EXPECT_EQ(m.name, "textures/liquids/water");
    } else {
      ++opaque;
      EXPECT_EQ(m.name, "textures/skies/blue");
      EXPECT_EQ(o.occluder, OccluderClass::always);
    }
  }
  EXPECT_EQ(opaque, 1u);
  EXPECT_EQ(translucent, 1u);
}

namespace {

const std::string kPk3 = std::string(OCCULL_DATA_DIR) + "/openarena/pak1-maps.pk3";

}  // namespace

TEST(OpenArena, ArchiveListsItsFiftyMaps) {
  OCCULL_REQUIRE_DATA(kPk3);
  const auto maps = q3::list_maps(kPk3);
  EXPECT_EQ(maps.size(), 50u);
  EXPECT_NE(std::find(maps.begin(), maps.end(), "oasago2"), maps.end());
}

TEST(OpenArena, MapsLoadWithTheTriangleCountsOfTheirFaces) {
  OCCULL_REQUIRE_DATA(kPk3);
  // Polygon + mesh triangles (REFERENCE.md) and curved patches.
  struct Expect {
    const char* map;
    std::uint64_t face_triangles;
    int patches;
  };
  for (const Expect& e : {Expect{"oasago2", 41167, 0}, Expect{"ctf_inyard", 16932, 212}, Expect{"oa_dm1", 7532, 0}}) {
    q3::LoadOptions o;
    o.patch_level = 4;
    const SceneBundle s = q3::load(kPk3 + ":" + e.map, o);
    const q3::Map m = q3::read_bsp(q3::read_map_from_pk3(kPk3, e.map), e.map);
    int patches = 0;
    std::uint64_t patch_triangles = 0;
    for (const auto& f : m.faces)
      if (f.type == q3::FaceType::patch) {
        ++patches;
        patch_triangles += std::uint64_t((f.patch_width - 1) / 2 * (f.patch_height - 1) / 2) * 2 * 16;
      }
    EXPECT_EQ(patches, e.patches) << e.map;
    const double expected = double(e.face_triangles + patch_triangles);
    // Sky, no-draw and degenerate triangles are left out: a few percent at most.
    EXPECT_GT(double(s.scene.triangle_count()), 0.9 * expected) << e.map;
    EXPECT_LE(double(s.scene.triangle_count()), expected) << e.map;
    EXPECT_GT(s.scene.objects().size(), 10u) << e.map;
    EXPECT_GT(s.paths.front().keys().size(), 4u) << e.map << ": the tour needs spawn points";
  }
}
