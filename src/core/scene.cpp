#include "occull/scene.hpp"

#include "occull/error.hpp"
#include "occull/input_limits.hpp"
#include "core/format.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>

namespace occull {

Aabb Mesh::bounds() const noexcept {
  Aabb b;
  for (const auto& p : positions) b.extend(p);
  return b;
}

double Mesh::surface_area() const noexcept {
  double area = 0.0;
  for (std::size_t i = 0; i + 2 < indices.size(); i += 3) {
    const glm::dvec3 a(positions[indices[i]]);
    const glm::dvec3 b(positions[indices[i + 1]]);
    const glm::dvec3 c(positions[indices[i + 2]]);
    area += 0.5 * glm::length(glm::cross(b - a, c - a));
  }
  return area;
}

MeshId Scene::add_mesh(Mesh mesh) {
  if (mesh.normals.size() != mesh.positions.size() || mesh.indices.size() % 3 != 0)
    throw UsageError(detail::format("scene {}: add_mesh: {} normals for {} positions and {} indices (one normal per "
                                    "position, 3 indices per triangle)",
                                    name_, mesh.normals.size(), mesh.positions.size(), mesh.indices.size()));
  for (const std::uint32_t i : mesh.indices)
    if (i >= mesh.positions.size())
      throw UsageError(detail::format("scene {}: add_mesh: index {} of a mesh of {} positions", name_, i,
                                      mesh.positions.size()));
  if (mesh_triangles_ + mesh.triangle_count() > caps_.mesh_triangles)
    throw InputError(detail::format("scene {}: {} triangles in its meshes is past the limit of {} "
                                 "(occull::limits::mesh_triangles)",
                                 name_, mesh_triangles_ + mesh.triangle_count(), caps_.mesh_triangles));
  mesh_triangles_ += mesh.triangle_count();
  mesh_bounds_.push_back(mesh.bounds());
  mesh_area_.push_back(mesh.surface_area());
  mesh_triangle_count_.push_back(std::uint32_t(mesh.triangle_count()));
  meshes_.push_back(std::move(mesh));
  return MeshId(meshes_.size() - 1);
}

MeshId Scene::add_mesh(const MeshInfo& info) {
  const auto finite = [](const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
  if (!info.bounds.empty() && !(finite(info.bounds.min) && finite(info.bounds.max)))
    throw InputError(detail::format("scene {}: a mesh's bounds ({}, {}, {}) - ({}, {}, {}) must be finite", name_,
                                 info.bounds.min.x, info.bounds.min.y, info.bounds.min.z, info.bounds.max.x,
                                 info.bounds.max.y, info.bounds.max.z));
  if (!(info.surface_area >= 0.0) || !std::isfinite(info.surface_area))
    throw InputError(detail::format("scene {}: a mesh's surface area {} must be a finite number >= 0", name_,
                                 info.surface_area));
  mesh_bounds_.push_back(info.bounds);
  mesh_area_.push_back(info.surface_area);
  mesh_triangle_count_.push_back(info.triangles);
  meshes_.emplace_back();  // no vertices: the engine draws it
  return MeshId(meshes_.size() - 1);
}

MaterialId Scene::add_material(Material material) {
  materials_.push_back(std::move(material));
  return MaterialId(materials_.size() - 1);
}

namespace {

bool finite(const glm::mat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

}  // namespace

void Scene::check_object(ObjectId id, const char* what) const {
  if (id >= objects_.size())
    throw UsageError(detail::format("scene {}: {} object {}: no such object (ids 0 to {})", name_, what, id,
                                 objects_.size() == 0 ? 0 : objects_.size() - 1));
  if (objects_[id].removed)
    throw UsageError(detail::format("scene {}: {} object {}: it was removed", name_, what, id));
}

void Scene::note_moved(ObjectId id) {
  ++placement_revision_;
  if (moved_.size() >= std::max<std::size_t>(2 * objects_.size(), 64)) clear_moved();  // bounded: consumers rescan
  moved_.push_back(id);
}

ObjectId Scene::add_object(MeshId mesh, MaterialId material, const glm::mat4& transform,
                           OccluderClass occluder) {
  if (mesh >= meshes_.size())
    throw UsageError(detail::format("scene {}: mesh {} does not exist ({} meshes)", name_, mesh, meshes_.size()));
  if (material >= materials_.size())
    throw UsageError(detail::format("scene {}: material {} does not exist ({} materials)", name_, material,
                                 materials_.size()));
  if (!finite(transform))
    throw InputError(detail::format("scene {}: a new object's transform has an entry that is not finite", name_));
  ObjectId id;
  if (!free_ids_.empty()) {
    id = free_ids_.back();
    free_ids_.pop_back();
    objects_[id] = make_object(mesh, material, transform, occluder);
  } else {
    if (objects_.size() >= caps_.objects)
      throw InputError(detail::format("scene {}: more than {} objects, the limit (occull::limits::objects)", name_,
                                   caps_.objects));
    objects_.push_back(make_object(mesh, material, transform, occluder));
    id = ObjectId(objects_.size() - 1);
  }
  ++layout_revision_;
  note_moved(id);
  return id;
}

void Scene::set_transform(ObjectId id, const glm::mat4& transform) {
  check_object(id, "set_transform of");
  if (!finite(transform))
    throw InputError(detail::format("scene {}: set_transform of object {}: the transform has an entry that is not finite",
                                 name_, id));
  Object& o = objects_[id];
  o.transform = transform;
  o.bounds = transform_box(mesh_bounds_[o.mesh], transform);
  if (!o.moving) note_moved(id);  // consumers follow every dynamic object each frame
}

void Scene::remove_object(ObjectId id) {
  check_object(id, "remove_object of");
  Object& o = objects_[id];
  if (o.moving) {
    std::erase(dynamic_, id);
    dynamic_range_[id] = Aabb{};
  }
  o.moving = false;
  o.removed = true;
  o.bounds = Aabb{};
  o.triangles = 0;
  free_ids_.push_back(id);
  ++layout_revision_;
  note_moved(id);
}

Object Scene::make_object(MeshId mesh, MaterialId material, const glm::mat4& transform,
                          OccluderClass occluder) const {
  Object o;
  o.mesh = mesh;
  o.material = material;
  o.transform = transform;
  o.bounds = transform_box(mesh_bounds_[mesh], transform);
  o.triangles = mesh_triangle_count_[mesh];
  o.occluder = occluder;
  return o;
}

ObjectId Scene::add_dynamic_object(MeshId mesh, MaterialId material, const glm::mat4& transform,
                                   OccluderClass occluder, const Aabb& range) {
  check_range(range, "add_dynamic_object");
  const ObjectId id = add_object(mesh, material, transform, occluder);
  objects_[id].moving = true;
  dynamic_.insert(std::upper_bound(dynamic_.begin(), dynamic_.end(), id), id);  // ascending, ids may be reused
  if (dynamic_range_.size() <= id) dynamic_range_.resize(std::size_t(id) + 1);
  dynamic_range_[id] = range;
  return id;
}

void Scene::check_range(const Aabb& range, const char* what) const {
  const auto finite3 = [](const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); };
  if (!range.empty() && !(finite3(range.min) && finite3(range.max)))
    throw InputError(detail::format("scene {}: {}: a dynamic object's range must be finite", name_, what));
}

Aabb Scene::dynamic_range(ObjectId id) const {
  return id < dynamic_range_.size() && alive(id) && objects_[id].moving ? dynamic_range_[id] : Aabb{};
}

void Scene::set_dynamic_range(ObjectId id, const Aabb& range) {
  check_object(id, "set_dynamic_range of");
  if (!objects_[id].moving)
    throw UsageError(detail::format("scene {}: set_dynamic_range of object {}: it is not dynamic", name_, id));
  check_range(range, "set_dynamic_range");
  dynamic_range_[id] = range;
}

void Scene::place_object(ObjectId id, MeshId mesh, MaterialId material, const glm::mat4& transform,
                         OccluderClass occluder) {
  check_object(id, "place_object");
  if (objects_[id].dynamic())
    throw UsageError(detail::format("scene {}: place_object of object {}: it is dynamic (moved from frame to frame)",
                                    name_, id));
  if (mesh >= meshes_.size() || material >= materials_.size())
    throw UsageError(detail::format("scene {}: place_object: mesh {} or material {} does not exist ({} meshes, {} "
                                    "materials)",
                                    name_, mesh, material, meshes_.size(), materials_.size()));
  objects_[id] = make_object(mesh, material, transform, occluder);
  note_moved(id);
}

std::uint64_t Scene::triangle_count() const noexcept {
  std::uint64_t n = 0;
  for (const auto& o : objects_) n += o.triangles;
  return n;
}

double Scene::object_surface_area(ObjectId id) const {
  const Object& o = objects_[id];
  const double scale = std::cbrt(std::abs(double(glm::determinant(glm::mat3(o.transform)))));
  return mesh_area_[o.mesh] * scale * scale;
}

Aabb Scene::bounds() const noexcept {
  Aabb b;
  for (const auto& o : objects_) b.extend(o.bounds);
  return b;
}

}  // namespace occull
