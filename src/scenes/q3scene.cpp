// From a Quake 3 map to an occull scene: triangles in metres and Y-up,
// grouped into culling-sized objects, flat colours per texture, and the
// `tour` camera path through the spawn points.
#include "occull/error.hpp"
#include "occull/input_limits.hpp"
#include "occull/q3bsp.hpp"
#include "triangle_soup.hpp"

#include <fmt/format.h>
#include <glm/gtc/constants.hpp>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <fstream>
#include <map>
#include <numeric>
#include <sstream>

namespace occull::q3 {
namespace {

glm::vec3 to_occull_direction(const glm::vec3& n) { return glm::vec3(n.x, n.z, -n.y); }

using Triangle = scenes::SoupTriangle;  // material = texture index

// A flat colour from a texture name: the folder picks the hue family, the
// name varies it a little. Deterministic.
glm::vec3 texture_color(const std::string& name) {
  std::uint32_t h = 2166136261u, folder = 2166136261u;
  const std::size_t slash = name.rfind('/');
  for (std::size_t i = 0; i < name.size(); ++i) {
    h = (h ^ std::uint8_t(name[i])) * 16777619u;
    if (i < slash) folder = (folder ^ std::uint8_t(name[i])) * 16777619u;
  }
  const float hue = float(folder % 360) / 360.0f + float(h % 40) / 1000.0f;
  const float sat = 0.25f + float((h >> 8) % 20) / 100.0f, val = 0.55f + float((h >> 16) % 30) / 100.0f;
  const glm::vec3 k = glm::clamp(glm::abs(glm::fract(glm::vec3(hue) + glm::vec3(1.0f, 2.0f / 3, 1.0f / 3)) * 6.0f - 3.0f) - 1.0f,
                                 0.0f, 1.0f);
  return val * glm::mix(glm::vec3(1.0f), k, sat);
}

// Most triangles triangles_of can make: polygons' and meshes' own, and each
// patch's 3x3 pieces tessellated to `patch_level` (two per grid square).
std::uint64_t triangle_bound(const Map& map, int patch_level) {
  std::uint64_t n = 0;
  for (const Face& f : map.faces) {
    if (f.type == FaceType::polygon || f.type == FaceType::mesh) n += std::uint64_t(f.meshvert_count / 3);
    if (f.type == FaceType::patch)
      n += std::uint64_t((f.patch_width - 1) / 2) * std::uint64_t((f.patch_height - 1) / 2) * 2u *
           std::uint64_t(patch_level) * std::uint64_t(patch_level);
  }
  return n;
}

// Triangles of every drawn face, in occull coordinates, wound counter-
// clockwise seen from the side their vertex normals point to.
std::vector<Triangle> triangles_of(const Map& map, int patch_level) {
  std::vector<Triangle> out;
  std::vector<Vertex> verts;
  std::vector<std::uint32_t> idx;
  for (std::size_t face = 0; face < map.faces.size(); ++face) {
    const Face& f = map.faces[face];
    const Texture& t = map.textures[std::size_t(f.texture)];
    // No-draw surfaces are invisible in the game. Sky surfaces are drawn
    // (the game paints the sky box on them) and hide what lies behind them:
    // they are opaque here too, or geometry the game never shows would be.
    if ((t.surface_flags & kSurfNoDraw) && !(t.surface_flags & kSurfSky)) continue;
    verts.clear();
    idx.clear();
    const std::span<const Vertex> fv(map.vertices.data() + f.first_vertex, std::size_t(f.vertex_count));
    if (f.type == FaceType::polygon || f.type == FaceType::mesh) {
      verts.assign(fv.begin(), fv.end());
      for (std::int32_t k = 0; k < f.meshvert_count; ++k)
        idx.push_back(std::uint32_t(map.meshverts[std::size_t(f.first_meshvert + k)]));
    } else if (f.type == FaceType::patch) {
      tessellate_patch(fv, f.patch_width, f.patch_height, patch_level, verts, idx);
    } else {
      continue;  // billboards (flares) are not geometry
    }
    for (std::size_t k = 0; k + 2 < idx.size(); k += 3) {
      Triangle tri;
      tri.material = f.texture;
      tri.source = std::int32_t(face);
      for (int c = 0; c < 3; ++c) {
        tri.p[c] = to_occull(verts[idx[k + std::size_t(c)]].position);
        tri.n[c] = to_occull_direction(verts[idx[k + std::size_t(c)]].normal);
      }
      const glm::vec3 geometric = glm::cross(tri.p[1] - tri.p[0], tri.p[2] - tri.p[0]);
      if (glm::dot(geometric, geometric) < 1e-14f) continue;  // degenerate
      if (glm::dot(geometric, tri.n[0] + tri.n[1] + tri.n[2]) < 0.0f) {
        std::swap(tri.p[1], tri.p[2]);
        std::swap(tri.n[1], tri.n[2]);
      }
      out.push_back(tri);
    }
  }
  return out;
}

struct Spawn {
  glm::vec3 eye;  // occull coordinates
  float yaw;      // radians, occull convention
};

std::vector<Spawn> spawn_points(const Map& map) {
  static const char* const kinds[] = {"info_player_deathmatch", "info_player_start", "team_CTF_redspawn",
                                      "team_CTF_bluespawn",     "team_CTF_redplayer", "team_CTF_blueplayer"};
  std::vector<Spawn> out;
  for (const Entity& e : map.entities) {
    const auto cls = e.find("classname");
    const auto origin = e.find("origin");
    if (cls == e.end() || origin == e.end()) continue;
    if (std::find(std::begin(kinds), std::end(kinds), cls->second) == std::end(kinds)) continue;
    glm::vec3 o;
    std::istringstream in(origin->second);
    if (!(in >> o.x >> o.y >> o.z)) continue;
    float angle = 0.0f;
    if (const auto a = e.find("angle"); a != e.end()) angle = std::strtof(a->second.c_str(), nullptr);
    // Quake's view height is 26 units above the player origin; yaw 0 looks down +X.
    out.push_back({to_occull(o + glm::vec3(0, 0, 26)), glm::radians(angle) - glm::half_pi<float>()});
  }
  return out;
}

// True when the segment a-b passes through no triangle (Möller–Trumbore).
bool segment_clear(const glm::vec3& a, const glm::vec3& b, const std::vector<Triangle>& tris) {
  const glm::vec3 d = b - a;
  for (const Triangle& t : tris) {
    const glm::vec3 e1 = t.p[1] - t.p[0], e2 = t.p[2] - t.p[0];
    const glm::vec3 p = glm::cross(d, e2);
    const float det = glm::dot(e1, p);
    if (std::abs(det) < 1e-12f) continue;
    const float inv = 1.0f / det;
    const glm::vec3 s = a - t.p[0];
    const float u = glm::dot(s, p) * inv;
    if (u < 0.0f || u > 1.0f) continue;
    const glm::vec3 q = glm::cross(s, e1);
    const float v = glm::dot(d, q) * inv;
    if (v < 0.0f || u + v > 1.0f) continue;
    const float hit = glm::dot(e2, q) * inv;
    if (hit > 0.0f && hit < 1.0f) return false;
  }
  return true;
}

CameraPath tour_path(std::vector<Spawn> spawns, const std::vector<Triangle>& tris, const Aabb& bounds) {
  if (spawns.empty()) {
    // No spawn points: look around from the middle of the level.
    spawns.push_back({bounds.center(), 0.0f});
  }
  // Nearest-neighbour order from the first spawn point.
  std::vector<Spawn> order{spawns.front()};
  std::vector<bool> used(spawns.size(), false);
  used[0] = true;
  for (std::size_t k = 1; k < spawns.size(); ++k) {
    std::size_t best = 0;
    float best_d = std::numeric_limits<float>::infinity();
    for (std::size_t i = 0; i < spawns.size(); ++i)
      if (!used[i] && glm::length(spawns[i].eye - order.back().eye) < best_d) {
        best = i;
        best_d = glm::length(spawns[i].eye - order.back().eye);
      }
    used[best] = true;
    order.push_back(spawns[best]);
  }
  constexpr float kWalk = 4.0f;       // m/s
  constexpr double kTurn = 2.4;       // s per full turn
  std::vector<CameraPath::Key> keys;
  double t = 0.0;
  for (std::size_t k = 0; k < order.size(); ++k) {
    const Spawn& s = order[k];
    if (k > 0) {
      const Spawn& prev = order[k - 1];
      const bool clear = segment_clear(prev.eye, s.eye, tris);
      t += clear ? std::max(0.5, double(glm::length(s.eye - prev.eye) / kWalk)) : 0.05;
      keys.push_back({t, {s.eye, s.yaw, 0.0f}, !clear});
    } else {
      keys.push_back({t, {s.eye, s.yaw, 0.0f}, false});
    }
    for (int step = 1; step <= 3; ++step) {  // a turn in place
      t += kTurn / 3.0;
      keys.push_back({t, {s.eye, s.yaw + glm::two_pi<float>() * float(step) / 3.0f, 0.0f}, false});
    }
  }
  return CameraPath("tour", "spawn points of the level, a turn in place at each; walks where the way is "
                            "clear, cuts where a wall is between",
                    std::move(keys));
}

}  // namespace

SceneBundle build_scene(const Map& map, std::string name, const LoadOptions& options,
                        std::vector<std::vector<std::int32_t>>* object_faces) {
  SceneBundle bundle{Scene(std::move(name)), {}, Lens{75.0f, 0.05f, 400.0f}};
  Scene& scene = bundle.scene;
  const int patch_level = std::clamp(options.patch_level, 1, 32);
  // Checked before tessellating: a map of big patches at a fine level would
  // otherwise allocate its triangles before the scene's cap sees them.
  if (const std::uint64_t n = triangle_bound(map, patch_level); n > limits::mesh_triangles)
    throw InputError(fmt::format("{}: its faces tessellate to {} triangles at patch level {}, past the limit of {} "
                                 "(occull::limits::mesh_triangles)",
                                 scene.name(), n, patch_level, limits::mesh_triangles));
  std::vector<Triangle> tris = triangles_of(map, patch_level);

  // Materials per texture.
  std::vector<MaterialId> material(map.textures.size());
  for (std::size_t i = 0; i < map.textures.size(); ++i) {
    const Texture& t = map.textures[i];
    const bool translucent = (t.contents & (kContentsLiquid | kContentsFog | kContentsTranslucent)) != 0;
    const bool sky = (t.surface_flags & kSurfSky) != 0;
    const glm::vec3 color = sky ? glm::vec3(0.62f, 0.74f, 0.86f) : texture_color(t.name);
    material[i] = scene.add_material({t.name, glm::vec4(color, translucent && !sky ? 0.45f : 1.0f),
                                      translucent && !sky, 0});
  }
  const auto translucent = [&](const Triangle& t) {
    return scene.material(material[std::size_t(t.material)]).translucent;
  };
  // Opaque and translucent triangles cluster separately.
  const auto split = std::stable_partition(tris.begin(), tris.end(), [&](const Triangle& t) { return !translucent(t); });
  const std::size_t opaque_end = std::size_t(split - tris.begin());
  std::vector<std::pair<std::size_t, std::size_t>> groups;
  const std::uint32_t target = std::max<std::uint32_t>(options.object_triangles, 16);
  scenes::cluster_triangles(tris, 0, opaque_end, target, groups);
  scenes::cluster_triangles(tris, opaque_end, tris.size(), target, groups);

  for (const auto& [begin, end] : groups) {
    bool solid = false;
    for (std::size_t i = begin; i < end; ++i)
      solid = solid || (map.textures[std::size_t(tris[i].material)].contents & kContentsSolid);
    auto [mesh, dominant] = scenes::mesh_of(tris, begin, end);
    const MaterialId m = material[std::size_t(dominant)];
    const OccluderClass cls = scene.material(m).translucent ? OccluderClass::never
                              : solid                       ? OccluderClass::always
                                                            : OccluderClass::sometimes;
    scene.add_object(scene.add_mesh(std::move(mesh)), m, glm::mat4(1.0f), cls);
    if (object_faces) {
      std::vector<std::int32_t> faces;
      for (std::size_t i = begin; i < end; ++i) faces.push_back(tris[i].source);
      std::sort(faces.begin(), faces.end());
      faces.erase(std::unique(faces.begin(), faces.end()), faces.end());
      object_faces->push_back(std::move(faces));
    }
  }
  // Only opaque triangles stop the camera's walk.
  tris.resize(opaque_end);
  bundle.paths.push_back(tour_path(spawn_points(map), tris, scene.bounds()));
  return bundle;
}

SceneBundle load(std::string_view spec, const LoadOptions& options) {
  const std::string s(spec);
  const std::string lowered = [&] {
    std::string l = s;
    for (char& c : l) c = char(std::tolower(static_cast<unsigned char>(c)));
    return l;
  }();
  std::vector<std::byte> bytes;
  std::string source, name;
  if (const auto at = lowered.find(".pk3:"); at != std::string::npos) {
    const std::string pk3 = s.substr(0, at + 4);
    name = s.substr(at + 5);
    if (name.empty()) throw InputError(fmt::format("q3:{}: name a map after the archive (q3:FILE.pk3:MAP)", s));
    bytes = read_map_from_pk3(pk3, name);
    source = fmt::format("{}:maps/{}.bsp", pk3, name);
  } else if (lowered.size() > 4 && lowered.substr(lowered.size() - 4) == ".bsp") {
    const std::string chars = limits::read_file(s, limits::map_bytes, "a map (occull::limits::map_bytes)");
    bytes.resize(chars.size());
    std::memcpy(bytes.data(), chars.data(), chars.size());
    source = s;
    const std::size_t slash = s.find_last_of('/');
    name = s.substr(slash == std::string::npos ? 0 : slash + 1);
    name = name.substr(0, name.size() - 4);
  } else {
    throw InputError(fmt::format("q3:{}: expected q3:FILE.pk3:MAP or q3:FILE.bsp", s));
  }
  const Map map = read_bsp(bytes, source);
  return build_scene(map, "q3:" + name, options);
}

}  // namespace occull::q3
