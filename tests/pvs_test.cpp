// An independent cross-check of the ground truth on real levels: whatever
// the truth pass finds visible must lie in the clusters the map's own PVS
// (the BSP visdata lump, computed by the level's compiler) says are visible
// from the eye's cluster.
#include "gl_test_util.hpp"
#include "require_data.hpp"
#include "occull/lab.hpp"
#include "occull/q3bsp.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

using namespace occull;

namespace {

const std::string kPk3 = std::string(OCCULL_DATA_DIR) + "/openarena/pak1-maps.pk3";

struct Level {
  q3::Map map;
  std::vector<std::vector<std::int32_t>> object_faces;     // per object id
  std::vector<std::vector<std::int32_t>> face_clusters;    // per face: clusters of the leaves holding it
  std::size_t objects = 0;
};

Level load_level(const std::string& name) {
  Level l;
  l.map = q3::read_bsp(q3::read_map_from_pk3(kPk3, name), name);
  l.objects = q3::build_scene(l.map, "q3:" + name, {}, &l.object_faces).scene.objects().size();
  l.face_clusters.resize(l.map.faces.size());
  for (const q3::Leaf& leaf : l.map.leaves)
    for (std::int32_t k = 0; k < leaf.face_count; ++k)
      l.face_clusters[std::size_t(l.map.leaf_faces[std::size_t(leaf.first_face + k)])].push_back(leaf.cluster);
  return l;
}

// Whether object `id` may be visible from `cluster` by the map's PVS. A face
// in no leaf belongs to a brush model (a door, a platform): the PVS says
// nothing about it.
bool pvs_allows(const Level& l, ObjectId id, std::int32_t cluster) {
  for (std::int32_t face : l.object_faces[id]) {
    const auto& clusters = l.face_clusters[std::size_t(face)];
    if (clusters.empty()) return true;
    for (std::int32_t c : clusters)
      if (q3::cluster_sees(l.map, cluster, c)) return true;
  }
  return false;
}

struct Tally {
  int frames_checked = 0, frames_skipped = 0;
  std::size_t truth_objects = 0, excluded_by_pvs = 0;
  std::vector<std::string> outside_pvs;  // truth objects the PVS rules out
};

Tally check_tour(const Level& level, const std::string& name, int frames) {
  Session session("q3:" + kPk3 + ":" + name, test::small_target(160, 90));
  EXPECT_EQ(session.bundle().scene.objects().size(), level.objects) << name << ": the same build";
  const CameraPath& tour = session.path("tour");
  const auto truth = session.ground_truth(tour, frames);
  Tally t;
  for (int k = 0; k < frames; ++k) {
    const std::int32_t cluster = q3::find_cluster(level.map, q3::to_quake(session.view_at(tour, k, frames).eye));
    if (cluster < 0) {
      ++t.frames_skipped;  // the eye in solid space: the PVS has nothing to say
      continue;
    }
    ++t.frames_checked;
    for (ObjectId id = 0; id < level.objects; ++id) t.excluded_by_pvs += pvs_allows(level, id, cluster) ? 0 : 1;
    for (const auto& v : truth[std::size_t(k)].visible) {
      ++t.truth_objects;
      if (!pvs_allows(level, v.id, cluster))
        t.outside_pvs.push_back(name + " frame " + std::to_string(k) + ": object " + std::to_string(v.id) + " (" +
                                std::to_string(v.pixels) + " px) is in the truth but outside the PVS of cluster " +
                                std::to_string(cluster));
    }
  }
  return t;
}

}  // namespace

TEST(OpenArenaPvs, TruthLiesInThePotentiallyVisibleSetOfTheEyesCluster) {
  OCCULL_REQUIRE_DATA(kPk3);
  for (const char* name : {"oasago2", "ctf_inyard", "oa_dm1", "hydronex", "oa_rpg3dm2"}) {
    const Level level = load_level(name);
    ASSERT_GT(level.map.vis.clusters, 1) << name << " carries a PVS";
    const Tally t = check_tour(level, name, 24);
    EXPECT_TRUE(t.outside_pvs.empty()) << t.outside_pvs.size() << " truth objects outside the PVS; first: "
                                       << (t.outside_pvs.empty() ? "" : t.outside_pvs.front());
    EXPECT_GE(t.frames_checked, 18) << name << ": the tour's eye is in open space";
    EXPECT_GT(t.truth_objects, 0u) << name;
    // Not vacuous: the PVS does rule objects out from these eyes.
    EXPECT_GT(t.excluded_by_pvs, 0u) << name;
  }
}

TEST(OpenArenaPvs, ACutDownPvsIsCaught) {
  // Break the map's PVS on purpose (each cluster sees only itself): the
  // cross-check must report truth objects outside it.
  OCCULL_REQUIRE_DATA(kPk3);
  Level level = load_level("oasago2");
  q3::VisData& v = level.map.vis;
  std::fill(v.bits.begin(), v.bits.end(), 0);
  for (std::int32_t c = 0; c < v.clusters; ++c)
    v.bits[std::size_t(c) * std::size_t(v.bytes_per_row) + std::size_t(c) / 8] |= std::uint8_t(1u << (c % 8));
  const Tally t = check_tour(level, "oasago2", 12);
  EXPECT_FALSE(t.outside_pvs.empty());
}
