// occull — the uniform grid scene index and its occlusion-order traversal
// (Seletsky 2013, chapters 2.5 and 4.2).
//
// A UniformGrid lists every object in each cell its box touches. It sits
// beside the BVH for engines whose scenes are not a hierarchy: it needs no
// rebuild when objects move (update() moves an object between cells), and it
// stores only the cells that ever held an object, so a 1000 x 10 x 1000 grid
// of a sparse world costs what its occupied cells cost.
//
// GridTraversal lists the cells a view frustum intersects in occlusion order:
// no cell comes before a cell that can occlude it from the eye. It rasterizes
// the frustum, clipped to the grid, slice by slice along the dominant view
// axis with a convex-polygon row rasterizer (the thesis' algorithm), or
// walks the frustum's bounding box (the simpler traversal the thesis
// mentions, for comparison).
#pragma once

#include "occull/geometry.hpp"
#include "occull/scene.hpp"
#include "occull/view.hpp"

#include <cstdint>
#include <span>
#include <unordered_map>
#include <vector>

namespace occull {

/// Cell coordinates (x, y, z) of a grid, each in [0, dims) for a cell of it.
using CellCoord = glm::ivec3;

/// Where the cells of a grid lie: `dims` cells of edge `cell` from `origin`.
struct GridGeometry {
  glm::vec3 origin{0.0f};  ///< min corner of cell (0, 0, 0), scene units
  glm::vec3 cell{1.0f};    ///< edge lengths of a cell, scene units, each > 0
  glm::ivec3 dims{1};      ///< cells along x, y, z, each >= 1

  /// Box of the whole grid.
  [[nodiscard]] Aabb bounds() const noexcept {
    return {origin, origin + cell * glm::vec3(dims)};
  }
  /// Box of cell c (c may lie outside the grid).
  [[nodiscard]] Aabb cell_box(const CellCoord& c) const noexcept {
    const glm::vec3 lo = origin + cell * glm::vec3(c);
    return {lo, lo + cell};
  }
  /// The cell holding point p, not clamped to the grid (p outside gives
  /// coordinates outside [0, dims)); clamped to [-1, dims] per axis.
  [[nodiscard]] CellCoord cell_of(const glm::vec3& p) const noexcept;
  [[nodiscard]] bool contains(const CellCoord& c) const noexcept {
    return c.x >= 0 && c.y >= 0 && c.z >= 0 && c.x < dims.x && c.y < dims.y && c.z < dims.z;
  }
  /// Number of cells, dims.x * dims.y * dims.z.
  [[nodiscard]] std::uint64_t cell_count() const noexcept {
    return std::uint64_t(dims.x) * std::uint64_t(dims.y) * std::uint64_t(dims.z);
  }
};

/// Cells of a grid listing the objects whose boxes touch them. Only cells
/// that ever held an object are stored ("occupied" cells, numbered densely
/// in the order they were first filled); a cell that empties keeps its number.
class UniformGrid {
 public:
  /// Marks "no such occupied cell".
  static constexpr std::uint32_t kNoCell = 0xffffffffu;

  /// An empty grid of this geometry. Precondition: cell edges > 0, dims >= 1.
  explicit UniformGrid(const GridGeometry& geometry);

  /// The grid of a scene with cubic cells of edge `cell_size` (scene units;
  /// 0: default_cell_size(scene)), covering every object and every place a
  /// dynamic object goes (its Scene::dynamic_range, grown by its size), with
  /// every object inserted.
  /// Throws InputError when cell_size is negative, or so small that the grid
  /// would exceed 2^20 cells along an axis or list the objects in more than
  /// 2^26 cells in all.
  [[nodiscard]] static UniformGrid of_scene(const Scene& scene, float cell_size = 0.0f);

  /// Default cell edge of a scene: twice the median of the objects' largest
  /// box extents — an object spans about two cells, so a cell culls a few
  /// objects at a time — but no finer than the scene's longest extent / 256.
  [[nodiscard]] static float default_cell_size(const Scene& scene);

  [[nodiscard]] const GridGeometry& geometry() const noexcept { return geometry_; }

  /// Lists object `id` with box `bounds` in every cell the box touches
  /// (clamped to the grid: a box beyond the grid is listed in its border
  /// cells). Precondition: id not inserted yet, bounds not empty.
  void insert(ObjectId id, const Aabb& bounds);
  /// Moves object `id` to the cells of its new box, touching only the cells
  /// that change. Precondition: id inserted.
  void update(ObjectId id, const Aabb& bounds);

  /// Occupied cells (including ones that emptied since).
  [[nodiscard]] std::uint32_t occupied() const noexcept { return std::uint32_t(coords_.size()); }
  /// The occupied cell at c, or kNoCell.
  [[nodiscard]] std::uint32_t find(const CellCoord& c) const;
  [[nodiscard]] const CellCoord& coord(std::uint32_t cell) const { return coords_[cell]; }
  /// Objects listed in occupied cell `cell` (an object spanning cells is
  /// listed in each of them).
  [[nodiscard]] std::span<const ObjectId> objects(std::uint32_t cell) const { return objects_[cell]; }
  /// Box of what cell `cell` holds: its objects' boxes clipped to the cell
  /// (empty for a cell that emptied). A query of it covers every object
  /// part inside the cell.
  [[nodiscard]] const Aabb& content_box(std::uint32_t cell) const { return content_[cell]; }

 private:
  struct Range {
    CellCoord lo{0}, hi{-1};
  };
  [[nodiscard]] Range range_of(const Aabb& bounds) const noexcept;
  [[nodiscard]] std::uint64_t key(const CellCoord& c) const noexcept;
  void add(const CellCoord& c, ObjectId id, const Aabb& bounds);
  void remove(const CellCoord& c, ObjectId id);
  void refresh_content(const CellCoord& c);

  GridGeometry geometry_;
  std::unordered_map<std::uint64_t, std::uint32_t> index_;  // key(c) -> occupied cell
  std::vector<CellCoord> coords_;
  std::vector<std::vector<ObjectId>> objects_;
  std::vector<Aabb> content_;
  std::vector<Range> object_cells_;  // per object id: the cells it is listed in
  std::vector<Aabb> object_bounds_;  // per object id: the box it was listed with
};

/// A straight run of cells of one traversal: `count` cells from `start`,
/// stepping by `step` (a unit vector along one axis) — visit them in order.
struct CellRun {
  CellCoord start{0};
  CellCoord step{0};
  int count = 0;
};

/// Lists the cells a view's frustum intersects, in occlusion order: a cell
/// that can occlude another from the eye comes first. (Along a ray from the
/// eye every coordinate changes monotonically, so any cell it crosses before
/// cell B lies, per axis, between the eye's cell and B; the traversal keeps
/// that order.)
///
/// The frustum is clipped to the grid and split by the axis-aligned planes
/// bounding the eye's cell into convex pieces: the eye's cell, the rows and
/// slabs of cells it shares one or two coordinates with, and the eight
/// octants. (The thesis splits at the eye into eight; splitting at the faces
/// of its cell instead keeps every cell in exactly one piece.) Pieces are
/// taken fanned out from the eye's cell — by how many coordinates they differ
/// from it — and each is rasterized slice by slice along the dominant view
/// axis, moving away from the eye, row by row within a slice; rows run along
/// the remaining axis with more cells, so runs are long.
class GridTraversal {
 public:
  enum class Mode : std::uint8_t {
    frustum,  ///< only the cells the frustum intersects (within a margin of 1e-4 cell edges)
    box,      ///< every cell of the frustum's bounding box (per piece), as the thesis' simple variant
  };

  /// Cells of `grid` that `view`'s frustum intersects, as runs in occlusion
  /// order (valid until the next call). Each cell appears once.
  std::span<const CellRun> traverse(const GridGeometry& grid, const View& view, Mode mode = Mode::frustum);

 private:
  // Per cell layer along the slicing axis, made in traversal number
  // `stamp`: its rows row_first.. (rows of them), each row's range of cells
  // along the run axis at row_cells_[offset + row - row_first].
  struct Slab {
    std::uint64_t stamp = 0;
    int row_first = 0, rows = 0;
    std::uint32_t offset = 0;
  };
  std::vector<CellRun> runs_;
  std::vector<Slab> slabs_;
  std::vector<glm::ivec2> row_cells_;
  std::uint64_t stamp_ = 0;
};

}  // namespace occull
