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
// span at least a couple of texels (occluders.hpp). Of an occluder, only the
// polygons that could cover a texel whole from where the camera is are
// rasterized (OcclusionBuffer::rasterize): skipping one never hides
// anything. Everything rasterized is drawn in the same frame (it passed its
// own test first), so a box the buffer hides is hidden on screen: the
// culler is conservative exactly when the buffer is. Which occluders are
// rasterized changes what is hidden, never whether the culler is
// conservative: an occluder of many polygons that has hidden nothing for
// `rest` frames rests (not rasterized, still drawn), tried again now and
// then; the buffer tags each texel with the occluder that wrote it, and a
// box found hidden credits the tags under it (Occluders::hidden).
// An interior node that held a drawn object in the last frame is not
// tested, against the buffer nor for holding a pixel centre: it is most
// likely visible again, and its children are tested. A
// box inside a hidden box is hidden by the same test (its rectangle is
// inside the other's, its nearest depth no nearer), so skipping the test
// changes what the walk costs, not what it draws. Its first frame, with no
// last frame, tests every node.
// The queue is drawn in one render-queue flush at the end.
#include "cullers.hpp"
#include "traversal.hpp"

#include "occluders.hpp"
#include "occull/occlusion_buffer.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <thread>

namespace occull::detail {
namespace {

class SocCuller final : public Culler {
 public:
  SocCuller(const SceneIndex& index, const SocConfig& config)
      : index_(index),
        config_(config),
        occluders_(index.scene, config.occluders),
        threads_(config.threads > 0 ? config.threads : int(std::clamp(std::thread::hardware_concurrency(), 1u, 2u))) {}

  void visit_counters(const CounterVisitor& visit) const override { counters_.visit(visit); }

  FrameResult cull(const View& view, Backend& backend) override {
    FrameResult result;
    BufferCounters& counters = counters_ = {};
    OcclusionBuffer& buffer = buffer_for(view);
    buffer.clear(view);
    occluders_.begin_frame(view, buffer);
    counters.buffer_texels = std::uint64_t(buffer.width()) * std::uint64_t(buffer.height());
    queue_.clear();
    frustum_.begin(index_.bvh, view);
    const Bvh& bvh = index_.bvh;
    if (shown_.size() != bvh.size() || generation_ != bvh.generation()) {
      shown_.assign(bvh.size(), 0);
      generation_ = bvh.generation();
    }
    if (++frame_ == 0) {  // wrapped: no node may look shown last frame
      std::fill(shown_.begin(), shown_.end(), 0u);
      std::fill(prerasterized_.begin(), prerasterized_.end(), 0u);
      std::fill(queued_.begin(), queued_.end(), 0u);
      frame_ = 2;
    }

    // The prepass: last frame's occluders still in the frustum, rasterized
    // first in one batch (on the buffer's threads), then each tested: one
    // found visible is drawn whatever the walk finds. One found hidden is
    // not drawn, and need not be: its polygons lie inside its box, so each
    // of its texels' keys is no nearer than the box, and the buffer already
    // holds a key nearer than the box at every texel the box reaches. Its
    // rasterizing changed no texel, now or later (keys only come nearer):
    // the buffer is what the drawn occluders alone make it.
    const std::size_t objects = index_.scene.objects().size();
    if (prerasterized_.size() != objects) prerasterized_.assign(objects, 0), queued_.assign(objects, 0);
    std::swap(last_occluders_, occluders_drawn_);
    occluders_drawn_.clear();
    if (config_.prepass) {
      draws_.clear();
      prepassed_.clear();
      for (const ObjectId id : last_occluders_) {
        if (id >= objects) continue;
        const Object& o = index_.scene.object(id);
        if (o.removed || view.frustum.classify(o.bounds) == Containment::outside) continue;
        const std::optional<OcclusionBuffer::OccluderDraw> draw = occluders_.occluder_draw(id, o.bounds, view);
        if (!draw) continue;
        draws_.push_back(*draw);
        prepassed_.push_back(id);
        prerasterized_[id] = frame_;
      }
      occluders_.rasterize(buffer, draws_, view, counters);
      for (const ObjectId id : prepassed_)
        if (!occluders_.hidden(buffer, index_.scene.object(id).bounds, view.view_proj, counters)) {
          queue_.push_back(id);
          queued_[id] = frame_;
        }
    }

    DistanceQueue open;
    open.push(bvh, Bvh::root(), view.eye);
    while (!open.empty()) {
      const NodeId n = open.pop();
      ++result.nodes_visited;
      const bool shown_last_frame = !bvh.is_leaf(n) && shown_[n] + 1 == frame_;
      if (bvh.node(n).object_count == 0 || frustum_.outside(bvh, n, !shown_last_frame)) continue;
      if (n != Bvh::root() && !shown_last_frame && occluders_.hidden(buffer, bvh.node(n).bounds, view.view_proj, counters))
        continue;
      if (!bvh.is_leaf(n)) {
        open.push(bvh, Bvh::left(n), view.eye);
        open.push(bvh, bvh.right(n), view.eye);
        continue;
      }
      leaf_.clear();
      frustum_.append_objects(index_, n, leaf_);
      // A leaf of one object: its box is the node's, tested above (the root aside).
      const bool tested = leaf_.size() == 1 && bvh.node(n).object_count == 1 && n != Bvh::root();
      for (ObjectId id : leaf_) {
        const Aabb& box = tested ? bvh.node(n).bounds : index_.scene.object(id).bounds;
        if (!tested && occluders_.hidden(buffer, box, view.view_proj, counters)) continue;
        if (prerasterized_[id] == frame_) {
          // Rasterized by the prepass; in the next prepass only if found visible again. (Found hidden after the
          // prepass, it cannot be visible now: drawing it anyway is safe.)
          if (queued_[id] != frame_) queue_.push_back(id), queued_[id] = frame_;
          occluders_drawn_.push_back(id);
        } else {
          queue_.push_back(id);
          if (occluders_.rasterize_if_occluder(buffer, id, box, view, counters)) occluders_drawn_.push_back(id);
        }
        for (NodeId m = n; m != kNoNode && shown_[m] != frame_; m = bvh.node(m).parent) shown_[m] = frame_;
      }
    }
    counters.occluders_resting = occluders_.resting();
    if (!queue_.empty()) backend.render(queue_);
    return result;
  }
  [[nodiscard]] const OcclusionBuffer* occlusion_buffer() const override { return buffer_ ? &*buffer_ : nullptr; }

 private:
  OcclusionBuffer& buffer_for(const View& view) {
    const int scale = config_.scale > 0 ? config_.scale : std::max(1, view.width / SocConfig::auto_width);
    const int w = config_.width > 0 ? config_.width : std::max(1, view.width / scale);
    const int h = config_.height > 0 ? config_.height : std::max(1, view.height / scale);
    const SimdPath simd = config_.simd ? SimdPath::best : SimdPath::scalar;
    if (!buffer_ || buffer_->width() != w || buffer_->height() != h) buffer_.emplace(w, h, simd);
    buffer_->set_fused_pairs(config_.fuse);
    buffer_->set_threads(threads_);
    buffer_->track_sources(occluders_.learns());
    return *buffer_;
  }

  SceneIndex index_;
  SocConfig config_;
  Occluders occluders_;
  int threads_;  // config_.threads, 0 resolved once (hardware_concurrency may read /sys)
  BufferCounters counters_;  // of the last frame
  std::optional<OcclusionBuffer> buffer_;
  FrustumCache frustum_;
  std::vector<ObjectId> queue_, leaf_;
  std::vector<ObjectId> occluders_drawn_, last_occluders_;  // occluders rasterized this frame, and last
  std::vector<std::uint32_t> prerasterized_;  // per object: the last frame_ the prepass rasterized it
  std::vector<std::uint32_t> queued_;         // per object: the last frame_ the prepass queued it to be drawn
  std::vector<ObjectId> prepassed_;           // the prepass's objects (scratch)
  std::vector<OcclusionBuffer::OccluderDraw> draws_;  // and their draws (scratch)
  std::vector<std::uint32_t> shown_;  // per node: the last frame_ it held a drawn object (0: none)
  std::uint32_t frame_ = 1;
  std::uint64_t generation_ = 0;      // of the hierarchy shown_ follows
};

}  // namespace

Registration soc_registration() {
  static const ConfigTable<SocConfig> table =
      ConfigTable<SocConfig>()
          .integer("scale", &SocConfig::scale, 0, 64,
                   "occlusion buffer = viewport / scale on each axis (0: about 320 texels across, scale = view width "
                   "/ 320, at least 1)")
          .integer("width", &SocConfig::width, 0, 8192, "occlusion buffer width in texels (0: from scale)")
          .integer("height", &SocConfig::height, 0, 8192, "occlusion buffer height in texels (0: from scale)")
          .integer("budget", [](auto& c) -> auto& { return c.occluders.budget; }, 0, 1 << 30,
                   "triangles of `sometimes` occluders rasterized per frame (`always` ones always are)")
          .real("min_texels", [](auto& c) -> auto& { return c.occluders.min_texels; }, 0.0, 1e6,
                "occluders whose bounding sphere spans fewer texels across are not rasterized")
          .real("detail", [](auto& c) -> auto& { return c.occluders.detail; }, 0.0, 1e6,
                "an occluder's polygons whose inscribed circle is below 1/detail of its largest are not rasterized "
                "(0: all)")
          .integer("rest", [](auto& c) -> auto& { return c.occluders.rest; }, 0, 1000000,
                   "frames an occluder that hides nothing goes on being rasterized; then it rests, rasterized one "
                   "frame in `rest` (then in 2, 4, 8 times `rest`) until a box it hides is found (0: every occluder "
                   "every frame)")
          .integer("rest_triangles", [](auto& c) -> auto& { return c.occluders.rest_triangles; }, 0, 1 << 30,
                   "with rest: occluders of fewer triangles never rest (cheap to rasterize)")
          .integer("threads", &SocConfig::threads, 0, OcclusionBuffer::max_threads,
                   "threads rasterizing the prepass and an occluder of many polygons (the caller's and the buffer's "
                   "own; the buffer is the same whatever the threads; 0: two, one on a one-thread machine)")
          .flag("prepass", &SocConfig::prepass,
                "last frame's occluders still in the frustum rasterized first, in one batch shared among the "
                "threads; those then found visible drawn whatever the walk finds")
          .flag("simd", &SocConfig::simd, "vectorised inner loops (off: the scalar reference, equal bit for bit)")
          .flag("fuse", &SocConfig::fuse,
                "polygons of an occluder that share an edge cover the seam between them (the buffer's rule 11; off: "
                "each alone, cheaper where they are smaller than a texel)");
  return registered({"soc",
                     "software occlusion culling: a strictly conservative CPU occlusion buffer, occluders "
                     "rasterized front to back as they are met, no queries",
                     true, {}, false, SceneKind::bvh, false, false, true},
                    table, [](const SceneIndex& index, const SocConfig& config, const Options&, const CullerContext&) {
                      return std::make_unique<SocCuller>(index, config);
                    });
}

}  // namespace occull::detail
