// `track`: a race track on flat open ground — thousands of small meshes laid
// out along one road (kerbs, barrier segments, signs, trees) and almost
// nothing tall enough to hide anything: the scene where an occlusion
// culler must notice that queries do not pay, and stop issuing them.
//
// The road is a closed loop whose radius swings with the angle (long
// bends, two straights). Kerb stones line both edges, barrier segments the
// outer edge, signs stand every `sign_spacing` metres and trees in bands
// beside the road; a few grandstands along the straights are the only real
// occluders. Paths: `lap` drives the loop at eye height; `overview` circles
// high above it.
#include "mesh_builder.hpp"
#include "scenes_internal.hpp"

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <cmath>

namespace occull::scenes {
namespace {

// The centre line: radius as a function of the angle, squashed along z.
glm::vec3 centre(float radius, float a) {
  const float r = radius * (1.0f + 0.22f * std::sin(2.0f * a) + 0.08f * std::cos(3.0f * a));
  return {r * std::cos(a), 0.0f, 0.72f * r * std::sin(a)};
}

// Samples of the centre line every `step` metres (about): positions, unit
// tangents and the left-hand normals in the ground plane.
struct Sample {
  glm::vec3 p, tangent, left;
  float s = 0.0f;  // distance along the loop, metres
};

std::vector<Sample> sample_loop(float radius, float step) {
  constexpr int kFine = 20000;
  std::vector<glm::vec3> fine(kFine + 1);
  for (int i = 0; i <= kFine; ++i) fine[std::size_t(i)] = centre(radius, glm::two_pi<float>() * float(i) / kFine);
  std::vector<Sample> out;
  float s = 0.0f, next = 0.0f;
  for (int i = 0; i < kFine; ++i) {
    const glm::vec3 a = fine[std::size_t(i)], b = fine[std::size_t(i + 1)];
    const float len = glm::length(b - a);
    if (s >= next) {
      const glm::vec3 t = glm::normalize(b - a);
      out.push_back({a, t, glm::vec3(t.z, 0.0f, -t.x), s});
      next += step;
    }
    s += len;
  }
  return out;
}

// A mesh-local transform: origin at p, local +z along the tangent.
glm::mat4 frame_at(const glm::vec3& p, const glm::vec3& tangent, float lift = 0.0f) {
  const float yaw = std::atan2(tangent.x, tangent.z);
  return glm::rotate(glm::translate(glm::mat4(1.0f), p + glm::vec3(0, lift, 0)), yaw, glm::vec3(0, 1, 0));
}

}  // namespace

SceneInfo track_info() {
  return {"track",
          "a race track on flat open ground: thousands of small meshes (kerbs, barriers, signs, trees) "
          "along one road and almost no occluders",
          {{"radius", 600, 100, 5000, false, "mean radius of the loop, metres"},
           {"trees", 2500, 0, 100000, true, "trees in the bands beside the road"},
           {"kerb_spacing", 5, 1, 100, false, "metres between kerb stones along each edge"},
           {"sign_spacing", 40, 5, 1000, false, "metres between signs"},
           {"stands", 6, 0, 100, true, "grandstands along the straights (the only tall occluders)"},
           {"shading", 0, 0, 64, true, "light evaluations per fragment (fragment cost)"},
           {"seed", 1, 0, 1e9, true, "random seed"}},
          {"lap", "overview"}};
}

SceneBundle make_track(const Params& params) {
  const float radius = float(params.at("radius"));
  const int tree_count = int(params.at("trees"));
  const float kerb_spacing = float(params.at("kerb_spacing"));
  const float sign_spacing = float(params.at("sign_spacing"));
  const int stands = int(params.at("stands"));
  const int shading = int(params.at("shading"));
  Rng rng(std::uint64_t(params.at("seed")));
  const float extent = radius * 1.6f;  // the ground reaches this far from the centre
  SceneBundle bundle{Scene("track"), {}, Lens{60.0f, 0.3f, std::max(2000.0f, 2.5f * extent)}};
  Scene& scene = bundle.scene;

  const MaterialId grass = scene.add_material({"grass", {0.40f, 0.56f, 0.27f, 1}, false, shading});
  const MaterialId asphalt = scene.add_material({"asphalt", {0.25f, 0.25f, 0.27f, 1}, false, shading});
  const MaterialId kerb_red = scene.add_material({"kerb red", {0.78f, 0.15f, 0.12f, 1}, false, shading});
  const MaterialId kerb_white = scene.add_material({"kerb white", {0.92f, 0.92f, 0.90f, 1}, false, shading});
  const MaterialId steel = scene.add_material({"barrier", {0.62f, 0.64f, 0.68f, 1}, false, shading});
  const MaterialId board = scene.add_material({"sign", {0.95f, 0.75f, 0.10f, 1}, false, shading});
  const MaterialId foliage = scene.add_material({"foliage", {0.20f, 0.40f, 0.17f, 1}, false, shading});
  const MaterialId concrete = scene.add_material({"stand", {0.70f, 0.68f, 0.64f, 1}, false, shading});

  // Flat ground in 100 m tiles, slightly below the road.
  const int tiles = std::max(2, int(std::ceil(2.0f * extent / 100.0f)));
  const float tile = 2.0f * extent / float(tiles);
  for (int j = 0; j < tiles; ++j)
    for (int i = 0; i < tiles; ++i) {
      const float x0 = -extent + float(i) * tile, z0 = -extent + float(j) * tile;
      MeshBuilder m;
      m.quad({x0, -0.05f, z0}, {x0 + tile, -0.05f, z0}, {x0 + tile, -0.05f, z0 + tile}, {x0, -0.05f, z0 + tile},
             {0, 1, 0});
      scene.add_object(scene.add_mesh(m.take()), grass, glm::mat4(1.0f), OccluderClass::always);
    }

  // Road: one 12 m wide segment per 20 m of the loop.
  constexpr float kHalfWidth = 6.0f;
  const std::vector<Sample> road = sample_loop(radius, 20.0f);
  for (std::size_t i = 0; i < road.size(); ++i) {
    const Sample& a = road[i];
    const Sample& b = road[(i + 1) % road.size()];
    MeshBuilder m;
    m.quad(a.p - a.left * kHalfWidth, a.p + a.left * kHalfWidth, b.p + b.left * kHalfWidth,
           b.p - b.left * kHalfWidth, {0, 1, 0});
    scene.add_object(scene.add_mesh(m.take()), asphalt, glm::mat4(1.0f), OccluderClass::always);
  }

  MeshId kerb, barrier, sign, stand;
  {
    MeshBuilder m;
    m.box({{-0.5f, 0.0f, -0.5f * kerb_spacing * 0.45f}, {0.5f, 0.12f, 0.5f * kerb_spacing * 0.45f}},
          MeshBuilder::no_bottom);
    kerb = scene.add_mesh(m.take());
  }
  {
    MeshBuilder m;  // a steel guard rail on two posts
    m.box({{-0.08f, 0.45f, -1.9f}, {0.08f, 0.85f, 1.9f}}, MeshBuilder::all);
    m.box({{-0.06f, 0.0f, -1.6f}, {0.06f, 0.45f, -1.45f}}, MeshBuilder::no_bottom);
    m.box({{-0.06f, 0.0f, 1.45f}, {0.06f, 0.45f, 1.6f}}, MeshBuilder::no_bottom);
    barrier = scene.add_mesh(m.take());
  }
  {
    MeshBuilder m;  // a post and a board
    m.prism({0, 0, 0}, 0.06f, 2.2f, 6);
    m.box({{-0.05f, 2.2f, -0.9f}, {0.05f, 3.2f, 0.9f}}, MeshBuilder::all);
    sign = scene.add_mesh(m.take());
  }
  {
    MeshBuilder m;  // a stepped grandstand, 60 m long, facing -x (the road side)
    for (int step = 0; step < 6; ++step) {
      const float x = 2.0f * float(step);
      m.box({{x, 0.0f, -30.0f}, {x + 2.0f, 1.6f * float(step + 1), 30.0f}}, MeshBuilder::no_bottom);
    }
    m.box({{12.0f, 0.0f, -30.0f}, {13.0f, 14.0f, 30.0f}}, MeshBuilder::no_bottom);  // back wall
    stand = scene.add_mesh(m.take());
  }

  // Kerbs on both edges, alternating red and white.
  const std::vector<Sample> kerbs = sample_loop(radius, kerb_spacing);
  for (std::size_t i = 0; i < kerbs.size(); ++i) {
    const Sample& k = kerbs[i];
    for (const float side : {-1.0f, 1.0f}) {
      const glm::vec3 p = k.p + k.left * (side * (kHalfWidth + 0.5f));
      scene.add_object(kerb, i % 2 ? kerb_red : kerb_white, frame_at(p, k.tangent), OccluderClass::never);
    }
  }
  // Barriers along both edges, 4 m apart, 9 m from the centre line.
  const std::vector<Sample> rails = sample_loop(radius, 4.0f);
  for (const Sample& r : rails)
    for (const float side : {-1.0f, 1.0f})
      scene.add_object(barrier, steel, frame_at(r.p + r.left * (side * 9.0f), r.tangent), OccluderClass::sometimes);
  // Signs, alternating sides.
  const std::vector<Sample> signs = sample_loop(radius, sign_spacing);
  for (std::size_t i = 0; i < signs.size(); ++i) {
    const float side = i % 2 ? 1.0f : -1.0f;
    scene.add_object(sign, board, frame_at(signs[i].p + signs[i].left * (side * 10.5f), signs[i].tangent),
                     OccluderClass::never);
  }
  // Trees in bands 14–60 m beside the road.
  std::vector<MeshId> trees;
  for (int v = 0; v < 3; ++v) {
    MeshBuilder m;
    const float h = 4.0f + 1.5f * float(v);
    m.prism({0, 0, 0}, 0.2f, 1.6f, 6);
    m.cone({0, 1.4f, 0}, 1.8f + 0.3f * float(v), h * 0.6f, 10);
    m.cone({0, 1.4f + h * 0.35f, 0}, 1.2f + 0.2f * float(v), h * 0.5f, 10);
    trees.push_back(scene.add_mesh(m.take()));
  }
  const std::vector<Sample> fine = sample_loop(radius, 2.0f);
  for (int n = 0; n < tree_count && !fine.empty(); ++n) {
    const Sample& at = fine[std::size_t(rng.integer(0, int(fine.size()) - 1))];
    const float side = rng.chance(0.5f) ? 1.0f : -1.0f;
    const glm::vec3 p = at.p + at.left * (side * rng.uniform(14.0f, 60.0f));
    glm::mat4 t = glm::translate(glm::mat4(1.0f), p);
    t = glm::rotate(t, rng.uniform(0.0f, glm::two_pi<float>()), glm::vec3(0, 1, 0));
    t = glm::scale(t, glm::vec3(rng.uniform(0.8f, 1.3f)));
    scene.add_object(trees[std::size_t(rng.integer(0, 2))], foliage, t, OccluderClass::sometimes);
  }
  // Grandstands outside the loop, spread over it, facing the road.
  for (int i = 0; i < stands; ++i) {
    const Sample& at = fine[std::size_t(i) * fine.size() / std::size_t(std::max(stands, 1))];
    const glm::vec3 outward = glm::dot(at.left, at.p) > 0.0f ? at.left : -at.left;
    const glm::vec3 p = at.p + outward * 16.0f;
    // Local +x (the stand's depth) points away from the road.
    const float yaw = std::atan2(-outward.z, outward.x);
    scene.add_object(stand, concrete, glm::rotate(glm::translate(glm::mat4(1.0f), p), yaw, glm::vec3(0, 1, 0)),
                     OccluderClass::always);
  }

  {  // lap: drive the loop at 50 m/s, eyes 1.2 m above the road, looking ahead.
    std::vector<CameraPath::Key> keys;
    const std::vector<Sample> way = sample_loop(radius, 25.0f);
    float previous_yaw = 0.0f;
    for (std::size_t i = 0; i <= way.size(); ++i) {
      const Sample& w = way[i % way.size()];
      const float s = i == way.size() ? way.back().s + glm::length(way.front().p - way.back().p) : w.s;
      float yaw = std::atan2(-w.tangent.x, -w.tangent.z) + glm::pi<float>();
      while (i > 0 && yaw - previous_yaw > glm::pi<float>()) yaw -= glm::two_pi<float>();
      while (i > 0 && yaw - previous_yaw < -glm::pi<float>()) yaw += glm::two_pi<float>();
      previous_yaw = yaw;
      keys.push_back({double(s) / 50.0, {w.p + glm::vec3(0, 1.2f, 0), yaw, glm::radians(-2.0f)}, false});
    }
    bundle.paths.emplace_back("lap", "drives one lap of the track at 50 m/s, eyes 1.2 m above the road",
                              std::move(keys));
  }
  {  // overview: circle high above, looking at the centre.
    std::vector<CameraPath::Key> keys;
    for (int k = 0; k <= 12; ++k) {
      const float a = glm::two_pi<float>() * float(k) / 12.0f * 0.75f;
      const glm::vec3 eye(1.1f * radius * std::cos(a), 0.35f * radius, 1.1f * radius * std::sin(a));
      keys.push_back(look_at_key(3.0 * k, eye, glm::vec3(0.0f)));
    }
    bundle.paths.emplace_back("overview", "circles high above the track looking down at its centre",
                              std::move(keys));
  }
  return bundle;
}

}  // namespace occull::scenes
