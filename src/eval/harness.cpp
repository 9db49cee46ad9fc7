#include "occull/harness.hpp"

#include "occull/error.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <numeric>

namespace occull {
namespace {

using Clock = std::chrono::steady_clock;

double ms_between(Clock::time_point a, Clock::time_point b) {
  return std::chrono::duration<double, std::milli>(b - a).count();
}

SceneBundle timed_make_scene(std::string_view spec, double& ms) {
  const auto t0 = Clock::now();
  SceneBundle b = make_scene(spec);
  ms = ms_between(t0, Clock::now());
  return b;
}

}  // namespace

// The scene first: a bad spec is reported before any GL work.
Session::Session(std::string_view scene_spec, const gl::RendererOptions& renderer_options)
    : bundle_(timed_make_scene(scene_spec, scene_build_ms_)) {
  const auto t0 = Clock::now();
  bvh_ = Bvh::build(bundle_.scene);
  bvh_build_ms_ = ms_between(t0, Clock::now());
  context_ = gl::Context::create();
  device_ = context_->info();
  renderer_ = std::make_unique<gl::Renderer>(bundle_.scene, renderer_options);
}

Session::~Session() {
  renderer_.reset();  // GL objects go before the context
  context_.reset();
}

View Session::view_at(const CameraPath& path, int k, int frames) const {
  return make_view(path.sample(path.frame_time(k, frames)), bundle_.lens, renderer_->width(),
                   renderer_->height());
}

FrameStats Session::run_frame(Culler& culler, const View& view, double time_s) {
  bundle_.scene.update(time_s);
  const auto t0 = Clock::now();
  bvh_.refit(bundle_.scene);
  renderer_->begin_frame(view);
  const BackendStats before = renderer_->stats();
  const auto c0 = Clock::now();
  FrameStats s = culler.render_frame(view, *renderer_);
  const auto c1 = Clock::now();
  const BackendStats during = renderer_->stats() - before;
  s.gpu_ms = renderer_->end_frame();
  const auto t1 = Clock::now();
  const BackendStats d = renderer_->stats() - before;
  s.frame_ms = ms_between(t0, t1);
  s.cpu_ms = std::max(0.0, ms_between(c0, c1) - during.backend_ms);
  s.wait_ms = d.wait_ms;
  s.queries = d.queries;
  s.query_boxes = d.query_boxes;
  s.state_changes = d.state_changes;
  s.material_changes = d.material_changes;
  s.render_flushes = d.render_flushes;
  s.draw_calls = d.draw_calls;
  s.triangles = d.triangles;
  s.objects_rendered = d.objects_rendered;
  return s;
}

Summary summarize(std::vector<double> v) {
  Summary s;
  if (v.empty()) return s;
  std::sort(v.begin(), v.end());
  s.mean = std::accumulate(v.begin(), v.end(), 0.0) / double(v.size());
  const std::size_t n = v.size();
  s.median = n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
  // Nearest-rank percentile.
  const auto rank = std::size_t(std::ceil(0.95 * double(n)));
  s.p95 = v[std::min(n, std::max<std::size_t>(rank, 1)) - 1];
  s.max = v.back();
  return s;
}

BenchResult run_bench(const BenchConfig& config, const ProgressFn& progress) {
  if (config.frames < 1) throw InputError("--frames must be at least 1");
  if (config.warmup < 0) throw InputError("--warmup must not be negative");
  std::vector<std::string> names = config.algorithms;
  if (names.empty())
    for (const auto& a : algorithms()) names.push_back(a.name);
  // Validate names and options before the (slow) scene set-up.
  for (const auto& n : names) (void)find_algorithm(n);
  check_options(config.options);
  gl::RendererOptions ropts;
  ropts.width = config.width;
  ropts.height = config.height;
  ropts.query_mode = config.query_mode;
  ropts.write_ids = false;
  ropts.multi_draw = config.multi_draw;
  Session session(config.scene, ropts);
  const CameraPath& path = config.path.empty() ? session.bundle().paths.front()
                                               : session.bundle().path(config.path);

  BenchResult result;
  result.device = session.device();
  result.scene = config.scene;
  result.path = path.name();
  result.objects = session.bundle().scene.objects().size();
  result.triangles = session.bundle().scene.triangle_count();
  result.bvh_nodes = session.bvh().size();
  result.scene_build_ms = session.scene_build_ms();
  result.bvh_build_ms = session.bvh_build_ms();
  result.frames = config.frames;
  result.width = config.width;
  result.height = config.height;

  for (const auto& name : names) {
    {
      auto warm = make_culler(name, session.index(), config.options);
      for (int k = 0; k < config.warmup; ++k) {
        const int f = config.warmup > 1 ? k * (config.frames - 1) / (config.warmup - 1) : 0;
        session.run_frame(*warm, session.view_at(path, f, config.frames),
                          path.frame_time(f, config.frames));
        if (progress) progress(name, k, config.warmup, true);
      }
    }
    AlgorithmRun run{name, {}};
    run.frames.reserve(std::size_t(config.frames));
    auto culler = make_culler(name, session.index(), config.options);
    for (int k = 0; k < config.frames; ++k) {
      run.frames.push_back(session.run_frame(*culler, session.view_at(path, k, config.frames),
                                             path.frame_time(k, config.frames)));
      if (progress) progress(name, k, config.frames, false);
    }
    result.runs.push_back(std::move(run));
  }
  return result;
}

}  // namespace occull
