// An engine's use of the culling core alone: its own meshes (bounds only),
// its own Backend, chcpp over ten frames. Exits 1 when the culler misses a
// visible object or culls nothing, 0 when it draws exactly what is visible.
#include <occull/bvh.hpp>
#include <occull/culler.hpp>

#include <cstdio>
#include <set>
#include <vector>

namespace {

// Behind this plane (z below it) the wall hides everything: the engine's
// stand-in for a depth test, answering queries on the CPU.
constexpr float kWallBack = -19.0f;
constexpr int kFrames = 10;

class EngineBackend final : public occull::Backend {
 public:
  std::set<occull::ObjectId> drawn;

  void render(std::span<const occull::ObjectId> objects) override {
    drawn.insert(objects.begin(), objects.end());
    stats_.draw_calls += objects.size();
    stats_.objects_rendered += objects.size();
    ++stats_.render_flushes;
  }
  occull::QueryId issue_query(std::span<const occull::Aabb> boxes) override {
    std::uint64_t samples = 0;
    for (const occull::Aabb& b : boxes) samples += b.max.z >= kWallBack ? 1 : 0;
    results_.push_back(samples);
    ++stats_.queries;
    return occull::QueryId(results_.size() - 1);
  }
  bool result_available(occull::QueryId) override { return true; }
  std::uint64_t result(occull::QueryId q) override { return results_[q]; }
  [[nodiscard]] occull::BackendStats stats() const override { return stats_; }

 private:
  std::vector<std::uint64_t> results_;
  occull::BackendStats stats_;
};

occull::MeshId box_mesh(occull::Scene& scene, const occull::Aabb& box) {
  const glm::vec3 d = box.max - box.min;
  // A crate of the engine's: 2,000 triangles (a mesh of a dozen would be drawn with its
  // neighbours as one "virtual leaf" of the hierarchy, Bittner et al. 2009).
  return scene.add_mesh(occull::MeshInfo{box, 2000, 2.0 * (d.x * d.y + d.y * d.z + d.z * d.x)});
}

}  // namespace

int main() {
  occull::Scene scene("engine");
  const occull::MaterialId grey = scene.add_material({"grey", {0.6f, 0.6f, 0.6f, 1.0f}, false, 0});
  std::set<occull::ObjectId> visible;
  // The wall, and ten crates before it: visible.
  visible.insert(scene.add_object(box_mesh(scene, {{-60, -20, -20}, {60, 20, kWallBack}}), grey, glm::mat4(1.0f),
                                  occull::OccluderClass::always));
  for (int i = 0; i < 10; ++i) {
    const float x = -5.0f + float(i);
    visible.insert(scene.add_object(box_mesh(scene, {{x, -1, -12}, {x + 0.8f, 1, -10}}), grey, glm::mat4(1.0f),
                                    occull::OccluderClass::never));
  }
  // Forty crates behind it: hidden.
  for (int i = 0; i < 40; ++i) {
    const float x = -20.0f + float(i);
    (void)scene.add_object(box_mesh(scene, {{x, -1, -42}, {x + 0.5f, 1, -40}}), grey, glm::mat4(1.0f),
                           occull::OccluderClass::never);
  }
  const occull::Bvh bvh = occull::Bvh::build(scene);
  auto culler = occull::make_culler("chcpp", {scene, bvh});

  occull::View view = occull::make_view(occull::CameraPose{{0, 0, 0}, 0, 0}, {70.0f, 0.1f, 500.0f}, 64, 64);
  view.samples = 0;  // the backend's "depth test" is geometric: no sub-pixel culling
  EngineBackend backend;
  for (int frame = 0; frame < kFrames; ++frame) {
    backend.drawn.clear();
    (void)culler->render_frame(view, backend);
  }
  int missed = 0;
  for (occull::ObjectId id : visible) missed += backend.drawn.count(id) ? 0 : 1;
  const std::size_t hidden_drawn = backend.drawn.size() - (visible.size() - std::size_t(missed));
  std::printf("core consumer: %zu objects, %zu visible, chcpp drew %zu (missed %d, hidden drawn %zu)\n",
              scene.objects().size(), visible.size(), backend.drawn.size(), missed, hidden_drawn);
  return missed == 0 && hidden_drawn == 0 ? 0 : 1;
}
