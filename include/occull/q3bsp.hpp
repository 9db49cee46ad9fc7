// occull — Quake 3 levels: a reader for IBSP version 46 maps (bare .bsp or
// inside a .pk3 zip archive), Bézier patch tessellation, and the conversion
// to an occull Scene with a `tour` camera path through the spawn points.
//
// Coordinates: Quake 3 is Z-up in units of about an inch; occull scenes are
// Y-up in metres. A point (x, y, z) becomes (x, z, -y) / 32.
#pragma once

#include "occull/scenes.hpp"

#include <cstddef>
#include <cstdint>
#include <map>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace occull::q3 {

inline constexpr float kUnitsPerMetre = 32.0f;

struct Vertex {
  glm::vec3 position;  ///< Quake units, Z-up (as stored)
  glm::vec3 normal;
};

enum class FaceType : std::int32_t { polygon = 1, patch = 2, mesh = 3, billboard = 4 };

struct Face {
  std::int32_t texture = 0;
  FaceType type = FaceType::polygon;
  std::int32_t first_vertex = 0, vertex_count = 0;
  std::int32_t first_meshvert = 0, meshvert_count = 0;
  std::int32_t patch_width = 0, patch_height = 0;  ///< control points, patches only
};

struct Texture {
  std::string name;
  std::int32_t surface_flags = 0;
  std::int32_t contents = 0;
};

struct Leaf {
  std::int32_t cluster = -1;
  std::int32_t area = 0;
  glm::ivec3 mins{0}, maxs{0};
  std::int32_t first_face = 0, face_count = 0;
};

struct Plane {
  glm::vec3 normal;  ///< Quake coordinates
  float dist = 0.0f; ///< points p with dot(normal, p) == dist lie on it
};

/// BSP node: points in front of its plane (dot(normal, p) >= dist) go to
/// children[0]. A child >= 0 is a node, a child < 0 the leaf -(child + 1).
struct Node {
  std::int32_t plane = 0;
  std::int32_t children[2] = {0, 0};
};

/// The potentially visible set: bit `to` of cluster `from`'s row says
/// whether anything in cluster `to` can be seen from anywhere in `from`.
struct VisData {
  std::int32_t clusters = 0;        ///< rows (and bits per row)
  std::int32_t bytes_per_row = 0;
  std::vector<std::uint8_t> bits;   ///< clusters * bytes_per_row
};

/// Entity: key/value pairs from the entities lump.
using Entity = std::map<std::string, std::string>;

/// Everything occull reads from an IBSP v46 file, validated: every index
/// and range refers to existing elements.
struct Map {
  std::vector<Texture> textures;
  std::vector<Vertex> vertices;
  std::vector<std::int32_t> meshverts;
  std::vector<Face> faces;
  std::vector<Leaf> leaves;
  std::vector<std::int32_t> leaf_faces;
  std::vector<Entity> entities;
  std::vector<Plane> planes;
  std::vector<Node> nodes;
  VisData vis;  ///< empty (0 clusters) when the map was not vis-compiled
};

/// Quake 3 coordinates (Z-up, units) of an occull point (Y-up, metres) and back.
[[nodiscard]] inline glm::vec3 to_quake(const glm::vec3& p) {
  return glm::vec3(p.x, -p.z, p.y) * kUnitsPerMetre;
}
[[nodiscard]] inline glm::vec3 to_occull(const glm::vec3& p) {
  return glm::vec3(p.x, p.z, -p.y) / kUnitsPerMetre;
}

/// The cluster of the leaf that contains `point` (Quake coordinates), found
/// by walking the BSP tree; -1 inside solid space or outside the map.
[[nodiscard]] std::int32_t find_cluster(const Map& map, const glm::vec3& point);

/// Whether the map's PVS says cluster `to` may be visible from cluster
/// `from`. True when either is -1 (no information) or the map has no
/// visibility data.
[[nodiscard]] bool cluster_sees(const Map& map, std::int32_t from, std::int32_t to);

// Surface flags and contents used when converting (Quake 3's values).
inline constexpr std::int32_t kSurfSky = 0x4;
inline constexpr std::int32_t kSurfNoDraw = 0x80;
inline constexpr std::int32_t kContentsSolid = 0x1;
inline constexpr std::int32_t kContentsLiquid = 0x8 | 0x10 | 0x20;  ///< lava, slime, water
inline constexpr std::int32_t kContentsFog = 0x40;
inline constexpr std::int32_t kContentsTranslucent = 0x20000000;

/// Parses an IBSP v46 file. Throws InputError "SOURCE: what is wrong" for a
/// truncated file, wrong magic or version, a lump outside the file or of a
/// size that is not a whole number of records, or any index out of range.
[[nodiscard]] Map read_bsp(std::span<const std::byte> data, std::string_view source);

/// The bytes of maps/NAME.bsp inside a .pk3 (zip) archive. Throws InputError
/// when the file is not a readable zip or has no such map (listing those it has).
[[nodiscard]] std::vector<std::byte> read_map_from_pk3(const std::string& pk3, std::string_view map);

/// Map names (without maps/ and .bsp) inside a .pk3, sorted.
[[nodiscard]] std::vector<std::string> list_maps(const std::string& pk3);

/// Tessellates a biquadratic Bézier patch of width x height control points
/// (both odd, >= 3) into 3x3 sub-patches of (level + 1)^2 vertices and
/// 2 level^2 triangles each. Indices are local to the returned vertices.
void tessellate_patch(std::span<const Vertex> control, int width, int height, int level,
                      std::vector<Vertex>& vertices, std::vector<std::uint32_t>& indices);

struct LoadOptions {
  int patch_level = 6;                  ///< tessellation level of curved patches (1..32)
  std::uint32_t object_triangles = 500;   ///< faces are grouped into objects of at most this many triangles
};

/// Builds a scene from a map: faces grouped into culling-sized objects by
/// spatial clustering, flat colours per texture, no-draw surfaces left
/// out, sky surfaces opaque in a sky colour (they hide what is behind them,
/// as in the game), liquids and fog translucent, non-solid surfaces never
/// occluders. Paths: `tour` (spawn points, a turn in place at each, walking
/// between them where the straight way is clear, cutting where a wall is in
/// the way). `name` names the scene.
/// With `object_faces`, also returns for each object of the scene (by id)
/// the map faces its triangles came from, ascending.
[[nodiscard]] SceneBundle build_scene(const Map& map, std::string name, const LoadOptions& options = {},
                                      std::vector<std::vector<std::int32_t>>* object_faces = nullptr);

/// Loads "PATH.pk3:MAP" or "PATH.bsp" (the part of a scene spec after "q3:").
[[nodiscard]] SceneBundle load(std::string_view spec, const LoadOptions& options = {});

}  // namespace occull::q3
