// occull — tiled worlds of unbounded extent (Gomez et al. 2013).
//
// A tiling set is a few predefined tiles, each a local scene of object
// instances in a cell of `cell_size` x `cell_size` scene units with its own
// BVH, built once. A pure tile function places a tile on every cell of the
// integer lattice in the XZ plane, from the cell's coordinates and a seed:
// nothing about the world is stored, so it has no edge.
//
// The world's objects live in a Scene all the same (the Backend draws
// objects by id), through a *window*: the W x W cells around the camera,
// W chosen so that every cell the view frustum can reach lies inside it.
// Cell (x, z) owns the object ids from first_object({x, z}) on, one per
// object of its tile: (x mod W, z mod W) picks a block of
// objects_per_cell() ids, so the ids of a cell never change while it is in
// the window, and two cells in the window never share one. follow() moves
// the window with the camera: the cells that enter it are placed in the ids
// of those that left (Scene::place_object). The Scene therefore holds a
// fixed number of objects however far the camera goes, each predefined
// tile's meshes once; ids a cell's tile does not use are parked far below
// the world (kParkedY), where no frustum reaches.
//
// Ground truth needs no global structure: every cell of the window is
// placed, so the lab's brute-force pass over the scene's objects sees
// every tile instance within the far plane.
#pragma once
#include "occull/bvh.hpp"
#include "occull/geometry.hpp"
#include "occull/scene.hpp"
#include "occull/view.hpp"
#include <compare>
#include <cstdint>
#include <span>
#include <string>
#include <vector>

namespace occull {

/// A cell of the lattice: it spans [x, x+1) x [z, z+1) cell sizes in world X and Z.
struct TileCoord {
  std::int32_t x = 0;
  std::int32_t z = 0;
  friend auto operator<=>(const TileCoord&, const TileCoord&) = default;
};

/// One object of a predefined tile, in tile-local space: the tile's cell
/// spans [0, cell_size] in X and Z.
struct TileObject {
  MeshId mesh = 0;
  MaterialId material = 0;
  glm::mat4 local{1.0f};
  OccluderClass occluder = OccluderClass::sometimes;
};

/// A predefined tile. Its objects, their local boxes and its BVH (object i
/// of the BVH is objects[i]) are built once, by TiledWorld's constructor.
struct Tile {
  std::string name;
  float weight = 1.0f;                 ///< how often the tile function picks it, relative (> 0)
  std::vector<TileObject> objects;
  std::vector<Aabb> object_bounds;     ///< local boxes, filled by TiledWorld
  Aabb bounds;                         ///< local box of all objects (its BVH's root)
  Bvh bvh;                             ///< over object_bounds, local ids
  std::uint64_t triangles = 0;
  double bvh_build_ms = 0.0;           ///< time to build its BVH
};

class TiledWorld {
 public:
  /// Where ids a cell's tile does not use are put (scene units, Y).
  static constexpr float kParkedY = -1.0e6f;
  /// The widest viewport (width / height) a window sized by reach() holds
  /// every cell in the frustum of; the lab refuses wider ones.
  static constexpr float kMaxAspect = 2.0f;
  /// Distance from the eye to the far corners of `lens`'s frustum at
  /// kMaxAspect (scene units): the reach to size a window with.
  [[nodiscard]] static float reach(const Lens& lens);

  /// Builds every tile's boxes and BVH (meshes must already be in `scene`)
  /// and sizes the window so that it holds every cell whose common box lies
  /// within `reach` scene units of the camera's cell (the frustum's farthest
  /// corner: the lens's far plane over its field of view). Throws InputError
  /// for an empty tiling set, a tile without objects, a non-positive cell
  /// size or weight, or a window past occull::limits::objects.
  TiledWorld(const Scene& scene, float cell_size, std::vector<Tile> tiles, std::uint64_t seed, float reach);

  // --- the tiling set ---------------------------------------------------
  [[nodiscard]] float cell_size() const noexcept { return cell_size_; }
  [[nodiscard]] std::span<const Tile> tiles() const noexcept { return tiles_; }
  /// The common bounding box: the union of every tile's box, local.
  [[nodiscard]] const Aabb& common_box() const noexcept { return common_box_; }
  /// The tile function: which tile cell `c` holds. Pure: depends only on
  /// `c` and the seed.
  [[nodiscard]] std::uint32_t tile_at(TileCoord c) const noexcept;
  /// World position of cell `c`'s local origin.
  [[nodiscard]] glm::vec3 origin(TileCoord c) const noexcept {
    return {float(c.x) * cell_size_, 0.0f, float(c.z) * cell_size_};
  }
  /// The common box offset to cell `c` (what a tile query draws).
  [[nodiscard]] Aabb common_box_at(TileCoord c) const noexcept;
  /// The box of the tile cell `c` holds, offset to it.
  [[nodiscard]] Aabb tile_box_at(TileCoord c) const noexcept;
  /// The cell whose column holds `p`.
  [[nodiscard]] TileCoord cell_of(const glm::vec3& p) const noexcept;

  // --- the window of object ids -------------------------------------------
  /// Cells from the centre to the window's edge (W = 2 radius + 1).
  [[nodiscard]] int radius() const noexcept { return radius_; }
  [[nodiscard]] TileCoord centre() const noexcept { return centre_; }
  /// Whether `c` is in the window around centre().
  [[nodiscard]] bool in_window(TileCoord c) const noexcept;
  /// Ids per cell: the most objects of any tile.
  [[nodiscard]] std::uint32_t objects_per_cell() const noexcept { return per_cell_; }
  /// First object id of cell `c`; its tile's object i is id + i.
  /// Meaningful while `c` is in the window.
  [[nodiscard]] ObjectId first_object(TileCoord c) const noexcept;
  /// Adds the window's objects to `scene` (once, when building it) and
  /// places the window around the origin's cell.
  void populate(Scene& scene);
  /// Centres the window on the cell of `eye` and places the cells that
  /// entered it. Starts with Scene::clear_moved(), so moved_objects() lists
  /// the ids placed by this call. Returns the number of cells placed.
  std::size_t follow(Scene& scene, const glm::vec3& eye);
  /// Whether every point of `view`'s frustum lies over the window's cells
  /// (its eight corners do: the frustum is their convex hull), so that the
  /// placed cells are all a frame can see. The lab checks it on every
  /// ground-truth frame.
  [[nodiscard]] bool covers(const View& view) const;
  /// Cells placed since construction (a measure of the walk).
  [[nodiscard]] std::uint64_t cells_placed() const noexcept { return cells_placed_; }
  /// "tile NAME at (x, z), object i": what object `id` is now.
  [[nodiscard]] std::string describe(ObjectId id) const;

 private:
  [[nodiscard]] std::size_t slot(TileCoord c) const noexcept;
  void place(Scene& scene, TileCoord c);

  float cell_size_;
  std::vector<Tile> tiles_;
  std::uint64_t seed_;
  float total_weight_ = 0.0f;
  Aabb common_box_;
  int radius_ = 0;
  std::uint32_t per_cell_ = 0;
  TileCoord centre_{};
  std::vector<TileCoord> slot_cell_;  // which cell each slot holds now
  std::vector<std::uint8_t> slot_set_;
  std::uint64_t cells_placed_ = 0;
  bool populated_ = false;
};

}  // namespace occull
