// occull — the measuring harness: flies a camera path through a scene with
// each culler on the reference renderer and records what every frame cost.
#pragma once

#include "occull/bvh.hpp"
#include "occull/culler.hpp"
#include "occull/gl/context.hpp"
#include "occull/gl/renderer.hpp"
#include "occull/scenes.hpp"
#include "occull/stats.hpp"

#include <functional>
#include <iosfwd>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace occull {

/// A scene set up on the GL device: the context, the generated scene with
/// its paths, its BVH and the renderer. Everything a run of frames needs.
class Session {
 public:
  /// Creates the GL context (throws GlUnavailable), builds the scene from
  /// `scene_spec` (throws InputError) and its BVH, and the renderer.
  Session(std::string_view scene_spec, const gl::RendererOptions& renderer_options);
  ~Session();

  /// Runs one frame: moves dynamic objects to `time_s` (untimed), then
  /// times refit, begin_frame, the culler and end_frame (closed by
  /// glFinish). Fills every timing and backend counter of the result.
  FrameStats run_frame(Culler& culler, const View& view, double time_s);

  /// View of `path` at frame k of `frames`.
  [[nodiscard]] View view_at(const CameraPath& path, int k, int frames) const;

  [[nodiscard]] const SceneBundle& bundle() const noexcept { return bundle_; }
  [[nodiscard]] SceneIndex index() const noexcept { return {bundle_.scene, bvh_}; }
  [[nodiscard]] gl::Renderer& renderer() noexcept { return *renderer_; }
  [[nodiscard]] const gl::DeviceInfo& device() const noexcept { return device_; }
  [[nodiscard]] double scene_build_ms() const noexcept { return scene_build_ms_; }
  [[nodiscard]] double bvh_build_ms() const noexcept { return bvh_build_ms_; }
  [[nodiscard]] const Bvh& bvh() const noexcept { return bvh_; }

 private:
  // Declared (so initialised) before bundle_, which records into it.
  double scene_build_ms_ = 0.0;
  double bvh_build_ms_ = 0.0;
  std::unique_ptr<gl::Context> context_;
  gl::DeviceInfo device_;
  SceneBundle bundle_;
  Bvh bvh_;
  std::unique_ptr<gl::Renderer> renderer_;
};

struct BenchConfig {
  std::string scene = "city";             ///< scene spec, see make_scene()
  std::string path;                       ///< camera path; empty = the scene's first
  std::vector<std::string> algorithms;    ///< empty = every algorithm
  int frames = 100;                       ///< timed frames per algorithm, >= 1
  int warmup = 8;                         ///< untimed frames per algorithm first, >= 0
  int width = 1280;                       ///< pixels
  int height = 720;
  Options options;
  gl::QueryMode query_mode = gl::QueryMode::samples_passed;
  bool multi_draw = false;                ///< see gl::RendererOptions::multi_draw
};

struct AlgorithmRun {
  std::string name;
  std::vector<FrameStats> frames;
};

struct BenchResult {
  gl::DeviceInfo device;
  std::string scene;
  std::string path;
  std::size_t objects = 0;
  std::uint64_t triangles = 0;
  std::size_t bvh_nodes = 0;
  double scene_build_ms = 0.0;
  double bvh_build_ms = 0.0;
  int frames = 0;
  int width = 0;
  int height = 0;
  std::vector<AlgorithmRun> runs;
};

/// Mean, median, 95th percentile and maximum of a sample (all 0 when empty).
struct Summary {
  double mean = 0.0, median = 0.0, p95 = 0.0, max = 0.0;
};
[[nodiscard]] Summary summarize(std::vector<double> values);

/// Called after each frame: algorithm, frame index (0-based), frame count,
/// and whether the frame was a warm-up frame.
using ProgressFn = std::function<void(std::string_view algorithm, int frame, int frames, bool warmup)>;

/// Runs every algorithm over the same path, one after another: `warmup`
/// frames spread over the path with a throw-away culler, then `frames`
/// timed frames with a fresh one. Throws InputError for unknown names or
/// options, GlUnavailable without a usable OpenGL.
[[nodiscard]] BenchResult run_bench(const BenchConfig& config, const ProgressFn& progress = {});

/// The per-algorithm table: frame ms mean / median / p95 / max, ratio to
/// vfc (when it ran), draw calls, triangles and objects rendered per frame,
/// culler CPU ms per frame.
void print_table(const BenchResult& result, std::ostream& out);

}  // namespace occull
