// Tiled worlds (Gomez et al. 2013): the tile function, the window of object ids, BVH
// instances, and the cullers tilevfc, pertile and tiles over a Backend test
// double. The GL check that they miss nothing is in culling_gl_test.cpp.
#include "occull/culler.hpp"
#include "occull/error.hpp"
#include "occull/scenes.hpp"
#include "occull/tiles.hpp"
#include "cull/tile_cache.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>
#include <glm/gtc/constants.hpp>

#include <set>

using namespace occull;

namespace {

// A tiled-world culler's own counters of a frame.
struct TileFrame {
  std::uint64_t tiles_rendered = 0, tile_queries = 0, tile_postponed = 0, tile_prediction_failures = 0,
                tiles_instantiated = 0, tiles_evicted = 0, tile_cache = 0;
};

// Renders a frame with `culler` and reads its counters.
TileFrame render(Culler& culler, const View& view, Backend& backend) {
  (void)culler.render_frame(view, backend);
  const auto read = [&](std::string_view name) { return std::uint64_t(test::counter(culler, name)); };
  return {read("tiles_rendered"),     read("tile_queries"),  read("tile_postponed"), read("tile_prediction_failures"),
          read("tiles_instantiated"), read("tiles_evicted"), read("tile_cache")};
}

// A small window: the far plane sets how many cells the scene holds.
SceneBundle small_city() { return make_scene("tiles_city:far=150"); }

View view_at(const SceneBundle& b, glm::vec3 eye, float yaw, float pitch = 0.0f) {
  return make_view({eye, yaw, pitch}, b.lens, 320, 180);
}

// The world's objects of the cells a frame rendered: each id maps back to
// the cell whose block of ids holds it.
std::set<TileCoord> cells_rendered(const TiledWorld& w, const std::vector<ObjectId>& ids) {
  std::set<TileCoord> out;
  const int r = w.radius();
  for (ObjectId id : ids)
    for (int dx = -r; dx <= r; ++dx)
      for (int dz = -r; dz <= r; ++dz) {
        const TileCoord c{w.centre().x + dx, w.centre().z + dz};
        if (id >= w.first_object(c) && id < w.first_object(c) + w.objects_per_cell()) out.insert(c);
      }
  return out;
}

}  // namespace

TEST(TiledWorld, TileFunctionIsPureAndPicksEveryTile) {
  const SceneBundle a = small_city(), b = small_city();
  const SceneBundle other = make_scene("tiles_city:far=150,seed=2");
  std::set<std::uint32_t> used;
  int differ = 0;
  for (int x = -40; x < 40; ++x)
    for (int z = -40; z < 40; ++z) {
      const TileCoord c{x * 1009, z * 917};  // far apart, negative too
      ASSERT_EQ(a.world->tile_at(c), b.world->tile_at(c));
      ASSERT_EQ(a.world->tile_at(c), a.world->tile_at(c));
      used.insert(a.world->tile_at(c));
      differ += a.world->tile_at(c) != other.world->tile_at(c);
    }
  EXPECT_EQ(used.size(), a.world->tiles().size());
  EXPECT_GT(differ, 1000) << "another seed should give another tiling";
}

TEST(TiledWorld, CommonBoxIsTheUnionOfTheTileBoxes) {
  const SceneBundle b = make_scene("tiles_hybrid:far=150");
  Aabb u;
  for (const Tile& t : b.world->tiles()) {
    u.extend(t.bounds);
    EXPECT_TRUE(b.world->common_box().contains(t.bounds.min) && b.world->common_box().contains(t.bounds.max)) << t.name;
  }
  EXPECT_EQ(u.min, b.world->common_box().min);
  EXPECT_EQ(u.max, b.world->common_box().max);
  const TileCoord c{-7, 12};
  EXPECT_EQ(b.world->common_box_at(c).min, b.world->common_box().min + b.world->origin(c));
}

TEST(TiledWorld, CellsOfTheWindowOwnDisjointIds) {
  SceneBundle b = small_city();
  const TiledWorld& w = *b.world;
  std::set<ObjectId> firsts;
  const int r = w.radius();
  for (int dx = -r; dx <= r; ++dx)
    for (int dz = -r; dz <= r; ++dz) {
      const ObjectId first = w.first_object({w.centre().x + dx, w.centre().z + dz});
      EXPECT_EQ(first % w.objects_per_cell(), 0u);
      EXPECT_TRUE(firsts.insert(first).second) << "two cells share ids";
      EXPECT_LT(first + w.objects_per_cell() - 1, b.scene.objects().size());
    }
}

TEST(TiledWorld, SceneKeepsItsSizeAndPlacesTilesRightOverTenKilometres) {
  SceneBundle b = small_city();
  TiledWorld& w = *b.world;
  const std::size_t objects = b.scene.objects().size(), meshes = b.scene.meshes().size();
  const std::size_t side = std::size_t(2 * w.radius() + 1);
  for (float z = 0.0f; z > -10000.0f; z -= 14.0f) {
    const std::size_t placed = w.follow(b.scene, {1.0f, 1.7f, z});
    EXPECT_LE(placed, side) << "a step of 14 m brings at most one row of cells";
    EXPECT_EQ(b.scene.moved_objects().size(), placed * w.objects_per_cell());
  }
  EXPECT_EQ(b.scene.objects().size(), objects);
  EXPECT_EQ(b.scene.meshes().size(), meshes);
  EXPECT_GE(w.cells_placed(), side * (10000 / 64));
  // Every cell of the window holds its tile's objects at its place; the ids
  // it does not use are parked below the world.
  const int r = w.radius();
  for (int dx = -r; dx <= r; ++dx)
    for (int dz = -r; dz <= r; ++dz) {
      const TileCoord c{w.centre().x + dx, w.centre().z + dz};
      const Tile& tile = w.tiles()[w.tile_at(c)];
      for (std::uint32_t i = 0; i < w.objects_per_cell(); ++i) {
        const Aabb box = b.scene.object(w.first_object(c) + i).bounds;
        if (i < tile.objects.size()) {
          const glm::vec3 o = w.origin(c);
          EXPECT_NEAR(box.min.x, tile.object_bounds[i].min.x + o.x, 0.01f);
          EXPECT_NEAR(box.max.z, tile.object_bounds[i].max.z + o.z, 0.01f);
          EXPECT_NEAR(box.max.y, tile.object_bounds[i].max.y, 0.01f);
        } else {
          EXPECT_LT(box.max.y, TiledWorld::kParkedY / 2);
        }
      }
    }
  EXPECT_NE(w.describe(w.first_object(w.centre())).find("tile city-"), std::string::npos)
      << w.describe(w.first_object(w.centre()));
}

// The frustum is the convex hull of its corners, so it lies within reach()
// of the eye at the widest viewport; every cell whose common box comes that
// close is in the window. (Plane tests alone would not do: they take some
// boxes beyond the far corners for intersecting.)
TEST(TiledWorld, WindowHoldsEveryCellTheFrustumReaches) {
  SceneBundle b = small_city();
  TiledWorld& w = *b.world;
  const float reach = TiledWorld::reach(b.lens);
  for (const glm::vec3 eye : {glm::vec3{1.0f, 1.7f, -3.0f}, glm::vec3{63.0f, 80.0f, 63.0f}, glm::vec3{-900.5f, 30.0f, 4000.0f}}) {
    w.follow(b.scene, eye);
    for (int k = 0; k < 16; ++k) {
      const View v = make_view({eye, glm::two_pi<float>() * float(k) / 16.0f, -0.3f}, b.lens,
                               int(180 * TiledWorld::kMaxAspect), 180);
      const glm::dmat4 inv = glm::inverse(glm::dmat4(v.view_proj));
      for (int corner = 0; corner < 8; ++corner) {
        const glm::dvec4 p = inv * glm::dvec4(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1, corner & 4 ? 1 : -1, 1);
        EXPECT_LE(glm::length(glm::dvec3(p) / p.w - glm::dvec3(eye)), reach * 1.001) << "corner " << corner;
      }
    }
    const int r = w.radius() + 4;
    int near_cells = 0;
    for (int dx = -r; dx <= r; ++dx)
      for (int dz = -r; dz <= r; ++dz) {
        const TileCoord c{w.centre().x + dx, w.centre().z + dz};
        const Aabb box = w.common_box_at(c);
        if (glm::length(glm::clamp(eye, box.min, box.max) - eye) > reach) continue;
        ++near_cells;
        EXPECT_TRUE(w.in_window(c)) << "cell (" << c.x << ", " << c.z << ") within reach, outside the window";
      }
    EXPECT_GT(near_cells, 9);
  }
}

TEST(TiledWorld, RefusesAnEmptyTilingSetAndEmptyTiles) {
  SceneBundle b = small_city();
  EXPECT_THROW(TiledWorld(b.scene, 64.0f, {}, 1, 100.0f), InputError);
  std::vector<Tile> empty(1);
  empty[0].name = "bare";
  EXPECT_THROW(TiledWorld(b.scene, 64.0f, empty, 1, 100.0f), InputError);
  std::vector<Tile> one(1, b.world->tiles()[0]);
  EXPECT_THROW(TiledWorld(b.scene, 0.0f, one, 1, 100.0f), InputError);
  EXPECT_THROW(TiledWorld(b.scene, 64.0f, one, 1, 1.0e7f), InputError) << "a window past the object limit";
}

TEST(Bvh, InstanceIsTheSameTreeMovedAndRenumbered) {
  const SceneBundle b = small_city();
  const Tile& t = b.world->tiles()[0];
  const Bvh inst = t.bvh.instance({64.0f, 0.0f, -128.0f}, 1000);
  ASSERT_EQ(inst.size(), t.bvh.size());
  for (NodeId n = 0; n < inst.size(); ++n) {
    EXPECT_EQ(inst.node(n).bounds.min, t.bvh.node(n).bounds.min + glm::vec3(64.0f, 0.0f, -128.0f));
    EXPECT_EQ(inst.objects(n).size(), t.bvh.objects(n).size());
    for (std::size_t i = 0; i < inst.objects(n).size(); ++i)
      EXPECT_EQ(inst.objects(n)[i], t.bvh.objects(n)[i] + 1000);
  }
}

TEST(Registry, TiledWorldsRunTheirOwnAlgorithmsOnly) {
  const SceneBundle tiled = small_city();
  const Bvh none = Bvh::build(std::span<const Aabb>{}, std::span<const std::uint32_t>{});
  try {
    (void)make_culler("vfc", {tiled.scene, none, tiled.world.get()});
    FAIL() << "vfc ran on a tiled world";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("tilevfc, pertile, tiles"), std::string::npos) << e.what();
  }
  const Scene plain = test::box_scene({{{0, 0, 0}, {1, 1, 1}}});
  const Bvh bvh = Bvh::build(plain);
  EXPECT_THROW((void)make_culler("tiles", {plain, bvh}), InputError);
  EXPECT_NO_THROW((void)make_culler("none", {tiled.scene, none, tiled.world.get()}));
  const auto names = default_algorithms(true);
  EXPECT_EQ(names, (std::vector<std::string>{"none", "tilevfc", "pertile", "tiles", "tiles:local=none", "oracle"}));
  const auto plain_names = default_algorithms(false);
  EXPECT_EQ(std::count(plain_names.begin(), plain_names.end(), "tiles"), 0);
}

namespace {

struct TiledCase {
  SceneBundle bundle = small_city();
  Bvh none = Bvh::build(std::span<const Aabb>{}, std::span<const std::uint32_t>{});
  SceneIndex index() const { return {bundle.scene, none, bundle.world.get()}; }
  View look(glm::vec3 eye, float yaw, float pitch = 0.0f) {
    bundle.world->follow(bundle.scene, eye);
    return view_at(bundle, eye, yaw, pitch);
  }
};

}  // namespace

TEST(TilesCuller, PropagationStopsWhereTheCommonBoxIsOccluded) {
  TiledCase t;
  const View v = t.look({1.0f, 1.7f, -20.0f}, 0.3f);
  test::ScriptedBackend backend;
  backend.visible_samples = [](std::span<const Aabb>) { return std::uint64_t(0); };
  Options o;
  o.set("tiles.local=none");
  auto culler = make_culler("tiles", t.index(), o);
  const TileFrame s = render(*culler, v, backend);
  // Only the nearest cell is drawn: every neighbour's tile query came back hidden.
  EXPECT_EQ(s.tiles_rendered, 1u);
  EXPECT_EQ(cells_rendered(*t.bundle.world, backend.rendered).size(), 1u);
  EXPECT_GE(s.tile_queries, 1u);
  EXPECT_LE(s.tile_queries, 8u);
  for (const auto& boxes : backend.queried) {
    ASSERT_EQ(boxes.size(), 1u);
    EXPECT_FLOAT_EQ(boxes[0].max.y, t.bundle.world->common_box().max.y) << "a tile query draws the common box";
  }
}

TEST(TilesCuller, AllQueriesVisibleDrawsEveryCellInTheFrustumOnce) {
  TiledCase t;
  const View v = t.look({1.0f, 1.7f, -20.0f}, 0.3f, -0.05f);
  test::ScriptedBackend backend;
  Options o;
  o.set("tiles.local=none");
  auto culler = make_culler("tiles", t.index(), o);
  const TileFrame s = render(*culler, v, backend);
  std::vector<TileCoord> in_frustum;
  detail::cells_in_frustum(*t.bundle.world, v, false, in_frustum);
  EXPECT_EQ(s.tiles_rendered, in_frustum.size());
  const std::set<ObjectId> unique(backend.rendered.begin(), backend.rendered.end());
  EXPECT_EQ(unique.size(), backend.rendered.size()) << "an object drawn twice in one frame";
  EXPECT_EQ(cells_rendered(*t.bundle.world, backend.rendered),
            std::set<TileCoord>(in_frustum.begin(), in_frustum.end()));
}

TEST(TilesCuller, PendingResultOfATileVisibleLastFrameIsPostponed) {
  TiledCase t;
  const View v = t.look({1.0f, 1.7f, -20.0f}, 0.3f);
  test::ScriptedBackend backend;
  bool ready = true;
  backend.available = [&](QueryId) { return ready; };
  Options o;
  o.set("tiles.local=none");
  auto culler = make_culler("tiles", t.index(), o);
  const TileFrame first = render(*culler, v, backend);
  ASSERT_GT(first.tiles_rendered, 1u);
  EXPECT_EQ(first.tile_postponed, 0u);
  // No result is ready: the tiles seen visible are drawn on their prediction
  // (Algorithm 3), and those still pending at the frame's end count as
  // prediction failures (Algorithm 4).
  ready = false;
  backend.read.clear();
  const TileFrame second = render(*culler, v, backend);
  EXPECT_EQ(second.tiles_rendered, first.tiles_rendered);
  EXPECT_GT(second.tile_postponed, 0u);
  EXPECT_EQ(second.tile_prediction_failures, second.tile_postponed);
  EXPECT_TRUE(backend.read.empty()) << "a postponed query was waited on";
  // Predicted hidden now, so the next frame waits for their results (visible).
  const TileFrame third = render(*culler, v, backend);
  EXPECT_EQ(third.tiles_rendered, first.tiles_rendered);
  EXPECT_EQ(third.tile_postponed, 0u);
  EXPECT_FALSE(backend.read.empty());
}

TEST(TileCache, InstancesUnusedForTheEvictionTimeAreFreed) {
  TiledCase t;
  test::ScriptedBackend backend;
  Options o;
  o.set("pertile.evict=3");
  auto culler = make_culler("pertile", t.index(), o);
  const glm::vec3 eye{1.0f, 1.7f, -20.0f};
  const TileFrame a = render(*culler, t.look(eye, 0.0f), backend);
  EXPECT_GT(a.tiles_instantiated, 0u);
  EXPECT_EQ(a.tile_cache, a.tiles_instantiated);
  // Turn round: the cells ahead go unused and are freed after 3 frames.
  std::uint64_t evicted = 0;
  TileFrame s;
  for (int k = 0; k < 5; ++k) {
    s = render(*culler, t.look(eye, glm::pi<float>()), backend);
    evicted += s.tiles_evicted;
  }
  EXPECT_GT(evicted, 0u);
  EXPECT_EQ(s.tile_cache, s.tiles_rendered) << "only the cells in view are held";
  // A long walk: the cache holds at most the window.
  for (float z = 0.0f; z > -3000.0f; z -= 14.0f) s = render(*culler, t.look({1.0f, 1.7f, z}, 0.0f), backend);
  const auto side = std::uint64_t(2 * t.bundle.world->radius() + 1);
  EXPECT_LE(s.tile_cache, side * side);
}

TEST(TilesCuller, RequeryDrawsVisibleTilesWithoutQueriesBetweenTheirReQueries) {
  TiledCase t;
  const View v = t.look({1.0f, 1.7f, -20.0f}, 0.3f, -0.05f);
  std::uint64_t queries[2] = {0, 0}, drawn[2] = {0, 0};
  for (int variant = 0; variant < 2; ++variant) {
    test::ScriptedBackend backend;
    Options o;
    o.set("tiles.local=none");
    if (variant == 1) o.set("tiles.requery=4");
    auto culler = make_culler("tiles", t.index(), o);
    for (int f = 0; f < 8; ++f) {
      const TileFrame s = render(*culler, v, backend);
      if (f == 0) continue;  // the first frame queries every tile either way
      queries[variant] += s.tile_queries;
      drawn[variant] += s.tiles_rendered;
    }
  }
  EXPECT_EQ(drawn[1], drawn[0]) << "the same tiles are drawn";
  EXPECT_LT(queries[1], queries[0] / 2) << "visible tiles are queried every 4th frame";
  EXPECT_GT(queries[1], 0u) << "but they are queried again";
}
