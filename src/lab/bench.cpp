// Running benches: every algorithm over the same views and frames,
// warmed up, verified and repeated.
#include "occull/lab.hpp"

#include "occull/counters.hpp"
#include "occull/error.hpp"

#include <fmt/format.h>
#include <glm/glm.hpp>

#include <algorithm>
#include <cmath>

#include "occull_commit.hpp"  // generated: OCCULL_COMMIT

namespace occull {
namespace {

// How far the camera moves and turns between consecutive frames of a run.
void measure_camera_motion(const Session& session, const CameraPath& path, int frames, BenchResult& r) {
  for (int k = 1; k < frames; ++k) {
    // Views of the path's own poses: relative to the scene as made, not to the floating origin.
    const auto view = [&](int f) {
      return make_view(path.sample(session.frame_time(path, f, frames)), session.bundle().lens, 1, 1);
    };
    const View a = view(k - 1), b = view(k);
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

void describe_run(const Session& session, const CameraPath& path, int frames, BenchResult& r) {
  r.device = session.device();
  r.commit = OCCULL_COMMIT;
  r.path = path.name();
  r.objects = session.bundle().scene.objects().size();
  r.triangles = session.bundle().scene.triangle_count();
  r.bvh_nodes = session.bvh().size();
  r.scene_build_ms = session.scene_build_ms();
  r.bvh_build_ms = session.bvh_build_ms();
  r.frames = frames;
  r.sampling = session.sampling();
  r.path_duration_s = path.duration();
  measure_camera_motion(session, path, frames, r);
}

namespace {

// The views of a run of frames: a culler, a path and (verified runs) the
// truth of each, and what starts a frame of all of them (a SplitScreen's
// begin_frame; nothing for cullers of their own).
struct Views {
  std::vector<Culler*> cullers;
  std::vector<const CameraPath*> paths;
  std::vector<const std::vector<FrameTruth>*> truths;  // nullptr: not verified
  std::function<void()> begin_frame;
};

// Frames 0..frames-1 of every view: the views render one after the other in
// each frame. Returns the run of whole frames (the views' figures combined
// as occull/counters.hpp says) and, with more than one view, one run per
// view ("NAME [view K]"). One view is the plain case: its run alone.
std::vector<AlgorithmRun> run_frames(Session& session, std::string_view name, const Views& v, int frames,
                                     const ProgressFn& progress, bool predict) {
  const std::size_t views = v.cullers.size();
  const bool split = views > 1;
  // The frame records are written (and so made resident) before the first
  // frame: the memory samples then see what the culler, the renderer and
  // the driver take, not this record growing by a frame's stats each frame.
  std::vector<AlgorithmRun> runs(split ? 1 + views : 1);
  runs[0].name = std::string(name);
  for (std::size_t k = 0; k < views && split; ++k) runs[1 + k].name = fmt::format("{} [view {}]", name, k + 1);
  for (AlgorithmRun& r : runs) r.frames.assign(std::size_t(frames), FrameStats{});
  AlgorithmRun& whole = runs[0];
  std::vector<MissRuns> misses(views, MissRuns(session.bundle().scene.objects().size()));
  for (int f = 0; f < frames; ++f) {
    if (v.begin_frame) v.begin_frame();
    FrameStats sum;
    for (std::size_t k = 0; k < views; ++k) {
      Culler& culler = *v.cullers[k];
      const CameraPath& path = *v.paths[k];
      AlgorithmRun& own = runs[split ? 1 + k : 0];
      FrameStats s = session.run_path_frame(culler, path, f, frames, v.truths[k]);
      if (predict) s.model_ms = session.predicted_frame_ms(session.view_at(path, f, frames));
      if (v.truths[k]) {
        const std::vector<ObjectId> missed =
            session.verify_frame(own.name, culler, path, f, (*v.truths[k])[std::size_t(f)], s);
        if (!missed.empty() && own.first_miss.empty())
          own.first_miss = fmt::format("frame {}: {}", f, session.describe_object(missed.front()));
        if (!missed.empty() && whole.first_miss.empty())  // (one view: set above, as its own)
          whole.first_miss = fmt::format("view {}, frame {}: {}", k + 1, f, session.describe_object(missed.front()));
        misses[k].add(missed);
      }
      own.frames[std::size_t(f)] = s;
      add_view(sum, s);
    }
    finish_views(sum, int(views));
    whole.frames[std::size_t(f)] = sum;
    if ((f + 1) % kMemorySampleFrames == 0) whole.memory.push_back(session.memory_sample(f + 1));
    if (progress) progress(name, f, frames, false);
  }
  for (std::size_t k = 0; k < views; ++k) {
    runs[split ? 1 + k : 0].choices = v.cullers[k]->choices();  // (a split-screen frame's whole has none)
    runs[split ? 1 + k : 0].longest_miss_frames = misses[k].longest();
    whole.longest_miss_frames = std::max(whole.longest_miss_frames, misses[k].longest());
  }
  return runs;
}

}  // namespace

AlgorithmRun Session::run_path(std::string_view name, Culler& culler, const CameraPath& path,
                               int frames, const std::vector<FrameTruth>* truth,
                               const ProgressFn& progress, bool predict) {
  return std::move(run_frames(*this, name, {{&culler}, {&path}, {truth}, {}}, frames, progress, predict).front());
}

namespace {

// The frame of the path warm-up frame `w` runs: the warm-up frames are
// spread over the path, so each algorithm sees its whole length once.
int warmup_frame(const BenchConfig& config, int w) {
  return config.warmup > 1 ? w * (config.frames - 1) / (config.warmup - 1) : 0;
}

// The cullers of the views of one run: one view's from the session; for
// more, make_split_screen's (an algorithm that shares state between views
// makes them together), or the session's, one per view, for the
// lab-only oracle.
struct ViewCullers {
  std::unique_ptr<SplitScreen> split;
  std::vector<std::unique_ptr<Culler>> own;

  ViewCullers(Session& session, const std::string& name, const Options& options, int views) {
    const AlgorithmSpec spec = parse_algorithm_spec(name, options);
    if (views == 1 || find_algorithm(spec.name).lab_only)
      for (int k = 0; k < views; ++k) own.push_back(session.make(name, options));
    else
      split = make_split_screen(name, session.index(), views, options, session.culler_context());
  }
  Culler& view(int k) { return split ? split->view(k) : *own.at(std::size_t(k)); }
  // The views over `paths`, with their truths (verified runs).
  Views over(const std::vector<const CameraPath*>& paths, const std::vector<const std::vector<FrameTruth>*>& truths) {
    Views v{{}, paths, truths, {}};
    for (int k = 0; k < int(paths.size()); ++k) v.cullers.push_back(&view(k));
    if (split) v.begin_frame = [s = split.get()] { s->begin_frame(); };
    return v;
  }
  void release(Session& session, int views) {
    for (int k = 0; k < views; ++k) session.release(view(k));
  }
};

// One algorithm over the views' frames (one view: a plain run): the warm-up
// frames with throw-away cullers, then the timed frames with fresh ones.
// The warm-up takes the one-off costs of the process out of the timed
// frames (the driver compiling its shader variants at their first use, pages
// touched for the first time), not the culler's own start-up: the timed
// cullers are new. An algorithm that runs others (auto: Culler::choices())
// has each of them warmed up as its own run would be, after its own warm-up:
// spread over the path, the warm-up frames are camera cuts to auto, whose
// schedule does not move on over them, so its candidates would otherwise pay
// those costs at their first timed frame (wrackdm17 at 320x180, three runs:
// CHC's first 8-11 ms, hiz's 15-21 ms, among frames of 1-2 ms).
// Appends the run of whole frames and, with more than one view, one run per
// view ("NAME [view K]").
void run_algorithm(Session& session, const std::string& name, const BenchConfig& config,
                   const std::vector<const CameraPath*>& paths, const std::vector<std::vector<FrameTruth>>& truths,
                   int rep, const std::string& label, const ProgressFn& progress, std::vector<AlgorithmRun>& out) {
  const int views = int(paths.size());
  std::vector<const std::vector<FrameTruth>*> truth_of;
  for (int k = 0; k < views; ++k) truth_of.push_back(config.verify ? &truths[std::size_t(k)] : nullptr);
  // Warms `spec` up; returns its choices.
  const auto warm_up = [&](const std::string& spec) {
    ViewCullers warm(session, spec, config.options, views);
    const Views v = warm.over(paths, truth_of);
    for (int w = 0; w < config.warmup; ++w) {
      const int f = warmup_frame(config, w);
      if (v.begin_frame) v.begin_frame();
      for (int k = 0; k < views; ++k)
        (void)session.run_path_frame(*v.cullers[std::size_t(k)], *paths[std::size_t(k)], f, config.frames,
                                     truth_of[std::size_t(k)]);
      if (progress) progress(label, w, config.warmup, true);
    }
    std::vector<std::string> choices = warm.view(0).choices();
    warm.release(session, views);
    return choices;
  };
  for (const std::string& choice : warm_up(name)) (void)warm_up(choice);
  ViewCullers cullers(session, name, config.options, views);
  std::vector<AlgorithmRun> runs = run_frames(session, name, cullers.over(paths, truth_of), config.frames,
                                              [&](std::string_view, int k, int n, bool w) {
                                                if (progress) progress(label, k, n, w);
                                              },
                                              config.model);
  cullers.release(session, views);
  session.check_queries_returned(label);
  const bool conservative = is_conservative(parse_algorithm_spec(name, config.options));
  for (AlgorithmRun& r : runs) {
    r.repeat = rep;
    r.conservative = conservative;
    out.push_back(std::move(r));
  }
}

}  // namespace

BenchResult run_bench(const BenchConfig& config, const ProgressFn& progress) {
  if (config.frames < 1) throw InputError(fmt::format("--frames {}: must be at least 1", config.frames));
  if (config.warmup < 0) throw InputError(fmt::format("--warmup {}: must not be negative", config.warmup));
  if (config.repeat < 1) throw InputError(fmt::format("--repeat {}: must be at least 1", config.repeat));
  std::vector<std::string> names = config.algorithms;
  const auto check_names = [&] {
    for (const auto& n : names) {
      if (find_algorithm(parse_algorithm_spec(n).name).lab_only && !config.verify)
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
  ropts.draw = config.draw;
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
  Session session(config.scene, ropts, config.bvh, copts, config.api);
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
  for (const auto& n : names) {
    (void)session.make(n, config.options, say);
    const AlgorithmSpec spec = parse_algorithm_spec(n, config.options);
    const auto set = spec.options.values().find("oracle.set");
    if (spec.name == "oracle" && set != spec.options.values().end() && set->second == "boxes") session.set_box_reach(true);
  }
  std::string profile_path = session.has_hardware_profile() ? session.hardware_profile_path() : "";
  for (const auto& n : names)
    if (const AlgorithmSpec spec = parse_algorithm_spec(n, config.options); spec.options.has("nohc.profile"))
      profile_path = spec.options.values().at("nohc.profile");

  BenchResult result;
  describe_run(session, path, config.frames, result);
  result.scene = config.scene;
  for (std::size_t k = 1; k < paths.size(); ++k) result.path += " | " + paths[k]->name();
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
  for (const auto& view_truth : truths)
    for (const FrameTruth& t : view_truth) {
      result.truth_probes += t.probes;
      result.truth_pixels += t.coverage.pixels;
    }

  for (int rep = 0; rep < config.repeat; ++rep) {
    for (const auto& name : names) {
      const std::string label = config.repeat > 1 ? fmt::format("{} #{}", name, rep + 1) : name;
      session.reset_renderer();
      run_algorithm(session, name, config, paths, truths, rep, label, progress, result.runs);
    }
  }
  result.summaries = summarize_runs(result.runs);
  if (session.bundle().origin != glm::dvec3(0.0) || session.origin_moves() > 0) {
    const glm::dvec3 o = session.origin();
    result.conditions += fmt::format("{}scene {:.0f} m out along x and z: occull's coordinates relative to a floating "
                                     "origin near the camera, last at ({:.0f}, {:.0f}, {:.0f}), cells of {:g} m, "
                                     "moved {} times",
                                     result.conditions.empty() ? "" : "; ", session.bundle().origin.x, o.x, o.y, o.z,
                                     session.origin_grid(), session.origin_moves());
  }
  return result;
}

}  // namespace occull
