// `occull traverse`: the grid's occlusion-order traversal timed on one core over random views.
#include "cli.hpp"
#include "occull/statistics.hpp"
#include "occull/error.hpp"
#include "occull/grid.hpp"
#include "occull/view.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <random>

namespace occull::app {

namespace {

struct TraverseArgs {
  std::string dims = "1000x10x1000";
  int views = 200;
  std::string mode = "frustum";
  float fov = 60.0f;
  unsigned seed = 1;
};

// Times GridTraversal on one core: random views inside a grid of unit
// cells, each looking roughly level (pitch within 20 degrees) with a far
// plane reaching across the whole grid, the worst case for the traversal.
int cmd_traverse(const TraverseArgs& a) {
  int x = 0, y = 0, z = 0;
  char c1 = 0, c2 = 0, extra = 0;
  if (std::sscanf(a.dims.c_str(), "%d%c%d%c%d%c", &x, &c1, &y, &c2, &z, &extra) != 5 || c1 != 'x' || c2 != 'x')
    throw occull::InputError(fmt::format("--dims '{}' is not XxYxZ (e.g. 1000x10x1000)", a.dims));
  if (x < 1 || y < 1 || z < 1 || x > (1 << 20) || y > (1 << 20) || z > (1 << 20))
    throw occull::InputError(fmt::format("--dims {}: each count must be in [1, 2^20]", a.dims));
  if (a.views < 1) throw occull::InputError("--views must be at least 1");
  if (!(a.fov > 1.0f && a.fov < 179.0f)) throw occull::InputError("--fov must be in (1, 179) degrees");
  occull::GridTraversal::Mode mode;
  if (a.mode == "frustum") mode = occull::GridTraversal::Mode::frustum;
  else if (a.mode == "box") mode = occull::GridTraversal::Mode::box;
  else throw occull::InputError(fmt::format("--mode '{}': valid modes are frustum, box", a.mode));

  occull::GridGeometry grid;
  grid.dims = {x, y, z};
  const glm::vec3 size(grid.dims);
  std::mt19937 rng(a.seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  occull::Lens lens;
  lens.fov_y_degrees = a.fov;
  lens.near = 0.1f;
  lens.far = glm::length(size) + 1.0f;
  occull::GridTraversal traversal;
  std::vector<double> us;
  double cells = 0.0, runs = 0.0;
  for (int i = 0; i < a.views; ++i) {
    occull::CameraPose pose;
    pose.position = size * glm::vec3(u(rng), std::min(0.5f, 1.5f / size.y) + 0.5f * u(rng), u(rng));
    pose.yaw = 6.2831853f * u(rng);
    pose.pitch = 0.7f * (u(rng) - 0.5f);
    const occull::View view = occull::make_view(pose, lens, 1280, 720);
    const auto t0 = std::chrono::steady_clock::now();
    const auto list = traversal.traverse(grid, view, mode);
    const auto t1 = std::chrono::steady_clock::now();
    us.push_back(std::chrono::duration<double, std::micro>(t1 - t0).count());
    runs += double(list.size());
    for (const occull::CellRun& r : list) cells += r.count;
  }
  const occull::Summary s = occull::summarize(us);
  fmt::print("grid {} ({} cells), {} views, fov {} deg, far {:.0f} cells, mode {}\n", a.dims,
             grid.cell_count(), a.views, a.fov, lens.far, a.mode);
  fmt::print("traversal per view: median {:.1f} us, p95 {:.1f} us, max {:.1f} us; {:.0f} cells in {:.0f} runs on average\n",
             s.median, s.p95, s.max, cells / a.views, runs / a.views);
  return 0;
}

}  // namespace

Command add_traverse(CLI::App& app) {
  auto a = std::make_shared<TraverseArgs>();
  auto* tv = app.add_subcommand("traverse",
                                "time the grid's occlusion-order traversal on one core over random views "
                                "(far plane across the whole grid)");
  tv->add_option("--dims", a->dims, "grid cells XxYxZ")->capture_default_str();
  tv->add_option("--views", a->views, "random views timed")->capture_default_str();
  tv->add_option("--mode", a->mode, "frustum (the thesis' rasterization) or box (the frustum's bounding box)")
      ->capture_default_str();
  tv->add_option("--fov", a->fov, "vertical field of view, degrees (16:9 viewport)")->capture_default_str();
  tv->add_option("--seed", a->seed, "random seed of the views")->capture_default_str();
  return [a] { return cmd_traverse(*a); };
}

}  // namespace occull::app
