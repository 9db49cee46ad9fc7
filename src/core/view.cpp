#include "occull/view.hpp"

#include "occull/error.hpp"
#include "occull/input_limits.hpp"

#include <fmt/format.h>
#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <limits>

namespace occull {

View make_view(const CameraPose& pose, const Lens& lens, int width, int height) {
  limits::check_viewport(width, height, "viewport");
  const glm::vec3& p = pose.position;
  if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z) || !std::isfinite(pose.yaw) ||
      !std::isfinite(pose.pitch))
    throw InputError(fmt::format("camera at ({}, {}, {}) with yaw {} and pitch {} rad: every number must be finite",
                                 p.x, p.y, p.z, pose.yaw, pose.pitch));
  if (!(std::abs(pose.pitch) < glm::half_pi<float>()))
    throw InputError(fmt::format("camera pitch {} rad: must be within (-pi/2, pi/2)", pose.pitch));
  if (!(lens.fov_y_degrees > 0.0f && lens.fov_y_degrees < 180.0f))
    throw InputError(fmt::format("lens field of view {} degrees: must be within (0, 180)", lens.fov_y_degrees));
  if (!(lens.near > 0.0f && lens.far > lens.near && std::isfinite(lens.far)))
    throw InputError(fmt::format("lens near {} far {}: needs 0 < near < far < infinity (a near plane of 0 leaves "
                                 "the depth buffer no precision)",
                                 lens.near, lens.far));
  View v;
  v.eye = pose.position;
  const float cp = std::cos(pose.pitch);
  const glm::vec3 forward(-std::sin(pose.yaw) * cp, std::sin(pose.pitch), -std::cos(pose.yaw) * cp);
  v.view = glm::lookAt(pose.position, pose.position + forward, glm::vec3(0, 1, 0));
  v.proj = glm::perspective(glm::radians(lens.fov_y_degrees), float(width) / float(height),
                            lens.near, lens.far);
  v.view_proj = v.proj * v.view;
  v.frustum = Frustum::from_view_projection(v.view_proj);
  v.width = width;
  v.height = height;
  v.near = lens.near;
  v.far = lens.far;
  return v;
}

float near_plane_radius(const View& view) {
  // proj[0][0] = 1 / (aspect * tan(fov/2)), proj[1][1] = 1 / tan(fov/2).
  const float half_w = view.near / view.proj[0][0];
  const float half_h = view.near / view.proj[1][1];
  return std::sqrt(view.near * view.near + half_w * half_w + half_h * half_h);
}

CameraPath::CameraPath(std::string name, std::string description, std::vector<Key> keys)
    : name_(std::move(name)), description_(std::move(description)), keys_(std::move(keys)) {
  assert(!keys_.empty());
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
