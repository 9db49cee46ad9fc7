#include "occull/geometry.hpp"

#include <algorithm>
#include <cmath>
#include <array>

namespace occull {

float Aabb::volume() const noexcept {
  if (empty()) return 0.0f;
  const glm::vec3 e = extent();
  return e.x * e.y * e.z;
}

Aabb transform_box(const Aabb& b, const glm::mat4& m) noexcept {
  // Arvo's method: each output axis is the sum of the extremes of the
  // products of one matrix row with the box interval.
  if (b.empty()) return {};  // infinities times zero entries would make NaN, or a box of everything
  Aabb out;
  const glm::vec3 t(m[3]);
  out.min = t;
  out.max = t;
  for (int col = 0; col < 3; ++col) {
    for (int row = 0; row < 3; ++row) {
      const float a = m[col][row] * b.min[col];
      const float c = m[col][row] * b.max[col];
      out.min[row] += std::min(a, c);
      out.max[row] += std::max(a, c);
    }
  }
  return out;
}

float distance_squared(const glm::vec3& p, const Aabb& b) noexcept {
  const glm::vec3 q = p - glm::clamp(p, b.min, b.max);
  return glm::dot(q, q);
}

float distance(const glm::vec3& p, const Aabb& b) noexcept { return std::sqrt(distance_squared(p, b)); }

Plane Plane::from_coefficients(const glm::vec4& abcd) noexcept {
  const glm::vec3 n(abcd);
  const float len = glm::length(n);
  return Plane{n / len, abcd.w / len};
}

Frustum Frustum::from_view_projection(const glm::mat4& m, const ClipSpace& clip) noexcept {
  const auto row = [&m](int i) { return glm::vec4(m[0][i], m[1][i], m[2][i], m[3][i]); };
  // A plane whose normal vanishes next to its offset lies at infinity (the
  // far plane of an infinite projection): nothing is outside it.
  const auto plane = [](const glm::vec4& abcd) {
    const float len = glm::length(glm::vec3(abcd));
    if (!(len > 1e-6f * std::abs(abcd.w))) return Plane{glm::vec3(0.0f), 1.0f};
    return Plane::from_coefficients(abcd);
  };
  // Clip space keeps -w <= x, y <= w and lo <= z <= w, where lo is -w for
  // depth in [-1, 1] and 0 for depth in [0, 1]. Reversed-Z swaps which of
  // the two depth bounds is the near plane.
  const glm::vec4 z_low = clip.depth == DepthRange::zero_to_one ? row(2) : row(3) + row(2);
  const glm::vec4 z_high = row(3) - row(2);
  Frustum f;
  f.planes_[left] = plane(row(3) + row(0));
  f.planes_[right] = plane(row(3) - row(0));
  f.planes_[bottom] = plane(row(3) + row(1));
  f.planes_[top] = plane(row(3) - row(1));
  f.planes_[near] = plane(clip.reversed_z ? z_high : z_low);
  f.planes_[far] = plane(clip.reversed_z ? z_low : z_high);
  return f;
}

Containment Frustum::classify(const Aabb& box, std::uint32_t& plane_mask) const noexcept {
  if (box.empty()) return Containment::outside;  // nothing to see (an object without triangles)
  for (int i = 0; i < count; ++i) {
    const std::uint32_t bit = 1u << i;
    if (!(plane_mask & bit)) continue;
    const Plane& p = planes_[i];
    // The corner farthest along the normal decides "outside"; the nearest
    // one decides "fully inside this plane".
    const glm::vec3 far_corner(p.n.x >= 0 ? box.max.x : box.min.x,
                               p.n.y >= 0 ? box.max.y : box.min.y,
                               p.n.z >= 0 ? box.max.z : box.min.z);
    const float beyond = p.signed_distance(far_corner);
    if (beyond < 0.0f) {
      // Outside only past the rounding of that sum (8 float units in the last
      // place of its largest possible term): undecidable is not outside.
      const float scale = std::abs(p.n.x * far_corner.x) + std::abs(p.n.y * far_corner.y) +
                          std::abs(p.n.z * far_corner.z) + std::abs(p.d);
      if (beyond < -8.0f * std::numeric_limits<float>::epsilon() * scale) return Containment::outside;
    }
    const glm::vec3 near_corner(p.n.x >= 0 ? box.min.x : box.max.x,
                                p.n.y >= 0 ? box.min.y : box.max.y,
                                p.n.z >= 0 ? box.min.z : box.max.z);
    if (p.signed_distance(near_corner) >= 0.0f) plane_mask &= ~bit;
  }
  return plane_mask == 0 ? Containment::inside : Containment::intersecting;
}

double polygon_area(std::span<const glm::dvec2> pts) noexcept {
  double twice = 0.0;
  for (std::size_t i = 0, n = pts.size(); i < n; ++i) {
    const glm::dvec2& a = pts[i];
    const glm::dvec2& b = pts[(i + 1) % n];
    twice += a.x * b.y - b.x * a.y;
  }
  return std::abs(twice) * 0.5;
}

std::size_t convex_hull(std::span<glm::dvec2> pts, glm::dvec2* out) noexcept {
  const auto cross = [](const glm::dvec2& o, const glm::dvec2& a, const glm::dvec2& b) {
    return (a.x - o.x) * (b.y - o.y) - (a.y - o.y) * (b.x - o.x);
  };
  std::sort(pts.begin(), pts.end(),
            [](const glm::dvec2& a, const glm::dvec2& b) { return a.x < b.x || (a.x == b.x && a.y < b.y); });
  const std::size_t n = pts.size();
  if (n < 3) {
    std::copy(pts.begin(), pts.end(), out);
    return n;
  }
  std::size_t k = 0;
  for (std::size_t i = 0; i < n; ++i) {
    while (k >= 2 && cross(out[k - 2], out[k - 1], pts[i]) <= 0) --k;
    out[k++] = pts[i];
  }
  for (std::size_t i = n - 1, lower = k + 1; i-- > 0;) {
    while (k >= lower && cross(out[k - 2], out[k - 1], pts[i]) <= 0) --k;
    out[k++] = pts[i];
  }
  return k - 1;  // the last point repeats the first
}

namespace {

// At most 8 corners plus 12 near-plane crossings; each of the four screen
// edges adds at most one vertex to a convex polygon.
constexpr std::size_t kMaxPoints = 24;
struct Polygon {
  std::array<glm::dvec2, kMaxPoints> p;
  std::size_t n = 0;
  void push(const glm::dvec2& v) noexcept {
    if (n < kMaxPoints) p[n++] = v;
  }
};

Polygon convex_hull(Polygon pts) noexcept {
  std::array<glm::dvec2, 2 * kMaxPoints> hull;
  const std::size_t k = occull::convex_hull(std::span<glm::dvec2>(pts.p.data(), pts.n), hull.data());
  Polygon out;
  for (std::size_t i = 0; i < k; ++i) out.push(hull[i]);
  return out;
}

// Sutherland–Hodgman against one axis-aligned half-plane: keeps points whose
// coordinate `axis` is >= bound (sign = +1) or <= bound (sign = -1).
Polygon clip_half_plane(const Polygon& poly, int axis, double bound, double sign) noexcept {
  Polygon out;
  for (std::size_t i = 0; i < poly.n; ++i) {
    const glm::dvec2& a = poly.p[i];
    const glm::dvec2& b = poly.p[(i + 1) % poly.n];
    const double da = sign * (a[axis] - bound);
    const double db = sign * (b[axis] - bound);
    if (da >= 0) out.push(a);
    if ((da >= 0) != (db >= 0)) out.push(a + (b - a) * (da / (da - db)));
  }
  return out;
}

}  // namespace

double projected_area(const Aabb& b, const glm::mat4& view_proj, int width, int height) noexcept {
  if (b.empty() || width <= 0 || height <= 0) return 0.0;
  static constexpr int edges[12][2] = {{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                       {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}};
  std::array<glm::dvec4, 8> clip;
  for (int i = 0; i < 8; ++i) clip[i] = glm::dvec4(view_proj * glm::vec4(b.corner(i), 1.0f));
  // Distance to the near plane in clip space is z + w (OpenGL conventions).
  const auto near_dist = [](const glm::dvec4& c) { return c.z + c.w; };

  Polygon pts;
  const auto add = [&](const glm::dvec4& c) {
    const glm::dvec2 ndc(c.x / c.w, c.y / c.w);
    pts.push({(ndc.x * 0.5 + 0.5) * width, (ndc.y * 0.5 + 0.5) * height});
  };
  bool crosses_near = false;
  for (const auto& c : clip) {
    if (near_dist(c) >= 0 && c.w > 0)
      add(c);
    else
      crosses_near = true;
  }
  if (crosses_near) {
    for (const auto& e : edges) {
      const glm::dvec4& a = clip[e[0]];
      const glm::dvec4& c = clip[e[1]];
      const double da = near_dist(a), dc = near_dist(c);
      if ((da >= 0) != (dc >= 0)) {
        const glm::dvec4 p = a + (c - a) * (da / (da - dc));
        if (p.w > 0) add(p);
      }
    }
  }
  if (pts.n < 3) return 0.0;
  Polygon poly = convex_hull(pts);
  // Clip to the screen only at the sides the outline crosses.
  glm::dvec2 lo = poly.p[0], hi = poly.p[0];
  for (std::size_t i = 1; i < poly.n; ++i) {
    lo = glm::min(lo, poly.p[i]);
    hi = glm::max(hi, poly.p[i]);
  }
  if (lo.x < 0.0) poly = clip_half_plane(poly, 0, 0.0, 1.0);
  if (hi.x > double(width)) poly = clip_half_plane(poly, 0, double(width), -1.0);
  if (lo.y < 0.0) poly = clip_half_plane(poly, 1, 0.0, 1.0);
  if (hi.y > double(height)) poly = clip_half_plane(poly, 1, double(height), -1.0);
  if (poly.n < 3) return 0.0;
  return polygon_area(std::span<const glm::dvec2>(poly.p.data(), poly.n));
}

}  // namespace occull
