// occull — geometry: axis-aligned boxes, planes, view frusta and the box
// measures that culling decisions are made of.
//
// Conventions (used everywhere in occull):
//   - right-handed world space, +Y up, units are scene units (metres for the
//     embedded scenes);
//   - OpenGL clip space (x, y, z in [-w, w]) for view-projection matrices;
//   - screen areas are in pixels of the viewport they are measured against.
#pragma once

#include <glm/glm.hpp>

#include <array>
#include <cstdint>
#include <limits>
#include <span>

namespace occull {

/// Axis-aligned bounding box. A default-constructed box is *empty*
/// (min = +inf, max = -inf) so that extending it by a point or box yields
/// exactly that point or box.
struct Aabb {
  glm::vec3 min{std::numeric_limits<float>::infinity()};
  glm::vec3 max{-std::numeric_limits<float>::infinity()};

  /// True when no point has been added (any min component > max component).
  [[nodiscard]] bool empty() const noexcept {
    return min.x > max.x || min.y > max.y || min.z > max.z;
  }
  [[nodiscard]] glm::vec3 center() const noexcept { return 0.5f * (min + max); }
  /// Edge lengths. Precondition: !empty().
  [[nodiscard]] glm::vec3 extent() const noexcept { return max - min; }
  /// Total surface area of the six faces; 0 for an empty box.
  [[nodiscard]] float surface_area() const noexcept {  // inline: the hierarchy's upkeep calls it per node
    if (empty()) return 0.0f;
    const glm::vec3 e = extent();
    return 2.0f * (e.x * e.y + e.y * e.z + e.z * e.x);
  }
  /// Volume; 0 for an empty box.
  [[nodiscard]] float volume() const noexcept;

  void extend(const glm::vec3& p) noexcept {
    min = glm::min(min, p);
    max = glm::max(max, p);
  }
  void extend(const Aabb& b) noexcept {
    min = glm::min(min, b.min);
    max = glm::max(max, b.max);
  }
  /// Grows the box by `margin` on every side (margin may be negative as long
  /// as the box stays non-empty).
  [[nodiscard]] Aabb grown(float margin) const noexcept {
    return {min - glm::vec3(margin), max + glm::vec3(margin)};
  }
  /// Corner i (0..7): bit 0 selects max.x, bit 1 max.y, bit 2 max.z.
  [[nodiscard]] glm::vec3 corner(int i) const noexcept {
    return {(i & 1) ? max.x : min.x, (i & 2) ? max.y : min.y, (i & 4) ? max.z : min.z};
  }
  /// Closed containment test (points on the boundary are inside).
  [[nodiscard]] bool contains(const glm::vec3& p) const noexcept {
    return p.x >= min.x && p.x <= max.x && p.y >= min.y && p.y <= max.y && p.z >= min.z &&
           p.z <= max.z;
  }
  [[nodiscard]] bool contains(const Aabb& b) const noexcept {
    return b.min.x >= min.x && b.min.y >= min.y && b.min.z >= min.z && b.max.x <= max.x &&
           b.max.y <= max.y && b.max.z <= max.z;
  }
  [[nodiscard]] bool overlaps(const Aabb& b) const noexcept {
    return min.x <= b.max.x && max.x >= b.min.x && min.y <= b.max.y && max.y >= b.min.y &&
           min.z <= b.max.z && max.z >= b.min.z;
  }
  friend bool operator==(const Aabb&, const Aabb&) = default;
};

/// The box of `b` after an affine transform `m` (the box of its 8 transformed
/// corners). Exact for rotations by multiples of 90 degrees. An empty box stays
/// empty.
[[nodiscard]] Aabb transform_box(const Aabb& b, const glm::mat4& m) noexcept;

/// Euclidean distance from point `p` to the box (0 when p is inside).
[[nodiscard]] float distance(const glm::vec3& p, const Aabb& b) noexcept;
/// The square of distance(p, b), without the square root: orders boxes by
/// distance the same way (front-to-back traversals), in scene units squared.
[[nodiscard]] float distance_squared(const glm::vec3& p, const Aabb& b) noexcept;

/// Plane n·x + d = 0 with unit normal n; the positive half-space is "inside".
struct Plane {
  glm::vec3 n{0.0f, 1.0f, 0.0f};
  float d = 0.0f;

  /// Signed distance (in scene units) of p from the plane.
  [[nodiscard]] float signed_distance(const glm::vec3& p) const noexcept {
    return glm::dot(n, p) + d;
  }
  /// Plane from coefficients (a, b, c, d) of a·x + b·y + c·z + d, normalised.
  /// Precondition: (a, b, c) is not the zero vector.
  [[nodiscard]] static Plane from_coefficients(const glm::vec4& abcd) noexcept;
};

/// Where a box lies relative to a frustum.
enum class Containment : std::uint8_t { outside, intersecting, inside };

/// The depth range of clip space after the perspective divide: OpenGL's
/// default [-1, 1], or [0, 1] (Vulkan, Direct3D, GL with
/// glClipControl(..., GL_ZERO_TO_ONE)).
enum class DepthRange : std::uint8_t { negative_one_to_one, zero_to_one };

/// The clip-space conventions of a projection matrix. With `reversed_z` the
/// near plane maps to the far end of the depth range (1) and the far plane to
/// its near end (-1 or 0): reversed-Z, usually with DepthRange::zero_to_one,
/// a floating-point depth buffer and a "greater" depth test.
struct ClipSpace {
  DepthRange depth = DepthRange::negative_one_to_one;
  bool reversed_z = false;

  /// Normalised depth of the near plane (-1, 0 or 1).
  [[nodiscard]] float near_depth() const noexcept {
    return reversed_z ? 1.0f : (depth == DepthRange::zero_to_one ? 0.0f : -1.0f);
  }
  /// Normalised depth of the far plane.
  [[nodiscard]] float far_depth() const noexcept {
    return reversed_z ? (depth == DepthRange::zero_to_one ? 0.0f : -1.0f) : 1.0f;
  }
  friend bool operator==(const ClipSpace&, const ClipSpace&) = default;
};

/// The six planes of a view frustum, normals pointing inwards.
class Frustum {
 public:
  enum Side : int { left, right, bottom, top, near, far, count };
  /// All planes of every box test, as a bit mask.
  static constexpr std::uint32_t all_planes = (1u << count) - 1;

  Frustum() = default;
  /// Extracts the planes from a combined projection * view matrix with the
  /// clip conventions `clip` (Gribb/Hartmann; OpenGL's by default). Works
  /// for perspective and orthographic, symmetric and asymmetric projections.
  /// A plane at infinity (an infinite far plane) keeps every box inside.
  [[nodiscard]] static Frustum from_view_projection(const glm::mat4& view_proj, const ClipSpace& clip = {}) noexcept;

  [[nodiscard]] const Plane& plane(int side) const noexcept { return planes_[side]; }

  /// Classifies a box. Conservative: may answer `intersecting` for a box that
  /// is outside near a frustum corner, never `outside` for a box that overlaps.
  /// A box is `outside` a plane only when it lies beyond it by more than the
  /// rounding of the plane's float arithmetic at the box's coordinates
  /// (a few units in the last place of |n.x x| + |n.y y| + |n.z z| + |d|):
  /// where float precision cannot tell, far from the origin, it is not
  /// outside. An empty box is `outside`.
  /// `plane_mask` selects the planes to test (bit i = plane i); on return it
  /// holds the planes the box still straddles, so children of an
  /// `intersecting` node can skip the planes their parent was fully inside.
  [[nodiscard]] Containment classify(const Aabb& box,
                                     std::uint32_t& plane_mask) const noexcept;
  [[nodiscard]] Containment classify(const Aabb& box) const noexcept {
    std::uint32_t mask = all_planes;
    return classify(box, mask);
  }

 private:
  std::array<Plane, count> planes_{};
};

/// Pixel area that box `b` covers on a `width` x `height` viewport under the
/// combined projection * view matrix: the area of the convex hull of the
/// box's projection, the box first clipped by the near plane (so a box around
/// the eye covers what its near-plane cross-section covers: usually the whole
/// viewport) and the result clipped to the viewport. Units: pixels, in
/// [0, width * height]. Preconditions: width > 0, height > 0.
[[nodiscard]] double projected_area(const Aabb& b, const glm::mat4& view_proj, int width,
                                    int height) noexcept;

/// Convex hull of `points` (Andrew's monotone chain), counter-clockwise,
/// without collinear points, into `out`; returns how many it wrote. Sorts
/// `points` in place. Fewer than 3 points (or all on a line) give at most 2.
/// Precondition: `out` has room for 2 * points.size() points.
std::size_t convex_hull(std::span<glm::dvec2> points, glm::dvec2* out) noexcept;

/// Area of a convex polygon given in order (either winding), by the shoelace
/// formula. Units: those of the points squared.
[[nodiscard]] double polygon_area(std::span<const glm::dvec2> points) noexcept;

}  // namespace occull
