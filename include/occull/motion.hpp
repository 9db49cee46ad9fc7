// occull — scripted motion of the embedded scenes' dynamic objects (the
// city's traffic): a looped path per object, and moving the objects along
// theirs for a time. Scene content, not the culling core: an engine moves
// its dynamic objects itself (Scene::set_transform).
#pragma once

#include "occull/scene.hpp"

#include <glm/glm.hpp>

#include <vector>

namespace occull {

/// A closed polyline followed at constant speed, looping forever. The object
/// faces along its direction of travel (its mesh's +X axis turned about +Y).
struct Motion {
  std::vector<glm::vec3> waypoints;  ///< >= 2 points; the last joins the first
  float speed = 1.0f;                ///< scene units per second, > 0
  float start_offset = 0.0f;         ///< distance along the loop at time 0

  /// World transform at `time_s` seconds. Precondition: a valid motion
  /// (valid_motion()).
  [[nodiscard]] glm::mat4 transform_at(double time_s) const;
  /// The box of the waypoints: where the object's position stays.
  [[nodiscard]] Aabb range() const noexcept;
};

/// Whether `motion` has 2 or more finite waypoints and a finite speed > 0
/// and start offset.
[[nodiscard]] bool valid_motion(const Motion& motion) noexcept;

/// A dynamic object of a scene on its scripted motion.
struct ScriptedObject {
  ObjectId id = 0;
  Motion motion;
  glm::mat4 local{1.0f};  ///< applied before the motion's transform
};

/// Adds to `scene` a dynamic object that follows `motion` (placed where it
/// is at time 0; its range the motion's, Scene::add_dynamic_object), and
/// appends it to `scripted`. Throws as Scene::add_dynamic_object(), and
/// InputError for an invalid motion.
ObjectId add_scripted_object(Scene& scene, std::vector<ScriptedObject>& scripted, MeshId mesh, MaterialId material,
                             Motion motion, OccluderClass occluder, const glm::mat4& local = glm::mat4(1.0f));

/// Moves every object of `scripted` still dynamic in `scene` to where it is
/// at `time_s` (Scene::set_transform). Deterministic: the same time gives
/// the same transforms. An owner that removes one of them from the scene
/// removes it from `scripted` too (its id may be reused).
void animate(Scene& scene, const std::vector<ScriptedObject>& scripted, double time_s);

}  // namespace occull
