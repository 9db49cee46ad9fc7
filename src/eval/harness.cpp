#include "occull/harness.hpp"
#include "occull/counters.hpp"

#include "occull/frame_log.hpp"

#include "watchdog.hpp"

#include "occull/error.hpp"
#include "occull/gl/calibrate.hpp"
#include "invariants.hpp"
#include "occull/process.hpp"
#include "occull/profile_io.hpp"
#include "oracle.hpp"

#include <fmt/format.h>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <numeric>

#include "occull_commit.hpp"  // generated: OCCULL_COMMIT

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

double median_of(std::vector<double> v) { return summarize(std::move(v)).median; }

// How far the camera moves and turns between consecutive frames of a run.
void measure_camera_motion(const Session& session, const CameraPath& path, int frames, BenchResult& r) {
  for (int k = 1; k < frames; ++k) {
    const View a = session.view_at(path, k - 1, frames), b = session.view_at(path, k, frames);
    const double step = glm::length(b.eye - a.eye);
    // Forward is -Z of the view: the third row of the view matrix, negated.
    const glm::vec3 fa(-a.view[0][2], -a.view[1][2], -a.view[2][2]), fb(-b.view[0][2], -b.view[1][2], -b.view[2][2]);
    const double turn = glm::degrees(std::acos(std::clamp(double(glm::dot(fa, fb)), -1.0, 1.0)));
    r.step_m_mean += step / double(frames - 1);
    r.turn_deg_mean += turn / double(frames - 1);
    r.step_m_max = std::max(r.step_m_max, step);
    r.turn_deg_max = std::max(r.turn_deg_max, turn);
  }
}

}  // namespace

std::vector<ObjectId> check_frame(std::span<const gl::Renderer::ObjectPixels> truth,
                                  std::span<const ObjectId> rendered, std::size_t object_count,
                                  FrameStats& stats) {
  std::vector<std::uint8_t> drawn(object_count, 0);
  for (ObjectId id : rendered) drawn[id] = 1;
  std::vector<ObjectId> missed;
  stats.truth_objects = std::uint32_t(truth.size());
  stats.missed_objects = 0;
  stats.wrong_pixels = 0;
  std::size_t rendered_and_visible = 0;
  for (const auto& t : truth) {
    if (drawn[t.id]) {
      ++rendered_and_visible;
    } else {
      missed.push_back(t.id);
      stats.wrong_pixels += t.pixels;
    }
  }
  stats.missed_objects = std::uint32_t(missed.size());
  const auto distinct = std::size_t(std::count(drawn.begin(), drawn.end(), std::uint8_t(1)));
  stats.extra_objects = std::uint32_t(distinct - rendered_and_visible);
  return missed;
}

// The scene first: a bad spec is reported before any GL work.
Session::Session(std::string_view scene_spec, const gl::RendererOptions& renderer_options,
                 const BvhOptions& bvh_options, const gl::ContextOptions& context_options)
    : scene_spec_(scene_spec), bundle_(timed_make_scene(scene_spec, scene_build_ms_)),
      context_options_(context_options) {
  const auto t0 = Clock::now();
  // A tiled world has no global hierarchy: its cullers keep one BVH
  // instance per tile (occull/tiles.hpp).
  bvh_ = bundle_.world ? Bvh::build(std::span<const Aabb>{}, std::span<const std::uint32_t>{})
                       : Bvh::build(bundle_.scene, bvh_options);
  bvh_build_ms_ = ms_between(t0, Clock::now());
  if (bundle_.world && float(renderer_options.width) > TiledWorld::kMaxAspect * float(renderer_options.height))
    throw InputError(fmt::format("{}: a {}x{} viewport is wider than {}:1, the widest a tiled world's window of "
                                 "placed tiles covers (occull::TiledWorld::kMaxAspect)",
                                 scene_spec, renderer_options.width, renderer_options.height,
                                 TiledWorld::kMaxAspect));
  context_ = gl::Context::create(context_options_);
  device_ = context_->info();
  renderer_options_ = renderer_options;
  renderer_ = std::make_unique<gl::Renderer>(bundle_.scene, renderer_options);
  set_watchdog(kWatchdogSeconds);
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
  logger_.reset();  // it wraps what backend() was
  guard_ = timeout_ms > 0.0 ? std::make_unique<StallGuard>(*renderer_, timeout_ms) : nullptr;
}

Backend& Session::backend() noexcept {
  if (guard_) return *guard_;
  return *renderer_;
}

void Session::reset_renderer() {
  logger_.reset();
  guard_.reset();
  renderer_.reset();
  retired_.reset();  // idle since the previous replacement
  retired_ = std::move(context_);
  context_ = gl::Context::create(context_options_);
  renderer_ = std::make_unique<gl::Renderer>(bundle_.scene, renderer_options_);
  set_stall_guard(stall_guard_ms_);
}

Session::~Session() {
  logger_.reset();
  guard_.reset();     // reads the queries it gave up on
  renderer_.reset();  // GL objects go before the context
  context_.reset();
  retired_.reset();
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

View Session::view_at(const CameraPath& path, int k, int frames) const {
  return make_view(path.sample(frame_time(path, k, frames)), bundle_.lens, renderer_->width(),
                   renderer_->height());
}

FrameStats Session::run_frame(Culler& culler, const View& view, double time_s, FrameLog* log) {
  const auto step = watchdog_->step(fmt::format("a culler's frame at {:.3f} s of the path", time_s));
  advance_scene(time_s);
  if (bundle_.world) bundle_.world->follow(bundle_.scene, view.eye);
  const ProcessUsage u0 = process_usage();
  const auto t0 = Clock::now();
  if (!bundle_.world) bvh_.refit(bundle_.scene);
  renderer_->begin_frame(view);
  if (log && !logger_) logger_ = std::make_unique<LoggingBackend>(this->backend());
  if (logger_) logger_->log_into(log);
  Backend& backend = log ? static_cast<Backend&>(*logger_) : this->backend();
  const BackendStats before = backend.stats();
  const auto c0 = Clock::now();
  FrameStats s = culler.render_frame(view, backend);
  const auto c1 = Clock::now();
  if (logger_) logger_->log_into(nullptr);  // `log` is this frame's only
  const BackendStats during = backend.stats() - before;
  context_->check("a culler's frame");  // before end_frame's own glGetError, which knows less
  s.gpu_ms = renderer_->end_frame();
  const auto t1 = Clock::now();
  const ProcessUsage u1 = process_usage();
  const BackendStats d = backend.stats() - before;
  s.minor_faults = u1.minor_faults - u0.minor_faults;
  s.major_faults = u1.major_faults - u0.major_faults;
  s.kernel_ms = u1.kernel_ms - u0.kernel_ms;
  s.frame_ms = ms_between(t0, t1);
  s.cpu_ms = std::max(0.0, ms_between(c0, c1) - during.backend_ms);
  copy_backend_counters(d, s);
  context_->check("the end of a frame");
  culler.frame_finished(s);
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
  for (std::size_t i = 0; i < engine_moved_.size(); ++i)  // back where they stood
    bundle_.scene.set_transform(engine_moved_[i], engine_home_[i]);
  engine_moved_.clear();
  engine_home_.clear();
  if (fraction <= 0.0) return;
  const auto every = std::max<ObjectId>(1, ObjectId(std::lround(1.0 / fraction)));
  for (ObjectId id = 0; id < bundle_.scene.objects().size(); id += every)
    if (bundle_.scene.alive(id) && !bundle_.scene.object(id).dynamic()) {
      engine_moved_.push_back(id);
      engine_home_.push_back(bundle_.scene.object(id).transform);
    }
}

void Session::advance_scene(double time_s) {
  bundle_.scene.update(time_s);
  for (std::size_t i = 0; i < engine_moved_.size(); ++i) {
    const double angle = time_s * (2.0 * 3.14159265358979 / 4.0) + 0.7 * double(i);
    const glm::vec3 offset(float(std::cos(angle)), 0.0f, float(std::sin(angle)));
    bundle_.scene.set_transform(engine_moved_[i], glm::translate(glm::mat4(1.0f), offset) * engine_home_[i]);
  }
}

void Session::release(Culler& culler) { culler.release(backend()); }

void Session::check_queries_returned(std::string_view who) const {
  const std::size_t abandoned = guard_ ? guard_->abandoned() : 0;
  const std::size_t in_flight = renderer_->queries_in_flight();
  if (in_flight > abandoned)
    detail::invariant_violated({scene_spec_, std::string(who), 0}, "queries-returned",
                               fmt::format("{} queries still in flight after the run's cullers were released ({} of "
                                           "them given up on by the stall guard)",
                                           in_flight, abandoned));
}

std::vector<FrameTruth> Session::ground_truth(const CameraPath& path, int frames,
                                              const ProgressFn& progress) {
  std::vector<FrameTruth> truth;
  truth.reserve(std::size_t(frames));
  for (int k = 0; k < frames; ++k) {
    truth.push_back(truth_at(path, k, frames));
    if (progress) progress("ground truth", k, frames, false);
  }
  return truth;
}

FrameTruth Session::truth_at(const CameraPath& path, int k, int frames) {
  advance_scene(frame_time(path, k, frames));
  const View view = view_at(path, k, frames);
  const detail::FrameLabel where{scene_spec_, path.name(), k};
  if (bundle_.world) {
    bundle_.world->follow(bundle_.scene, view.eye);
    // The truth sees only the placed cells: the window must hold the frustum.
    if (!bundle_.world->covers(view))
      detail::invariant_violated(where, "window-covers-frustum",
                                 fmt::format("the frustum reaches past the {} x {} cells placed around the eye",
                                             2 * bundle_.world->radius() + 1, 2 * bundle_.world->radius() + 1));
  }
  return truth_of(view, where);
}

FrameTruth Session::truth_of(const View& view) { return truth_of(view, {scene_spec_, "(free camera)", 0}); }

FrameTruth Session::truth_of(const View& view, const detail::FrameLabel& where) {
  const Scene& scene = bundle_.scene;
  const auto objects = scene.objects();
  const auto step = watchdog_->step(fmt::format("ground-truth frame {} of path {}", where.frame, where.path));
  std::vector<ObjectId> in_frustum, outside;
  for (ObjectId id = 0; id < objects.size(); ++id)
    if (view.frustum.classify(objects[id].bounds) != Containment::outside) in_frustum.push_back(id);
  if (hooks_.truth_objects) hooks_.truth_objects(in_frustum);

  FrameTruth t;
  gl::Renderer::PassImages images;
  t.visible = renderer_->visible_pixels(view, in_frustum, &images);
  if (hooks_.truth_images) hooks_.truth_images(t.visible, images);
  // The full scene, for comparison: every opaque object left out of the
  // truth pass, drawn over its depth, must not pass a single sample.
  std::vector<std::uint8_t> drawn(objects.size(), 0);
  for (ObjectId id : in_frustum) drawn[id] = 1;
  for (ObjectId id = 0; id < objects.size(); ++id)
    if (!drawn[id] && scene.alive(id) && !scene.material(objects[id].material).translucent) outside.push_back(id);
  const std::uint64_t outside_samples = renderer_->samples_in_front(view, outside);

  context_->check("the ground truth");
  std::sort(in_frustum.begin(), in_frustum.end());
  detail::check_truth_in_frustum(where, t.visible, in_frustum);
  detail::check_truth_covers_full_render(where, images.ids, images.depth, outside_samples);
  detail::check_truth_not_empty(where, t.visible, images.ids, scene);
  t.probes = std::uint32_t(detail::check_truth_probes(where, scene, view, in_frustum, images.depth,
                                                       renderer_options_.cull_backfaces));
  t.coverage = detail::depth_coverage(images.depth);
  return t;
}

std::unique_ptr<Culler> Session::make(std::string_view spec, const Options& options,
                                      const std::function<void(const std::string&)>& progress) {
  const AlgorithmSpec a = parse_algorithm_spec(spec, options);
  if (a.name == "oracle") return std::make_unique<detail::OracleCuller>(bundle_.scene);
  return make_culler(a.name, index(), a.options, culler_context(progress));
}

CullerContext Session::culler_context(const std::function<void(const std::string&)>& progress) {
  CullerContext context;  // nohc: the calibrated profile, unless an option names a file
  context.nohc_profile_source = [this, progress]() -> const HardwareProfile& { return hardware_profile(progress); };
  return context;
}

std::string Session::renderer_key() const { return device_.renderer + " | " + device_.version; }

std::string Session::hardware_profile_path() const { return default_profile_path(renderer_key()); }

const HardwareProfile& Session::hardware_profile(const std::function<void(const std::string&)>& progress) {
  if (profile_) return *profile_;
  const std::string path = hardware_profile_path();
  profile_ = load_profile(path);
  if (profile_ && profile_->renderer == renderer_key()) return *profile_;
  if (progress) progress("calibrating the hardware cost model (a few seconds)");
  gl::CalibrationOptions co;
  co.repeats = 3;  // a first-use calibration stays within a few seconds
  co.width = renderer_->width();
  co.height = renderer_->height();
  gl::CalibrationResult cal = gl::calibrate(co, progress);
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
  for (ObjectId id : renderer_->frame_objects()) {
    const Object& o = scene.object(id);
    NodeCost c;
    c.draws = 1;
    c.triangles = o.triangles;
    c.shading_cost = scene.material(o.material).shading_cost;
    c.c_bb = projected_area(o.bounds, view.view_proj, view.width, view.height) / pixels;
    c.r_cov = coverage_ratio(scene.object_surface_area(id), o.bounds.surface_area());
    ms += render_time(hw, c, view.width, view.height);
  }
  const auto boxes = renderer_->frame_query_boxes();
  std::size_t next = 0;
  for (std::uint32_t n : renderer_->frame_query_sizes()) {
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
    std::vector<ObjectId> visible;
    visible.reserve((*truth)[std::size_t(k)].visible.size());
    for (const auto& t : (*truth)[std::size_t(k)].visible) visible.push_back(t.id);
    if (hooks_.oracle_objects) hooks_.oracle_objects(visible);
    oracle->set_visible(std::move(visible));
  }
  return run_frame(culler, view_at(path, k, frames), frame_time(path, k, frames));
}

AlgorithmRun Session::run_path(std::string_view name, Culler& culler, const CameraPath& path,
                               int frames, const std::vector<FrameTruth>* truth,
                               const ProgressFn& progress, bool predict) {
  AlgorithmRun run{std::string(name), 0, true, {}, 0};
  // The frame records are written (and so made resident) before the first
  // frame: the memory samples then see what the culler, the renderer and
  // the driver take, not this record growing by a frame's stats each frame.
  run.frames.assign(std::size_t(frames), FrameStats{});
  MissRuns misses(bundle_.scene.objects().size());
  for (int k = 0; k < frames; ++k) {
    FrameStats s = run_path_frame(culler, path, k, frames, truth);
    if (predict) s.model_ms = predicted_frame_ms(view_at(path, k, frames));
    if (truth) {
      const std::vector<ObjectId> missed = verify_frame(name, culler, path, k, (*truth)[std::size_t(k)], s);
      if (!missed.empty() && run.first_miss.empty())
        run.first_miss = fmt::format("frame {}: {}", k, describe_object(missed.front()));
      misses.add(missed);
    }
    run.frames[std::size_t(k)] = s;
    if ((k + 1) % kMemorySampleFrames == 0) run.memory.push_back(memory_sample(k + 1));
    if (progress) progress(name, k, frames, false);
  }
  run.longest_miss_frames = misses.longest();
  return run;
}

MemorySample Session::memory_sample(int frame) const {
  const MemoryUsage m = memory_usage();
  return {frame, double(m.resident_bytes) / (1 << 20), double(renderer_->resources().buffer_bytes) / (1 << 20)};
}

std::string Session::describe_object(ObjectId id) const {
  if (bundle_.world) return bundle_.world->describe(id);
  if (id >= bundle_.scene.objects().size()) return fmt::format("object {} (not in the scene)", id);
  return fmt::format("object {} (mesh {})", id, bundle_.scene.object(id).mesh);
}

std::vector<ObjectId> Session::verify_frame(std::string_view name, const Culler& culler, const CameraPath& path,
                                            int k, const FrameTruth& t, FrameStats& s) {
  const detail::FrameLabel where{scene_spec_, path.name(), k};
  std::vector<float> depth = renderer_->read_depth();
  if (hooks_.frame_depth) hooks_.frame_depth(depth);
  const Coverage frame = detail::depth_coverage(depth);
  detail::check_frame_within_truth(where, std::string(name), t.coverage, frame);
  if (dynamic_cast<const detail::OracleCuller*>(&culler))
    detail::check_oracle_draws_truth(where, t.visible, renderer_->frame_objects(), t.coverage.depth_hash,
                                     frame.depth_hash);
  return check_frame(t.visible, renderer_->frame_objects(), bundle_.scene.objects().size(), s);
}

void MissRuns::add(const std::vector<ObjectId>& missed) {
  for (ObjectId id : previous_)
    if (!std::binary_search(missed.begin(), missed.end(), id)) run_[id] = 0;
  for (ObjectId id : missed) longest_ = std::max(longest_, ++run_[id]);
  previous_ = missed;
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

namespace {

// One repeat's figure of a counter from the sum, the largest value and the
// number of its frames (Counter::frames).
double run_figure(const Counter& c, double sum, double largest, double frames) {
  switch (c.frames) {
    case Combine::mean: return sum / frames;
    case Combine::sum: return sum;
    case Combine::max: return largest;
    default: return 0.0;
  }
}

// Puts a counter's figure into its summary member (Counter::summary).
void set_summary(const Counter& c, AlgorithmSummary& a, double value) {
  std::visit(
      [&](auto member) {
        if constexpr (!std::is_same_v<decltype(member), std::monostate>) {
          using T = std::remove_reference_t<decltype(a.*member)>;
          a.*member = static_cast<T>(value);
        }
      },
      c.summary);
}

}  // namespace

std::vector<AlgorithmSummary> summarize_runs(std::span<const AlgorithmRun> runs) {
  const std::span<const Counter> counters = frame_counters();
  // Per repeat: the mean frame time of each algorithm, for ratios within it.
  std::map<std::pair<int, std::string>, double> mean_ms;
  std::vector<std::string> names;
  for (const AlgorithmRun& r : runs) {
    std::vector<double> ms;
    for (const FrameStats& f : r.frames) ms.push_back(f.frame_ms);
    mean_ms[{r.repeat, r.name}] = summarize(ms).mean;
    if (std::find(names.begin(), names.end(), r.name) == names.end()) names.push_back(r.name);
  }
  const auto sum_of = [&](const std::vector<double>& sums, std::string_view name) {
    return sums[std::size_t(find_counter(name) - counters.data())];
  };

  std::vector<AlgorithmSummary> out;
  for (const std::string& name : names) {
    AlgorithmSummary a;
    a.name = name;
    // Each counter's figure per repeat (Counter::frames), then over the
    // repeats (Counter::repeats); the derived figures beside them.
    std::vector<std::vector<double>> counter_repeats(counters.size());
    std::map<std::string, std::vector<double>> per_repeat;
    for (const AlgorithmRun& r : runs) {
      if (r.name != name) continue;
      a.conservative = r.conservative;
      const double n = std::max<double>(1.0, double(r.frames.size()));
      std::vector<double> ms, sums(counters.size(), 0.0), largest(counters.size(), 0.0);
      std::uint64_t frames_missing = 0, worst = 0;
      for (const FrameStats& f : r.frames) {
        ms.push_back(f.frame_ms);
        for (std::size_t c = 0; c < counters.size(); ++c) {
          const double v = counter_value(counters[c], f);
          sums[c] += v;
          largest[c] = std::max(largest[c], v);
        }
        frames_missing += f.missed_objects > 0 ? 1 : 0;
        worst = std::max(worst, f.wrong_pixels);
      }
      for (std::size_t c = 0; c < counters.size(); ++c)
        if (counters[c].frames != Combine::none)
          counter_repeats[c].push_back(run_figure(counters[c], sums[c], largest[c], n));
      const Summary s = summarize(ms);
      per_repeat["mean"].push_back(s.mean);
      per_repeat["median"].push_back(s.median);
      per_repeat["p95"].push_back(s.p95);
      per_repeat["max"].push_back(s.max);
      // Figures derived from two counters' sums over the run.
      const double tile_queries = sum_of(sums, "tile_queries"), instantiated = sum_of(sums, "tiles_instantiated");
      const double nodes = sum_of(sums, "nodes_visited");
      if (tile_queries > 0)
        per_repeat["tile_prediction_failure_share"].push_back(sum_of(sums, "tile_prediction_failures") / tile_queries);
      if (instantiated > 0)
        per_repeat["instantiate_ms_per_tile"].push_back(sum_of(sums, "instantiate_ms") / instantiated);
      if (nodes > 0) per_repeat["cpu_us_per_node"].push_back(1e3 * sum_of(sums, "cpu_ms") / nodes);
      if (r.repeat == 0) a.memory = r.memory;
      if (a.first_miss.empty()) a.first_miss = r.first_miss;
      // A view of a split-screen run compares with the same view of the baseline.
      const std::size_t view_at = r.name.find(" [view ");
      const std::string view = view_at == std::string::npos ? "" : r.name.substr(view_at);
      const auto ratio = [&](const char* base, const char* key) {
        const auto it = mean_ms.find({r.repeat, base + view});
        if (it != mean_ms.end() && it->second > 0) per_repeat[key].push_back(s.mean / it->second);
      };
      // The frustum-culling baseline: vfc, or tilevfc on a tiled world (a
      // run has one or the other: each refuses the other's scenes).
      const bool tiled_run = mean_ms.count({r.repeat, std::string(vfc_baseline(true)) + view}) > 0;
      ratio(std::string(vfc_baseline(tiled_run)).c_str(), "ratio_to_vfc");
      ratio("oracle", "ratio_to_oracle");
      // Correctness: the worst repeat's.
      a.frames_with_misses = std::max(a.frames_with_misses, frames_missing);
      a.worst_frame_wrong_pixels = std::max(a.worst_frame_wrong_pixels, worst);
      a.longest_miss_frames = std::max(a.longest_miss_frames, r.longest_miss_frames);
    }
    for (std::size_t c = 0; c < counters.size(); ++c) {
      const std::vector<double>& v = counter_repeats[c];
      if (v.empty()) continue;
      set_summary(counters[c], a,
                  counters[c].repeats == Combine::max ? *std::max_element(v.begin(), v.end()) : median_of(v));
    }
    const auto med = [&](const char* key) {
      const auto it = per_repeat.find(key);
      return it == per_repeat.end() ? 0.0 : median_of(it->second);
    };
    a.frame_ms = {med("mean"), med("median"), med("p95"), med("max")};
    a.ratio_to_vfc = med("ratio_to_vfc");
    a.ratio_to_oracle = med("ratio_to_oracle");
    a.cpu_us_per_node = med("cpu_us_per_node");
    a.tile_prediction_failure_share = med("tile_prediction_failure_share");
    a.instantiate_ms_per_tile = med("instantiate_ms_per_tile");
    out.push_back(std::move(a));
  }
  return out;
}

std::vector<const AlgorithmSummary*> verification_failures(const BenchResult& result) {
  std::vector<const AlgorithmSummary*> failed;
  if (!result.verified) return failed;
  for (const AlgorithmSummary& a : result.summaries)
    if (a.conservative && a.missed_objects > 0) failed.push_back(&a);
  return failed;
}

namespace {

// The frame of the path warm-up frame `w` runs: the warm-up frames are
// spread over the path, so each algorithm sees its whole length once.
int warmup_frame(const BenchConfig& config, int w) {
  return config.warmup > 1 ? w * (config.frames - 1) / (config.warmup - 1) : 0;
}

// The cullers of the views of one split-screen run: make_split_screen's
// (an algorithm that shares state between views makes them together), or
// the session's, one per view, for the harness-only oracle.
struct ViewCullers {
  std::unique_ptr<SplitScreen> split;
  std::vector<std::unique_ptr<Culler>> own;

  ViewCullers(Session& session, const std::string& name, const Options& options, int views) {
    const AlgorithmSpec spec = parse_algorithm_spec(name, options);
    if (find_algorithm(spec.name).harness_only)
      for (int k = 0; k < views; ++k) own.push_back(session.make(name, options));
    else
      split = make_split_screen(name, session.index(), views, options, session.culler_context());
  }
  Culler& view(int k) { return split ? split->view(k) : *own.at(std::size_t(k)); }
  void begin_frame() {
    if (split) split->begin_frame();
  }
  void release(Session& session, int views) {
    for (int k = 0; k < views; ++k) session.release(view(k));
  }
};

// One algorithm over a split-screen frame sequence: the views render one
// after the other in each frame. Appends the run of the whole frames, then
// one run per view ("NAME [view K]").
void run_split_screen(Session& session, const std::string& name, const BenchConfig& config,
                      const std::vector<const CameraPath*>& paths, const std::vector<std::vector<FrameTruth>>& truths,
                      int rep, const std::string& label, const ProgressFn& progress, std::vector<AlgorithmRun>& out) {
  const int views = int(paths.size());
  const auto truth_of = [&](int k) { return config.verify ? &truths[std::size_t(k)] : nullptr; };
  {
    ViewCullers warm(session, name, config.options, views);
    for (int w = 0; w < config.warmup; ++w) {
      const int f = warmup_frame(config, w);
      warm.begin_frame();
      for (int k = 0; k < views; ++k)
        (void)session.run_path_frame(warm.view(k), *paths[std::size_t(k)], f, config.frames, truth_of(k));
      if (progress) progress(label, w, config.warmup, true);
    }
    warm.release(session, views);
  }
  const bool conservative = is_conservative(parse_algorithm_spec(name, config.options));
  ViewCullers cullers(session, name, config.options, views);
  AlgorithmRun whole{name, rep, conservative, {}, 0};
  std::vector<AlgorithmRun> each;
  std::vector<MissRuns> misses;
  for (int k = 0; k < views; ++k) {
    each.push_back({fmt::format("{} [view {}]", name, k + 1), rep, conservative, {}, 0});
    misses.emplace_back(session.bundle().scene.objects().size());
  }
  for (int f = 0; f < config.frames; ++f) {
    cullers.begin_frame();
    FrameStats sum;
    for (int k = 0; k < views; ++k) {
      const CameraPath& path = *paths[std::size_t(k)];
      FrameStats s = session.run_path_frame(cullers.view(k), path, f, config.frames, truth_of(k));
      if (config.verify) {
        const std::vector<ObjectId> missed = session.verify_frame(each[std::size_t(k)].name, cullers.view(k), path,
                                                                  f, truths[std::size_t(k)][std::size_t(f)], s);
        // As run_path records it, for the whole run and for the view.
        if (!missed.empty() && each[std::size_t(k)].first_miss.empty())
          each[std::size_t(k)].first_miss = fmt::format("frame {}: {}", f, session.describe_object(missed.front()));
        if (!missed.empty() && whole.first_miss.empty())
          whole.first_miss = fmt::format("view {}, frame {}: {}", k + 1, f, session.describe_object(missed.front()));
        misses[std::size_t(k)].add(missed);
      }
      add_view(sum, s);
      each[std::size_t(k)].frames.push_back(s);
    }
    finish_views(sum, views);
    whole.frames.push_back(sum);
    if ((f + 1) % kMemorySampleFrames == 0) whole.memory.push_back(session.memory_sample(f + 1));
    if (progress) progress(label, f, config.frames, false);
  }
  cullers.release(session, views);
  session.check_queries_returned(label);
  for (int k = 0; k < views; ++k) {
    each[std::size_t(k)].longest_miss_frames = misses[std::size_t(k)].longest();
    whole.longest_miss_frames = std::max(whole.longest_miss_frames, misses[std::size_t(k)].longest());
  }
  out.push_back(std::move(whole));
  for (AlgorithmRun& r : each) out.push_back(std::move(r));
}

}  // namespace

BenchResult run_bench(const BenchConfig& config, const ProgressFn& progress) {
  if (config.frames < 1) throw InputError(fmt::format("--frames {}: must be at least 1", config.frames));
  if (config.warmup < 0) throw InputError(fmt::format("--warmup {}: must not be negative", config.warmup));
  if (config.repeat < 1) throw InputError(fmt::format("--repeat {}: must be at least 1", config.repeat));
  std::vector<std::string> names = config.algorithms;
  const auto check_names = [&] {
    for (const auto& n : names) {
      if (find_algorithm(parse_algorithm_spec(n).name).harness_only && !config.verify)
        throw InputError(fmt::format("{} needs ground truth: drop it or turn verification on", n));
    }
  };
  // Validate names and options before the (slow) scene set-up.
  check_names();
  check_options(config.options);

  if (config.views < 1 || config.views > 8)
    throw InputError(fmt::format("--views {}: must be in [1, 8]", config.views));
  if (config.model && config.views > 1) throw InputError("--model predicts one view: drop it or --views");
  if (config.width / config.views < 16)
    throw InputError(fmt::format("--size {}x{} is too narrow for {} views side by side (16 px each at least)",
                                 config.width, config.height, config.views));
  gl::RendererOptions ropts;
  ropts.width = config.width / config.views;
  ropts.height = config.height;
  ropts.query_mode = config.query_mode;
  ropts.write_ids = false;  // timed frames draw colour and depth only
  ropts.multi_draw = config.multi_draw;
  ropts.query_raster = config.query_raster;
  ropts.query_margin_px = config.query_margin_px;
  if (!(config.query_margin_px >= 0.0f && config.query_margin_px <= 16.0f))
    throw InputError(fmt::format("--query-margin {}: must be in [0, 16] pixels", config.query_margin_px));
  if (config.sampling.fps < 0.0 || !std::isfinite(config.sampling.fps))
    throw InputError(fmt::format("--fps {}: must be a number >= 0 (0: spread the frames over the path)",
                                 config.sampling.fps));
  if (config.sampling.start_s < 0.0 || !std::isfinite(config.sampling.start_s))
    throw InputError(fmt::format("--start {}: must be a number of seconds >= 0", config.sampling.start_s));
  gl::ContextOptions copts;
  copts.debug = config.gl_debug;
  Session session(config.scene, ropts, config.bvh, copts);
  session.set_depth(config.depth);
  session.set_engine_moves(config.engine_moves);
  session.set_fault_hooks(config.hooks);
  session.set_sampling(config.sampling);
  session.set_stall_guard(config.stall_guard_ms);
  session.set_watchdog(config.watchdog_s);
  if (names.empty()) {  // every algorithm that runs on this kind of scene
    names = default_algorithms(session.bundle().world != nullptr);
    check_names();
  }
  // The path of each view: those named, else the scene's paths in turn.
  std::vector<const CameraPath*> paths;
  for (int k = 0; k < config.views; ++k) {
    if (config.views == 1)
      paths.push_back(&session.path(config.path));
    else if (!config.view_paths.empty())
      paths.push_back(&session.path(config.view_paths.at(std::size_t(k) % config.view_paths.size())));
    else
      paths.push_back(&session.bundle().paths.at(std::size_t(k) % session.bundle().paths.size()));
  }
  for (const CameraPath* p : paths)
    if (const int fit = p->frames_that_fit(config.sampling); config.frames > fit)
      throw InputError(fmt::format(
          "--frames {} at --fps {} from --start {} s runs past the end of path {} ({:.1f} s): {} frames fit",
          config.frames, config.sampling.fps, config.sampling.start_s, p->name(), p->duration(), fit));
  const CameraPath& path = *paths.front();
  // Each culler made once early: its options checked, and the hardware
  // profile calibrated (first use on this renderer: seconds) if one needs it.
  const auto say = [&](const std::string& line) {
    if (progress) progress(line, 0, 0, false);
  };
  if (config.model) (void)session.hardware_profile(say);
  for (const auto& n : names) (void)session.make(n, config.options, say);
  std::string profile_path = session.has_hardware_profile() ? session.hardware_profile_path() : "";
  for (const auto& n : names)
    if (const AlgorithmSpec spec = parse_algorithm_spec(n, config.options); spec.options.has("nohc.profile"))
      profile_path = spec.options.values().at("nohc.profile");

  BenchResult result;
  result.device = session.device();
  result.commit = OCCULL_COMMIT;
  result.scene = config.scene;
  result.path = path.name();
  for (std::size_t k = 1; k < paths.size(); ++k) result.path += " | " + paths[k]->name();
  result.objects = session.bundle().scene.objects().size();
  result.triangles = session.bundle().scene.triangle_count();
  result.bvh_nodes = session.bvh().size();
  if (const TiledWorld* w = session.bundle().world.get()) {
    std::size_t nodes = 0;
    double build_ms = 0.0;
    for (const Tile& t : w->tiles()) {
      nodes += t.bvh.size();
      build_ms += t.bvh_build_ms;
    }
    const glm::vec3 box = w->common_box().extent();
    const int side = 2 * w->radius() + 1;
    result.tiled_world = fmt::format(
        "tiled world: {} tiles in {:g} m cells, common box {:.0f} x {:.0f} x {:.0f} m; {} x {} cells placed around "
        "the eye; tile BVHs {} nodes in all, built in {:.1f} ms",
        w->tiles().size(), w->cell_size(), box.x, box.y, box.z, side, side, nodes, build_ms);
  }
  result.scene_build_ms = session.scene_build_ms();
  result.bvh_build_ms = session.bvh_build_ms();
  result.frames = config.frames;
  result.sampling = config.sampling;
  result.path_duration_s = path.duration();
  measure_camera_motion(session, path, config.frames, result);
  result.warmup = config.warmup;
  result.repeat = config.repeat;
  result.verified = config.verify;
  result.modelled = config.model;
  result.profile_path = profile_path;
  result.width = config.width;
  result.height = config.height;
  result.query_geometry = gl::describe_query_raster(ropts);
  result.allocator = config.allocator;
  if (config.depth == DepthMode::reversed)
    result.conditions += "views: reversed-Z, depth in [0, 1], an infinite far plane (--depth reversed)";
  if (config.engine_moves > 0.0)
    result.conditions += fmt::format("{}engine moves: {:.0f}% of the static objects moved by set_transform every "
                                     "frame (--engine-moves {})",
                                     result.conditions.empty() ? "" : "; ", 100.0 * config.engine_moves,
                                     config.engine_moves);

  std::vector<std::vector<FrameTruth>> truths(paths.size());
  if (config.verify)
    for (std::size_t k = 0; k < paths.size(); ++k) truths[k] = session.ground_truth(*paths[k], config.frames, progress);
  const std::vector<FrameTruth>& truth = truths.front();
  const std::vector<FrameTruth>* truth_ptr = config.verify ? &truth : nullptr;
  for (const auto& view_truth : truths)
    for (const FrameTruth& t : view_truth) {
      result.truth_probes += t.probes;
      result.truth_pixels += t.coverage.pixels;
    }

  for (int rep = 0; rep < config.repeat; ++rep) {
    for (const auto& name : names) {
      const std::string label = config.repeat > 1 ? fmt::format("{} #{}", name, rep + 1) : name;
      session.reset_renderer();
      if (config.views > 1) {
        run_split_screen(session, name, config, paths, truths, rep, label, progress, result.runs);
        continue;
      }
      {
        auto warm = session.make(name, config.options);
        for (int k = 0; k < config.warmup; ++k) {
          const int f = warmup_frame(config, k);
          (void)session.run_path_frame(*warm, path, f, config.frames, truth_ptr);
          if (progress) progress(label, k, config.warmup, true);
        }
        session.release(*warm);
      }
      auto culler = session.make(name, config.options);
      AlgorithmRun run = session.run_path(name, *culler, path, config.frames, truth_ptr,
                                          [&](std::string_view, int k, int n, bool w) {
                                            if (progress) progress(label, k, n, w);
                                          },
                                          config.model);
      session.release(*culler);
      session.check_queries_returned(label);
      run.repeat = rep;
      run.conservative = is_conservative(parse_algorithm_spec(name, config.options));
      result.runs.push_back(std::move(run));
    }
  }
  result.summaries = summarize_runs(result.runs);
  return result;
}

}  // namespace occull
