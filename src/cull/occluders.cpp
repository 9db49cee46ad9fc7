#include "occluders.hpp"

#include "occull/error.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>

namespace occull::detail {

Occluders::Occluders(const Scene& scene, const OccluderChoice& choice) : scene_(scene), choice_(choice) {
  for (const Object& o : scene.objects())
    if (o.occluder != OccluderClass::never && !o.removed) (void)occluder_of(o.mesh);
}

void Occluders::begin_frame(const View& view, const OcclusionBuffer& buffer) {
  // Texels per scene unit of radius at unit distance (orthographic: at any distance).
  texel_scale_ = std::abs(double(view.proj[1][1])) * 0.5 * double(buffer.height());
  sometimes_left_ = std::uint64_t(choice_.budget);
  resting_ = 0;
  if (!learns()) return;
  if (!buffer.tracks_sources()) throw UsageError("Occluders: rest needs a buffer that tracks sources");
  if (++frame_ == 0) {  // wrapped: every occluder starts afresh
    std::fill(useful_.begin(), useful_.end(), 0u);
    std::fill(met_.begin(), met_.end(), 0u);
    frame_ = 2;
  }
  useful_.resize(scene_.objects().size(), 0);
  met_.resize(scene_.objects().size(), 0);
}

bool Occluders::learns() {
  if (choice_.rest == 0) return false;
  const std::span<const Object> objects = scene_.objects();
  for (; restable_checked_ < objects.size() && !restable_; ++restable_checked_) {
    const Object& o = objects[restable_checked_];
    restable_ = o.occluder != OccluderClass::never && o.triangles >= std::uint64_t(choice_.rest_triangles);
  }
  return restable_;
}

bool Occluders::rests(ObjectId id) {
  if (!restable_ || scene_.object(id).triangles < std::uint64_t(choice_.rest_triangles)) return false;
  std::uint32_t& useful = useful_[id];
  // Met twice a frame: by soc's prepass, resting, then by its walk.
  const bool again = met_[id] == frame_;
  if (!again && met_[id] + 1 != frame_) useful = frame_;  // back in view, or new: a fresh trial
  met_[id] = frame_;
  const auto rest = std::uint32_t(choice_.rest);
  const std::uint32_t idle = frame_ - useful;
  if (idle <= rest) return false;
  // Tried again one frame in `period`: `rest`, doubled while it finds nothing, up to 8 × rest.
  std::uint32_t period = rest;
  while (period < 8 * rest && idle >= 2 * period) period *= 2;
  if ((frame_ + id) % period == 0) return false;
  if (!again) ++resting_;
  return true;
}

bool Occluders::hidden(OcclusionBuffer& buffer, const Aabb& box, const glm::mat4& view_proj,
                       BufferCounters& counters) {
  if (!restable_) return test_box(buffer, box, view_proj, counters);
  tags_.clear();
  if (!test_box(buffer, box, view_proj, counters, &tags_)) return false;
  for (const std::uint32_t tag : tags_)
    if (tag < useful_.size()) useful_[tag] = frame_;
  return true;
}

std::optional<OcclusionBuffer::OccluderDraw> Occluders::occluder_draw(ObjectId id, const Aabb& bounds,
                                                                       const View& view) {
  // How many texels across the box's bounding sphere spans: a smaller
  // occluder covers next to no texel whole (rule 3), and costs its polygons.
  const double radius = 0.5 * double(glm::length(bounds.extent()));
  const double distance = view.orthographic ? 1.0 : std::max(double(glm::length(bounds.center() - view.eye)), 1e-6);
  if (2.0 * radius * texel_scale_ / distance < choice_.min_texels) return std::nullopt;
  const Object& o = scene_.object(id);
  if (o.removed || o.occluder == OccluderClass::never || scene_.material(o.material).translucent) return std::nullopt;
  const Mesh& mesh = scene_.mesh(o.mesh);
  if (mesh.positions.empty()) return std::nullopt;  // the engine keeps its vertices: nothing to rasterize
  if (rests(id)) return std::nullopt;
  if (o.occluder == OccluderClass::sometimes) {
    if (o.triangles > sometimes_left_) return std::nullopt;
    sometimes_left_ -= o.triangles;
  }
  return OcclusionBuffer::OccluderDraw{mesh.positions, &occluder_of(o.mesh), o.transform, o.bounds, id};
}

bool Occluders::rasterize_if_occluder(OcclusionBuffer& buffer, ObjectId id, const Aabb& bounds, const View& view,
                                      BufferCounters& counters) {
  const std::optional<OcclusionBuffer::OccluderDraw> draw = occluder_draw(id, bounds, view);
  if (!draw) return false;
  const auto start = std::chrono::steady_clock::now();
  buffer.set_source(draw->source);
  counters.occluder_triangles += buffer.rasterize(draw->positions, *draw->mesh, view, draw->object_to_world, draw->bounds);
  counters.raster_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return true;
}

void Occluders::rasterize(OcclusionBuffer& buffer, std::span<const OcclusionBuffer::OccluderDraw> draws,
                          const View& view, BufferCounters& counters) {
  const auto start = std::chrono::steady_clock::now();
  counters.occluder_triangles += buffer.rasterize(draws, view);
  counters.raster_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
}

bool test_box(OcclusionBuffer& buffer, const Aabb& box, const glm::mat4& view_proj, BufferCounters& counters,
              std::vector<std::uint32_t>* sources) {
  if (counters.boxes_tested++ % kTestsPerTimedTest != 0) return buffer.occluded(box, view_proj, sources);
  const auto start = std::chrono::steady_clock::now();
  const bool out = buffer.occluded(box, view_proj, sources);
  counters.test_ms += double(kTestsPerTimedTest) *
                      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
  return out;
}

const OccluderMesh& Occluders::occluder_of(MeshId mesh) {
  if (meshes_.size() <= mesh) meshes_.resize(std::size_t(mesh) + 1);
  if (!meshes_[mesh]) {
    const Mesh& m = scene_.mesh(mesh);
    meshes_[mesh] = make_occluder_mesh(m.positions, m.indices, choice_.detail);
  }
  return *meshes_[mesh];
}

}  // namespace occull::detail
