// `tiles_city`, `tiles_forest`, `tiles_hybrid`: tiled worlds without edge
// (Gomez et al. 2013), in the spirit of the paper's City, Forest and Hybrid sets.
//
// Each tiling set is a few predefined tiles in 64 m cells, placed on the
// XZ lattice by TiledWorld's tile function (occull/tiles.hpp). Every tile
// keeps a lane clear along its cell's edges, so the lattice's cell borders
// are streets (city: 12 m curb to curb) or forest lanes (6 m) that the
// camera paths follow; every tile has a ground slab over its whole cell.
//   city:   a block of 2-6 tall buildings on a sidewalk, lamps and trees;
//   forest: 35-70 conifers of three shapes and a few rocks;
//   hybrid: city blocks, forest patches and open squares with a fountain.
// Paths: `walk10k` drives 10 km down one street at eye height (14 m/s,
// weaving a little and looking around), `grazing` flies low over the
// tiling, just above its tallest objects, at grazing angles (the paper's
// worst case), `turn` turns in place
// at a crossing.
#include "mesh_builder.hpp"
#include "scenes_internal.hpp"

#include "occull/error.hpp"

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <cmath>

namespace occull::scenes {
namespace {

constexpr float kCell = 64.0f;

enum class Set { city, forest, hybrid };

struct Materials {
  MaterialId asphalt, sidewalk, facade[4], roof, grass, foliage, bark, stone, water, metal;
};

Materials add_materials(Scene& scene, int shading) {
  Materials m{};
  m.asphalt = scene.add_material({"asphalt", {0.30f, 0.30f, 0.32f, 1}, false, shading});
  m.sidewalk = scene.add_material({"sidewalk", {0.62f, 0.60f, 0.57f, 1}, false, shading});
  const glm::vec3 facades[4] = {{0.78f, 0.70f, 0.60f}, {0.60f, 0.62f, 0.68f}, {0.72f, 0.52f, 0.42f},
                                {0.85f, 0.83f, 0.78f}};
  for (int i = 0; i < 4; ++i)
    m.facade[i] = scene.add_material({"facade" + std::to_string(i), glm::vec4(facades[i], 1), false, shading});
  m.roof = scene.add_material({"roof", {0.35f, 0.25f, 0.22f, 1}, false, shading});
  m.grass = scene.add_material({"grass", {0.40f, 0.55f, 0.27f, 1}, false, shading});
  m.foliage = scene.add_material({"foliage", {0.18f, 0.38f, 0.16f, 1}, false, shading});
  m.bark = scene.add_material({"bark", {0.38f, 0.27f, 0.18f, 1}, false, shading});
  m.stone = scene.add_material({"stone", {0.55f, 0.53f, 0.50f, 1}, false, shading});
  m.water = scene.add_material({"water", {0.25f, 0.45f, 0.60f, 1}, false, shading});
  m.metal = scene.add_material({"metal", {0.25f, 0.27f, 0.30f, 1}, false, shading});
  return m;
}

// Meshes every tile of a set may share.
struct Shared {
  MeshId ground;      // the whole cell, 0.2 m thick, top at y = 0
  MeshId trees[3];    // conifers, base at the origin
  MeshId rocks[2];
  MeshId lamp;
  MeshId bench;
};

Shared add_shared(Scene& scene) {
  Shared s{};
  {
    MeshBuilder b;
    b.box({{0.0f, -0.2f, 0.0f}, {kCell, 0.0f, kCell}}, MeshBuilder::pos_y | MeshBuilder::neg_x |
                                                           MeshBuilder::pos_x | MeshBuilder::neg_z |
                                                           MeshBuilder::pos_z);
    s.ground = scene.add_mesh(b.take());
  }
  for (int v = 0; v < 3; ++v) {
    MeshBuilder b;
    const float h = 9.0f + 3.0f * float(v);
    // Spruces: branches down to the ground (a forest is dense at eye height).
    b.prism({0, 0, 0}, 0.3f, 1.0f, 6);
    b.cone({0, 0.4f, 0}, 2.6f + 0.3f * float(v), h * 0.55f, 10);
    b.cone({0, 0.4f + h * 0.3f, 0}, 2.0f + 0.2f * float(v), h * 0.5f, 10);
    b.cone({0, 0.4f + h * 0.55f, 0}, 1.3f, h * 0.45f, 10);
    s.trees[v] = scene.add_mesh(b.take());
  }
  for (int v = 0; v < 2; ++v) {
    MeshBuilder b;
    b.prism({0, -0.2f, 0}, 1.2f + 0.5f * float(v), 0.9f + 0.4f * float(v), 7 + 2 * v);
    b.cone({0, 0.7f + 0.4f * float(v), 0}, 1.2f + 0.5f * float(v), 0.6f, 7 + 2 * v);
    s.rocks[v] = scene.add_mesh(b.take());
  }
  {
    MeshBuilder b;
    b.prism({0, 0, 0}, 0.12f, 6.0f, 8);
    b.box({{-0.3f, 6.0f, -0.3f}, {0.3f, 6.4f, 0.3f}});
    s.lamp = scene.add_mesh(b.take());
  }
  {
    MeshBuilder b;
    b.box({{-1.0f, 0.4f, -0.25f}, {1.0f, 0.5f, 0.25f}});
    b.box({{-1.0f, 0.5f, 0.2f}, {1.0f, 1.0f, 0.25f}});
    b.box({{-0.9f, 0.0f, -0.2f}, {-0.8f, 0.4f, 0.2f}});
    b.box({{0.8f, 0.0f, -0.2f}, {0.9f, 0.4f, 0.2f}});
    s.bench = scene.add_mesh(b.take());
  }
  return s;
}

glm::mat4 at(float x, float y, float z, float yaw = 0.0f, float scale = 1.0f) {
  glm::mat4 t = glm::translate(glm::mat4(1.0f), {x, y, z});
  t = glm::rotate(t, yaw, {0, 1, 0});
  return glm::scale(t, glm::vec3(scale));
}

// A city block: sidewalk, 2-6 buildings on lots, lamps at the corners and a
// few trees. Street margin 6 m on every side.
Tile city_tile(Scene& scene, const Materials& m, const Shared& s, Rng& rng, int index, float height_max) {
  Tile t;
  t.name = "city-" + std::to_string(index);
  t.objects.push_back({s.ground, m.asphalt, glm::mat4(1.0f), OccluderClass::always});
  {
    MeshBuilder b;
    b.box({{6.0f, 0.0f, 6.0f}, {kCell - 6.0f, 0.2f, kCell - 6.0f}}, MeshBuilder::no_bottom);
    t.objects.push_back({scene.add_mesh(b.take()), m.sidewalk, glm::mat4(1.0f), OccluderClass::always});
  }
  const int nx = rng.integer(1, 3), nz = rng.integer(1, 2);
  const float x0 = 9.0f, z0 = 9.0f, span = kCell - 18.0f;
  for (int i = 0; i < nx; ++i) {
    for (int j = 0; j < nz; ++j) {
      const float lx0 = x0 + span * float(i) / float(nx), lx1 = x0 + span * float(i + 1) / float(nx);
      const float lz0 = z0 + span * float(j) / float(nz), lz1 = z0 + span * float(j + 1) / float(nz);
      const float u = rng.uniform();
      const float h = 10.0f + (height_max - 10.0f) * u * u;
      MeshBuilder b;
      const Aabb body{{lx0 + 0.5f, 0.2f, lz0 + 0.5f}, {lx1 - 0.5f, 0.2f + h, lz1 - 0.5f}};
      b.box(body, MeshBuilder::no_bottom);
      // Storey bands: thin ledges every 3.5 m on the street faces (detail triangles).
      for (float y = 3.5f; y < h - 1.0f; y += 3.5f)
        b.box({{body.min.x - 0.15f, y, body.min.z - 0.15f}, {body.max.x + 0.15f, y + 0.25f, body.max.z + 0.15f}},
              MeshBuilder::all);
      t.objects.push_back({scene.add_mesh(b.take()), m.facade[rng.integer(0, 3)], glm::mat4(1.0f),
                           OccluderClass::always});
      MeshBuilder roof;
      roof.box({{body.min.x + 1.0f, body.max.y, body.min.z + 1.0f},
                {body.min.x + 4.0f, body.max.y + 2.5f, body.min.z + 3.0f}});
      t.objects.push_back({scene.add_mesh(roof.take()), m.roof, glm::mat4(1.0f), OccluderClass::never});
    }
  }
  const float c0 = 7.0f, c1 = kCell - 7.0f;
  for (const auto& [x, z] : {std::pair{c0, c0}, std::pair{c0, c1}, std::pair{c1, c0}, std::pair{c1, c1}})
    t.objects.push_back({s.lamp, m.metal, at(x, 0.2f, z), OccluderClass::never});
  const int trees = rng.integer(0, 4);
  for (int i = 0; i < trees; ++i) {
    const bool along_x = rng.chance(0.5f);
    const float a = rng.uniform(12.0f, kCell - 12.0f), e = rng.chance(0.5f) ? 7.5f : kCell - 7.5f;
    t.objects.push_back({s.trees[rng.integer(0, 2)], m.foliage,
                         at(along_x ? a : e, 0.2f, along_x ? e : a, rng.uniform(0, 6.28f), 0.6f),
                         OccluderClass::sometimes});
  }
  return t;
}

// A forest patch: conifers and rocks, a 3 m lane kept clear at the edges.
Tile forest_tile(const Materials& m, const Shared& s, Rng& rng, int index) {
  Tile t;
  t.name = "forest-" + std::to_string(index);
  t.objects.push_back({s.ground, m.grass, glm::mat4(1.0f), OccluderClass::always});
  const int trees = rng.integer(35, 70);
  // The random draws one by one, in the order GCC evaluated them as one
  // call's arguments (C++ leaves it open; GCC: right to left), so the tiles
  // stay as they were. The same for the rocks and lamps below.
  for (int i = 0; i < trees; ++i) {
    const MeshId tree = s.trees[rng.integer(0, 2)];
    const float scale = rng.uniform(0.8f, 1.4f), yaw = rng.uniform(0, 6.28f);
    const float z = rng.uniform(5.0f, kCell - 5.0f), x = rng.uniform(5.0f, kCell - 5.0f);
    t.objects.push_back({tree, m.foliage, at(x, 0.0f, z, yaw, scale), OccluderClass::sometimes});
  }
  const int rocks = rng.integer(3, 8);
  for (int i = 0; i < rocks; ++i) {
    const MeshId rock = s.rocks[rng.integer(0, 1)];
    const float scale = rng.uniform(0.7f, 1.8f), yaw = rng.uniform(0, 6.28f);
    const float z = rng.uniform(5.0f, kCell - 5.0f), x = rng.uniform(5.0f, kCell - 5.0f);
    t.objects.push_back({rock, m.stone, at(x, 0.0f, z, yaw, scale), OccluderClass::never});
  }
  return t;
}

// An open square: paving, a fountain, benches and lamps — little occlusion.
Tile square_tile(Scene& scene, const Materials& m, const Shared& s, Rng& rng, int index) {
  Tile t;
  t.name = "square-" + std::to_string(index);
  t.objects.push_back({s.ground, m.sidewalk, glm::mat4(1.0f), OccluderClass::always});
  {
    MeshBuilder b;
    b.prism({kCell / 2, 0.0f, kCell / 2}, 6.0f, 0.8f, 24);
    b.prism({kCell / 2, 0.0f, kCell / 2}, 0.8f, 3.5f, 12);
    t.objects.push_back({scene.add_mesh(b.take()), m.stone, glm::mat4(1.0f), OccluderClass::sometimes});
  }
  for (int i = 0; i < 8; ++i) {
    const float a = glm::two_pi<float>() * float(i) / 8.0f;
    t.objects.push_back({s.bench, m.bark,
                         at(kCell / 2 + 11.0f * std::cos(a), 0.0f, kCell / 2 + 11.0f * std::sin(a),
                            -a + glm::half_pi<float>()),
                         OccluderClass::never});
  }
  for (int i = 0; i < 4; ++i) {
    const float z = rng.uniform(10.0f, kCell - 10.0f);  // before x (GCC's order, above)
    const float x = rng.chance(0.5f) ? 12.0f : kCell - 12.0f;
    t.objects.push_back({s.lamp, m.metal, at(x, 0.0f, z), OccluderClass::never});
  }
  return t;
}

// `top`: the height of the common box, which the grazing flight skims.
std::vector<CameraPath> tile_paths(float lane_weave, float top) {
  std::vector<CameraPath> paths;
  {  // walk10k: 10 km down the street along x = 0 (a cell border), towards -Z.
    std::vector<CameraPath::Key> keys;
    const double speed = 14.0, length = 10000.0, step = 50.0;
    for (double d = 0.0; d <= length + 1e-6; d += step) {
      const float z = 32.0f - float(d);
      const float x = lane_weave * std::sin(float(d) / 170.0f);
      const float look = 0.25f * std::sin(float(d) / 230.0f);
      keys.push_back({d / speed, {{x, 1.7f, z}, look, glm::radians(-1.0f)}, false});
    }
    paths.emplace_back("walk10k", "drives 10 km down one street at eye height (14 m/s), looking around a little",
                       std::move(keys));
  }
  {  // grazing: low flight just over the tallest objects, looking at the horizon.
    std::vector<CameraPath::Key> keys;
    const double speed = 30.0, length = 3000.0, step = 50.0;
    for (double d = 0.0; d <= length + 1e-6; d += step) {
      const float f = float(d);
      const glm::vec3 eye(0.55f * f + 10.0f, top + 18.0f + 12.0f * std::sin(f / 400.0f), -0.83f * f + 10.0f);
      const float pitch = glm::radians(-6.0f - 5.0f * std::sin(f / 260.0f));
      keys.push_back({d / speed, {eye, 0.585f + 0.3f * std::sin(f / 500.0f), pitch}, false});
    }
    paths.emplace_back("grazing",
                       "flies 3 km low over the tiling (6-30 m above its tallest objects) at grazing angles: the worst case",
                       std::move(keys));
  }
  {  // turn: a full turn in place at a crossing of two streets.
    std::vector<CameraPath::Key> keys;
    for (int k = 0; k <= 24; ++k)
      keys.push_back({0.5 * k, {{0.0f, 1.7f, 0.0f}, glm::two_pi<float>() * float(k) / 24.0f, 0.0f}, false});
    paths.emplace_back("turn", "turns once in place at a crossing (12 s)", std::move(keys));
  }
  return paths;
}

std::vector<SceneParamInfo> tile_params(double far) {
  return {{"far", far, 100, 2000, false, "far plane (scene units); sets the window of tiles kept placed"},
          {"height", 90, 15, 300, false, "tallest city building (metres)"},
          {"shading", 0, 0, 64, true, "light evaluations per fragment (fragment cost)"},
          {"seed", 1, 0, 1e9, true, "random seed of the tiles and of the tile function"}};
}

SceneBundle make_tiled(Set set, const std::string& name, const Params& params) {
  const float far = float(params.at("far"));
  SceneBundle bundle{Scene(name), {}, Lens{60.0f, 0.1f, far}};
  Scene& scene = bundle.scene;
  const Materials m = add_materials(scene, int(params.at("shading")));
  const Shared s = add_shared(scene);
  const auto seed = std::uint64_t(params.at("seed"));
  Rng rng(seed);
  const float height = float(params.at("height"));
  std::vector<Tile> tiles;
  if (set == Set::city) {
    for (int i = 0; i < 8; ++i) tiles.push_back(city_tile(scene, m, s, rng, i, height));
  } else if (set == Set::forest) {
    for (int i = 0; i < 6; ++i) tiles.push_back(forest_tile(m, s, rng, i));
  } else {
    for (int i = 0; i < 4; ++i) tiles.push_back(city_tile(scene, m, s, rng, i, height));
    for (int i = 0; i < 3; ++i) tiles.push_back(forest_tile(m, s, rng, i));
    for (int i = 0; i < 2; ++i) {
      tiles.push_back(square_tile(scene, m, s, rng, i));
      tiles.back().weight = 0.5f;
    }
  }
  bundle.world = std::make_shared<TiledWorld>(scene, kCell, std::move(tiles), seed,
                                              TiledWorld::reach(bundle.lens));
  bundle.world->populate(scene);
  bundle.paths = tile_paths(set == Set::forest ? 0.8f : 2.0f, bundle.world->common_box().max.y);
  return bundle;
}

}  // namespace

SceneInfo tiles_city_info() {
  return {"tiles_city", "tiled world without edge: city blocks of tall buildings (Gomez et al. 2013's City)",
          tile_params(400), {"walk10k", "grazing", "turn"}};
}
SceneInfo tiles_forest_info() {
  return {"tiles_forest", "tiled world without edge: forest patches of dense conifers and rocks (Gomez et al. 2013's Forest)",
          tile_params(300), {"walk10k", "grazing", "turn"}};
}
SceneInfo tiles_hybrid_info() {
  return {"tiles_hybrid", "tiled world without edge: city blocks, forest patches and open squares (Gomez et al. 2013's Hybrid)",
          tile_params(400), {"walk10k", "grazing", "turn"}};
}
SceneBundle make_tiles_city(const Params& p) { return make_tiled(Set::city, "tiles_city", p); }
SceneBundle make_tiles_forest(const Params& p) { return make_tiled(Set::forest, "tiles_forest", p); }
SceneBundle make_tiles_hybrid(const Params& p) { return make_tiled(Set::hybrid, "tiles_hybrid", p); }

}  // namespace occull::scenes
