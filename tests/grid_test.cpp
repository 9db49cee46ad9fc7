#include "occull/grid.hpp"

#include "occull/error.hpp"
#include "occull/scenes.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <map>
#include <random>
#include <set>

using namespace occull;

namespace {

GridGeometry unit_grid(glm::ivec3 dims, glm::vec3 cell = glm::vec3(1.0f)) {
  GridGeometry g;
  g.dims = dims;
  g.cell = cell;
  return g;
}

std::vector<ObjectId> listed(const UniformGrid& grid, const CellCoord& c) {
  const std::uint32_t cell = grid.find(c);
  if (cell == UniformGrid::kNoCell) return {};
  std::vector<ObjectId> out(grid.objects(cell).begin(), grid.objects(cell).end());
  std::sort(out.begin(), out.end());
  return out;
}

// Separating-axis test of a box against the frustum of `view` (both convex),
// independent of the traversal's clipping: true when they overlap.
bool box_meets_frustum(const Aabb& box, const View& view) {
  const glm::dmat4 inv = glm::inverse(glm::dmat4(view.view_proj));
  std::array<glm::dvec3, 8> fc, bc;
  for (int i = 0; i < 8; ++i) {
    const glm::dvec4 p = inv * glm::dvec4((i & 1) ? 1 : -1, (i & 2) ? 1 : -1, (i & 4) ? 1 : -1, 1);
    fc[std::size_t(i)] = glm::dvec3(p) / p.w;
    bc[std::size_t(i)] = glm::dvec3(box.corner(i));
  }
  std::vector<glm::dvec3> axes = {{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  for (int i = 0; i < 6; ++i) axes.push_back(glm::dvec3(view.frustum.plane(i).n));
  const std::array<std::array<int, 2>, 12> edges = {{{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                                     {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}}};
  for (const auto& e : edges)
    for (const glm::dvec3 a : {glm::dvec3(1, 0, 0), glm::dvec3(0, 1, 0), glm::dvec3(0, 0, 1)}) {
      const glm::dvec3 c = glm::cross(fc[std::size_t(e[1])] - fc[std::size_t(e[0])], a);
      if (glm::length(c) > 1e-9) axes.push_back(glm::normalize(c));
    }
  for (const glm::dvec3& a : axes) {
    double f0 = 1e300, f1 = -1e300, b0 = 1e300, b1 = -1e300;
    for (const auto& p : fc) {
      f0 = std::min(f0, glm::dot(a, p));
      f1 = std::max(f1, glm::dot(a, p));
    }
    for (const auto& p : bc) {
      b0 = std::min(b0, glm::dot(a, p));
      b1 = std::max(b1, glm::dot(a, p));
    }
    if (f1 < b0 || b1 < f0) return false;
  }
  return true;
}

std::vector<CellCoord> cells_of(std::span<const CellRun> runs) {
  std::vector<CellCoord> out;
  for (const CellRun& r : runs)
    for (int i = 0; i < r.count; ++i) out.push_back(r.start + r.step * i);
  return out;
}

// Whether cell a can occlude cell b from an eye in cell e: along any ray
// from the eye each coordinate changes monotonically, so a cell crossed
// before b lies, per axis, between e and b.
bool can_occlude(const CellCoord& a, const CellCoord& b, const CellCoord& e) {
  if (a == b) return false;
  for (int k = 0; k < 3; ++k)
    if (a[k] < std::min(e[k], b[k]) || a[k] > std::max(e[k], b[k])) return false;
  return true;
}

struct Scenario {
  GridGeometry grid;
  View view;
};

Scenario random_scenario(std::mt19937& rng) {
  std::uniform_int_distribution<int> dim(1, 12);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Scenario s;
  s.grid = unit_grid({dim(rng), dim(rng) / 2 + 1, dim(rng)}, {0.5f + 2.0f * u(rng), 0.5f + u(rng), 0.5f + 2.0f * u(rng)});
  s.grid.origin = {-3.0f * u(rng), -1.0f * u(rng), -3.0f * u(rng)};
  const Aabb b = s.grid.bounds();
  CameraPose pose;
  // Mostly inside the grid, sometimes outside it.
  pose.position = b.min + (b.max - b.min) * glm::vec3(1.4f * u(rng) - 0.2f, 1.4f * u(rng) - 0.2f, 1.4f * u(rng) - 0.2f);
  pose.yaw = 6.2831853f * u(rng);
  pose.pitch = 2.8f * (u(rng) - 0.5f);
  Lens lens;
  lens.fov_y_degrees = 30.0f + 90.0f * u(rng);
  lens.near = 0.05f + 0.5f * u(rng);
  lens.far = lens.near + 2.0f + 30.0f * u(rng);
  s.view = make_view(pose, lens, 160 + int(200 * u(rng)), 90 + int(100 * u(rng)));
  return s;
}

}  // namespace

TEST(UniformGrid, ListsAnObjectInEveryCellItsBoxTouches) {
  UniformGrid grid(unit_grid({4, 1, 4}));
  grid.insert(7, Aabb{{0.5f, 0.2f, 0.5f}, {2.5f, 0.8f, 1.5f}});
  for (int x = 0; x < 4; ++x)
    for (int z = 0; z < 4; ++z) {
      const bool touched = x <= 2 && z <= 1;
      EXPECT_EQ(listed(grid, {x, 0, z}), touched ? std::vector<ObjectId>{7} : std::vector<ObjectId>{})
          << x << "," << z;
    }
  EXPECT_EQ(grid.occupied(), 6u);
  // Its content box in a cell is the part of its box inside that cell.
  const Aabb part = grid.content_box(grid.find({0, 0, 0}));
  EXPECT_EQ(part.min, glm::vec3(0.5f, 0.2f, 0.5f));
  EXPECT_EQ(part.max, glm::vec3(1.0f, 0.8f, 1.0f));
}

TEST(UniformGrid, MovesAnObjectBetweenCellsWithoutARebuild) {
  UniformGrid grid(unit_grid({5, 1, 1}));
  grid.insert(1, Aabb{{0.1f, 0.1f, 0.1f}, {0.9f, 0.9f, 0.9f}});
  grid.insert(2, Aabb{{0.2f, 0.2f, 0.2f}, {1.5f, 0.5f, 0.5f}});
  grid.update(2, Aabb{{3.2f, 0.2f, 0.2f}, {4.5f, 0.5f, 0.5f}});
  EXPECT_EQ(listed(grid, {0, 0, 0}), std::vector<ObjectId>{1});
  EXPECT_TRUE(listed(grid, {1, 0, 0}).empty());
  EXPECT_EQ(listed(grid, {3, 0, 0}), std::vector<ObjectId>{2});
  EXPECT_EQ(listed(grid, {4, 0, 0}), std::vector<ObjectId>{2});
  // A cell that emptied has an empty content box; one it stayed in shrinks to it.
  EXPECT_TRUE(grid.content_box(grid.find({1, 0, 0})).empty());
  EXPECT_EQ(grid.content_box(grid.find({0, 0, 0})).max, glm::vec3(0.9f));
  grid.update(1, Aabb{{0.1f, 0.1f, 0.1f}, {0.3f, 0.3f, 0.3f}});
  EXPECT_EQ(grid.content_box(grid.find({0, 0, 0})).max, glm::vec3(0.3f));
}

TEST(UniformGrid, StoresOnlyOccupiedCellsOfAHugeGrid) {
  UniformGrid grid(unit_grid({1000, 10, 1000}));
  grid.insert(0, Aabb{{10.5f, 0.5f, 10.5f}, {11.5f, 0.9f, 10.9f}});
  grid.insert(1, Aabb{{999.2f, 9.2f, 999.2f}, {999.8f, 9.8f, 999.8f}});
  EXPECT_EQ(grid.occupied(), 3u);
  EXPECT_EQ(listed(grid, {999, 9, 999}), std::vector<ObjectId>{1});
  EXPECT_EQ(grid.find({500, 5, 500}), UniformGrid::kNoCell);
  EXPECT_EQ(grid.find({-1, 0, 0}), UniformGrid::kNoCell);
}

TEST(UniformGrid, OfASceneCoversEveryObjectWithCellsAboutTwiceTheMedianObject) {
  const SceneBundle city = make_scene("city");
  const UniformGrid grid = UniformGrid::of_scene(city.scene);
  EXPECT_TRUE(grid.geometry().bounds().contains(city.scene.bounds()));
  std::set<ObjectId> seen;
  for (std::uint32_t c = 0; c < grid.occupied(); ++c)
    for (ObjectId id : grid.objects(c)) seen.insert(id);
  EXPECT_EQ(seen.size(), city.scene.objects().size());
  EXPECT_GT(grid.geometry().cell.x, 0.0f);
  EXPECT_THROW((void)UniformGrid::of_scene(city.scene, -1.0f), InputError);
  EXPECT_THROW((void)UniformGrid::of_scene(city.scene, 1e-6f), InputError);
}

// The thesis' traversal claims, over random grids and views (eyes inside
// and outside the grid, any direction, wide and narrow lenses).
TEST(GridTraversal, VisitsEveryCellTheFrustumMeetsOnceNoneOutsideAndOccludersFirst) {
  std::mt19937 rng(12345);
  GridTraversal traversal;
  int nonempty = 0;
  for (int trial = 0; trial < 300; ++trial) {
    const Scenario s = random_scenario(rng);
    const std::vector<CellCoord> order = cells_of(traversal.traverse(s.grid, s.view));
    std::map<std::tuple<int, int, int>, std::size_t> position;
    for (std::size_t i = 0; i < order.size(); ++i) {
      const CellCoord& c = order[i];
      ASSERT_TRUE(s.grid.contains(c)) << "trial " << trial;
      ASSERT_TRUE(position.emplace(std::tuple(c.x, c.y, c.z), i).second) << "trial " << trial << ": visited twice";
    }
    nonempty += order.empty() ? 0 : 1;
    const float slack = 2e-3f * std::min({s.grid.cell.x, s.grid.cell.y, s.grid.cell.z});
    for (int x = 0; x < s.grid.dims.x; ++x)
      for (int y = 0; y < s.grid.dims.y; ++y)
        for (int z = 0; z < s.grid.dims.z; ++z) {
          const Aabb box = s.grid.cell_box({x, y, z});
          const bool visited = position.count(std::tuple(x, y, z)) != 0;
          if (box_meets_frustum(box.grown(-slack), s.view))
            ASSERT_TRUE(visited) << "trial " << trial << ": cell " << x << "," << y << "," << z << " missed";
          if (!box_meets_frustum(box.grown(slack), s.view))
            ASSERT_FALSE(visited) << "trial " << trial << ": cell " << x << "," << y << "," << z << " is outside";
        }
    const CellCoord eye = s.grid.cell_of(s.view.eye);
    for (std::size_t i = 0; i < order.size(); ++i)
      for (std::size_t j = 0; j < i; ++j)
        ASSERT_FALSE(can_occlude(order[i], order[j], eye))
            << "trial " << trial << ": a cell came before a cell that can occlude it";
  }
  EXPECT_GT(nonempty, 200);  // the scenarios do look at the grid
}

TEST(GridTraversal, BoxModeVisitsASupersetOnceInOcclusionOrder) {
  std::mt19937 rng(777);
  GridTraversal traversal;
  for (int trial = 0; trial < 100; ++trial) {
    const Scenario s = random_scenario(rng);
    const std::vector<CellCoord> tight = cells_of(traversal.traverse(s.grid, s.view));
    const std::vector<CellCoord> box = cells_of(traversal.traverse(s.grid, s.view, GridTraversal::Mode::box));
    std::set<std::tuple<int, int, int>> in_box;
    for (const CellCoord& c : box) ASSERT_TRUE(in_box.emplace(c.x, c.y, c.z).second) << "trial " << trial;
    for (const CellCoord& c : tight) ASSERT_TRUE(in_box.count({c.x, c.y, c.z})) << "trial " << trial;
    const CellCoord eye = s.grid.cell_of(s.view.eye);
    for (std::size_t i = 0; i < box.size(); ++i)
      for (std::size_t j = 0; j < i; ++j) ASSERT_FALSE(can_occlude(box[i], box[j], eye)) << "trial " << trial;
  }
}
