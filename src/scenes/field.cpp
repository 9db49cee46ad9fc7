// `field`: many objects scattered on open, gently rolling ground — low depth
// complexity, the scene where culling must not cost more than it saves.
//
// The ground is a grid of terrain tiles; trees, rocks, houses and haystacks
// stand on it at random positions. Paths: `overview` orbits high above,
// looking down at the centre; `glide` skims across at a glancing angle.
#include "mesh_builder.hpp"
#include "scenes_internal.hpp"

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <cmath>

namespace occull::scenes {
namespace {

float ground_height(float x, float z) {
  return 1.6f * std::sin(x * 0.011f) * std::cos(z * 0.013f) + 0.7f * std::sin((x + z) * 0.027f);
}

glm::vec3 ground_normal(float x, float z) {
  const float e = 0.5f;
  const float dx = (ground_height(x + e, z) - ground_height(x - e, z)) / (2 * e);
  const float dz = (ground_height(x, z + e) - ground_height(x, z - e)) / (2 * e);
  return glm::normalize(glm::vec3(-dx, 1.0f, -dz));
}

Mesh terrain_tile(float x0, float z0, float size, int cells) {
  Mesh m;
  const float step = size / float(cells);
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i) {
      const float x = x0 + float(i) * step, z = z0 + float(j) * step;
      m.positions.emplace_back(x, ground_height(x, z), z);
      m.normals.push_back(ground_normal(x, z));
    }
  const auto at = [cells](int i, int j) { return std::uint32_t(j * (cells + 1) + i); };
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i) {
      // Counter-clockwise seen from above (+Y).
      m.indices.insert(m.indices.end(), {at(i, j), at(i, j + 1), at(i + 1, j + 1),
                                         at(i, j), at(i + 1, j + 1), at(i + 1, j)});
    }
  return m;
}

// A lumpy rock: a latitude/longitude sphere with its radius jittered.
Mesh rock_mesh(Rng& rng) {
  constexpr int rings = 8, segments = 14;
  Mesh m;
  std::vector<float> jitter(std::size_t((rings + 1) * segments));
  for (float& j : jitter) j = rng.uniform(0.85f, 1.15f);
  for (int r = 0; r <= rings; ++r) {
    const float phi = glm::pi<float>() * float(r) / float(rings);
    for (int s = 0; s < segments; ++s) {
      const float theta = glm::two_pi<float>() * float(s) / float(segments);
      const glm::vec3 d(std::sin(phi) * std::cos(theta), std::cos(phi), std::sin(phi) * std::sin(theta));
      const float k = (r == 0 || r == rings) ? 1.0f : jitter[std::size_t(r * segments + s)];
      m.positions.push_back(glm::vec3(d.x * k, d.y * 0.6f * k + 0.35f, d.z * k));
      m.normals.push_back(d);
    }
  }
  const auto at = [](int r, int s) { return std::uint32_t(r * segments + (s % segments)); };
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      // Outward (counter-clockwise seen from outside).
      m.indices.insert(m.indices.end(), {at(r, s), at(r, s + 1), at(r + 1, s + 1),
                                         at(r, s), at(r + 1, s + 1), at(r + 1, s)});
    }
  return m;
}

}  // namespace

SceneInfo field_info() {
  return {"field",
          "open rolling ground with trees, rocks, houses and haystacks scattered on it: low depth "
          "complexity",
          {{"objects", 5000, 10, 1000000, true, "objects scattered on the ground (instances of 9 meshes)"},
           {"size", 800, 100, 10000, false, "side of the square field, metres"},
           {"shading", 0, 0, 64, true, "light evaluations per fragment (fragment cost)"},
           {"seed", 1, 0, 1e9, true, "random seed"}},
          {"overview", "glide"}};
}

SceneBundle make_field(const Params& params) {
  const int count = int(params.at("objects"));
  const float size = float(params.at("size"));
  const int shading = int(params.at("shading"));
  Rng rng(std::uint64_t(params.at("seed")));
  SceneBundle bundle{Scene("field"), {}, Lens{60.0f, 0.5f, std::max(3000.0f, 3.0f * size)}};
  Scene& scene = bundle.scene;

  const MaterialId grass = scene.add_material({"grass", {0.42f, 0.58f, 0.28f, 1}, false, shading});
  const MaterialId foliage = scene.add_material({"foliage", {0.22f, 0.42f, 0.18f, 1}, false, shading});
  const MaterialId stone = scene.add_material({"stone", {0.55f, 0.53f, 0.50f, 1}, false, shading});
  const MaterialId plaster = scene.add_material({"plaster", {0.85f, 0.80f, 0.70f, 1}, false, shading});
  const MaterialId hay = scene.add_material({"hay", {0.85f, 0.72f, 0.35f, 1}, false, shading});

  // Ground: tiles of about 50 m, 16 x 16 cells each.
  const int tiles = std::max(2, int(std::round(size / 50.0f)));
  const float tile = size / float(tiles);
  for (int j = 0; j < tiles; ++j)
    for (int i = 0; i < tiles; ++i) {
      const MeshId mesh = scene.add_mesh(
          terrain_tile(-0.5f * size + float(i) * tile, -0.5f * size + float(j) * tile, tile, 16));
      scene.add_object(mesh, grass, glm::mat4(1.0f), OccluderClass::always);
    }

  std::vector<MeshId> trees, rocks;
  for (int v = 0; v < 3; ++v) {
    MeshBuilder m;
    const float h = 5.0f + 1.5f * float(v);
    m.prism({0, 0, 0}, 0.25f, 2.0f, 7);
    m.cone({0, 1.8f, 0}, 2.4f + 0.3f * float(v), h * 0.55f, 16);
    m.cone({0, 1.8f + h * 0.3f, 0}, 1.8f + 0.2f * float(v), h * 0.5f, 16);
    m.cone({0, 1.8f + h * 0.55f, 0}, 1.2f, h * 0.4f, 16);
    trees.push_back(scene.add_mesh(m.take()));
  }
  for (int v = 0; v < 4; ++v) rocks.push_back(scene.add_mesh(rock_mesh(rng)));
  MeshId house;
  {
    MeshBuilder m;
    const Aabb body{{-4.0f, -0.5f, -3.0f}, {4.0f, 3.2f, 3.0f}};
    m.box(body, MeshBuilder::no_bottom);
    m.gable(body, 2.4f, true);
    m.box({{2.0f, 3.6f, -1.2f}, {2.7f, 5.6f, -0.5f}}, MeshBuilder::no_bottom);  // chimney
    m.box({{-1.0f, -0.5f, 3.0f}, {1.0f, 2.3f, 4.2f}}, MeshBuilder::no_bottom);   // porch
    m.gable({{-1.2f, -0.5f, 3.0f}, {1.2f, 2.3f, 4.4f}}, 0.8f, false);
    house = scene.add_mesh(m.take());
  }
  MeshId haystack;
  {
    MeshBuilder m;
    m.prism({0, -0.3f, 0}, 1.6f, 1.8f, 14);
    m.cone({0, 1.5f, 0}, 1.7f, 1.5f, 14);
    haystack = scene.add_mesh(m.take());
  }

  for (int n = 0; n < count; ++n) {
    const float x = rng.uniform(-0.48f, 0.48f) * size;
    const float z = rng.uniform(-0.48f, 0.48f) * size;
    const float yaw = rng.uniform(0.0f, glm::two_pi<float>());
    const float kind = rng.uniform();
    glm::mat4 t = glm::translate(glm::mat4(1.0f), {x, ground_height(x, z), z});
    t = glm::rotate(t, yaw, glm::vec3(0, 1, 0));
    if (kind < 0.45f) {
      t = glm::scale(t, glm::vec3(rng.uniform(0.8f, 1.3f)));
      scene.add_object(trees[std::size_t(rng.integer(0, 2))], foliage, t, OccluderClass::sometimes);
    } else if (kind < 0.75f) {
      t = glm::scale(t, glm::vec3(rng.uniform(0.6f, 2.2f)));
      scene.add_object(rocks[std::size_t(rng.integer(0, 3))], stone, t, OccluderClass::sometimes);
    } else if (kind < 0.88f) {
      scene.add_object(house, plaster, t, OccluderClass::always);
    } else {
      scene.add_object(haystack, hay, t, OccluderClass::never);
    }
  }

  {  // overview: orbit high above, looking at the centre.
    std::vector<CameraPath::Key> keys;
    const float radius = 0.42f * size, height = 0.3f * size;
    for (int k = 0; k <= 12; ++k) {
      const float a = glm::two_pi<float>() * float(k) / 12.0f * 0.75f;
      keys.push_back(look_at_key(2.0 * k, {radius * std::cos(a), height, radius * std::sin(a)},
                                 {0.0f, 0.0f, 0.0f}));
    }
    bundle.paths.emplace_back("overview", "orbits high above the field looking down at its centre",
                              std::move(keys));
  }
  {  // glide: a low diagonal pass at a glancing angle, swaying left and right.
    std::vector<CameraPath::Key> keys;
    const float flight = 14.0f;
    for (int k = 0; k <= 10; ++k) {
      const float f = float(k) / 10.0f;
      const float s = (-0.45f + 0.9f * f) * size;
      const glm::vec3 eye(s, flight + ground_height(s, s), s + 0.08f * size * std::sin(f * 6.0f));
      const float sway = 0.35f * std::sin(f * 9.0f);
      CameraPath::Key key{2.0 * k, {eye, glm::radians(-135.0f) + sway, glm::radians(-7.0f)}, false};
      keys.push_back(key);
    }
    bundle.paths.emplace_back("glide", "skims low across the field at a glancing angle",
                              std::move(keys));
  }
  return bundle;
}

}  // namespace occull::scenes
