// TiledWorld: the tiling set, the tile function and the window of object ids.
#include "occull/tiles.hpp"

#include "occull/error.hpp"
#include "occull/input_limits.hpp"
#include "core/format.hpp"

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>

namespace occull {
namespace {

std::uint64_t mix(std::uint64_t z) {
  z = (z ^ (z >> 30)) * 0xBF58476D1CE4E5B9ull;
  z = (z ^ (z >> 27)) * 0x94D049BB133111EBull;
  return z ^ (z >> 31);
}

// x mod n in [0, n) for negative x too.
std::int64_t wrap(std::int64_t x, std::int64_t n) { return ((x % n) + n) % n; }

}  // namespace

TiledWorld::TiledWorld(const Scene& scene, float cell_size, std::vector<Tile> tiles, std::uint64_t seed,
                       float reach)
    : cell_size_(cell_size), tiles_(std::move(tiles)), seed_(seed) {
  if (!(cell_size_ > 0.0f) || !std::isfinite(cell_size_))
    throw InputError(detail::format("tiled world: cell size {} must be a positive number", cell_size_));
  if (tiles_.empty()) throw InputError("tiled world: the tiling set has no tiles");
  for (Tile& t : tiles_) {
    if (t.objects.empty()) throw InputError(detail::format("tiled world: tile {} has no objects", t.name));
    if (!(t.weight > 0.0f)) throw InputError(detail::format("tiled world: tile {} has weight {}", t.name, t.weight));
    total_weight_ += t.weight;
    std::vector<std::uint32_t> triangles;
    t.object_bounds.clear();
    t.bounds = Aabb{};
    t.triangles = 0;
    for (const TileObject& o : t.objects) {
      const Aabb box = transform_box(scene.mesh(o.mesh).bounds(), o.local);
      t.object_bounds.push_back(box);
      t.bounds.extend(box);
      triangles.push_back(std::uint32_t(scene.mesh(o.mesh).triangle_count()));
      t.triangles += triangles.back();
    }
    const auto t0 = std::chrono::steady_clock::now();
    t.bvh = Bvh::build(t.object_bounds, triangles);
    t.bvh_build_ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    common_box_.extend(t.bounds);
    per_cell_ = std::max(per_cell_, std::uint32_t(t.objects.size()));
  }
  // A cell is inside the window when its common box can lie within `reach`
  // of the camera, wherever the camera is in its own cell.
  const float overhang = std::max({0.0f, -common_box_.min.x, -common_box_.min.z,
                                   common_box_.max.x - cell_size_, common_box_.max.z - cell_size_});
  radius_ = int(std::ceil((std::max(reach, 0.0f) + overhang) / cell_size_)) + 1;
  const std::size_t side = std::size_t(2 * radius_ + 1);
  const std::size_t objects = side * side * per_cell_;
  if (objects > limits::objects)
    throw InputError(detail::format("tiled world: a window of {}x{} cells of {} objects is {} objects, past the "
                                 "limit of {} (occull::limits::objects); lower the far plane or the tile sizes",
                                 side, side, per_cell_, objects, limits::objects));
}

float TiledWorld::reach(const Lens& lens) {
  const float t = std::tan(glm::radians(lens.fov_y_degrees) * 0.5f);
  return lens.far * std::sqrt(1.0f + t * t * (1.0f + kMaxAspect * kMaxAspect));
}

std::uint32_t TiledWorld::tile_at(TileCoord c) const noexcept {
  const std::uint64_t h = mix(seed_ * 0x9E3779B97F4A7C15ull ^
                              mix((std::uint64_t(std::uint32_t(c.x)) << 32) | std::uint32_t(c.z)));
  float pick = float(h >> 40) * (1.0f / 16777216.0f) * total_weight_;
  for (std::uint32_t i = 0; i < tiles_.size(); ++i) {
    if (pick < tiles_[i].weight) return i;
    pick -= tiles_[i].weight;
  }
  return std::uint32_t(tiles_.size() - 1);
}

Aabb TiledWorld::common_box_at(TileCoord c) const noexcept {
  const glm::vec3 o = origin(c);
  return {common_box_.min + o, common_box_.max + o};
}

Aabb TiledWorld::tile_box_at(TileCoord c) const noexcept {
  const glm::vec3 o = origin(c);
  const Aabb& b = tiles_[tile_at(c)].bounds;
  return {b.min + o, b.max + o};
}

TileCoord TiledWorld::cell_of(const glm::vec3& p) const noexcept {
  const auto coord = [&](float v) {
    const double c = std::floor(double(v) / double(cell_size_));
    return std::int32_t(std::clamp(c, -2.0e9, 2.0e9));
  };
  return {coord(p.x), coord(p.z)};
}

bool TiledWorld::in_window(TileCoord c) const noexcept {
  return std::abs(std::int64_t(c.x) - centre_.x) <= radius_ && std::abs(std::int64_t(c.z) - centre_.z) <= radius_;
}

std::size_t TiledWorld::slot(TileCoord c) const noexcept {
  const std::int64_t side = 2 * radius_ + 1;
  return std::size_t(wrap(c.x, side) * side + wrap(c.z, side));
}

ObjectId TiledWorld::first_object(TileCoord c) const noexcept { return ObjectId(slot(c) * per_cell_); }

void TiledWorld::populate(Scene& scene) {
  const std::size_t side = std::size_t(2 * radius_ + 1);
  const TileObject& any = tiles_[0].objects[0];
  const glm::mat4 parked = glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, kParkedY, 0.0f));
  for (std::size_t i = 0; i < side * side * per_cell_; ++i)
    scene.add_object(any.mesh, any.material, parked, OccluderClass::never);
  slot_cell_.assign(side * side, TileCoord{});
  slot_set_.assign(side * side, 0);
  populated_ = true;
  follow(scene, glm::vec3(0.5f * cell_size_, 0.0f, 0.5f * cell_size_));
}

void TiledWorld::place(Scene& scene, TileCoord c) {
  const std::size_t s = slot(c);
  const Tile& tile = tiles_[tile_at(c)];
  const ObjectId first = ObjectId(s * per_cell_);
  const glm::mat4 to_world = glm::translate(glm::mat4(1.0f), origin(c));
  for (std::size_t i = 0; i < tile.objects.size(); ++i) {
    const TileObject& o = tile.objects[i];
    scene.place_object(first + ObjectId(i), o.mesh, o.material, to_world * o.local, o.occluder);
  }
  const glm::mat4 parked = glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, kParkedY, 0.0f));
  const TileObject& any = tile.objects[0];
  for (std::size_t i = tile.objects.size(); i < per_cell_; ++i)
    scene.place_object(first + ObjectId(i), any.mesh, any.material, parked, OccluderClass::never);
  slot_cell_[s] = c;
  slot_set_[s] = 1;
  ++cells_placed_;
}

std::size_t TiledWorld::follow(Scene& scene, const glm::vec3& eye) {
  scene.clear_moved();
  if (!populated_) return 0;
  centre_ = cell_of(eye);
  std::size_t placed = 0;
  for (std::int64_t dx = -radius_; dx <= radius_; ++dx) {
    for (std::int64_t dz = -radius_; dz <= radius_; ++dz) {
      const TileCoord c{std::int32_t(centre_.x + dx), std::int32_t(centre_.z + dz)};
      const std::size_t s = slot(c);
      if (slot_set_[s] && slot_cell_[s] == c) continue;
      place(scene, c);
      ++placed;
    }
  }
  return placed;
}

bool TiledWorld::covers(const View& view) const {
  const glm::dmat4 inv = glm::inverse(glm::dmat4(view.view_proj));
  const double lo_x = double(centre_.x - radius_) * cell_size_, hi_x = double(centre_.x + radius_ + 1) * cell_size_;
  const double lo_z = double(centre_.z - radius_) * cell_size_, hi_z = double(centre_.z + radius_ + 1) * cell_size_;
  if (!std::isfinite(view.far)) return false;  // an infinite frustum reaches past any window
  for (int corner = 0; corner < 8; ++corner) {
    const double depth = corner & 4 ? view.clip.far_depth() : view.clip.near_depth();
    const glm::dvec4 p = inv * glm::dvec4(corner & 1 ? 1 : -1, corner & 2 ? 1 : -1, depth, 1);
    const double x = p.x / p.w, z = p.z / p.w;
    if (!(x >= lo_x && x <= hi_x && z >= lo_z && z <= hi_z)) return false;
  }
  return true;
}

std::string TiledWorld::describe(ObjectId id) const {
  if (per_cell_ == 0 || id / per_cell_ >= slot_cell_.size()) return detail::format("object {}", id);
  const std::size_t s = id / per_cell_;
  const std::uint32_t i = id % per_cell_;
  const TileCoord c = slot_cell_[s];
  const Tile& tile = tiles_[tile_at(c)];
  if (i >= tile.objects.size()) return detail::format("object {} (unused id of cell ({}, {}))", id, c.x, c.z);
  return detail::format("tile {} at ({}, {}), object {}", tile.name, c.x, c.z, i);
}

}  // namespace occull
