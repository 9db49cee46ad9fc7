// Helpers shared by the tests: small constructed scenes and a Backend test
// double that answers queries from a known visibility.
#pragma once

#include "occull/backend.hpp"
#include "occull/cost_model.hpp"
#include "occull/culler.hpp"
#include "occull/profile_io.hpp"
#include "occull/scene.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <filesystem>
#include <functional>
#include <optional>
#include <stdexcept>
#include <string>
#include <vector>

namespace occull::test {

/// A fixed NOHC hardware profile (not this machine's), for tests that run nohc.
inline HardwareProfile hardware_profile() {
  HardwareProfile p;
  p.renderer = "test";
  p.width = 100;
  p.height = 100;
  p.draw_setup_ms = 0.01;
  p.triangle_ms = 1e-5;
  p.fragment_ms = {{0, 1e-6}, {10, 11e-6}};
  p.query_setup_ms = 0.02;
  p.query_fragment_ms = 1e-7;
  p.query_latency_ms = 0.2;
  p.query_overhead_ms = 0.005;
  return p;
}

/// hardware_profile() in a file of its own (for --opt nohc.profile=FILE),
/// removed when this goes.
class ProfileFile {
 public:
  explicit ProfileFile(const std::string& name)
      : path_((std::filesystem::temp_directory_path() / name).string()) {
    save_profile(hardware_profile(), path_);
  }
  ~ProfileFile() { std::filesystem::remove(path_); }
  ProfileFile(const ProfileFile&) = delete;
  ProfileFile& operator=(const ProfileFile&) = delete;
  [[nodiscard]] const std::string& path() const noexcept { return path_; }

 private:
  std::string path_;
};

/// A culler context that reads the profile files options name
/// (nohc.profile=FILE), as Session's does.
/// The counter `name` of `culler`'s last frame (Culler::counter); throws
/// when the culler keeps none of that name, so a renamed counter fails.
inline double counter(const Culler& culler, std::string_view name) {
  const std::optional<double> value = culler.counter(name);
  if (!value) throw std::logic_error("the culler has no counter " + std::string(name));
  return *value;
}

inline CullerContext reading_profiles() {
  CullerContext context;
  context.hardware_profile = [](const std::string& file) -> std::optional<HardwareProfile> {
    if (file.empty()) return std::nullopt;  // no device here to calibrate
    return load_profile(file);
  };
  return context;
}

/// `n` boxes of 1-3 x 0.8 x 0.9 units scattered over x in [-11, 14],
/// y in [-6, 7], z in [-50, -5]: in front of a camera at the origin looking
/// down -Z, some overlapping.
inline std::vector<Aabb> scattered_boxes(int n) {
  std::vector<Aabb> boxes;
  for (int i = 0; i < n; ++i) {
    const float x = float((i * 37) % 23) - 11.0f, y = float((i * 11) % 13) - 6.0f;
    const float z = -6.0f - float((i * 7) % 45);
    boxes.push_back({{x, y, z}, {x + 0.7f + float(i % 3), y + 0.8f, z + 0.9f}});
  }
  return boxes;
}

/// A closed box mesh (12 triangles) spanning b, outward CCW faces.
/// A view whose "truth" is a test double's geometry rather than an image
/// sampled at pixel centres: no exact sub-pixel culling (View::samples = 0),
/// so every object in the frustum counts.
inline View unsampled(View view) {
  view.samples = 0;
  return view;
}

inline Mesh box_mesh(const Aabb& b) {
  Mesh m;
  const glm::vec3 n[6] = {{-1, 0, 0}, {1, 0, 0}, {0, -1, 0}, {0, 1, 0}, {0, 0, -1}, {0, 0, 1}};
  for (int f = 0; f < 6; ++f) {
    const int axis = f / 2;
    const bool hi = f % 2;
    const int u = (axis + 1) % 3, v = (axis + 2) % 3;
    glm::vec3 p[4];
    for (int k = 0; k < 4; ++k) {
      glm::vec3 q;
      q[axis] = hi ? b.max[axis] : b.min[axis];
      q[u] = (k == 1 || k == 2) ? b.max[u] : b.min[u];
      q[v] = (k >= 2) ? b.max[v] : b.min[v];
      p[k] = q;
    }
    // (u, v) order is counter-clockwise seen from +axis.
    const auto base = std::uint32_t(m.positions.size());
    for (const auto& q : p) {
      m.positions.push_back(q);
      m.normals.push_back(n[f]);
    }
    if (hi)
      m.indices.insert(m.indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    else
      m.indices.insert(m.indices.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
  }
  return m;
}

/// A scene of axis-aligned boxes, one object (and mesh) each, in order.
inline Scene box_scene(const std::vector<Aabb>& boxes, OccluderClass cls = OccluderClass::always) {
  Scene s("boxes");
  const MaterialId mat = s.add_material({"grey", {0.7f, 0.7f, 0.7f, 1.0f}, false, 0});
  for (const Aabb& b : boxes) s.add_object(s.add_mesh(box_mesh(b)), mat, glm::mat4(1.0f), cls);
  return s;
}

/// Glass pane 10 m down -Z (object 0, translucent), a grey box 20 m down
/// behind it (1, opaque), and a small glass box 40 m down hidden behind the
/// grey one (2, translucent).
inline Scene glass_scene() {
  Scene s("glass");
  const MaterialId glass = s.add_material({"glass", {0.5f, 0.8f, 1.0f, 0.3f}, true, 0});
  const MaterialId grey = s.add_material({"grey", {0.6f, 0.6f, 0.6f, 1.0f}, false, 0});
  s.add_object(s.add_mesh(box_mesh({{-3, -3, -11}, {3, 3, -10}})), glass, glm::mat4(1), OccluderClass::never);
  s.add_object(s.add_mesh(box_mesh({{-1, -1, -21}, {1, 1, -19}})), grey, glm::mat4(1), OccluderClass::always);
  s.add_object(s.add_mesh(box_mesh({{-0.5f, -0.5f, -40}, {0.5f, 0.5f, -39}})), glass, glm::mat4(1),
               OccluderClass::never);
  return s;
}

/// Backend double: records what was rendered and queried; a query's
/// result comes from `visible_samples(boxes)` (default: 1 sample per box)
/// and is available when `available(query)` says so (default: at once).
///
/// It enforces the query contract of occull/backend.hpp and throws
/// std::logic_error, failing the test loudly, for a query read twice, read
/// or polled after it was read, or that this backend never issued (one of
/// another device: give two backends different `first_id`s to tell them
/// apart). in_flight() counts the queries issued and never read.
class ScriptedBackend final : public Backend {
 public:
  /// Query ids start at `first_id`: query q is queried[q - first_id].
  explicit ScriptedBackend(QueryId first_id = 0) : first_id_(first_id) {}

  std::function<std::uint64_t(std::span<const Aabb>)> visible_samples =
      [](std::span<const Aabb> b) { return std::uint64_t(b.size()); };
  std::function<bool(QueryId)> available = [](QueryId) { return true; };
  std::vector<ObjectId> rendered;
  std::vector<std::vector<Aabb>> queried;
  /// With conditional rendering on, render_conditional() records its
  /// objects here as well as in `rendered`, with the query they depend on.
  bool conditional = false;
  std::vector<std::pair<ObjectId, QueryId>> rendered_conditionally;

  void render(std::span<const ObjectId> objects) override {
    rendered.insert(rendered.end(), objects.begin(), objects.end());
    ++stats_.render_flushes;
    stats_.draw_calls += objects.size();
  }
  [[nodiscard]] bool conditional_rendering() const override { return conditional; }
  void render_conditional(std::span<const ObjectId> objects, QueryId q, ConditionalWait wait) override {
    check_in_flight(q, "render_conditional");
    if (!conditional) return Backend::render_conditional(objects, q, wait);
    for (ObjectId id : objects) rendered_conditionally.emplace_back(id, q);
    render(objects);
  }
  QueryId issue_query(std::span<const Aabb> boxes) override {
    if (boxes.empty()) throw std::logic_error("ScriptedBackend::issue_query: no boxes");
    queried.emplace_back(boxes.begin(), boxes.end());
    results_.push_back(visible_samples(boxes));
    live_.push_back(1);
    ++in_flight_;
    ++stats_.queries;
    return first_id_ + QueryId(results_.size() - 1);
  }
  bool result_available(QueryId q) override {
    check_in_flight(q, "result_available");
    return available(q);
  }
  std::uint64_t result(QueryId q) override {
    check_in_flight(q, "result");
    live_[q - first_id_] = 0;
    --in_flight_;
    read.push_back(q);
    return results_[q - first_id_];
  }
  [[nodiscard]] BackendStats stats() const override { return stats_; }
  std::vector<QueryId> read;  ///< queries whose result() was called, in order
  /// Queries issued and not yet read.
  [[nodiscard]] std::size_t in_flight() const noexcept { return in_flight_; }

 private:
  void check_in_flight(QueryId q, const char* call) const {
    if (q < first_id_ || q - first_id_ >= live_.size())
      throw std::logic_error("ScriptedBackend::" + std::string(call) + ": query " + std::to_string(q) +
                             " was never issued by this backend");
    if (!live_[q - first_id_])
      throw std::logic_error("ScriptedBackend::" + std::string(call) + ": query " + std::to_string(q) +
                             " was read already");
  }

  QueryId first_id_;
  std::vector<std::uint64_t> results_;
  std::vector<std::uint8_t> live_;
  std::size_t in_flight_ = 0;
  BackendStats stats_;
};

}  // namespace occull::test
