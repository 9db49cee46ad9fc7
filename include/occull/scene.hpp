// occull — the scene model: meshes, materials, objects and their motion.
//
// A Scene owns everything the renderer draws and the cullers reason about.
// Objects reference meshes and materials by index; several objects may share
// one mesh (instancing). Dynamic objects follow a looped Motion and are moved
// by Scene::update(); everything else never moves.
#pragma once

#include "occull/geometry.hpp"
#include "occull/input_limits.hpp"

#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace occull {

using ObjectId = std::uint32_t;
using MeshId = std::uint32_t;
using MaterialId = std::uint32_t;

/// Indexed triangle mesh in object space. Front faces wind counter-clockwise.
struct Mesh {
  std::vector<glm::vec3> positions;
  std::vector<glm::vec3> normals;       ///< one per position, unit length
  std::vector<std::uint32_t> indices;   ///< 3 per triangle, each < positions.size()

  [[nodiscard]] std::size_t triangle_count() const noexcept { return indices.size() / 3; }
  /// Box of all positions (empty for an empty mesh).
  [[nodiscard]] Aabb bounds() const noexcept;
  /// Sum of triangle areas, in squared scene units.
  [[nodiscard]] double surface_area() const noexcept;
};

/// How an object is shaded. `shading_cost` is the number of light
/// evaluations per fragment (0 = flat colour): the knob that makes a scene
/// fragment-bound, as the NOHC paper's Vienna model is.
struct Material {
  std::string name;
  glm::vec4 color{0.8f, 0.8f, 0.8f, 1.0f};  ///< linear RGB; alpha is the opacity when translucent
  bool translucent = false;  ///< drawn after opaque objects, back to front, never an occluder
  int shading_cost = 0;      ///< >= 0
};

/// The occluder classes of Seletsky (seed 003): which objects belong in a
/// depth pre-pass. Walls and terrain `always`, large props `sometimes`,
/// small details `never`.
enum class OccluderClass : std::uint8_t { always, sometimes, never };

/// A closed polyline followed at constant speed, looping forever. The object
/// faces along its direction of travel (its mesh's +X axis turned about +Y).
struct Motion {
  std::vector<glm::vec3> waypoints;  ///< >= 2 points; the last joins the first
  float speed = 1.0f;                ///< scene units per second, > 0
  float start_offset = 0.0f;         ///< distance along the loop at time 0

  /// World transform at `time_s` seconds.
  [[nodiscard]] glm::mat4 transform_at(double time_s) const;
};

struct Object {
  MeshId mesh = 0;
  MaterialId material = 0;
  glm::mat4 transform{1.0f};     ///< object to world
  Aabb bounds;                   ///< world-space box of the transformed mesh
  std::uint32_t triangles = 0;   ///< triangle count of the mesh
  OccluderClass occluder = OccluderClass::sometimes;
  std::int32_t motion = -1;      ///< index into Scene::motions(), -1 for static objects

  [[nodiscard]] bool dynamic() const noexcept { return motion >= 0; }
};

/// The most a Scene holds; past it add_object / add_mesh throw InputError.
/// The defaults are the documented caps of occull/input_limits.hpp.
struct SceneLimits {
  std::size_t objects = limits::objects;
  std::uint64_t mesh_triangles = limits::mesh_triangles;  ///< each mesh counted once
};

/// A scene: the meshes, materials, objects and motions of one world.
/// Invariant: every object's `bounds` and `triangles` match its mesh and
/// transform (add_object and update maintain it).
class Scene {
 public:
  explicit Scene(std::string name = {}, const SceneLimits& caps = {}) : name_(std::move(name)), caps_(caps) {}

  /// Adds a mesh. Precondition: indices in range, normals.size() == positions.size().
  /// Throws InputError past SceneLimits::mesh_triangles triangles in all meshes.
  MeshId add_mesh(Mesh mesh);
  MaterialId add_material(Material material);
  /// Adds a static object. Preconditions: mesh and material exist.
  /// Throws InputError past SceneLimits::objects objects.
  ObjectId add_object(MeshId mesh, MaterialId material, const glm::mat4& transform,
                      OccluderClass occluder);
  /// Adds a dynamic object that follows `motion` (its transform at time 0 is
  /// applied at once). `local` is applied before the motion's transform.
  ObjectId add_dynamic_object(MeshId mesh, MaterialId material, Motion motion,
                              OccluderClass occluder, const glm::mat4& local = glm::mat4(1.0f));

  /// Makes static object `id` another object in place: its mesh, material,
  /// transform and class (a tiled world reuses the ids of a tile that left
  /// its window for the one that entered). Bounds and triangles follow.
  /// Records `id` in moved_objects(). Preconditions: `id` exists and is
  /// static; mesh and material exist.
  void place_object(ObjectId id, MeshId mesh, MaterialId material, const glm::mat4& transform,
                    OccluderClass occluder);
  /// Objects placed since the last clear_moved(), in placing order (an id
  /// may appear more than once). A renderer that keeps transforms on the
  /// device re-uploads these.
  [[nodiscard]] std::span<const ObjectId> moved_objects() const noexcept { return moved_; }
  void clear_moved() noexcept { moved_.clear(); }
  /// Moves every dynamic object to where it is at `time_s` and updates its
  /// bounds. Deterministic: the same time gives the same transforms.
  void update(double time_s);

  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  [[nodiscard]] std::span<const Mesh> meshes() const noexcept { return meshes_; }
  [[nodiscard]] std::span<const Material> materials() const noexcept { return materials_; }
  [[nodiscard]] std::span<const Object> objects() const noexcept { return objects_; }
  [[nodiscard]] const Object& object(ObjectId id) const { return objects_[id]; }
  [[nodiscard]] const Mesh& mesh(MeshId id) const { return meshes_[id]; }
  [[nodiscard]] const Material& material(MaterialId id) const { return materials_[id]; }
  [[nodiscard]] std::span<const Motion> motions() const noexcept { return motions_; }
  /// Ids of the dynamic objects, ascending.
  [[nodiscard]] std::span<const ObjectId> dynamic_objects() const noexcept { return dynamic_; }
  /// Sum of the objects' triangle counts (instances counted each time).
  [[nodiscard]] std::uint64_t triangle_count() const noexcept;
  /// Box of every object's bounds.
  [[nodiscard]] Aabb bounds() const noexcept;
  /// World-space surface area of an object's triangles (its mesh's area
  /// times the square of the transform's uniform scale), squared scene units.
  [[nodiscard]] double object_surface_area(ObjectId id) const;

 private:
  std::string name_;
  SceneLimits caps_;
  std::vector<Mesh> meshes_;
  std::vector<Material> materials_;
  std::vector<Object> objects_;
  std::vector<Motion> motions_;
  std::vector<glm::mat4> dynamic_local_;  // per motion: local transform
  std::vector<ObjectId> dynamic_;
  std::vector<ObjectId> moved_;
  // A static object of `mesh` at `transform`, its bounds and triangles filled.
  [[nodiscard]] Object make_object(MeshId mesh, MaterialId material, const glm::mat4& transform,
                                   OccluderClass occluder) const;
  std::vector<Aabb> mesh_bounds_;
  std::vector<double> mesh_area_;
  std::uint64_t mesh_triangles_ = 0;  // sum over meshes_, against caps_
};

}  // namespace occull
