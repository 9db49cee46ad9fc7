// `tilevfc`: view-frustum culling over a tiled world (Gomez et al. 2013's baseline).
//
// Every cell of the window whose tile box is not outside the frustum is
// visited nearest first; the objects of its tile instance are culled
// against the frustum through the instance's BVH and queued, and the
// queue is rendered as one flush. No occlusion queries.
#include "cullers.hpp"
#include "tile_cache.hpp"
#include "traversal.hpp"

namespace occull::detail {
namespace {

class TileVfcCuller final : public Culler {
 public:
  TileVfcCuller(const SceneIndex& index, const TileVfcConfig& c, const Options& o)
      : index_(index), world_(tiled_world(index, "tilevfc")), cache_(index, "", o, c.evict) {}

  void visit_counters(const CounterVisitor& visit) const override { cache_.visit_counters(visit); }

  FrameResult cull(const View& view, Backend& backend) override {
    FrameResult result;
    cache_.begin_frame(++frame_);
    cells_in_frustum(world_, view, true, cells_);
    queue_.clear();
    for (TileCoord c : cells_) {
      TileInstance& t = cache_.fetch(c);
      collect_in_frustum_front_to_back(SceneIndex{index_.scene, *t.bvh, nullptr}, view, queue_, result.nodes_visited, /*subpixel=*/false);  // the baseline: frustum only
      ++cache_.counters().tiles_rendered;
      cache_.note(world_.tile_box_at(c), true);
    }
    if (!queue_.empty()) backend.render(queue_);
    cache_.end_frame();
    return result;
  }
  [[nodiscard]] std::span<const CullRegion> regions() const override { return cache_.regions(); }

 private:
  SceneIndex index_;
  const TiledWorld& world_;
  TileCache cache_;
  std::uint64_t frame_ = 0;
  std::vector<TileCoord> cells_;
  std::vector<ObjectId> queue_;
};

}  // namespace

Registration tilevfc_registration() {
  static const ConfigTable<TileVfcConfig> table = ConfigTable<TileVfcConfig>().integer(
      "evict", &TileVfcConfig::evict, 1, 1000000,
      "frames a tile instance may go unused before its BVH instance is freed");
  return registered({"tilevfc",
                     "tiled worlds: view-frustum culling over the BVH of every tile instance in the frustum, nearest "
                     "tile first (Gomez et al. 2013's baseline)",
                     true, {}, false, SceneKind::tiled},
                    table, [](const SceneIndex& index, const TileVfcConfig& c, const Options& o, const CullerContext&) {
                      return std::make_unique<TileVfcCuller>(index, c, o);
                    });
}

}  // namespace occull::detail
