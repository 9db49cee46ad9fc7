#include "mesh_builder.hpp"

#include <glm/gtc/constants.hpp>

#include <cmath>

namespace occull::scenes {

void MeshBuilder::triangle(const glm::vec3& a, const glm::vec3& b, const glm::vec3& c,
                           const glm::vec3& normal) {
  const auto base = std::uint32_t(mesh_.positions.size());
  const bool ccw = glm::dot(glm::cross(b - a, c - a), normal) >= 0.0f;
  mesh_.positions.insert(mesh_.positions.end(), {a, ccw ? b : c, ccw ? c : b});
  const glm::vec3 n = glm::normalize(normal);
  mesh_.normals.insert(mesh_.normals.end(), {n, n, n});
  mesh_.indices.insert(mesh_.indices.end(), {base, base + 1, base + 2});
}

void MeshBuilder::quad(const glm::vec3& p0, const glm::vec3& p1, const glm::vec3& p2,
                       const glm::vec3& p3, const glm::vec3& normal) {
  const auto base = std::uint32_t(mesh_.positions.size());
  const bool ccw = glm::dot(glm::cross(p1 - p0, p2 - p0), normal) >= 0.0f;
  if (ccw)
    mesh_.positions.insert(mesh_.positions.end(), {p0, p1, p2, p3});
  else
    mesh_.positions.insert(mesh_.positions.end(), {p0, p3, p2, p1});
  const glm::vec3 n = glm::normalize(normal);
  mesh_.normals.insert(mesh_.normals.end(), {n, n, n, n});
  mesh_.indices.insert(mesh_.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
}

void MeshBuilder::box(const Aabb& b, unsigned faces) {
  const glm::vec3 lo = b.min, hi = b.max;
  if (faces & neg_x)
    quad({lo.x, lo.y, lo.z}, {lo.x, hi.y, lo.z}, {lo.x, hi.y, hi.z}, {lo.x, lo.y, hi.z}, {-1, 0, 0});
  if (faces & pos_x)
    quad({hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, hi.y, hi.z}, {hi.x, lo.y, hi.z}, {1, 0, 0});
  if (faces & neg_y)
    quad({lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, lo.y, hi.z}, {lo.x, lo.y, hi.z}, {0, -1, 0});
  if (faces & pos_y)
    quad({lo.x, hi.y, lo.z}, {hi.x, hi.y, lo.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}, {0, 1, 0});
  if (faces & neg_z)
    quad({lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z}, {0, 0, -1});
  if (faces & pos_z)
    quad({lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}, {0, 0, 1});
}

void MeshBuilder::prism(const glm::vec3& c, float radius, float height, int sides,
                        bool bottom_cap) {
  const float step = glm::two_pi<float>() / float(sides);
  const glm::vec3 top(c.x, c.y + height, c.z);
  for (int i = 0; i < sides; ++i) {
    const float a0 = step * float(i), a1 = step * float(i + 1);
    const glm::vec3 d0(std::cos(a0), 0, std::sin(a0)), d1(std::cos(a1), 0, std::sin(a1));
    const glm::vec3 p0 = c + radius * d0, p1 = c + radius * d1;
    const glm::vec3 up(0, height, 0);
    quad(p0, p1, p1 + up, p0 + up, glm::normalize(d0 + d1));
    triangle(top, p0 + up, p1 + up, {0, 1, 0});
    if (bottom_cap) triangle(c, p0, p1, {0, -1, 0});
  }
}

void MeshBuilder::cylinder_z(const glm::vec3& s, float radius, float length, int sides) {
  const float step = glm::two_pi<float>() / float(sides);
  const glm::vec3 e(s.x, s.y, s.z + length);
  for (int i = 0; i < sides; ++i) {
    const float a0 = step * float(i), a1 = step * float(i + 1);
    const glm::vec3 d0(std::cos(a0), std::sin(a0), 0), d1(std::cos(a1), std::sin(a1), 0);
    quad(s + radius * d0, s + radius * d1, e + radius * d1, e + radius * d0, glm::normalize(d0 + d1));
    triangle(s, s + radius * d0, s + radius * d1, {0, 0, -1});
    triangle(e, e + radius * d0, e + radius * d1, {0, 0, 1});
  }
}

void MeshBuilder::cone(const glm::vec3& c, float radius, float height, int sides) {
  const float step = glm::two_pi<float>() / float(sides);
  const glm::vec3 apex(c.x, c.y + height, c.z);
  for (int i = 0; i < sides; ++i) {
    const float a0 = step * float(i), a1 = step * float(i + 1);
    const glm::vec3 p0 = c + radius * glm::vec3(std::cos(a0), 0, std::sin(a0));
    const glm::vec3 p1 = c + radius * glm::vec3(std::cos(a1), 0, std::sin(a1));
    const glm::vec3 mid = 0.5f * (p0 + p1) - c;
    const glm::vec3 n = glm::normalize(glm::vec3(mid.x * height, radius * radius, mid.z * height));
    triangle(p0, p1, apex, n);
    triangle(c, p0, p1, {0, -1, 0});
  }
}

void MeshBuilder::gable(const Aabb& f, float ridge_height, bool along_x) {
  const float y0 = f.max.y, y1 = f.max.y + ridge_height;
  if (along_x) {
    const float zm = 0.5f * (f.min.z + f.max.z);
    const float half = 0.5f * (f.max.z - f.min.z);
    const glm::vec3 n0 = glm::normalize(glm::vec3(0, half, -ridge_height));
    const glm::vec3 n1 = glm::normalize(glm::vec3(0, half, ridge_height));
    quad({f.min.x, y0, f.min.z}, {f.max.x, y0, f.min.z}, {f.max.x, y1, zm}, {f.min.x, y1, zm}, n0);
    quad({f.min.x, y0, f.max.z}, {f.max.x, y0, f.max.z}, {f.max.x, y1, zm}, {f.min.x, y1, zm}, n1);
    triangle({f.min.x, y0, f.min.z}, {f.min.x, y0, f.max.z}, {f.min.x, y1, zm}, {-1, 0, 0});
    triangle({f.max.x, y0, f.min.z}, {f.max.x, y0, f.max.z}, {f.max.x, y1, zm}, {1, 0, 0});
  } else {
    const float xm = 0.5f * (f.min.x + f.max.x);
    const float half = 0.5f * (f.max.x - f.min.x);
    const glm::vec3 n0 = glm::normalize(glm::vec3(-ridge_height, half, 0));
    const glm::vec3 n1 = glm::normalize(glm::vec3(ridge_height, half, 0));
    quad({f.min.x, y0, f.min.z}, {f.min.x, y0, f.max.z}, {xm, y1, f.max.z}, {xm, y1, f.min.z}, n0);
    quad({f.max.x, y0, f.min.z}, {f.max.x, y0, f.max.z}, {xm, y1, f.max.z}, {xm, y1, f.min.z}, n1);
    triangle({f.min.x, y0, f.min.z}, {f.max.x, y0, f.min.z}, {xm, y1, f.min.z}, {0, 0, -1});
    triangle({f.min.x, y0, f.max.z}, {f.max.x, y0, f.max.z}, {xm, y1, f.max.z}, {0, 0, 1});
  }
}

CameraPath::Key look_at_key(double t, const glm::vec3& eye, const glm::vec3& target) {
  const glm::vec3 d = target - eye;
  const float yaw = std::atan2(-d.x, -d.z);
  const float pitch = std::atan2(d.y, std::sqrt(d.x * d.x + d.z * d.z));
  return {t, {eye, yaw, pitch}, false};
}

}  // namespace occull::scenes
