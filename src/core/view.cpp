#include "occull/view.hpp"

#include "occull/error.hpp"
#include "occull/input_limits.hpp"
#include "core/format.hpp"

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

namespace occull {

namespace {

void check_finite(const glm::mat4& m, const char* what) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r]))
        throw InputError(detail::format("{} matrix: entry [column {}][row {}] is {}; every entry must be finite", what,
                                     c, r, m[c][r]));
}

std::string depth_name(const ClipSpace& clip) {
  return detail::format("{} depth{}", clip.depth == DepthRange::zero_to_one ? "[0, 1]" : "[-1, 1]",
                     clip.reversed_z ? ", reversed" : "");
}

}  // namespace

glm::dmat4 eye_relative_projection(const View& view) noexcept {
  return glm::dmat4(view.proj) * glm::dmat4(glm::dmat3(glm::mat3(view.view)));
}

bool holds_no_sample(const Aabb& box, const View& view, const SubpixelRules& rules) noexcept {
  if (view.samples != 1 || box.empty()) return false;  // rule 1
  glm::dvec3 lo(box.min), hi(box.max);
  if (rules.grow_for_rounding) {  // rule 2
    double magnitude = 0.0;
    for (int a = 0; a < 3; ++a) magnitude = std::max({magnitude, std::abs(lo[a]), std::abs(hi[a])});
    const double grow = magnitude * 0x1p-20;
    lo -= grow;
    hi += grow;
  }
  // Rule 3: eye-relative, in double. The corners' clip coordinates by
  // linearity: the low corner's, plus one column of the matrix per axis
  // scaled by the box's size (a few units in the last place of a double
  // from multiplying each corner, far inside the 1/64 pixel margin).
  const glm::dmat4& m = view.eye_projection;  // all zero in a View not made by make_view: every box kept (w = 0)
  const glm::dvec4 low = m * glm::dvec4(lo - glm::dvec3(view.eye), 1.0);
  const glm::dvec3 size = hi - lo;
  const glm::dvec4 along[3] = {m[0] * size.x, m[1] * size.y, m[2] * size.z};
  const double near_depth = double(view.clip.near_depth());
  const double half_w = 0.5 * double(view.width), half_h = 0.5 * double(view.height);
  double min_x = std::numeric_limits<double>::infinity(), max_x = -min_x, min_y = min_x, max_y = -min_x;
  // Adds corner k's pixel position to the rectangle; false when rule 4 keeps the box.
  const auto add_corner = [&](int k) {
    glm::dvec4 c = low;
    if (k & 1) c += along[0];
    if (k & 2) c += along[1];
    if (k & 4) c += along[2];
    // Rule 4: every corner beyond the near plane.
    const bool beyond_near = view.clip.reversed_z ? c.z < c.w : c.z > near_depth * c.w;
    if (!(c.w > 0.0) || !beyond_near) return false;
    const double inv_w = 1.0 / c.w;
    const double x = (c.x * inv_w + 1.0) * half_w, y = (c.y * inv_w + 1.0) * half_h;
    min_x = std::min(min_x, x), max_x = std::max(max_x, x);
    min_y = std::min(min_y, y), max_y = std::max(max_y, y);
    return true;
  };
  const double margin = rules.snapping_margin ? 1.0 / 64.0 : 0.0;
  // Centres lie at k + 0.5, k in [0, size): the rectangle holds one on an
  // axis when the lowest centre at or past its start is at or before its end
  // (rule 5). Both axes must hold one.
  const auto holds_centre = [](double from, double to, int size) {
    const double first = std::max(0.0, std::ceil(from - 0.5));
    return first <= std::min(double(size - 1), std::floor(to - 0.5));
  };
  const auto holds_sample = [&] {
    return holds_centre(min_x - margin, max_x + margin, view.width) &&
           holds_centre(min_y - margin, max_y + margin, view.height);
  };
  // Two opposite corners first: when their rectangle already holds a
  // centre, the other six only grow it (or keep the box by rule 4): kept.
  if (!add_corner(0) || !add_corner(7)) return false;
  if (rules.pixel_centres && holds_sample()) return false;
  for (int k = 1; k < 7; ++k)
    if (!add_corner(k)) return false;
  if (!rules.pixel_centres)  // broken: a size threshold
    return max_x - min_x + 2.0 * margin < 1.0 && max_y - min_y + 2.0 * margin < 1.0;
  return !holds_sample();
}

View make_view(const glm::mat4& view, const glm::mat4& proj, int width, int height, const ClipSpace& clip) {
  limits::check_viewport(width, height, "viewport");
  check_finite(view, "view");
  check_finite(proj, "projection");
  const double view_det = double(glm::determinant(view));
  if (!(std::abs(view_det) > 1e-12) || !std::isfinite(view_det))
    throw InputError(detail::format("view matrix: determinant {} — it cannot be inverted (a camera needs a position and "
                                 "three independent axes)",
                                 view_det));
  const double proj_det = double(glm::determinant(proj));
  if (!(std::abs(proj_det) > 0.0) || !std::isfinite(proj_det))
    throw InputError(detail::format("projection matrix: determinant {} — a singular projection maps space onto a plane",
                                 proj_det));
  // glm is column-major: proj[column][row]. The row that makes w.
  const double w_x = proj[0][3], w_y = proj[1][3], w_z = proj[2][3], w_1 = proj[3][3];
  const bool perspective = w_x == 0.0 && w_y == 0.0 && w_z != 0.0 && w_1 == 0.0;
  const bool orthographic = w_x == 0.0 && w_y == 0.0 && w_z == 0.0 && w_1 != 0.0;
  if (!perspective && !orthographic)
    throw InputError(detail::format("projection matrix: its w row ({}, {}, {}, {}) is neither perspective (w from "
                                 "eye-space z alone, (0, 0, -1, 0)) nor orthographic ((0, 0, 0, 1))",
                                 w_x, w_y, w_z, w_1));
  const double z_z = proj[2][2], z_1 = proj[3][2];
  const double zn = clip.near_depth(), zf = clip.far_depth();
  double near = 0.0, far = 0.0;
  if (perspective) {
    // Normalised depth at clip w = s (in front: s > 0) is z_z / w_z + z_1 / s.
    // The eye distance along the view axis is s / |w_z|.
    const double base = z_z / w_z;
    const auto distance_at = [&](double ndc) {
      const double denominator = ndc - base;
      return denominator == 0.0 ? std::numeric_limits<double>::infinity() : z_1 / denominator / std::abs(w_z);
    };
    near = distance_at(zn);
    far = distance_at(zf);
    if (!(near > 0.0) || !std::isfinite(near))
      throw InputError(detail::format("projection matrix: its near plane (normalised depth {} with {}) lies {} scene "
                                   "units in front of the eye; a perspective view needs it in front (> 0). Are the "
                                   "clip conventions right (--depth, ClipSpace)?",
                                   zn, depth_name(clip), near));
    // Past infinity (an infinite projection with an epsilon): no far plane.
    if (!(far > 0.0) || !std::isfinite(far)) far = std::numeric_limits<double>::infinity();
  } else {
    // Normalised depth is (z_z * z + z_1) / w_1 for eye-space z.
    const auto eye_z = [&](double ndc) { return (ndc * w_1 - z_1) / z_z; };
    const double z_near = eye_z(zn), z_far = eye_z(zf);
    // The view direction is the eye axis along which depth runs from near to far.
    const double forward = z_far > z_near ? 1.0 : -1.0;
    near = forward * z_near;
    far = forward * z_far;
  }
  if (!(far > near))
    throw InputError(detail::format("projection matrix: near {} and far {} scene units with {}: depth must grow from the "
                                 "near plane to the far plane",
                                 near, far, depth_name(clip)));
  View v;
  v.view = view;
  v.proj = proj;
  v.view_proj = proj * view;
  v.clip = clip;
  v.eye = glm::vec3(glm::inverse(view)[3]);
  v.frustum = Frustum::from_view_projection(v.view_proj, clip);
  v.eye_projection = eye_relative_projection(v);
  v.width = width;
  v.height = height;
  v.orthographic = orthographic;
  v.near = float(near);
  v.far = float(far);
  // The near-plane rectangle's corners, back in eye space.
  const glm::mat4 unproject = glm::inverse(proj);
  float radius = 0.0f;
  for (const float x : {-1.0f, 1.0f})
    for (const float y : {-1.0f, 1.0f}) {
      const glm::vec4 p = unproject * glm::vec4(x, y, float(zn), 1.0f);
      radius = std::max(radius, glm::length(glm::vec3(p) / p.w));
    }
  v.near_radius = radius * (1.0f + 1e-5f);  // a hair beyond float rounding: a box closer is visible untested
  return v;
}

glm::mat4 perspective_reversed_infinite(float fov_y, float aspect, float near) noexcept {
  glm::mat4 proj(0.0f);
  const float f = 1.0f / std::tan(fov_y / 2.0f);
  proj[0][0] = f / aspect;
  proj[1][1] = f;
  proj[2][3] = -1.0f;  // w = distance along the view axis
  proj[3][2] = near;   // z = near, so depth = near / distance
  return proj;
}

DepthMode parse_depth_mode(std::string_view name) {
  if (name == "standard") return DepthMode::standard;
  if (name == "reversed") return DepthMode::reversed;
  throw InputError(detail::format("depth mode '{}': must be standard (OpenGL's [-1, 1]) or reversed (reversed-Z in "
                               "[0, 1], infinite far plane)",
                               name));
}

View make_view(const CameraPose& pose, const Lens& lens, int width, int height) {
  limits::check_viewport(width, height, "viewport");
  const glm::vec3& p = pose.position;
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(pose.yaw) ||
      !std::isfinite(pose.pitch))
    throw InputError(detail::format("camera at ({}, {}, {}) with yaw {} and pitch {} rad: every number must be finite",
                                 p.x, p.y, p.z, pose.yaw, pose.pitch));
  if (!(std::abs(pose.pitch) < glm::half_pi<float>()))
    throw InputError(detail::format("camera pitch {} rad: must be within (-pi/2, pi/2)", pose.pitch));
  if (!(lens.fov_y_degrees > 0.0f && lens.fov_y_degrees < 180.0f))
    throw InputError(detail::format("lens field of view {} degrees: must be within (0, 180)", lens.fov_y_degrees));
  if (!(lens.near > 0.0f && lens.far > lens.near && std::isfinite(lens.far)))
    throw InputError(detail::format("lens near {} far {}: needs 0 < near < far < infinity (a near plane of 0 leaves "
                                 "the depth buffer no precision)",
                                 lens.near, lens.far));
  const float cp = std::cos(pose.pitch);
  const glm::vec3 forward(-std::sin(pose.yaw) * cp, std::sin(pose.pitch), -std::cos(pose.yaw) * cp);
  const glm::mat4 view = glm::lookAt(pose.position, pose.position + forward, glm::vec3(0, 1, 0));
  const float aspect = float(width) / float(height);
  View v;
  if (lens.depth == DepthMode::reversed) {
    v = make_view(view, perspective_reversed_infinite(glm::radians(lens.fov_y_degrees), aspect, lens.near), width,
                  height, {DepthRange::zero_to_one, true});
  } else {
    v = make_view(view, glm::perspective(glm::radians(lens.fov_y_degrees), aspect, lens.near, lens.far), width,
                  height);
    v.far = lens.far;  // the lens's own number, free of the matrix's rounding
  }
  v.eye = pose.position;
  v.near = lens.near;
  return v;
}

CameraPath::CameraPath(std::string name, std::string description, std::vector<Key> keys)
    : name_(std::move(name)), description_(std::move(description)), keys_(std::move(keys)) {
  if (keys_.empty()) throw UsageError(detail::format("CameraPath {}: no keys (a path needs one at least)", name_));
}

double CameraPath::duration() const noexcept {
  return keys_.empty() ? 0.0 : keys_.back().time - keys_.front().time;
}

double CameraPath::frame_time(int k, int frames, const FrameSampling& sampling) const noexcept {
  if (keys_.empty()) return 0.0;
  if (sampling.fps > 0.0) return keys_.front().time + sampling.start_s + double(k) / sampling.fps;
  if (frames <= 1) return keys_.front().time;
  return keys_.front().time + duration() * double(k) / double(frames - 1);
}

int CameraPath::frames_that_fit(const FrameSampling& sampling) const noexcept {
  if (!(sampling.fps > 0.0)) return std::numeric_limits<int>::max();
  const double room = duration() - sampling.start_s;
  if (room < 0.0) return 0;
  // A hair of slack so that a path of exactly n / fps seconds fits n + 1 frames.
  return int(std::min(std::floor(room * sampling.fps + 1e-9), 1e9)) + 1;
}

CameraPose CameraPath::sample(double t) const {
  assert(!keys_.empty());
  if (t <= keys_.front().time) return keys_.front().pose;
  if (t >= keys_.back().time) return keys_.back().pose;
  const auto it = std::upper_bound(keys_.begin(), keys_.end(), t,
                                   [](double time, const Key& k) { return time < k.time; });
  const Key& b = *it;
  const Key& a = *(it - 1);
  if (b.cut) return a.pose;  // hold until the jump
  const float f = float((t - a.time) / (b.time - a.time));
  CameraPose p;
  p.position = glm::mix(a.pose.position, b.pose.position, f);
  float dyaw = std::remainder(b.pose.yaw - a.pose.yaw, glm::two_pi<float>());
  p.yaw = a.pose.yaw + dyaw * f;
  p.pitch = glm::mix(a.pose.pitch, b.pose.pitch, f);
  return p;
}

}  // namespace occull
