// Internal: building blocks for the procedural scenes — a deterministic
// random generator and a mesh builder for boxes, prisms and cones.
#pragma once

#include "occull/scene.hpp"
#include "occull/view.hpp"

#include <cstdint>

namespace occull::scenes {

/// SplitMix64: tiny, fast and identical on every platform and standard
/// library (std::uniform_*_distribution is not), so scenes are reproducible.
class Rng {
 public:
  explicit Rng(std::uint64_t seed) : state_(seed * 0x9E3779B97F4A7C15ull + 0x1234567ull) {}
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9E3779B97F4A7C15ull);
    z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
    z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
    return z ^ (z >> 31);
  }
  /// Uniform in [0, 1).
  float uniform() { return float(next() >> 40) * (1.0f / 16777216.0f); }
  /// Uniform in [lo, hi).
  float uniform(float lo, float hi) { return lo + (hi - lo) * uniform(); }
  /// Uniform integer in [lo, hi] (inclusive).
  int integer(int lo, int hi) { return lo + int(next() % std::uint64_t(hi - lo + 1)); }
  bool chance(float p) { return uniform() < p; }

 private:
  std::uint64_t state_;
};

/// Appends primitives to one mesh. Every primitive is closed or faces
/// outwards with counter-clockwise front faces.
class MeshBuilder {
 public:
  /// Faces of a box to emit.
  enum Faces : unsigned {
    neg_x = 1, pos_x = 2, neg_y = 4, pos_y = 8, neg_z = 16, pos_z = 32, all = 63,
    no_bottom = all & ~neg_y,
  };

  /// Quad p0 p1 p2 p3 (a planar convex loop) facing `normal`; the winding
  /// is chosen to face that way whatever the order of the loop.
  void quad(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2, const glm::vec3& p3,
            const glm::vec3& normal);
  void triangle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                const glm::vec3& normal);
  void box(const Aabb& b, unsigned faces = all);
  /// Upright prism with `sides` sides around (center.x, center.z), from
  /// center.y up by `height`; with a top cap (and a bottom cap if asked).
  void prism(const glm::vec3& base_center, float radius, float height, int sides,
             bool bottom_cap = false);
  /// Closed cylinder (`sides`-sided) with its axis along +Z, from
  /// start.z to start.z + length, centred on (start.x, start.y). A wheel.
  void cylinder_z(const glm::vec3& start, float radius, float length, int sides);
  /// Upright cone (pyramid with `sides` sides) from base_center up by height.
  void cone(const glm::vec3& base_center, float radius, float height, int sides);
  /// Gable roof over the box's top face, ridge along x (or z when !along_x).
  void gable(const Aabb& footprint, float ridge_height, bool along_x);

  [[nodiscard]] std::size_t triangle_count() const noexcept { return mesh_.indices.size() / 3; }
  Mesh take() { return std::move(mesh_); }

 private:
  Mesh mesh_;
};

/// A camera-path key at time `t` (seconds): the eye at `eye`, looking at `target`.
CameraPath::Key look_at_key(double t, const glm::vec3& eye, const glm::vec3& target);

}  // namespace occull::scenes
