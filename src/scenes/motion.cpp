// Scripted motion of the embedded scenes' dynamic objects.
#include "occull/motion.hpp"

#include "occull/error.hpp"

#include <fmt/format.h>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>

namespace occull {

glm::mat4 Motion::transform_at(double time_s) const {
  assert(waypoints.size() >= 2 && speed > 0.0f);
  const std::size_t n = waypoints.size();
  double loop = 0.0;
  for (std::size_t i = 0; i < n; ++i) loop += glm::length(waypoints[(i + 1) % n] - waypoints[i]);
  if (loop <= 0.0) return glm::translate(glm::mat4(1.0f), waypoints.front());
  double s = std::fmod(start_offset + speed * time_s, loop);
  if (s < 0.0) s += loop;
  for (std::size_t i = 0; i < n; ++i) {
    const glm::vec3 a = waypoints[i];
    const glm::vec3 b = waypoints[(i + 1) % n];
    const double len = glm::length(b - a);
    if (s <= len || i + 1 == n) {
      const float f = len > 0.0 ? float(std::min(s / len, 1.0)) : 0.0f;
      const glm::vec3 p = a + (b - a) * f;
      const glm::vec3 dir = b - a;
      const float yaw = std::atan2(-dir.z, dir.x);  // +X turned about +Y
      return glm::rotate(glm::translate(glm::mat4(1.0f), p), yaw, glm::vec3(0, 1, 0));
    }
    s -= len;
  }
  return glm::translate(glm::mat4(1.0f), waypoints.front());
}

Aabb Motion::range() const noexcept {
  Aabb box;
  for (const glm::vec3& p : waypoints) box.extend(Aabb{p, p});
  return box;
}

bool valid_motion(const Motion& motion) noexcept {
  const bool finite_points = std::all_of(motion.waypoints.begin(), motion.waypoints.end(), [](const glm::vec3& p) {
    return std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
  });
  return motion.waypoints.size() >= 2 && finite_points && std::isfinite(motion.speed) && motion.speed > 0.0f &&
         std::isfinite(motion.start_offset);
}

ObjectId add_scripted_object(Scene& scene, std::vector<ScriptedObject>& scripted, MeshId mesh, MaterialId material,
                             Motion motion, OccluderClass occluder, const glm::mat4& local) {
  if (!valid_motion(motion))
    throw InputError(fmt::format("scene {}: a motion needs 2 or more finite waypoints and a finite speed > 0",
                                 scene.name()));
  const ObjectId id = scene.add_dynamic_object(mesh, material, motion.transform_at(0.0) * local, occluder, motion.range());
  scripted.push_back({id, std::move(motion), local});
  return id;
}

void animate(Scene& scene, const std::vector<ScriptedObject>& scripted, double time_s) {
  for (const ScriptedObject& s : scripted)
    if (scene.alive(s.id) && scene.object(s.id).dynamic())
      scene.set_transform(s.id, s.motion.transform_at(time_s) * s.local);
}

}  // namespace occull
