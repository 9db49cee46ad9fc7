// Session: the device and the scene for a run of frames (scene, BVH, GL
// context, renderer, stall guard, logger, watchdog), the cullers made for
// it, the hardware profile, paths and the timed frame itself.
#include "occull/lab.hpp"

#include "fault_hooks.hpp"
#include "invariants.hpp"
#include "oracle.hpp"
#include "watchdog.hpp"
#include "occull/counters.hpp"
#include "occull/error.hpp"
#include "occull/frame_log.hpp"
#include "occull/gl/calibrate.hpp"
#include "occull/process.hpp"
#include "occull/profile_io.hpp"

#include <fmt/format.h>
#include <glm/gtc/matrix_transform.hpp>

#include <chrono>
#include <cmath>

namespace occull {
namespace {

using Clock = std::chrono::steady_clock;

// The centre of the cell of side `grid` that world point `p` is in.
glm::dvec3 origin_cell(const glm::dvec3& p, double grid) { return glm::round(p / grid) * grid; }

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
Session::Session(std::string_view scene_spec, const gl::RendererOptions& renderer_options,
                 const BvhOptions& bvh_options, const gl::ContextOptions& context_options, Api api)
    : scene_spec_(scene_spec), bundle_(timed_make_scene(scene_spec, scene_build_ms_)),
      context_options_(context_options), api_(api) {
  start(renderer_options, bvh_options);
}

Session::Session(std::string name, SceneBundle bundle, const gl::RendererOptions& renderer_options,
                 const BvhOptions& bvh_options, const gl::ContextOptions& context_options, Api api)
    : scene_spec_(std::move(name)), bundle_(std::move(bundle)), context_options_(context_options), api_(api) {
  start(renderer_options, bvh_options);
}

void Session::start(const gl::RendererOptions& renderer_options, const BvhOptions& bvh_options) {
  const auto t0 = Clock::now();
  // The floating origin: the scene's frame starts where the scene was made,
  // then snaps to its cell (a scene far out is re-placed near it at once).
  origin_ = bundle_.origin;
  for (const Object& o : bundle_.scene.objects()) home_.push_back(o.transform);
  home_scripted_ = bundle_.scripted;
  if (!bundle_.world) move_origin(origin_cell(bundle_.origin, origin_grid_));
  // A tiled world has no global hierarchy: its cullers keep one BVH
  // instance per tile (occull/tiles.hpp).
  bvh_ = bundle_.world ? Bvh::build(std::span<const Aabb>{}, std::span<const std::uint32_t>{})
                       : Bvh::build(bundle_.scene, bvh_options);
  bvh_build_ms_ = ms_between(t0, Clock::now());
  if (bundle_.world && float(renderer_options.width) > TiledWorld::kMaxAspect * float(renderer_options.height))
    throw InputError(fmt::format("{}: a {}x{} viewport is wider than {}:1, the widest a tiled world's window of "
                                 "placed tiles covers (occull::TiledWorld::kMaxAspect)",
                                 scene_spec_, renderer_options.width, renderer_options.height,
                                 TiledWorld::kMaxAspect));
  renderer_options_ = renderer_options;
  device_ = make_render_device(api_, bundle_.scene, renderer_options, context_options_);
  wrap_renderer();
  set_watchdog(kWatchdogSeconds);
}

void Session::wrap_renderer() {
  logger_.reset();  // it wraps what backend() was
  guard_.reset();   // reads the queries it gave up on, through the recorder
  recorder_ = std::make_unique<RecordingBackend>(device_->backend(), bundle_.scene);
  guard_ = stall_guard_ms_ > 0.0 ? std::make_unique<StallGuard>(*recorder_, stall_guard_ms_) : nullptr;
}

void Session::set_watchdog(double seconds) {
  if (!(seconds >= 0.0) || !std::isfinite(seconds))
    throw InputError(fmt::format("watchdog {} s: must be a number of seconds >= 0 (0: off)", seconds));
  watchdog_ = std::make_unique<detail::Watchdog>(seconds);
}

void Session::set_stall_guard(double timeout_ms) {
  if (!(timeout_ms >= 0.0) || !std::isfinite(timeout_ms))
    throw InputError(fmt::format("stall guard {} ms: must be a number of milliseconds >= 0 (0: off)", timeout_ms));
  stall_guard_ms_ = timeout_ms;
  wrap_renderer();
}

Backend& Session::backend() noexcept {
  if (guard_) return *guard_;
  return *recorder_;
}

void Session::reset_renderer() {
  logger_.reset();
  guard_.reset();
  recorder_.reset();
  device_->reset();
  wrap_renderer();
}

gl::Renderer& Session::renderer() {
  if (!device_->gl_renderer())
    throw UsageError(fmt::format("Session::renderer: the session renders through {}, not OpenGL", api_name(api())));
  return *device_->gl_renderer();
}

gl::Context& Session::context() {
  if (!device_->gl_context())
    throw UsageError(fmt::format("Session::context: the session renders through {}, not OpenGL", api_name(api())));
  return *device_->gl_context();
}

Session::~Session() {
  logger_.reset();
  guard_.reset();     // reads the queries it gave up on
  recorder_.reset();
  device_.reset();
}

const CameraPath& Session::path(std::string_view name) {
  if (name.empty()) return bundle_.paths.front();
  if (name.rfind("file:", 0) == 0) {
    CameraPath p = read_path_file(std::string(name.substr(5)));
    for (const CameraPath& known : bundle_.paths)
      if (known.name() == p.name()) return known;
    bundle_.paths.push_back(std::move(p));
    return bundle_.paths.back();
  }
  return bundle_.path(name);
}

View Session::view_at(const CameraPath& path, int k, int frames) {
  return view_of(path.sample(frame_time(path, k, frames)));
}

glm::dvec3 Session::origin_for(const CameraPose& pose) const {
  if (bundle_.world) return origin_;
  return origin_cell(bundle_.origin + glm::dvec3(pose.position), origin_grid_);
}

View Session::view_of(CameraPose pose) {
  if (!bundle_.world) {
    move_origin(origin_for(pose));
    pose.position = placed(pose.position);
  }
  return make_view(pose, bundle_.lens, device_->width(), device_->height());
}

void Session::set_origin_grid(double metres) {
  if (!(metres > 0.0) || !std::isfinite(metres))
    throw InputError(fmt::format("origin grid {} m: must be a number of metres > 0", metres));
  origin_grid_ = metres;
}

glm::mat4 Session::placed(const glm::mat4& home) const {
  glm::dmat4 m(home);
  m[3] += glm::dvec4(bundle_.origin - origin_, 0.0);
  return glm::mat4(m);
}

glm::vec3 Session::placed(const glm::vec3& home) const { return glm::vec3(glm::dvec3(home) + bundle_.origin - origin_); }

void Session::move_origin(const glm::dvec3& origin) {
  if (origin == origin_) return;
  origin_ = origin;
  ++origin_moves_;
  Scene& scene = bundle_.scene;
  for (ObjectId id = 0; id < home_.size(); ++id)
    if (scene.alive(id) && !scene.object(id).dynamic()) scene.set_transform(id, placed(home_[id]));
  for (std::size_t i = 0; i < home_scripted_.size(); ++i) {
    ScriptedObject& s = bundle_.scripted[i];
    s.motion = home_scripted_[i].motion;
    for (glm::vec3& p : s.motion.waypoints) p = placed(p);
    if (scene.alive(s.id) && scene.object(s.id).dynamic()) scene.set_dynamic_range(s.id, s.motion.range());
  }
}

FrameStats Session::run_frame(Culler& culler, const View& view, double time_s, FrameLog* log) {
  const auto step = watchdog_->step(fmt::format("a culler's frame at {:.3f} s of the path", time_s));
  advance_scene(time_s);
  if (bundle_.world) bundle_.world->follow(bundle_.scene, view.eye);
  const ProcessUsage u0 = process_usage();
  const auto t0 = Clock::now();
  if (!bundle_.world) bvh_.refit(bundle_.scene);
  device_->begin_frame(view);
  recorder_->start_frame();
  if (log && !logger_) logger_ = std::make_unique<LoggingBackend>(this->backend());
  if (logger_) logger_->log_into(log);
  Backend& backend = log ? static_cast<Backend&>(*logger_) : this->backend();
  const BackendStats before = backend.stats();
  const FrameResult result = culler.render_frame(view, backend);
  FrameStats s;
  copy_culler_counters(result, culler, s);
  if (logger_) logger_->log_into(nullptr);  // `log` is this frame's only
  device_->check("a culler's frame");  // before end_frame's own glGetError, which knows less
  s.gpu_ms = device_->end_frame();
  const auto t1 = Clock::now();
  recorder_->finish_frame([this](QueryId q) { return device_->unread_result(q); });
  const ProcessUsage u1 = process_usage();
  const BackendStats d = backend.stats() - before;
  s.minor_faults = u1.minor_faults - u0.minor_faults;
  s.major_faults = u1.major_faults - u0.major_faults;
  s.kernel_ms = u1.kernel_ms - u0.kernel_ms;
  s.frame_ms = ms_between(t0, t1);
  copy_backend_counters(d, s);
  device_->check("the end of a frame");
  culler.frame_finished(measure_of(s));
  return s;
}

void Session::set_depth(DepthMode depth) {
  if (depth == DepthMode::reversed && bundle_.world)
    throw InputError(fmt::format("{}: --depth reversed has an infinite far plane, and a tiled world's window of tiles "
                                 "is sized by the lens's far plane; use --depth standard there",
                                 scene_spec_));
  bundle_.lens.depth = depth;
}

void Session::set_engine_moves(double fraction) {
  if (!(fraction >= 0.0 && fraction <= 1.0))
    throw InputError(fmt::format("engine moves {}: must be a fraction of the objects in [0, 1]", fraction));
  if (bundle_.world && fraction > 0.0)
    throw InputError(fmt::format("{}: a tiled world places its own objects; engine moves are for other scenes",
                                 scene_spec_));
  for (ObjectId id : engine_moved_)  // back where they stood
    if (bundle_.scene.alive(id)) bundle_.scene.set_transform(id, placed(home_[id]));
  engine_moved_.clear();
  if (fraction <= 0.0) return;
  const auto every = std::max<ObjectId>(1, ObjectId(std::lround(1.0 / fraction)));
  for (ObjectId id = 0; id < home_.size(); id += every)
    if (bundle_.scene.alive(id) && !bundle_.scene.object(id).dynamic()) engine_moved_.push_back(id);
}

void Session::advance_scene(double time_s) {
  animate(bundle_.scene, bundle_.scripted, time_s);
  for (std::size_t i = 0; i < engine_moved_.size(); ++i) {
    const double angle = time_s * (2.0 * 3.14159265358979 / 4.0) + 0.7 * double(i);
    const glm::vec3 offset(float(std::cos(angle)), 0.0f, float(std::sin(angle)));
    bundle_.scene.set_transform(engine_moved_[i],
                                glm::translate(glm::mat4(1.0f), offset) * placed(home_[engine_moved_[i]]));
  }
}

void Session::release(Culler& culler) { culler.release(backend()); }

void Session::check_queries_returned(std::string_view who) const {
  const std::size_t abandoned = guard_ ? guard_->abandoned() : 0;
  const std::size_t in_flight = device_->queries_in_flight();
  if (in_flight > abandoned)
    detail::invariant_violated({scene_spec_, std::string(who), 0}, "queries-returned",
                               fmt::format("{} queries still in flight after the run's cullers were released ({} of "
                                           "them given up on by the stall guard)",
                                           in_flight, abandoned));
}

std::unique_ptr<Culler> Session::make(std::string_view spec, const Options& options,
                                      const std::function<void(const std::string&)>& progress) {
  const AlgorithmSpec a = parse_algorithm_spec(spec, options);
  if (a.name == "oracle") {
    const auto set = a.options.values().find("oracle.set");
    const std::string value = set == a.options.values().end() ? "pixels" : set->second;
    if (value != "pixels" && value != "boxes")
      throw InputError(fmt::format("option oracle.set: '{}' is not one of pixels, boxes", value));
    return std::make_unique<detail::OracleCuller>(bundle_.scene, value == "boxes");
  }
  if (find_algorithm(a.name).device && !device_->backend().device_culling())
    throw InputError(fmt::format("{} culls on the device, and the {} renderer has no device culling "
                                 "(DeviceCulling is occull's OpenGL renderer's only): run it with --api gl",
                                 a.name, api_name(api())));
  return make_culler(a.name, index(), a.options, culler_context(progress));
}

CullerContext Session::culler_context(const std::function<void(const std::string&)>& progress) {
  CullerContext context;  // nohc: the calibrated profile, unless an option names a file
  context.hardware_profile = [this, progress](const std::string& file) -> std::optional<HardwareProfile> {
    if (!file.empty()) return load_profile(file);
    return hardware_profile(progress);
  };
  return context;
}

std::string Session::renderer_key() const { return device().renderer + " | " + device().version; }

std::string Session::hardware_profile_path() const { return default_profile_path(renderer_key()); }

const HardwareProfile& Session::hardware_profile(const std::function<void(const std::string&)>& progress) {
  if (profile_) return *profile_;
  const std::string path = hardware_profile_path();
  profile_ = load_profile(path);
  if (profile_ && profile_->renderer == renderer_key()) return *profile_;
  // The calibration draws through OpenGL; a Vulkan session makes a context
  // for it (on the same machine: the same driver's rasteriser) while it runs.
  std::unique_ptr<gl::Context> calibration_context;
  if (api() != Api::gl) calibration_context = gl::Context::create(context_options_);
  if (progress)
    progress(api() == Api::gl ? "calibrating the hardware cost model (a few seconds)"
                              : "calibrating the hardware cost model through OpenGL (a few seconds; no Vulkan "
                                "calibration yet)");
  gl::CalibrationOptions co;
  co.repeats = 3;  // a first-use calibration stays within a few seconds
  co.width = device_->width();
  co.height = device_->height();
  gl::CalibrationResult cal = gl::calibrate(co, progress);
  calibration_context.reset();
  cal.profile.renderer = renderer_key();
  save_profile(cal.profile, path);
  profile_ = cal.profile;
  return *profile_;
}

double Session::predicted_frame_ms(const View& view) {
  const HardwareProfile& hw = hardware_profile();
  const Scene& scene = bundle_.scene;
  const double pixels = double(view.width) * double(view.height);
  double ms = 0.0;
  for (ObjectId id : recorder_->objects()) {
    const Object& o = scene.object(id);
    NodeCost c;
    c.draws = 1;
    c.triangles = o.triangles;
    c.shading_cost = scene.material(o.material).shading_cost;
    c.c_bb = projected_area(o.bounds, view.view_proj, view.width, view.height) / pixels;
    c.r_cov = coverage_ratio(scene.object_surface_area(id), o.bounds.surface_area());
    ms += render_time(hw, c, view.width, view.height);
  }
  const auto boxes = recorder_->query_boxes();
  std::size_t next = 0;
  for (std::uint32_t n : recorder_->query_sizes()) {
    double covered = 0.0;
    for (std::uint32_t i = 0; i < n; ++i)
      covered += projected_area(boxes[next + i], view.view_proj, view.width, view.height) / pixels;
    next += n;
    ms += query_time(hw, covered, view.width, view.height);
  }
  return ms;
}

FrameStats Session::run_path_frame(Culler& culler, const CameraPath& path, int k, int frames,
                                   const std::vector<FrameTruth>* truth) {
  if (auto* oracle = dynamic_cast<detail::OracleCuller*>(&culler)) {
    if (!truth) throw InputError("the oracle needs ground truth: run it with verification on");
    const FrameTruth& t = (*truth)[std::size_t(k)];
    std::vector<ObjectId> visible;
    if (oracle->boxes()) {
      if (!box_reach_) throw InputError("oracle:set=boxes needs the box reach: Session::set_box_reach(true)");
      visible = t.box_reach;
    } else {
      visible.reserve(t.visible.size());
      for (const auto& v : t.visible) visible.push_back(v.id);
    }
    if (hooks_ && hooks_->oracle_objects) hooks_->oracle_objects(visible);
    oracle->set_visible(std::move(visible));
  }
  return run_frame(culler, view_at(path, k, frames), frame_time(path, k, frames));
}

MemorySample Session::memory_sample(int frame) const {
  const MemoryUsage m = memory_usage();
  return {frame, double(m.resident_bytes) / (1 << 20), double(device_->resources().buffer_bytes) / (1 << 20)};
}

std::string Session::describe_object(ObjectId id) const {
  if (bundle_.world) return bundle_.world->describe(id);
  if (id >= bundle_.scene.objects().size()) return fmt::format("object {} (not in the scene)", id);
  return fmt::format("object {} (mesh {})", id, bundle_.scene.object(id).mesh);
}

}  // namespace occull
