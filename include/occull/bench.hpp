// occull — running benches: every algorithm over the same views and
// frames, warmed up, verified and repeated (run_bench), and their summaries.
// Each per-frame counter is declared once in occull/counters.hpp.
#pragma once

#include "occull/session.hpp"
#include "occull/statistics.hpp"

#include <span>
#include <string>
#include <vector>

namespace occull {

struct BenchConfig {
  std::string scene = "city";             ///< scene spec, see make_scene()
  std::string path;                       ///< camera path; empty = the scene's first
  /// Split screen: this many views side by side, each width/views x height,
  /// each on its own path (view_paths, else the scene's paths in turn),
  /// rendered one after the other in every frame with a culler each (grid:
  /// one GridViews sharing its grid and query cap). A frame's figures are
  /// the sums over the views; runs named "ALGO [view K]" hold each view's.
  int views = 1;
  std::vector<std::string> view_paths;    ///< with views > 1: the path of each view (empty: the scene's)
  std::vector<std::string> algorithms;    ///< specs (see parse_algorithm_spec); empty = every algorithm
  int frames = 100;                       ///< timed frames per algorithm and repeat, >= 1
  FrameSampling sampling;                 ///< where they lie on the path (default: spread over it)
  int warmup = 8;                         ///< untimed frames per algorithm and repeat first, >= 0
  int repeat = 1;                         ///< runs of the whole set, interleaved (A B C A B C), >= 1
  bool verify = true;                     ///< check every frame against ground truth
  int width = 1280;                       ///< pixels
  int height = 720;
  Options options;
  gl::QueryMode query_mode = gl::QueryMode::samples_passed;
  gl::QueryRaster query_raster = gl::QueryRaster::margin;  ///< see gl::RendererOptions
  float query_margin_px = gl::RendererOptions{}.query_margin_px;
  gl::DrawMode draw = gl::DrawMode::single;  ///< see gl::RendererOptions::draw
  DepthMode depth = DepthMode::standard;  ///< the views' depth convention (Session::set_depth)
  double engine_moves = 0.0;              ///< fraction of static objects the engine moves each frame (Session::set_engine_moves)
  BvhOptions bvh;                         ///< how the scene's hierarchy is built
  bool model = false;                     ///< also predict each frame with the NOHC cost model
  bool gl_debug = false;                  ///< GL debug contexts (Vulkan: the validation layer): a failing call stops the run
  Api api = Api::gl;                      ///< the graphics API frames render through (occull/render_device.hpp)
  double stall_guard_ms = 0.0;            ///< > 0: results not there within this time count as visible (StallGuard)
  double watchdog_s = 300.0;              ///< a frame running longer stops the process, exit 1 (Session::set_watchdog; 0: off)
  std::string allocator;                  ///< the process's allocator policy, as the report names it (apply_allocator_policy)
  std::shared_ptr<detail::FaultHooks> hooks;  ///< tests only: break a step on purpose (src/lab/fault_hooks.hpp)
};


/// One algorithm over all repeats. Timings and per-frame means are the
/// median over repeats of each repeat's figure (ratios are taken within a
/// repeat first, so drift of a shared machine cancels); correctness figures
/// are the worst repeat's.
struct AlgorithmSummary {
  std::string name;
  bool conservative = true;      ///< its misses are failures; otherwise popping
  Summary frame_ms;
  double ratio_to_vfc = 0.0;     ///< mean frame time / vfc's in the same repeat; 0 if vfc did not run
  double ratio_to_oracle = 0.0;  ///< same against the oracle
  double queries_per_frame = 0.0;
  double multiqueries_per_frame = 0.0;
  double failed_multiqueries_per_frame = 0.0;
  double query_batches_per_frame = 0.0;
  double capped_share = 0.0;              ///< share of frames that reached the query cap (FrameStats::capped)
  double over_cap_per_frame = 0.0;        ///< queries deferred by the cap (FrameStats::over_cap)
  double result_age_frames = 0.0;         ///< mean age of the answers used (FrameStats::result_age)
  double revealed_per_frame = 0.0;        ///< hidden cells drawn in the frame of the query that found them visible
  double state_changes_per_frame = 0.0;
  double render_flushes_per_frame = 0.0;
  double draw_calls_per_frame = 0.0;
  double triangles_per_frame = 0.0;
  double objects_rendered_per_frame = 0.0;
  double conditional_objects_per_frame = 0.0;  ///< drawn under conditional rendering (FrameStats)
  double conditional_skipped_per_frame = 0.0;  ///< ... skipped by the device (FrameStats)
  double stalled_per_frame = 0.0;  ///< query results given up on by --stall-guard (FrameStats::stalled)
  double nodes_visited_per_frame = 0.0;
  double extra_objects_per_frame = 0.0;  ///< over-rendering (verified runs)
  double subpixel_objects_per_frame = 0.0;  ///< objects of the frustum holding no pixel centre (FrameStats::subpixel_objects)
  double wait_ms_per_frame = 0.0;
  double blocking_waits_per_frame = 0.0;  ///< query reads that had to wait (sync points)
  double flushes_per_frame = 0.0;         ///< submissions to the device mid-frame (BackendStats::flushes)
  double cpu_ms_per_frame = 0.0;
  double gpu_ms_per_frame = 0.0;
  double pyramid_ms_per_frame = 0.0;      ///< GPU time building depth pyramids (hiz)
  double device_cull_ms_per_frame = 0.0;  ///< GPU time of device culling's dispatches (hiz)
  double raster_ms_per_frame = 0.0;       ///< CPU time rasterizing occluders (soc)
  double test_ms_per_frame = 0.0;         ///< CPU time testing boxes against the occlusion buffer (soc)
  double occluder_triangles_per_frame = 0.0;  ///< triangles rasterized into the occlusion buffer (soc)
  double boxes_tested_per_frame = 0.0;    ///< boxes tested against the occlusion buffer (soc)
  double buffer_texels = 0.0;             ///< the occlusion buffer's texels (soc; median over frames)
  double occluders_resting_per_frame = 0.0;  ///< occluders left out for hiding nothing lately (soc's rest)
  double model_ms_per_frame = 0.0;        ///< cost-model prediction (0 without --model)
  double auto_tries = 0.0;                ///< auto: tries of a challenger over the run (FrameStats::auto_tries)
  double auto_switches = 0.0;             ///< auto: changes of the culler kept over the run
  /// auto: median over the frames it predicted of |predicted − measured| /
  /// measured frame time (FrameStats::auto_predicted_ms); 0 for the others.
  double auto_prediction_error = 0.0;
  /// auto: each candidate (Culler::choices(), in order) and the share of
  /// the frames it ran, over every repeat; empty for the other cullers.
  std::vector<std::pair<std::string, double>> auto_choices;
  double cpu_us_per_node = 0.0;           ///< culler CPU time per visited node, microseconds (0: no nodes)
  double kernel_ms_per_frame = 0.0;       ///< process CPU time in the kernel (FrameStats::kernel_ms)
  double minor_faults_per_frame = 0.0;    ///< process page faults (FrameStats::minor_faults)
  double major_faults_per_frame = 0.0;
  std::uint64_t missed_objects = 0;       ///< sum over frames of objects missed
  std::uint64_t frames_with_misses = 0;
  std::uint64_t wrong_pixels = 0;         ///< sum over frames
  std::uint64_t worst_frame_wrong_pixels = 0;
  std::uint32_t longest_miss_frames = 0;
  std::uint64_t truth_object_frames = 0;  ///< sum over frames of the objects visible in the truth
  /// Sum over frames of objects left undrawn that only the rasteriser's
  /// depth errors showed (FrameStats::depth_error_objects; not missed).
  std::uint64_t depth_error_objects = 0;
  // Tiled worlds (FrameStats' tile counters): per frame, and in all.
  double tiles_rendered_per_frame = 0.0;
  double tile_queries_per_frame = 0.0;
  double tile_postponed_per_frame = 0.0;
  double tile_prediction_failure_share = 0.0;  ///< prediction failures / tile queries, over the run
  double tiles_instantiated = 0.0;             ///< tile instances created over the run
  double tiles_evicted = 0.0;                  ///< ... and freed
  double tile_cache_max = 0.0;                 ///< most tile instances held after a frame
  double instantiate_ms_per_tile = 0.0;        ///< mean time to create one tile instance, ms
  std::vector<MemorySample> memory;            ///< of the first repeat's run
  std::string first_miss;                      ///< of the first run that missed (AlgorithmRun::first_miss)
  /// missed_objects / truth_object_frames: the share of visible object-frames missed (0 unverified).
  [[nodiscard]] double missed_share() const noexcept {
    return truth_object_frames > 0 ? double(missed_objects) / double(truth_object_frames) : 0.0;
  }
};

struct BenchResult {
  gl::DeviceInfo device;
  std::string commit;  ///< occull's git commit at build time
  std::string scene;
  std::string path;
  std::size_t objects = 0;
  std::uint64_t triangles = 0;
  std::size_t bvh_nodes = 0;
  /// A tiled world in words (its tiles, cells placed, tile BVHs); empty otherwise.
  std::string tiled_world;
  double scene_build_ms = 0.0;
  double bvh_build_ms = 0.0;
  int frames = 0;
  FrameSampling sampling;
  double path_duration_s = 0.0;
  /// How far the camera moves and turns from one frame to the next (the
  /// temporal coherence the cullers see): mean and max, metres and degrees.
  double step_m_mean = 0.0, step_m_max = 0.0, turn_deg_mean = 0.0, turn_deg_max = 0.0;
  int warmup = 0;
  int repeat = 1;
  bool verified = false;
  std::uint64_t truth_probes = 0;    ///< triangles the truth-probe invariant checked, all frames
  std::uint64_t truth_pixels = 0;    ///< pixels the truth covers, summed over frames
  bool modelled = false;          ///< frames carry cost-model predictions
  std::string profile_path;       ///< the hardware profile used (when modelled or nohc ran)
  int width = 0;
  int height = 0;
  std::string query_geometry;                ///< how query boxes were kept conservative (describe_query_raster)
  std::string allocator;                     ///< BenchConfig::allocator ("" when not given)
  /// Run conditions beyond the defaults, for a person: reversed depth,
  /// engine moves ("" when none).
  std::string conditions;
  std::vector<AlgorithmRun> runs;            ///< in execution order
  std::vector<AlgorithmSummary> summaries;   ///< one per algorithm, in the order asked
};

/// Fills what `r` says of the run before its rows: device, commit, path,
/// object, triangle and node counts, build times, frames and the session's
/// sampling, path duration, and how far the camera moves and turns from one
/// frame to the next.
void describe_run(const Session& session, const CameraPath& path, int frames, BenchResult& r);

/// The conservative algorithms of a verified result that missed a visible
/// object (empty when verification passed or did not run).
[[nodiscard]] std::vector<const AlgorithmSummary*> verification_failures(const BenchResult& result);

/// Summaries of `runs` (see AlgorithmSummary), one per algorithm name in
/// first-appearance order.
[[nodiscard]] std::vector<AlgorithmSummary> summarize_runs(std::span<const AlgorithmRun> runs);

/// Runs every algorithm over the same path, `repeat` times interleaved:
/// per algorithm `warmup` frames spread over the path with a throw-away
/// culler, then `frames` timed frames with a fresh one. Throws InputError
/// for unknown names or options, GlUnavailable without a usable OpenGL.
[[nodiscard]] BenchResult run_bench(const BenchConfig& config, const ProgressFn& progress = {});

}  // namespace occull
