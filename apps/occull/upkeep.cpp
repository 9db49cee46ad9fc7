// `occull upkeep`: the hierarchy's upkeep (Bvh::refit under an engine's moves) timed on one core.
#include "cli.hpp"
#include "occull/bvh.hpp"
#include "occull/error.hpp"
#include "occull/input_limits.hpp"
#include "occull/statistics.hpp"

#include <fmt/format.h>
#include <glm/gtc/matrix_transform.hpp>

#include <chrono>
#include <cmath>
#include <random>

namespace occull::app {

namespace {

struct UpkeepArgs {
  int objects = 40000;
  double moving = 0.1;
  int frames = 1000;
  unsigned seed = 1;
};

// Times the hierarchy's upkeep on one core (Bvh::refit after an engine's
// set_transform calls): random boxes over a 1 km square, a fraction of them
// taking a random step of up to 2 m every frame, drifting over the run.
int cmd_upkeep(const UpkeepArgs& a) {
  if (a.objects < 1 || a.objects > int(occull::limits::objects))
    throw occull::InputError(fmt::format("--objects must be in [1, {}]", occull::limits::objects));
  if (!(a.moving >= 0.0 && a.moving <= 1.0)) throw occull::InputError("--moving must be a fraction in [0, 1]");
  if (a.frames < 1) throw occull::InputError("--frames must be at least 1");
  occull::Scene scene("upkeep");
  const occull::MeshId cube = scene.add_mesh(occull::MeshInfo{{glm::vec3(-0.5f), glm::vec3(0.5f)}, 12, 6.0});
  const occull::MaterialId material = scene.add_material({});
  std::mt19937 rng(a.seed);
  std::uniform_real_distribution<float> at(-500.0f, 500.0f), size(0.5f, 8.0f), step(-2.0f, 2.0f);
  std::vector<glm::vec3> position, scale;
  for (int i = 0; i < a.objects; ++i) {
    position.emplace_back(at(rng), 0.05f * at(rng), at(rng));
    scale.emplace_back(size(rng), size(rng), size(rng));
    (void)scene.add_object(cube, material, glm::scale(glm::translate(glm::mat4(1.0f), position.back()), scale.back()),
                           occull::OccluderClass::sometimes);
  }
  const auto t_build = std::chrono::steady_clock::now();
  occull::Bvh bvh = occull::Bvh::build(scene);
  const double build_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t_build).count();
  const double start_sah = bvh.sah_cost();
  const int moving = int(std::lround(a.moving * a.objects));
  std::uniform_int_distribution<int> pick(0, a.objects - 1);
  std::vector<double> ms;
  for (int f = 0; f < a.frames; ++f) {
    for (int k = 0; k < moving; ++k) {  // the engine's game logic, untimed
      const auto id = std::size_t(pick(rng));
      position[id] += glm::vec3(step(rng), 0.0f, step(rng));
      scene.set_transform(occull::ObjectId(id),
                          glm::scale(glm::translate(glm::mat4(1.0f), position[id]), scale[id]));
    }
    const auto t0 = std::chrono::steady_clock::now();
    bvh.refit(scene);
    ms.push_back(std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
    scene.clear_moved();
  }
  const occull::Summary s = occull::summarize(ms);
  const double fresh = occull::Bvh::build(scene).sah_cost();
  fmt::print("{} objects, {} moved per frame ({:.0f}%), {} frames; a build takes {:.2f} ms\n", a.objects, moving,
             100.0 * a.moving, a.frames, build_ms);
  fmt::print("refit per frame: mean {:.3f} ms, median {:.3f} ms, p95 {:.3f} ms, max {:.3f} ms; {} rebuilds "
             "(SAH past {:.2f}x its last build)\n",
             s.mean, s.median, s.p95, s.max, bvh.generation(), occull::Bvh::kRebuildFactor);
  fmt::print("SAH cost: {:.2f} at the start, {:.2f} now, {:.2f} for a fresh build of the scene now: {:.3f}x fresh\n",
             start_sah, bvh.sah_cost(), fresh, bvh.sah_cost() / fresh);
  return 0;
}

}  // namespace

Command add_upkeep(CLI::App& app) {
  auto a = std::make_shared<UpkeepArgs>();
  auto* up = app.add_subcommand("upkeep",
                                "time the hierarchy's upkeep on one core: random boxes, a fraction moved by the "
                                "engine every frame (set_transform), Bvh::refit timed, SAH cost against a fresh "
                                "build at the end");
  up->add_option("--objects", a->objects, "objects in the scene")->capture_default_str();
  up->add_option("--moving", a->moving, "fraction moved every frame")->capture_default_str();
  up->add_option("--frames", a->frames, "frames")->capture_default_str();
  up->add_option("--seed", a->seed, "random seed")->capture_default_str();
  return [a] { return cmd_upkeep(*a); };
}

}  // namespace occull::app
