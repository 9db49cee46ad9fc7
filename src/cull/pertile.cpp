// `pertile`: per-tile CHC++ over a tiled world, no tile queries (Gomez et al. 2013's
// "per-tile CHC++" comparison).
//
// Every cell of the window whose tile box is not outside the frustum is
// rendered nearest first by the CHC++ context of its tile instance (kept in
// the tile cache across frames, so each keeps its temporal coherence).
// Farther tiles' CHC++ queries test against the nearer tiles already drawn,
// but no tile is skipped as a whole: each pays at least its root's query.
#include "cullers.hpp"
#include "tile_cache.hpp"

namespace occull::detail {
namespace {

class PerTileCuller final : public Culler {
 public:
  PerTileCuller(const SceneIndex& index, const PerTileConfig& c, const Options& o)
      : world_(tiled_world(index, "pertile")), cache_(index, "chcpp", o, c.evict) {}

  void visit_counters(const CounterVisitor& visit) const override { cache_.visit_counters(visit); }

  FrameResult cull(const View& view, Backend& backend) override {
    cache_.begin_frame(++frame_);
    cells_in_frustum(world_, view, true, cells_);
    for (TileCoord c : cells_) cache_.render(cache_.fetch(c), view, backend);
    cache_.end_frame();
    return cache_.result();
  }
  [[nodiscard]] std::span<const CullRegion> regions() const override { return cache_.regions(); }

 private:
  const TiledWorld& world_;
  TileCache cache_;
  std::uint64_t frame_ = 0;
  std::vector<TileCoord> cells_;
};

}  // namespace

Registration pertile_registration() {
  static const ConfigTable<PerTileConfig> table = ConfigTable<PerTileConfig>().integer(
      "evict", &PerTileConfig::evict, 1, 1000000,
      "frames a tile instance may go unused before its BVH instance and CHC++ context are freed");
  return registered({"pertile",
                     "tiled worlds: every tile instance in the frustum culled by its own CHC++ context, nearest first, "
                     "no tile queries (Gomez et al. 2013)",
                     true, {}, false, SceneKind::tiled},
                    table, [](const SceneIndex& index, const PerTileConfig& c, const Options& o, const CullerContext&) {
                      return std::make_unique<PerTileCuller>(index, c, o);
                    });
}

}  // namespace occull::detail
