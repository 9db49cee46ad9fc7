// occull — a scene set up on the GL device for runs of frames (Session),
// the ground truth of a frame and the verification of a culler's frames
// against it. The lab's bench types are in occull/bench.hpp.
//
// Ground truth: an untimed pass per frame renders every object inside the
// view frustum into the object-id buffer; the truth set is every object with
// at least one pixel (translucent objects: at least one sample passing the
// depth test). It depends only on the frame, so it is computed once per
// frame and shared by every algorithm and repeat.
//
// Verification compares what an algorithm rendered in a timed frame with
// that truth, outside the timed region. An object in the truth set that the
// algorithm did not render is *missed*. Because the algorithm draws a subset
// of the objects with the same depth test, every object it did render owns
// exactly its truth pixels in its own image, so the pixels its image gets
// wrong are exactly the truth pixels of the missed objects (`wrong_pixels`).
// Timed frames are identical with and without verification.
#pragma once

#include "occull/bvh.hpp"
#include "occull/cost_model.hpp"
#include "occull/culler.hpp"
#include "occull/frame_log.hpp"
#include "occull/recording_backend.hpp"
#include "occull/render_device.hpp"
#include "occull/gl/context.hpp"
#include "occull/gl/renderer.hpp"
#include "occull/scenes.hpp"
#include "occull/stall_guard.hpp"
#include "occull/stats.hpp"

#include <functional>
#include <iosfwd>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

namespace occull {

namespace detail {
class Watchdog;    // src/lab/watchdog.hpp
struct FaultHooks;  // src/lab/fault_hooks.hpp (tests only)
struct FrameLabel;  // src/lab/invariants.hpp
}  // namespace detail

/// Where opaque geometry covers an image: one bit per pixel (row-major,
/// bottom row first, bit i of word i / 64), how many pixels, and a hash of
/// the depth image (equal hashes: bit-identical depth).
struct Coverage {
  std::vector<std::uint64_t> bits;
  std::uint64_t pixels = 0;
  std::uint64_t depth_hash = 0;
};

/// Ground truth of one frame.
struct FrameTruth {
  std::vector<gl::Renderer::ObjectPixels> visible;  ///< objects with a visible pixel, sorted by id
  Coverage coverage;                                ///< of the truth pass's depth image
  std::uint32_t probes = 0;  ///< triangles the CPU probe (truth-probe) checked in this frame
  /// The objects of `visible` that the image shows only through the
  /// rasteriser's depth errors (seen_only_through_depth_errors), ascending:
  /// leaving one out is not a miss. Usually empty.
  std::vector<ObjectId> depth_error_only;
  /// Objects of the frustum whose boxes hold no sample (holds_no_sample):
  /// none of them is in `visible` (invariant truth-holds-samples).
  std::uint32_t subpixel = 0;
  /// Filled only when the session was asked (Session::set_box_reach): the
  /// objects of the frustum whose boxes reach in front of the truth's depth
  /// (boxes_reaching_depth), ascending. Every object of `visible` but those
  /// of `depth_error_only` is among them (invariant box-reach-holds-truth).
  std::vector<ObjectId> box_reach;
};

/// The share of the distance from the eye by which a pixel's depth may lie
/// nearer than where the pixel's ray enters its object's box (grown as
/// seen_only_through_depth_errors says) and still be taken as the object's
/// own surface: arithmetic noise of the check itself.
inline constexpr double kDepthErrorTolerance = 1e-4;

/// The objects of an id image (row-major, bottom row first; 0 background,
/// else id + 1) every one of whose pixels lies, by the depth image beside
/// it (canonical window depth, read_depth()), nearer to the eye than where
/// the pixel centre's ray enters the object's box — by more than
/// kDepthErrorTolerance of that distance, with the depth read at its
/// farthest within float precision (4 units in the last place of a window
/// depth near 1) and the box grown by what a correct rasteriser may put between a
/// surface and its pixels (2^-16 of the coordinates' magnitude for their
/// float precision, and a 64th of a pixel at that depth for vertex
/// snapping). No surface of the object lies there: the rasteriser put it
/// there. Mesa's llvmpipe does, in its early depth test, for sub-pixel
/// sliver triangles (a terrain seen edge-on far away): it extrapolates
/// their depth outside their vertices' range, so a tile 528 m away shows one pixel at 206 m, through
/// a rock at 417 m (docs/lab.md, "Depth errors of the rasteriser").
/// A pixel whose ray misses the box (snapping widened the outline) or
/// starts inside it counts as the object's own. Ascending ids.
/// Preconditions: ids and depth hold width * height values, `view` is the
/// one they were drawn with.
[[nodiscard]] std::vector<ObjectId> seen_only_through_depth_errors(const Scene& scene, const View& view,
                                                                   std::span<const std::uint32_t> ids,
                                                                   std::span<const float> depth, int width,
                                                                   int height);

/// The objects of `objects` whose boxes reach in front of the depth image
/// (canonical window depth, read_depth(); width * height values, bottom row
/// first) at some pixel centre: where the pixel's ray enters the box, grown
/// and with the depth read at its farthest as seen_only_through_depth_errors
/// does, no nearer than kDepthErrorTolerance of its distance behind the
/// pixel's depth (a pixel showing nothing: anywhere along its ray). A
/// box that reaches the near plane counts as reaching. Ascending ids.
///
/// It is the bound of every culler that decides an object by a test of its
/// own box against the depth of other objects (queries, soc's buffer, hiz's
/// pyramid): the depth they test against lies at or behind the full scene's
/// at each pixel, so each draws at least these objects (and leaves out at
/// most those of the frustum that are not). `oracle:set=boxes` draws them.
[[nodiscard]] std::vector<ObjectId> boxes_reaching_depth(const Scene& scene, const View& view,
                                                         std::span<const ObjectId> objects,
                                                         std::span<const float> depth, int width, int height);

/// Called as work progresses: a label (algorithm name, or "ground truth"),
/// the step just done (0-based), the number of steps, and whether it was a
/// warm-up step. With 0 steps the label is a message line of its own (e.g.
/// "calibrating the hardware cost model").
using ProgressFn = std::function<void(std::string_view label, int step, int steps, bool warmup)>;

/// Verification of one frame: fills truth_objects, missed_objects,
/// wrong_pixels, extra_objects and depth_error_objects of `stats` from the
/// frame's truth and the objects the algorithm rendered (duplicates
/// allowed), and returns the missed ids (ascending). `object_count` is the
/// scene's object count. An object of `depth_error_only` (ascending; the
/// truth's FrameTruth::depth_error_only) left out is not missed: it counts
/// in depth_error_objects.
std::vector<ObjectId> check_frame(std::span<const gl::Renderer::ObjectPixels> truth,
                                  std::span<const ObjectId> rendered, std::size_t object_count,
                                  FrameStats& stats, std::span<const ObjectId> depth_error_only = {});

/// The process's memory after a frame of a run (every kMemorySampleFrames).
struct MemorySample {
  int frame = 0;        ///< frames of the run done (1000, 2000, ...)
  double rss_mb = 0.0;  ///< resident set of the process, MiB
  double gpu_mb = 0.0;  ///< the renderer's buffer objects as GL sizes them, MiB
};
/// Frames between two MemorySamples of a run.
inline constexpr int kMemorySampleFrames = 1000;

/// Frames of one algorithm over a path (one repeat).
struct AlgorithmRun {
  std::string name;
  int repeat = 0;
  bool conservative = true;  ///< must miss nothing (is_conservative of its spec)
  std::vector<FrameStats> frames;
  std::uint32_t longest_miss_frames = 0;  ///< longest run of frames one object stayed missed
  std::vector<MemorySample> memory;       ///< after every kMemorySampleFrames frames
  std::string first_miss;                 ///< "frame K: <describe_object>" of the first missed object; empty if none
  std::vector<std::string> choices;       ///< the culler's Culler::choices() (auto's candidates), numbered by FrameStats::auto_choice
};

/// How long objects stay missed over consecutive frames of one run.
class MissRuns {
 public:
  explicit MissRuns(std::size_t objects) : run_(objects, 0) {}
  /// The missed ids of the next frame (ascending, as check_frame returns them).
  void add(const std::vector<ObjectId>& missed);
  /// Longest run of consecutive frames one object stayed missed so far.
  [[nodiscard]] std::uint32_t longest() const noexcept { return longest_; }

 private:
  std::vector<std::uint32_t> run_;
  std::vector<ObjectId> previous_;
  std::uint32_t longest_ = 0;
};

/// A scene set up on the GL device: the context, the generated scene with
/// its paths, its BVH and the renderer. Everything a run of frames needs.
///
/// Verified runs check the run-time invariants of src/lab/invariants.hpp
/// on every frame (the truth pass covers what the full scene shows, the
/// truth is non-empty where anything is drawn, an independent CPU probe of
/// sampled triangles, every algorithm frame within the truth, the oracle
/// reproducing it exactly) and throw InvariantViolation on the first that
/// fails.
class Session {
 public:
  /// Builds the scene from `scene_spec` (throws InputError) and its BVH,
  /// then creates the context and the renderer of `api` (occull/render_device.hpp:
  /// throws GlUnavailable or VulkanUnavailable; InputError for an option
  /// the API does not have).
  Session(std::string_view scene_spec, const gl::RendererOptions& renderer_options,
          const BvhOptions& bvh_options = {}, const gl::ContextOptions& context_options = {}, Api api = Api::gl);
  /// The same over a scene made elsewhere (a model converted by its
  /// owner: `occull osg --file`), named `name` in messages and reports.
  Session(std::string name, SceneBundle bundle, const gl::RendererOptions& renderer_options,
          const BvhOptions& bvh_options = {}, const gl::ContextOptions& context_options = {}, Api api = Api::gl);
  ~Session();
  Session(const Session&) = delete;
  Session& operator=(const Session&) = delete;

  /// Replaces the context and the renderer by fresh ones, so one
  /// algorithm's run cannot leave driver state that slows the next (seen on
  /// llvmpipe: after `perobject`'s thousands of small flushes per frame,
  /// chc/chcpp in the same context ran 10-20% slower for the rest of the
  /// process). Costs a fraction of a second.
  ///
  /// The replaced context is not destroyed at once: it stays, idle, until
  /// the next replacement (or the session's end) destroys it. Destroyed
  /// right after its last frame, llvmpipe's rasterizer threads could still
  /// be leaving that frame's scene when the context freed it, and about one
  /// bench in 25-120 died of heap corruption in the next algorithm's first
  /// frames (docs/performance.md, "A crash in the driver").
  void reset_renderer();

  /// Runs one frame: moves dynamic objects to `time_s` (untimed), then
  /// times refit, begin_frame, the culler and end_frame (closed by
  /// glFinish). Fills every timing and backend counter of the result.
  /// With `log`, also logs the culler's backend calls into it (the debug
  /// views; the log costs time of its own): the culler then renders through
  /// the session's LoggingBackend, a decorator over the same device.
  FrameStats run_frame(Culler& culler, const View& view, double time_s, FrameLog* log = nullptr);

  /// Hands back every query `culler` holds (Culler::release) through the
  /// session's backend. Call it when a culler's run ends, before the culler
  /// goes and before reset_renderer().
  void release(Culler& culler);
  /// The run-time invariant "queries-returned": the renderer has no query in
  /// flight but those the stall guard gave up on. Call it once every culler
  /// of a run was released; throws InvariantViolation naming `who` otherwise.
  void check_queries_returned(std::string_view who) const;

  /// The ground truth of frames 0..frames-1 of `path` (untimed), each
  /// frame checked by the truth invariants. Throws InvariantViolation.
  [[nodiscard]] std::vector<FrameTruth> ground_truth(const CameraPath& path, int frames,
                                                     const ProgressFn& progress = {});
  /// The ground truth of frame k of `frames` along `path` alone (untimed;
  /// moves the scene to that frame's time), checked as ground_truth()'s.
  /// Overwrites the renderer's targets.
  [[nodiscard]] FrameTruth truth_at(const CameraPath& path, int k, int frames);
  /// The ground truth of `view` over the scene as it stands (a free camera:
  /// occull view), checked as ground_truth()'s. Overwrites the renderer's targets.
  [[nodiscard]] FrameTruth truth_of(const View& view);

  /// Tests only: hooks that break a step on purpose
  /// (src/lab/fault_hooks.hpp); none by default.
  void set_fault_hooks(std::shared_ptr<const detail::FaultHooks> hooks) { hooks_ = std::move(hooks); }

  /// Makes a culler from an algorithm spec ("chcpp" or
  /// "chcpp:multiquery=off", see parse_algorithm_spec) for this scene;
  /// `oracle` too (run_path feeds it the truth). A culler that needs nohc's
  /// hardware profile and is given no file gets hardware_profile(), which
  /// calibrates on first use (its lines go to `progress`). Throws
  /// InputError like make_culler().
  [[nodiscard]] std::unique_ptr<Culler> make(std::string_view spec, const Options& options,
                                             const std::function<void(const std::string&)>& progress = {});
  /// What cullers made for this session get: nohc's profile from
  /// hardware_profile() (calibrated on first use, its lines to `progress`).
  /// Valid while the session lives.
  [[nodiscard]] CullerContext culler_context(const std::function<void(const std::string&)>& progress = {});
  /// Whether hardware_profile() has been loaded or calibrated in this session.
  [[nodiscard]] bool has_hardware_profile() const noexcept { return profile_.has_value(); }

  /// Runs frame k of `frames` along `path` (feeding the oracle that
  /// frame's truth; it needs `truth`). Timings as run_frame.
  FrameStats run_path_frame(Culler& culler, const CameraPath& path, int k, int frames,
                            const std::vector<FrameTruth>* truth);

  /// Checks the frame `culler` just ran (frame k of `path`) against its
  /// truth, outside the timed region: frame-within-truth, and
  /// oracle-draws-truth for the oracle (throw InvariantViolation); fills
  /// the verification figures of `stats` and returns the missed ids.
  std::vector<ObjectId> verify_frame(std::string_view name, const Culler& culler, const CameraPath& path, int k,
                                     const FrameTruth& truth, FrameStats& stats);
  /// What object `id` is now, for a person: "tile city-3 at (0, -97),
  /// object 12" in a tiled world (its ids are reused as the window moves),
  /// else "object 812 (mesh 5)".
  [[nodiscard]] std::string describe_object(ObjectId id) const;
  /// The process's memory now, as the sample after `frame` frames of a run.
  [[nodiscard]] MemorySample memory_sample(int frame) const;

  /// Runs `culler` over frames 0..frames-1 of `path`. With `truth` (one
  /// entry per frame), checks every frame against it (frame-within-truth,
  /// and oracle-draws-truth for the oracle; the oracle needs it); throws
  /// InvariantViolation. With `predict`, also fills FrameStats::model_ms
  /// (see predicted_frame_ms).
  AlgorithmRun run_path(std::string_view name, Culler& culler, const CameraPath& path, int frames,
                        const std::vector<FrameTruth>* truth, const ProgressFn& progress = {},
                        bool predict = false);

  /// The NOHC hardware profile of this renderer: loaded from the per-user
  /// cache (default_profile_path), or calibrated now — a few seconds — and
  /// cached. Throws InputError when the cached file is corrupt.
  const HardwareProfile& hardware_profile(const std::function<void(const std::string&)>& progress = {});
  /// Where hardware_profile() reads and writes the profile.
  [[nodiscard]] std::string hardware_profile_path() const;
  /// "renderer | version": the key profiles are cached under.
  [[nodiscard]] std::string renderer_key() const;

  /// The cost model's estimate of the frame just run: t_r of every object
  /// rendered plus t_o of every query issued (milliseconds).
  [[nodiscard]] double predicted_frame_ms(const View& view);

  /// The named camera path of the scene (empty: its first), or a recorded
  /// one for "file:PATH" (read_path_file). Throws InputError listing the
  /// valid names, or naming what is wrong in the file.
  const CameraPath& path(std::string_view name);

  /// Bounds every frame (a culler's, or one of the ground truth) to this
  /// many seconds of wall time: past it, the process says which frame hung
  /// and exits with 1 (a GL call that never returns cannot be unwound).
  /// 0 turns it off. Default: kWatchdogSeconds. Throws InputError for a
  /// negative or non-finite time.
  void set_watchdog(double seconds);
  static constexpr double kWatchdogSeconds = 300.0;

  /// Culler frames get the renderer through a StallGuard of this many
  /// milliseconds (0, the default: none, results are waited for).
  /// Throws InputError for a negative or non-finite time.
  void set_stall_guard(double timeout_ms);
  /// What culler frames render through: the renderer under the session's
  /// RecordingBackend, and over both the StallGuard when one is set.
  [[nodiscard]] Backend& backend() noexcept;
  /// What the last culler frame drew and queried (run_frame() starts and
  /// finishes the record with the frame).
  [[nodiscard]] const RecordingBackend& recording() const noexcept { return *recorder_; }

  /// Where frames lie on paths (default: spread over the whole path).
  void set_sampling(const FrameSampling& sampling) { sampling_ = sampling; }
  /// How the scene's lens projects from now on (--depth): OpenGL's standard
  /// depth, or reversed-Z with an infinite far plane. The renderer, the
  /// ground truth and the verifier follow each view's conventions.
  /// Throws InputError for reversed depth on a tiled world (its window of
  /// tiles is sized by a finite far plane).
  void set_depth(DepthMode depth);
  /// Whether the ground truth from now on also lists FrameTruth::box_reach
  /// (off by default: it reads every box of the frustum against the truth's
  /// depth, pixel by pixel). `oracle:set=boxes` needs it.
  void set_box_reach(bool on) noexcept { box_reach_ = on; }
  /// Objects moved by the engine, for benchmarks (--engine-moves): from now
  /// on, before every frame and its truth, `fraction` of the static objects
  /// (every round(1 / fraction)-th; 0: none) are moved with
  /// Scene::set_transform, as static objects (not scripted dynamic ones), around small circles (2 scene units
  /// across, one turn in 4 s of path time) about where they stood, as an
  /// engine's game logic would; the hierarchy follows in run_frame().
  /// Throws InputError for a fraction outside [0, 1] or on a tiled world.
  void set_engine_moves(double fraction);
  [[nodiscard]] const FrameSampling& sampling() const noexcept { return sampling_; }
  /// Path time of frame k of `frames` under the session's sampling.
  [[nodiscard]] double frame_time(const CameraPath& path, int k, int frames) const {
    return path.frame_time(k, frames, sampling_);
  }
  /// View of `path` at frame k of `frames`: view_of its pose.
  [[nodiscard]] View view_at(const CameraPath& path, int k, int frames);
  /// The view of a pose of the scene's paths (relative to the bundle's
  /// origin), in the frame the scene is in for it: the floating origin
  /// moves to the cell of the camera first (re-placing every object when
  /// it changes; see origin()). Use the view before asking for another.
  [[nodiscard]] View view_of(CameraPose pose);

  /// The floating origin: where the frame of occull's coordinates (the
  /// scene's objects, its hierarchy, views) stands in the world, metres. As
  /// an engine keeps a large world, the session keeps it near the camera: at
  /// the centre of the cell of side origin_grid() the camera is in (a pure
  /// function of the camera, so every pass over a frame sees the same
  /// placements). When it moves, every object is placed anew from where the
  /// scene put it, in double precision — an engine's own set_transform calls
  /// between frames; the hierarchy refits and the cullers keep their state.
  /// Changes the engine made to objects' transforms are lost then.
  /// docs/library.md, "Far from the origin". Tiled worlds keep theirs at 0.
  [[nodiscard]] const glm::dvec3& origin() const noexcept { return origin_; }
  [[nodiscard]] double origin_grid() const noexcept { return origin_grid_; }
  /// Where the floating origin stands for a camera at `pose` (a pose of the
  /// scene's paths): the centre of the camera's cell. Tiled worlds: origin().
  [[nodiscard]] glm::dvec3 origin_for(const CameraPose& pose) const;
  /// How many times the floating origin moved since the session began.
  [[nodiscard]] std::uint64_t origin_moves() const noexcept { return origin_moves_; }
  /// The side of the floating origin's cells, metres (> 0), from the next
  /// view on. Default kOriginGrid. Throws InputError for a side <= 0 or not finite.
  void set_origin_grid(double metres);
  static constexpr double kOriginGrid = 4096.0;

  [[nodiscard]] const SceneBundle& bundle() const noexcept { return bundle_; }
  /// The scene, for an engine's changes between frames (set_transform,
  /// remove_object, add_object reusing removed ids): run_frame() refits the
  /// hierarchy to them. The renderer refuses objects added past the count
  /// the scene had when it was made.
  [[nodiscard]] Scene& scene() noexcept { return bundle_.scene; }
  [[nodiscard]] SceneIndex index() const noexcept { return {bundle_.scene, bvh_, bundle_.world.get()}; }
  /// The renderer the session draws with, whichever API.
  [[nodiscard]] RenderDevice& render_device() noexcept { return *device_; }
  [[nodiscard]] Api api() const noexcept { return device_->api(); }
  /// The OpenGL renderer and context (occull view, occull osg). Throw
  /// UsageError in a session of another API.
  [[nodiscard]] gl::Renderer& renderer();
  [[nodiscard]] gl::Context& context();
  [[nodiscard]] const gl::DeviceInfo& device() const noexcept { return device_->info(); }
  [[nodiscard]] double scene_build_ms() const noexcept { return scene_build_ms_; }
  [[nodiscard]] double bvh_build_ms() const noexcept { return bvh_build_ms_; }
  [[nodiscard]] const Bvh& bvh() const noexcept { return bvh_; }

 private:
  // Declared (so initialised) before bundle_, which records into it.
  double scene_build_ms_ = 0.0;
  double bvh_build_ms_ = 0.0;
  std::string scene_spec_;
  SceneBundle bundle_;
  std::vector<ObjectId> engine_moved_;      // set_engine_moves: the objects moved (from home_)
  // The floating origin (see origin()): where the scene's frame stands now,
  // the cells it snaps to, and every object's transform and every motion as
  // the scene was made (relative to bundle_.origin), placed anew from them
  // when the origin moves, so a placement depends on the origin alone.
  glm::dvec3 origin_{0.0};
  double origin_grid_ = kOriginGrid;
  std::uint64_t origin_moves_ = 0;
  std::vector<glm::mat4> home_;
  std::vector<ScriptedObject> home_scripted_;
  // `home` (a transform or a point relative to bundle_.origin) relative to origin_, in double.
  [[nodiscard]] glm::mat4 placed(const glm::mat4& home) const;
  [[nodiscard]] glm::vec3 placed(const glm::vec3& home) const;
  // Moves the scene's frame to `origin` (world), re-placing every object and motion.
  void move_origin(const glm::dvec3& origin);
  // The scene at path time `time_s`: Motions, then the engine's moves.
  void advance_scene(double time_s);
  Bvh bvh_;
  gl::RendererOptions renderer_options_;
  gl::ContextOptions context_options_;
  Api api_ = Api::gl;
  std::unique_ptr<RenderDevice> device_;  // the context and the renderer
  double stall_guard_ms_ = 0.0;
  // The backend chain of culler frames: renderer_ <- recorder_ (what the
  // frame drew and queried, for verification and the cost model) <- guard_
  // (with a stall guard) <- logger_ (logged frames). Each goes before what
  // it wraps.
  std::unique_ptr<RecordingBackend> recorder_;
  std::unique_ptr<StallGuard> guard_;
  void wrap_renderer();  // (re)builds recorder_ and guard_ over renderer_
  void start(const gl::RendererOptions& renderer_options, const BvhOptions& bvh_options);  // BVH, device
  std::unique_ptr<LoggingBackend> logger_;  // over backend(), for logged frames; goes before both
  std::unique_ptr<detail::Watchdog> watchdog_;
  std::optional<HardwareProfile> profile_;
  std::shared_ptr<const detail::FaultHooks> hooks_;
  bool box_reach_ = false;
  FrameTruth truth_of(const View& view, const detail::FrameLabel& where);
  FrameSampling sampling_;
};

}  // namespace occull
