// Internal: the cache of tile instances the tiled-world cullers share — a
// tile instance's BVH instance and, with a local culler, its culling
// context (CHC++), keyed by tile coordinates, reused across frames and
// freed after a number of frames unused (Gomez et al. 2013, Section III-B).
#pragma once
#include "occull/culler.hpp"
#include "occull/tiles.hpp"
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace occull::detail {

struct TileInstance {
  TileCoord coord;
  std::uint32_t tile = 0;             ///< index into TiledWorld::tiles()
  ObjectId first_object = 0;          ///< its objects: first_object + local index
  std::uint32_t object_count = 0;
  std::unique_ptr<Bvh> bvh;           ///< the tile's BVH moved to the cell, world ids
  std::unique_ptr<Culler> local;      ///< its own culler (CHC++ context), or null
  std::uint64_t last_used = 0;        ///< frame it was last fetched in
};

/// The counters of a tiled-world culler's frame beyond FrameResult.
struct TileCounters {
  std::uint64_t tiles_rendered = 0;            ///< tile instances drawn
  std::uint64_t tile_queries = 0;              ///< queries of the common box at a tile (tiles)
  std::uint64_t tile_postponed = 0;            ///< tiles drawn on last frame's visibility, their query pending
  std::uint64_t tile_prediction_failures = 0;  ///< postponed queries still without a result at the frame's end
  std::uint64_t tiles_instantiated = 0;        ///< tile instances created in the frame
  std::uint64_t tiles_evicted = 0;             ///< ... and freed, unused for the eviction time
  std::uint64_t tile_cache = 0;                ///< tile instances held after the frame
  double instantiate_ms = 0.0;                 ///< time spent creating tile instances, ms

  void visit(const CounterVisitor& visit) const;
};

class TileCache {
 public:
  /// `local`: the algorithm culling inside a tile ("chcpp"), or empty for
  /// none; it gets `options`. `evict_after`: frames an instance may go unused.
  TileCache(const SceneIndex& index, std::string local, const Options& options, int evict_after);

  /// Starts frame `frame` (> every earlier one); its counters start at 0.
  void begin_frame(std::uint64_t frame);
  /// fetchBVHInstance: the instance of cell `c`, created on first use.
  /// Precondition: `c` is in the world's window.
  TileInstance& fetch(TileCoord c);
  /// Frees instances unused for `evict_after` frames (after the frame's
  /// last fetch) and records the cache size in the frame's counters.
  void end_frame();
  /// Draws a fetched instance: through its local culler, or all its objects.
  /// Records its tile's box as a visible region, and adds the local
  /// culler's nodes and counters to the frame's.
  void render(TileInstance& t, const View& view, Backend& backend);
  /// Records a region of this frame: a cell's box, drawn or found hidden.
  void note(const Aabb& box, bool visible) { regions_.push_back({box, visible}); }
  /// This frame's regions (Culler::regions), cleared by begin_frame().
  [[nodiscard]] std::span<const CullRegion> regions() const noexcept { return regions_; }

  /// The frame's counters (the tiled-world culler adds its own).
  [[nodiscard]] TileCounters& counters() noexcept { return counters_; }
  /// The frame's result: the nodes the local cullers visited.
  [[nodiscard]] FrameResult result() const noexcept { return {.nodes_visited = nodes_visited_}; }
  /// The last frame's counters: the tiles' and the sums of the local cullers'.
  void visit_counters(const CounterVisitor& visit) const;

  [[nodiscard]] std::size_t size() const noexcept { return cache_.size(); }
  [[nodiscard]] int evict_after() const noexcept { return evict_after_; }

 private:
  SceneIndex index_;
  std::string local_;
  Options options_;
  int evict_after_;
  std::map<TileCoord, TileInstance> cache_;
  std::uint64_t frame_ = 0;
  TileCounters counters_;
  std::uint64_t nodes_visited_ = 0;
  std::vector<std::pair<std::string_view, double>> local_counters_;  // summed over the frame's tiles
  std::vector<ObjectId> all_;
  std::vector<CullRegion> regions_;
};

/// The world of `index`; InputError naming `algorithm` when there is none.
const TiledWorld& tiled_world(const SceneIndex& index, std::string_view algorithm);

/// Cells of the window whose box (`tile_box`: the tile's own, else the
/// common box) is not outside the frustum, nearest box first.
void cells_in_frustum(const TiledWorld& world, const View& view, bool tile_box, std::vector<TileCoord>& out);
/// The first cell cells_in_frustum() would list for the common box, without sorting them all.
std::optional<TileCoord> nearest_cell_in_frustum(const TiledWorld& world, const View& view);

}  // namespace occull::detail
