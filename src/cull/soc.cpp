// `soc`: software occlusion culling with a strictly conservative CPU
// occlusion buffer (occull/occlusion_buffer.hpp), no queries at all.
//
// Each frame the buffer is cleared and the BVH is walked front to back
// (nearest node box first). A node outside the frustum, or whose box the
// buffer proves hidden, is skipped with its subtree. Each object of a leaf
// reached is tested the same way; an object that passes is queued to be
// drawn and, if it is an occluder worth rasterizing, rasterized at once so
// that it hides what lies behind it from the nodes met later. Occluders:
// opaque objects of class `always`, and of class `sometimes` while the
// frame's budget of their triangles lasts, whose mesh has vertices on the
// CPU (a mesh an engine registered by MeshInfo only never occludes) and that
// span at least a couple of texels. Of an occluder, only the triangles that
// could cover a texel whole from this distance are rasterized (their
// inscribed circle, magnified as much as the lens can, reaches half a
// texel; OccluderMesh): skipping a triangle never hides anything. Everything rasterized is drawn in the
// same frame (it passed its own test first), so a box the buffer hides is
// hidden on screen: the culler is conservative exactly when the buffer is.
// The queue is drawn in one render-queue flush at the end.
#include "cullers.hpp"
#include "traversal.hpp"

#include "occull/occlusion_buffer.hpp"

#include <chrono>
#include <cmath>
#include <optional>

namespace occull::detail {
namespace {

struct SocConfig {
  int scale = 4;        // buffer = viewport / scale on each axis
  int width = 0;        // explicit buffer size (0: from scale)
  int height = 0;
  int budget = 20000;   // triangles of `sometimes` occluders per frame
  double min_texels = 2.0;  // occluders whose box spans fewer texels across are not rasterized
  bool simd = true;
};

using Clock = std::chrono::steady_clock;
double ms_since(Clock::time_point t) { return std::chrono::duration<double, std::milli>(Clock::now() - t).count(); }

class SocCuller final : public Culler {
 public:
  // Prepares the occluders' meshes now rather than in a frame (a mesh added
  // later is prepared when first rasterized).
  SocCuller(const SceneIndex& index, const SocConfig& config) : index_(index), config_(config) {
    for (const Object& o : index.scene.objects())
      if (o.occluder != OccluderClass::never && !o.removed) (void)occluder_of(o.mesh);
  }

  FrameStats cull(const View& view, Backend& backend) override {
    FrameStats stats;
    OcclusionBuffer& buffer = buffer_for(view);
    buffer.clear(view.clip);
    stats.buffer_texels = std::uint64_t(buffer.width()) * std::uint64_t(buffer.height());
    queue_.clear();
    frustum_.begin(index_.bvh, view);
    const Bvh& bvh = index_.bvh;
    const Scene& scene = index_.scene;
    // Texels per scene unit of radius at unit distance (orthographic: at any distance).
    texel_scale_ = std::abs(view.proj[1][1]) * 0.5 * double(buffer.height());
    // The most a length at view depth z can grow on the buffer: texels per
    // unit at unit depth, times 1 + tan^2 of the lens's half angles (off
    // axis, and for the depth of a point at a given distance).
    const double fx = std::abs(view.proj[0][0]) * 0.5 * double(buffer.width());
    const double tan2 = (view.orthographic ? 0.0 : 1.0 / double(view.proj[0][0] * view.proj[0][0]) +
                                                       1.0 / double(view.proj[1][1] * view.proj[1][1]));
    magnification_ = std::max(fx, texel_scale_) * (1.0 + tan2);
    sometimes_left_ = std::uint64_t(config_.budget);

    DistanceQueue open;
    open.push(bvh, Bvh::root(), view.eye);
    while (!open.empty()) {
      const NodeId n = open.pop();
      ++stats.nodes_visited;
      if (bvh.node(n).object_count == 0 || frustum_.outside(bvh, n)) continue;
      if (n != Bvh::root() && hidden(buffer, bvh.node(n).bounds, view, stats)) continue;
      if (!bvh.is_leaf(n)) {
        open.push(bvh, Bvh::left(n), view.eye);
        open.push(bvh, bvh.right(n), view.eye);
        continue;
      }
      leaf_.clear();
      append_objects_in_frustum(index_, n, view, leaf_, frustum_.planes(n));
      for (ObjectId id : leaf_) {
        if (hidden(buffer, scene.object(id).bounds, view, stats)) continue;
        queue_.push_back(id);
        rasterize_if_occluder(buffer, id, view, stats);
      }
    }
    if (!queue_.empty()) backend.render(queue_);
    return stats;
  }

 private:
  OcclusionBuffer& buffer_for(const View& view) {
    const int w = config_.width > 0 ? config_.width : std::max(1, view.width / config_.scale);
    const int h = config_.height > 0 ? config_.height : std::max(1, view.height / config_.scale);
    const SimdPath simd = config_.simd ? SimdPath::best : SimdPath::scalar;
    if (!buffer_ || buffer_->width() != w || buffer_->height() != h) buffer_.emplace(w, h, simd);
    return *buffer_;
  }

  bool hidden(OcclusionBuffer& buffer, const Aabb& box, const View& view, FrameStats& stats) {
    const auto start = Clock::now();
    const bool out = buffer.occluded(box, view.view_proj);
    stats.test_ms += ms_since(start);
    ++stats.boxes_tested;
    return out;
  }

  void rasterize_if_occluder(OcclusionBuffer& buffer, ObjectId id, const View& view, FrameStats& stats) {
    const Scene& scene = index_.scene;
    const Object& o = scene.object(id);
    if (o.occluder == OccluderClass::never || scene.material(o.material).translucent) return;
    const Mesh& mesh = scene.mesh(o.mesh);
    if (mesh.positions.empty()) return;  // the engine keeps its vertices: nothing to rasterize
    if (o.occluder == OccluderClass::sometimes && o.triangles > sometimes_left_) return;
    // How many texels across the box's bounding sphere spans: a smaller
    // occluder covers next to no texel whole (rule 3), and costs its triangles.
    const double radius = 0.5 * double(glm::length(o.bounds.extent()));
    const double distance = view.orthographic ? 1.0 : std::max(double(glm::length(o.bounds.center() - view.eye)), 1e-6);
    if (2.0 * radius * texel_scale_ / distance < config_.min_texels) return;
    // Triangles whose inscribed circle can reach half a texel on the buffer.
    const OccluderMesh& tris = occluder_of(o.mesh);
    const glm::mat3 m(o.transform);
    const double stretch = std::max({glm::length(m[0]), glm::length(m[1]), glm::length(m[2])});
    const double depth = view.orthographic ? 1.0 : std::max(double(occull::distance(view.eye, o.bounds)), double(view.near));
    const double grow = stretch * magnification_ / depth;  // texels per object unit, at most
    const std::size_t count = tris.count_at_least(float(0.5 / grow));
    if (count == 0) return;
    const auto start = Clock::now();
    const std::uint32_t drawn =
        buffer.rasterize(mesh.positions, tris, count, glm::dmat4(view.view_proj) * glm::dmat4(o.transform));
    stats.raster_ms += ms_since(start);
    stats.occluder_triangles += drawn;
    if (o.occluder == OccluderClass::sometimes) sometimes_left_ -= o.triangles;
  }

  const OccluderMesh& occluder_of(MeshId mesh) {
    if (sorted_.size() <= mesh) sorted_.resize(std::size_t(mesh) + 1);
    if (!sorted_[mesh]) {
      const Mesh& m = index_.scene.mesh(mesh);
      sorted_[mesh] = make_occluder_mesh(m.positions, m.indices);
    }
    return *sorted_[mesh];
  }

  SceneIndex index_;
  SocConfig config_;
  std::vector<std::optional<OccluderMesh>> sorted_;  // per mesh, made when first rasterized
  double magnification_ = 1.0;
  std::optional<OcclusionBuffer> buffer_;
  FrustumCache frustum_;
  std::vector<ObjectId> queue_, leaf_;
  double texel_scale_ = 1.0;
  std::uint64_t sometimes_left_ = 0;
};

}  // namespace

Registration soc_registration() {
  static const ConfigTable<SocConfig> table =
      ConfigTable<SocConfig>()
          .integer("scale", &SocConfig::scale, 1, 64, "occlusion buffer = viewport / scale on each axis")
          .integer("width", &SocConfig::width, 0, 8192, "occlusion buffer width in texels (0: from scale)")
          .integer("height", &SocConfig::height, 0, 8192, "occlusion buffer height in texels (0: from scale)")
          .integer("budget", &SocConfig::budget, 0, 1 << 30,
                   "triangles of `sometimes` occluders rasterized per frame (`always` ones always are)")
          .real("min_texels", &SocConfig::min_texels, 0.0, 1e6,
                "occluders whose bounding sphere spans fewer texels across are not rasterized")
          .flag("simd", &SocConfig::simd, "vectorised inner loops (off: the scalar reference, equal bit for bit)");
  return registered({"soc",
                     "software occlusion culling: a strictly conservative CPU occlusion buffer, occluders "
                     "rasterized front to back as they are met, no queries"},
                    table, [](const SceneIndex& index, const SocConfig& config, const Options&, const CullerContext&) {
                      return std::make_unique<SocCuller>(index, config);
                    });
}

}  // namespace occull::detail
