// occull — the scene model: meshes, materials and objects.
//
// A Scene owns everything the renderer draws and the cullers reason about.
// Objects reference meshes and materials by index; several objects may share
// one mesh (instancing). The engine moves objects with set_transform();
// dynamic objects (add_dynamic_object) are those it moves from frame to
// frame, which the hierarchy keeps apart.
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

/// What the culling side needs of a mesh that an engine keeps and draws
/// itself: no vertices. occull's own renderer draws nothing for it.
struct MeshInfo {
  Aabb bounds;                  ///< object space; empty for a mesh without triangles
  std::uint32_t triangles = 0;  ///< what a draw of it costs
  double surface_area = 0.0;    ///< sum of its triangles' areas, squared object-space units (>= 0)
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

/// The occluder classes of Seletsky 2013: which objects belong in a
/// depth pre-pass. Walls and terrain `always`, large props `sometimes`,
/// small details `never`.
enum class OccluderClass : std::uint8_t { always, sometimes, never };

struct Object {
  MeshId mesh = 0;
  MaterialId material = 0;
  glm::mat4 transform{1.0f};     ///< object to world
  Aabb bounds;                   ///< world-space box of the transformed mesh
  std::uint32_t triangles = 0;   ///< triangle count of the mesh
  OccluderClass occluder = OccluderClass::sometimes;
  bool moving = false;           ///< a dynamic object (Scene::add_dynamic_object)
  bool removed = false;          ///< removed by Scene::remove_object: empty bounds, no triangles

  [[nodiscard]] bool dynamic() const noexcept { return moving; }
};

/// The most a Scene holds; past it add_object / add_mesh throw InputError.
/// The defaults are the documented caps of occull/input_limits.hpp.
struct SceneLimits {
  std::size_t objects = limits::objects;
  std::uint64_t mesh_triangles = limits::mesh_triangles;  ///< each mesh counted once
};

/// A scene: the meshes, materials and objects of one world.
/// Invariant: every object's `bounds` and `triangles` match its mesh and
/// transform (every call that changes an object maintains it).
///
/// An engine drives it between frames: set_transform() moves any object,
/// add_object() and remove_object() change the set. Object ids are stable
/// while the object lives; a removed id keeps its slot (empty bounds, no
/// triangles, so every culler passes it over) until a later add_object()
/// reuses it, the most recently removed first. The hierarchy (Bvh::refit)
/// and the cullers follow these changes by the revisions below.
class Scene {
 public:
  explicit Scene(std::string name = {}, const SceneLimits& caps = {}) : name_(std::move(name)), caps_(caps) {}

  /// Adds a mesh. Throws UsageError unless every index is in range, there
  /// are 3 per triangle and one normal per position; InputError past
  /// SceneLimits::mesh_triangles triangles in all meshes.
  MeshId add_mesh(Mesh mesh);
  /// Adds a mesh the engine keeps itself: bounds, triangle count and area,
  /// no vertices. Throws InputError for bounds or an area that is not finite.
  MeshId add_mesh(const MeshInfo& info);
  MaterialId add_material(Material material);
  /// Adds a static object, in the slot of the most recently removed object
  /// if there is one. Throws UsageError for a mesh or material that does not
  /// exist; InputError for a transform that is not finite, or past
  /// SceneLimits::objects objects; the scene is unchanged then.
  ObjectId add_object(MeshId mesh, MaterialId material, const glm::mat4& transform,
                      OccluderClass occluder);
  /// Sets object `id`'s object-to-world transform; its bounds follow. Any
  /// object, static or dynamic (a dynamic object's moves are not recorded in
  /// moved_objects() nor counted by placement_revision(): every consumer
  /// follows the dynamic objects each frame). Throws, the scene unchanged, UsageError for an id that
  /// does not exist or was removed, InputError for a transform with an entry
  /// that is not finite.
  void set_transform(ObjectId id, const glm::mat4& transform);
  /// Removes object `id` (static or dynamic): it keeps the id with empty
  /// bounds and no triangles until add_object() reuses it. Throws UsageError,
  /// the scene unchanged, for an id that does not exist or was removed.
  void remove_object(ObjectId id);
  /// Whether `id` is an object that was not removed.
  [[nodiscard]] bool alive(ObjectId id) const noexcept { return id < objects_.size() && !objects_[id].removed; }

  /// Counts every add_object() and remove_object() (not place_object):
  /// per-object state sized or listed by the set of objects is stale when it
  /// changed.
  [[nodiscard]] std::uint64_t layout_revision() const noexcept { return layout_revision_; }
  /// Counts every change of an object's transform or placement other than a
  /// dynamic object's moves: set_transform, place_object, add_object,
  /// remove_object.
  [[nodiscard]] std::uint64_t placement_revision() const noexcept { return placement_revision_; }
  /// Calls `f(id)` for every object changed (placed, moved, added, removed)
  /// since placement revision `since`: from the list of moved objects when
  /// it reaches back that far, else for every object (a consumer that missed
  /// changes gets them all). An id may come more than once. Returns the
  /// current placement revision, to pass next time.
  template <class F>
  std::uint64_t for_each_changed_since(std::uint64_t since, F&& f) const {
    if (since == placement_revision_) return since;
    if (since >= moved_from_revision_) {
      for (ObjectId id : moved_) f(id);
    } else {
      for (ObjectId id = 0; id < objects_.size(); ++id) f(id);
    }
    return placement_revision_;
  }
  /// Adds a dynamic object: one the engine moves (set_transform) from frame
  /// to frame, a car or a door. The hierarchy keeps dynamic objects apart
  /// (Bvh), and every consumer follows all of them each frame. `range`: the
  /// world box the object's position (its transform's translation) stays
  /// within, where known (empty: unknown), so that structures sized once
  /// (the grid of `grid`) reach where it goes. Throws as add_object(), and
  /// InputError for a range that is not finite.
  ObjectId add_dynamic_object(MeshId mesh, MaterialId material, const glm::mat4& transform,
                              OccluderClass occluder, const Aabb& range = {});
  /// Where dynamic object `id`'s position stays (add_dynamic_object); empty
  /// when unknown, and for other objects.
  [[nodiscard]] Aabb dynamic_range(ObjectId id) const;
  /// Sets it (an engine that re-routes the object, or moves its floating
  /// origin). Throws UsageError unless `id` is a dynamic object, InputError
  /// for a range that is not finite.
  void set_dynamic_range(ObjectId id, const Aabb& range);

  /// Makes static object `id` another object in place: its mesh, material,
  /// transform and class (a tiled world reuses the ids of a tile that left
  /// its window for the one that entered). Bounds and triangles follow.
  /// Records `id` in moved_objects(). Throws UsageError unless `id` exists
  /// and is static and mesh and material exist.
  void place_object(ObjectId id, MeshId mesh, MaterialId material, const glm::mat4& transform,
                    OccluderClass occluder);
  /// Objects placed, moved, added or removed since the last clear_moved(),
  /// in order (an id may appear more than once). A renderer that keeps
  /// transforms on the device re-uploads these. The scene clears the list
  /// itself when it grows past the number of objects (for_each_changed_since
  /// then visits every object), so an owner that never clears it leaks nothing.
  [[nodiscard]] std::span<const ObjectId> moved_objects() const noexcept { return moved_; }
  void clear_moved() noexcept {
    moved_.clear();
    moved_from_revision_ = placement_revision_;
  }

  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  [[nodiscard]] std::span<const Mesh> meshes() const noexcept { return meshes_; }
  [[nodiscard]] std::span<const Material> materials() const noexcept { return materials_; }
  [[nodiscard]] std::span<const Object> objects() const noexcept { return objects_; }
  [[nodiscard]] const Object& object(ObjectId id) const { return objects_[id]; }
  [[nodiscard]] const Mesh& mesh(MeshId id) const { return meshes_[id]; }
  [[nodiscard]] const Material& material(MaterialId id) const { return materials_[id]; }
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
  std::vector<ObjectId> dynamic_;
  std::vector<Aabb> dynamic_range_;  // per object id (grown on demand): empty for static ones
  std::vector<ObjectId> moved_;
  std::vector<ObjectId> free_ids_;  // removed objects' ids, the most recent last
  std::uint64_t layout_revision_ = 0;
  std::uint64_t placement_revision_ = 0;
  std::uint64_t moved_from_revision_ = 0;  // moved_ lists every change after this revision
  // Records a change of object `id`'s placement.
  void note_moved(ObjectId id);
  // Throw UsageError for an object that is not there, InputError for a range that is not finite.
  void check_object(ObjectId id, const char* what) const;
  void check_range(const Aabb& range, const char* what) const;
  // A static object of `mesh` at `transform`, its bounds and triangles filled.
  [[nodiscard]] Object make_object(MeshId mesh, MaterialId material, const glm::mat4& transform,
                                   OccluderClass occluder) const;
  std::vector<Aabb> mesh_bounds_;
  std::vector<double> mesh_area_;
  std::vector<std::uint32_t> mesh_triangle_count_;
  std::uint64_t mesh_triangles_ = 0;  // sum over meshes_, against caps_
};

}  // namespace occull
