// The tile-instance cache of the tiled-world cullers.
#include "tile_cache.hpp"

#include "occull/error.hpp"
#include "core/format.hpp"

#include <algorithm>
#include <chrono>

namespace occull::detail {

TileCache::TileCache(const SceneIndex& index, std::string local, const Options& options, int evict_after)
    : index_(index), local_(std::move(local)), options_(options), evict_after_(evict_after) {}

void TileCounters::visit(const CounterVisitor& visit) const {
  visit("tiles_rendered", double(tiles_rendered));
  visit("tile_queries", double(tile_queries));
  visit("tile_postponed", double(tile_postponed));
  visit("tile_prediction_failures", double(tile_prediction_failures));
  visit("tiles_instantiated", double(tiles_instantiated));
  visit("tiles_evicted", double(tiles_evicted));
  visit("tile_cache", double(tile_cache));
  visit("instantiate_ms", instantiate_ms);
}

void TileCache::begin_frame(std::uint64_t frame) {
  frame_ = frame;
  counters_ = {};
  nodes_visited_ = 0;
  for (auto& [name, value] : local_counters_) value = 0.0;
  regions_.clear();
}

void TileCache::visit_counters(const CounterVisitor& visit) const {
  counters_.visit(visit);
  for (const auto& [name, value] : local_counters_) visit(name, value);
}

TileInstance& TileCache::fetch(TileCoord c) {
  auto it = cache_.find(c);
  if (it == cache_.end()) {
    const auto t0 = std::chrono::steady_clock::now();
    const TiledWorld& world = *index_.world;
    TileInstance t;
    t.coord = c;
    t.tile = world.tile_at(c);
    t.first_object = world.first_object(c);
    const Tile& tile = world.tiles()[t.tile];
    t.object_count = std::uint32_t(tile.objects.size());
    t.bvh = std::make_unique<Bvh>(tile.bvh.instance(world.origin(c), t.first_object));
    if (!local_.empty()) t.local = make_culler(local_, SceneIndex{index_.scene, *t.bvh, nullptr}, options_);
    it = cache_.emplace(c, std::move(t)).first;
    ++counters_.tiles_instantiated;
    counters_.instantiate_ms += std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  }
  it->second.last_used = frame_;
  return it->second;
}

void TileCache::render(TileInstance& t, const View& view, Backend& backend) {
  ++counters_.tiles_rendered;
  note(index_.world->tile_box_at(t.coord), true);
  if (t.local) {
    nodes_visited_ += t.local->render_frame(view, backend).nodes_visited;
    t.local->visit_counters([this](std::string_view name, double value) {
      const auto it = std::find_if(local_counters_.begin(), local_counters_.end(),
                                   [&](const auto& c) { return c.first == name; });
      if (it == local_counters_.end())
        local_counters_.emplace_back(name, value);
      else
        it->second += value;
    });
    return;
  }
  all_.clear();
  for (std::uint32_t i = 0; i < t.object_count; ++i) all_.push_back(t.first_object + i);
  backend.render(all_);
}

void TileCache::end_frame() {
  for (auto it = cache_.begin(); it != cache_.end();) {
    const bool stale = frame_ - it->second.last_used >= std::uint64_t(evict_after_) ||
                       !index_.world->in_window(it->first);
    if (stale) {
      it = cache_.erase(it);
      ++counters_.tiles_evicted;
    } else {
      ++it;
    }
  }
  counters_.tile_cache = cache_.size();
}

const TiledWorld& tiled_world(const SceneIndex& index, std::string_view algorithm) {
  if (!index.world)
    throw InputError(detail::format("{} runs on tiled worlds only (tiles_city, tiles_forest, tiles_hybrid)", algorithm));
  return *index.world;
}

namespace {

// Calls visit(cell, distance from the eye to its box) for every cell of the
// window whose box (the tile's own or the common box) is not outside the frustum.
template <class Visit>
void for_cells_in_frustum(const TiledWorld& world, const View& view, bool tile_box, Visit&& visit) {
  const TileCoord centre = world.centre();
  const int r = world.radius();
  for (int dx = -r; dx <= r; ++dx) {
    for (int dz = -r; dz <= r; ++dz) {
      const TileCoord c{centre.x + dx, centre.z + dz};
      const Aabb box = tile_box ? world.tile_box_at(c) : world.common_box_at(c);
      if (view.frustum.classify(box) == Containment::outside) continue;
      visit(c, glm::length(glm::clamp(view.eye, box.min, box.max) - view.eye));
    }
  }
}

// Nearer first; ties by coordinates, so the order is deterministic.
bool nearer(float da, TileCoord a, float db, TileCoord b) { return da < db || (da == db && a < b); }

}  // namespace

void cells_in_frustum(const TiledWorld& world, const View& view, bool tile_box, std::vector<TileCoord>& out) {
  struct Cell {
    float distance;
    TileCoord c;
  };
  std::vector<Cell> cells;
  for_cells_in_frustum(world, view, tile_box, [&](TileCoord c, float d) { cells.push_back({d, c}); });
  std::sort(cells.begin(), cells.end(),
            [](const Cell& a, const Cell& b) { return nearer(a.distance, a.c, b.distance, b.c); });
  out.clear();
  for (const Cell& cell : cells) out.push_back(cell.c);
}

std::optional<TileCoord> nearest_cell_in_frustum(const TiledWorld& world, const View& view) {
  std::optional<TileCoord> best;
  float best_distance = 0.0f;
  for_cells_in_frustum(world, view, false, [&](TileCoord c, float d) {
    if (!best || nearer(d, c, best_distance, *best)) {
      best = c;
      best_distance = d;
    }
  });
  return best;
}

}  // namespace occull::detail
