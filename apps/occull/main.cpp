// occull — command-line tool: device info, scenes, algorithms, benchmarks
// and screenshots.
//
// Exit codes: kExitCodes below (printed by --help; the README's table is
// tested equal to it).
#include "occull/culler.hpp"
#include "occull/debug_view.hpp"
#include "occull/error.hpp"
#include "occull/grid.hpp"
#include "occull/gl/calibrate.hpp"
#include "occull/gl/context.hpp"
#include "occull/gl/painter.hpp"
#include "occull/gl/renderer.hpp"
#include "occull/process.hpp"
#include "occull/profile_io.hpp"
#include "occull/q3bsp.hpp"
#include "occull/harness.hpp"
#ifdef OCCULL_OSG
#include "occull/osg/osg_bench.hpp"
#include "occull/osg/scene_graph.hpp"
#include <osgDB/WriteFile>
#endif
#include "occull/input_limits.hpp"
#include "occull/report.hpp"
#include "occull/scenes.hpp"
#include "occull/soak.hpp"
#include "occull/suite.hpp"
#include "occull/sweep.hpp"
#include "raster_bench.hpp"
#include "viewer.hpp"

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <stb_image_write.h>

#include <algorithm>
#include <charconv>
#include <chrono>
#include <glm/gtc/matrix_transform.hpp>
#include <cstdio>
#include <fstream>
#include <iostream>
#include <memory>
#include <utility>
#include <random>
#include <unistd.h>

namespace {

constexpr int kExitInternal = 1;
constexpr int kExitInput = 2;
constexpr int kExitNoGl = 3;
constexpr int kExitVerificationFailed = 4;
constexpr int kExitSoakLeak = 5;

constexpr const char* kMallocHelp =
    "allocator policy of the process: engine (keep freed heap memory, as engines do, so driver batches do "
    "not page-fault it back in) or system (glibc's defaults)";

constexpr const char* kGlDebugHelp =
    "GL debug contexts: the driver checks every call, and a failing one stops the run with exit 1, "
    "naming the call and its stack (slower: not for timings)";
constexpr const char* kDepthHelp =
    "depth convention of the views: standard (OpenGL's [-1, 1]) or reversed (reversed-Z in [0, 1] with an "
    "infinite far plane, as engines render); the truth and the verifier follow it";

struct Size {
  int width = 1280;
  int height = 720;
};

Size parse_size(const std::string& text) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X'))
    throw occull::InputError(fmt::format("--size '{}' is not WIDTHxHEIGHT (e.g. 1280x720)", text));
  occull::limits::check_viewport(w, h, "--size");
  return {w, h};
}

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> out;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t comma = std::min(text.find(',', pos), text.size());
    std::string item = text.substr(pos, comma - pos);
    if (!item.empty()) out.push_back(item);
    pos = comma + 1;
  }
  return out;
}

occull::gl::QueryRaster parse_query_raster(const std::string& s) {
  if (s == "margin") return occull::gl::QueryRaster::margin;
  if (s == "hardware") return occull::gl::QueryRaster::hardware;
  if (s == "exact") return occull::gl::QueryRaster::exact;
  throw occull::InputError(
      fmt::format("unknown query raster '{}'; valid values: margin, hardware, exact", s));
}

occull::gl::QueryMode parse_query_mode(const std::string& s) {
  if (s == "samples") return occull::gl::QueryMode::samples_passed;
  if (s == "any") return occull::gl::QueryMode::any_samples_passed;
  if (s == "conservative") return occull::gl::QueryMode::any_samples_passed_conservative;
  throw occull::InputError(
      fmt::format("unknown query mode '{}'; valid modes: samples, any, conservative", s));
}

int cmd_info() {
  const auto context = occull::gl::Context::create();
  const auto d = context->info();
  fmt::print("vendor          {}\nrenderer        {}\nversion         {}\nGLSL            {}\n"
             "EGL platform    {}\n",
             d.vendor, d.renderer, d.version, d.glsl_version, d.egl_platform);
  fmt::print("query counter bits: GL_SAMPLES_PASSED {}, GL_ANY_SAMPLES_PASSED {}, GL_TIME_ELAPSED {}, "
             "GL_TIMESTAMP {}\n",
             d.samples_passed_bits, d.any_samples_passed_bits, d.time_elapsed_bits, d.timestamp_bits);
  fmt::print("occlusion queries (GL_SAMPLES_PASSED, GL_ANY_SAMPLES_PASSED[_CONSERVATIVE]), "
             "conditional rendering and timer queries are core in OpenGL 4.5.\n");
  fmt::print("query boxes are kept conservative by: {}\n",
             occull::gl::describe_query_raster(occull::gl::RendererOptions{}));
  fmt::print("culling-relevant extensions ({}):\n", d.culling_extensions.size());
  for (const auto& e : d.culling_extensions) fmt::print("  {}\n", e);
  return 0;
}

int cmd_list_maps(const std::string& pk3) {
  const auto maps = occull::q3::list_maps(pk3);
  fmt::print("{} maps in {} (use --scene q3:{}:NAME):\n", maps.size(), pk3, pk3);
  for (const auto& m : maps) fmt::print("  {}\n", m);
  return 0;
}

struct PathArgs {
  std::string scene = "city";
  std::string path;
  std::string out;
};

int cmd_path(const PathArgs& a) {
  if (a.out.empty()) throw occull::InputError("--out FILE is required");
  const occull::SceneBundle bundle = occull::make_scene(a.scene);
  const occull::CameraPath& path = a.path.empty() ? bundle.paths.front() : bundle.path(a.path);
  occull::write_path_file(path, a.out);
  fmt::print("wrote {} ({} poses, {:.1f} s) of {} / {}; replay it with --path file:{}\n", a.out,
             path.keys().size(), path.duration(), a.scene, path.name(), a.out);
  return 0;
}

int cmd_scenes() {
  for (const auto& info : occull::embedded_scenes()) {
    const auto bundle = occull::make_scene(info.name);
    fmt::print("{} — {}\n", info.name, info.summary);
    fmt::print("  default: {} objects ({} dynamic), {} triangles\n", bundle.scene.objects().size(),
               bundle.scene.dynamic_objects().size(), bundle.scene.triangle_count());
    fmt::print("  parameters ({}:key=value,...):\n", info.name);
    for (const auto& p : info.params) {
      if (!p.choices.empty()) {
        std::string names;
        for (const auto& c : p.choices) names += (names.empty() ? "" : " | ") + c;
        fmt::print("    {:<10} default {:<6} one of {}  {}\n", p.key,
                   p.choices.at(std::size_t(p.default_value)), names, p.help);
        continue;
      }
      fmt::print("    {:<10} default {:<6} range [{}, {}]  {}\n", p.key, p.default_value, p.min,
                 p.max, p.help);
    }
    fmt::print("  paths:\n");
    for (const auto& path : bundle.paths)
      fmt::print("    {:<10} {:.1f} s  {}\n", path.name(), path.duration(), path.description());
    fmt::print("\n");
  }
  fmt::print("q3:FILE.pk3:MAP, q3:FILE.bsp — a Quake 3 level (IBSP 46); path tour. "
             "occull scenes --list-maps FILE.pk3 lists the maps of an archive.\n"
             "file:MODEL — any model assimp reads (glTF 2, OBJ, ...); paths orbit, through.\n"
             "Any scene also takes --path file:PATH, a recorded path (see occull path).\n");
  return 0;
}

int cmd_algos() {
  for (const auto& a : occull::algorithms()) {
    const bool has_threshold = std::any_of(a.options.begin(), a.options.end(),
                                           [](const occull::OptionInfo& o) { return o.key == "threshold"; });
    fmt::print("{:<10} {}{}\n", a.name, a.summary,
               !a.conservative ? " (may pop: not conservative)"
               : has_threshold ? " (conservative; threshold > 0 makes a run approximate)"
                               : " (conservative)");
    for (const auto& o : a.options)
      fmt::print("    --opt {}.{}={}  {}{}\n", a.name, o.key, o.default_value,
                 o.values.empty() ? "" : fmt::format("({}) ", o.values), o.help);
  }
  return 0;
}

class Progress {
 public:
  Progress() : tty_(isatty(fileno(stderr)) != 0) {}
  void operator()(std::string_view algo, int frame, int frames, bool warmup) {
    if (frames == 0) {  // a message
      std::fprintf(stderr, "%.*s\n", int(algo.size()), algo.data());
      return;
    }
    const bool last = frame + 1 == frames;
    if (!tty_ && !last) return;
    std::fprintf(stderr, "%s[%.*s] %s %d/%d%s", tty_ ? "\r" : "", int(algo.size()), algo.data(),
                 warmup ? "warm-up" : "frame", frame + 1, frames, tty_ ? "   " : "\n");
    if (tty_ && last) std::fputc('\n', stderr);
    std::fflush(stderr);
  }

 private:
  bool tty_;
};

struct BenchArgs {
  std::string scene = "city";
  std::string path;
  std::string algos;
  int frames = 100;
  int warmup = 8;
  double fps = 0.0;
  double start = 0.0;
  std::string size = "1280x720";
  std::vector<std::string> opts;
  std::string query_mode = "samples";
  std::string query_raster = "margin";
  float query_margin = occull::gl::RendererOptions{}.query_margin_px;
  std::string draw = "single";
  std::string depth = "standard";
  double engine_moves = 0.0;
  int bvh_leaf = occull::BvhOptions{}.max_leaf_objects;
  int repeat = 1;
  std::string verify = "on";
  std::string json;
  std::string csv;
  std::string report = "occull-report";
  bool no_report = false;
  bool model = false;
  std::string malloc_policy = "engine";
  std::string suite;
  int views = 1;
  bool gl_debug = false;
  double stall_guard = 0.0;
  double watchdog = occull::Session::kWatchdogSeconds;
};

bool parse_on_off(const std::string& flag, const std::string& s) {
  if (s == "on" || s == "true" || s == "yes" || s == "1") return true;
  if (s == "off" || s == "false" || s == "no" || s == "0") return false;
  throw occull::InputError(fmt::format("{} '{}': expected on or off", flag, s));
}

occull::gl::DrawMode parse_draw_mode(const std::string& s) {
  if (s == "single") return occull::gl::DrawMode::single;
  if (s == "multi") return occull::gl::DrawMode::multi;
  if (s == "indirect") return occull::gl::DrawMode::indirect;
  throw occull::InputError(fmt::format("unknown draw mode '{}'; valid modes: single, multi, indirect", s));
}

occull::Options parse_options(const std::vector<std::string>& opts) {
  occull::Options options;
  for (const auto& o : opts) options.set(o);
  occull::check_options(options);
  return options;
}

// Opens an output file before the (long) run, so a bad path fails at once.
std::unique_ptr<std::ofstream> open_output(const std::string& path) {
  if (path.empty()) return nullptr;
  auto f = std::make_unique<std::ofstream>(path, std::ios::binary);
  if (!*f) throw occull::InputError(fmt::format("cannot open '{}' for writing", path));
  return f;
}

void check_written(const std::ofstream& f, const std::string& path) {
  if (!f) throw occull::InputError(fmt::format("cannot write '{}'", path));
}

// `bench --suite NAME`: every entry of the suite with the same settings,
// a table per entry, then the summary over all of them.
int run_suite(const BenchArgs& a, occull::BenchConfig c, bool report) {
  const occull::Suite& suite = occull::find_suite(a.suite);
  if (!a.csv.empty()) throw occull::InputError("--csv is per scene; with --suite use --json or the report folder");
  const auto json = open_output(a.json);
  if (report) occull::prepare_report_folder(a.report);
  std::vector<occull::BenchResult> results;
  std::vector<std::string> skipped;
  for (std::size_t i = 0; i < suite.entries.size(); ++i) {
    const occull::SuiteEntry& e = suite.entries[i];
    if (!e.needs_file.empty() && access(e.needs_file.c_str(), R_OK) != 0) {
      skipped.push_back(fmt::format("{} / {} ({} is missing: make data fetches it)", e.scene, e.path, e.needs_file));
      std::fprintf(stderr, "suite %s: skipping %s / %s: %s is missing (make data fetches it)\n", suite.name.c_str(),
                   e.scene.c_str(), e.path.c_str(), e.needs_file.c_str());
      continue;
    }
    std::fprintf(stderr, "suite %s: entry %zu of %zu: %s / %s\n", suite.name.c_str(), i + 1, suite.entries.size(),
                 e.scene.c_str(), e.path.c_str());
    c.scene = e.scene;
    c.path = e.path;
    Progress progress;
    try {
      results.push_back(occull::run_bench(c, std::ref(progress)));
    } catch (const occull::InputError& error) {
      // One entry that cannot run (a map missing from the archive) must
      // not throw away the others' results.
      skipped.push_back(fmt::format("{} / {} ({})", e.scene, e.path, error.what()));
      std::fprintf(stderr, "suite %s: skipping %s / %s: %s\n", suite.name.c_str(), e.scene.c_str(),
                   e.path.c_str(), error.what());
      continue;
    }
    std::cout << fmt::format("== {}. {} / {}\n", i + 1, e.scene, e.path);
    occull::print_table(results.back(), std::cout);
    std::cout << "\n";
    std::cout.flush();
  }
  occull::print_suite_summary(suite, results, skipped, std::cout);
  std::cout.flush();
  if (json) {
    occull::write_suite_json(suite, results, skipped, *json);
    json->flush();
    check_written(*json, a.json);
  }
  if (report) {
    const auto files = occull::write_suite_report(suite, results, skipped, a.report);
    std::fprintf(stderr, "report: %s/suite.md (%zu files)\n", a.report.c_str(), files.size());
  }
  for (const occull::BenchResult& r : results)
    if (!occull::verification_failures(r).empty()) return kExitVerificationFailed;
  return 0;
}

occull::BenchConfig bench_config(const BenchArgs& a) {
  occull::BenchConfig c;
  c.allocator = occull::apply_allocator_policy(occull::parse_allocator_policy(a.malloc_policy));
  c.scene = a.scene;
  c.views = a.views;
  if (a.views > 1)
    c.view_paths = split_list(a.path);
  else if (a.path.find(',') != std::string::npos)
    throw occull::InputError(fmt::format("--path {}: one path per view needs --views", a.path));
  else
    c.path = a.path;
  c.algorithms = split_list(a.algos);
  c.frames = a.frames;
  c.warmup = a.warmup;
  c.sampling = {a.fps, a.start};
  const Size size = parse_size(a.size);
  c.width = size.width;
  c.height = size.height;
  c.options = parse_options(a.opts);
  c.query_mode = parse_query_mode(a.query_mode);
  c.query_raster = parse_query_raster(a.query_raster);
  c.query_margin_px = a.query_margin;
  c.draw = parse_draw_mode(a.draw);
  c.depth = occull::parse_depth_mode(a.depth);
  c.engine_moves = a.engine_moves;
  c.gl_debug = a.gl_debug;
  c.stall_guard_ms = a.stall_guard;
  c.watchdog_s = a.watchdog;
  c.repeat = a.repeat;
  if (a.bvh_leaf < 1 || a.bvh_leaf > 64)
    throw occull::InputError(fmt::format("--bvh-leaf {}: must be in [1, 64]", a.bvh_leaf));
  c.bvh.max_leaf_objects = a.bvh_leaf;
  c.verify = parse_on_off("--verify", a.verify);
  c.model = a.model;
  return c;
}

// Writes a bench's JSON and CSV (to the streams given, opened before the run)
// and its report folder (when `report` is not empty).
void write_outputs(const occull::BenchResult& result, std::ofstream* json, const std::string& json_path,
                   std::ofstream* csv, const std::string& csv_path, const std::string& report) {
  if (json) {
    occull::write_json(result, *json);
    json->flush();
    check_written(*json, json_path);
  }
  if (csv) {
    occull::write_csv(result, *csv);
    csv->flush();
    check_written(*csv, csv_path);
  }
  if (!report.empty()) {
    const auto files = occull::write_report(result, report);
    std::fprintf(stderr, "report: %s/report.md (%zu files)\n", report.c_str(), files.size());
  }
}

int cmd_bench(const BenchArgs& a) {
  const occull::BenchConfig c = bench_config(a);
  const bool report = !a.no_report && !a.report.empty();
  if (!a.suite.empty()) return run_suite(a, c, report);
  const auto json = open_output(a.json);
  const auto csv = open_output(a.csv);
  if (report) occull::prepare_report_folder(a.report);
  Progress progress;
  const auto result = occull::run_bench(c, std::ref(progress));
  occull::print_table(result, std::cout);
  std::cout.flush();
  write_outputs(result, json.get(), a.json, csv.get(), a.csv, report ? a.report : std::string());
  // A conservative culler that misses a visible object is broken, whatever its frame time.
  return occull::verification_failures(result).empty() ? 0 : kExitVerificationFailed;
}

#ifdef OCCULL_OSG
struct OsgArgs {
  BenchArgs run;  // scene, path, frames, warmup, fps, start, size, opts, repeat, verify, json, report
  std::string rows;
  std::string threading = "single";
  std::string export_file;
  std::string file;
  std::string png;
};

// `osg`: occull's cullers inside OpenSceneGraph beside OSG's OcclusionQueryNode.
int cmd_osg(const OsgArgs& a) {
  const BenchArgs& r = a.run;
  if (!a.export_file.empty()) {
    const occull::SceneBundle bundle = occull::make_scene(r.scene);
    const osgOccull::ExportedScene exported = osgOccull::export_scene(bundle.scene);
    if (!osgDB::writeNodeFile(*exported.root, a.export_file))
      throw occull::InputError(fmt::format("{}: OpenSceneGraph cannot write it (no plugin for its extension, or "
                                           "the folder is not writable)", a.export_file));
    std::fprintf(stderr, "exported %s (%zu objects) to %s\n", r.scene.c_str(), bundle.scene.objects().size(),
                 a.export_file.c_str());
    return 0;
  }
  osgOccull::OsgBenchConfig c;
  c.scene = r.scene;
  c.file = a.file;
  c.path = r.path;
  c.rows = split_list(a.rows);
  c.frames = r.frames;
  c.warmup = r.warmup;
  c.repeat = r.repeat;
  c.sampling = {r.fps, r.start};
  const Size size = parse_size(r.size);
  c.width = size.width;
  c.height = size.height;
  c.verify = parse_on_off("--verify", r.verify);
  c.threading = a.threading;
  c.options = parse_options(r.opts);
  if (!a.png.empty())
    c.last_frame = [&](const std::string& row, int width, int height, const std::vector<std::uint8_t>& rgba) {
      std::string name = row;
      std::replace_if(name.begin(), name.end(), [](char ch) { return ch == ':' || ch == '=' || ch == '/'; }, '_');
      const std::string file = fmt::format("{}-{}.png", a.png, name);
      if (!stbi_write_png(file.c_str(), width, height, 4, rgba.data(), width * 4))
        throw occull::InputError(fmt::format("cannot write '{}'", file));
      std::fprintf(stderr, "wrote %s\n", file.c_str());
    };
  const bool report = !r.no_report && !r.report.empty();
  const auto json = open_output(r.json);
  if (report) occull::prepare_report_folder(r.report);
  Progress progress;
  const auto result = osgOccull::run_osg_bench(c, std::ref(progress));
  occull::print_table(result, std::cout);
  std::cout.flush();
  write_outputs(result, json.get(), r.json, nullptr, "", report ? r.report : std::string());
  return occull::verification_failures(result).empty() ? 0 : kExitVerificationFailed;
}
#endif

struct SweepArgs {
  BenchArgs bench;  // scene, path, frames, size, ...; bench.algos holds the algorithm
  std::vector<std::string> vary;
  std::string baseline = "vfc";
  double popping = 0.1;
  int longest = 3;
};

// `sweep`: one algorithm over every combination of --vary values, with the
// baselines, in one interleaved benchmark; a table per setting.
int cmd_sweep(const SweepArgs& a) {
  if (a.bench.algos.empty() || a.bench.algos.find(',') != std::string::npos ||
      a.bench.algos.find(':') != std::string::npos)
    throw occull::InputError("--algo takes one algorithm name (its options: --vary, or --opt for fixed ones)");
  if (!(a.popping >= 0.0 && a.popping <= 100.0))
    throw occull::InputError(fmt::format("--popping {}: must be a percentage in [0, 100]", a.popping));
  if (a.longest < 0) throw occull::InputError(fmt::format("--longest {}: must not be negative", a.longest));
  const std::string& algo = a.bench.algos;
  std::vector<occull::SweepAxis> axes;
  for (const std::string& v : a.vary) axes.push_back(occull::parse_sweep_axis(algo, v));
  BenchArgs b = a.bench;
  b.algos = a.baseline;
  for (const std::string& spec : occull::sweep_specs(algo, axes)) b.algos += (b.algos.empty() ? "" : ",") + spec;
  const occull::BenchConfig c = bench_config(b);
  const auto json = open_output(b.json);
  Progress progress;
  const auto result = occull::run_bench(c, std::ref(progress));
  occull::print_sweep_table(result, algo, axes, {a.popping / 100.0, std::uint32_t(a.longest)}, std::cout);
  std::cout.flush();
  if (json) {
    occull::write_json(result, *json);
    json->flush();
    check_written(*json, b.json);
  }
  return occull::verification_failures(result).empty() ? 0 : kExitVerificationFailed;
}

struct CalibrateArgs {
  std::string size = "1280x720";
  int repeats = 5;
  std::string out;
  bool check = false;
  std::string malloc_policy = "engine";
};

std::string time_text(double ms) {
  return ms >= 0.01 ? fmt::format("{:.4f} ms", ms) : fmt::format("{:.3f} ns", ms * 1e6);
}

void print_calibration(const occull::gl::CalibrationResult& result) {
  fmt::print("{:<10} {:>14} {:>8}  {}\n", "quantity", "time", "spread", "meaning");
  for (const auto& v : result.values)
    fmt::print("{:<10} {:>14} {:>7.0f}%  {}\n", v.name, time_text(v.value_ms), 100.0 * v.spread, v.meaning);
}

int cmd_calibrate(const CalibrateArgs& a) {
  const Size size = parse_size(a.size);
  if (a.repeats < 1 || a.repeats > 100)
    throw occull::InputError(fmt::format("--repeats {}: must be in [1, 100]", a.repeats));
  const std::string allocator = occull::apply_allocator_policy(occull::parse_allocator_policy(a.malloc_policy));
  std::fprintf(stderr, "allocator: %s\n", allocator.c_str());
  const auto context = occull::gl::Context::create();
  const auto device = context->info();
  const std::string key = device.renderer + " | " + device.version;
  occull::gl::CalibrationOptions o;
  o.width = size.width;
  o.height = size.height;
  o.repeats = a.repeats;
  const auto progress = [](const std::string& line) { std::fprintf(stderr, "%s\n", line.c_str()); };
  if (a.check) {
    // Two independent calibrations, compared: a report, nothing is written.
    const auto first = occull::gl::calibrate(o, progress);
    const auto second = occull::gl::calibrate(o, progress);
    fmt::print("calibration check of {} at {}x{} ({} rounds per run, 2 runs)\n\nfirst run:\n", key,
               size.width, size.height, a.repeats);
    print_calibration(first);
    fmt::print("\nsecond run:\n");
    print_calibration(second);
    const auto checks = occull::gl::check_calibrations(first, second);
    std::size_t failed = 0;
    fmt::print("\n{:<7} {:<62} {}\n", "verdict", "check", "first | second run");
    for (const auto& c : checks) {
      failed += c.ok ? 0 : 1;
      fmt::print("{:<7} {:<62} {}\n", c.ok ? "ok" : "SUSPECT", c.name, c.detail);
    }
    fmt::print("\n{} of {} checks suspect. Timings on a shared machine are noisy: a suspect "
               "repeatability line says the profile is only as good as its spread; a suspect "
               "ordering line says the measurement method does not fit this renderer.\n",
               failed, checks.size());
    return 0;
  }
  const auto result = occull::gl::calibrate(o, progress);
  occull::HardwareProfile profile = result.profile;
  profile.renderer = key;
  const std::string path = a.out.empty() ? occull::default_profile_path(key) : a.out;
  occull::save_profile(profile, path);
  fmt::print("hardware profile of {} at {}x{} ({} rounds, {:.1f} s)\n\n", key, size.width, size.height,
             a.repeats, result.seconds);
  print_calibration(result);
  fmt::print("\nN_q (queries in flight before the oldest must be done): {}\n", profile.max_parallel_queries());
  fmt::print("spread = (max - min) / median over the rounds; T_o^l is the maximum.\nwritten: {}\n", path);
  return 0;
}

struct RenderArgs {
  std::string scene = "city";
  std::string path;
  std::string algo;  // empty: the scene's frustum-culling baseline
  std::string frame = "0";  // K, or A-B for a numbered sequence
  int frames = 100;
  double fps = 0.0;
  double start = 0.0;
  std::string size = "1280x720";
  std::string out = "occull.png";
  std::string view = "color";
  std::vector<std::string> opts;
  bool gl_debug = false;
  std::string depth = "standard";
};

// "K" or "A-B" (inclusive), each in [0, frames).
std::pair<int, int> parse_frame_range(const std::string& text, int frames) {
  const auto dash = text.find('-');
  const auto number = [&](const std::string& part) {
    int v = 0;
    const auto [end, ec] = std::from_chars(part.data(), part.data() + part.size(), v);
    if (part.empty() || ec != std::errc() || end != part.data() + part.size())
      throw occull::InputError(fmt::format("--frame '{}' is not a frame K or a range A-B", text));
    return v;
  };
  const int first = number(text.substr(0, dash));
  const int last = dash == std::string::npos ? first : number(text.substr(dash + 1));
  if (first > last) throw occull::InputError(fmt::format("--frame {}: the range ends before it starts", text));
  if (first < 0 || last >= frames)
    throw occull::InputError(fmt::format("--frame {} is outside [0, {}] (--frames {})", text, frames - 1, frames));
  return {first, last};
}

// out.png for one frame; out-0012.png for frame 12 of a range.
std::string numbered(const std::string& out, int frame, bool range) {
  if (!range) return out;
  const auto dot = out.rfind('.');
  const auto slash = out.rfind('/');
  const bool has_ext = dot != std::string::npos && (slash == std::string::npos || dot > slash);
  return fmt::format("{}-{:04d}{}", has_ext ? out.substr(0, dot) : out, frame, has_ext ? out.substr(dot) : ".png");
}

// The views that need an algorithm of one kind refuse the others.
void check_view_fits(occull::DebugView view, const std::string& algo_spec) {
  const occull::AlgorithmInfo& info = occull::find_algorithm(occull::parse_algorithm_spec(algo_spec).name);
  if (occull::view_fits(view, info)) return;
  if (view == occull::DebugView::cells)
    throw occull::InputError(fmt::format("--view cells shows the cells of the grid culler (--algo grid), not {}",
                                         info.name));
  throw occull::InputError(fmt::format(
        "--view tiles shows tile instances of a tiled-world algorithm (tilevfc, pertile, tiles), not {}", info.name));
}

int cmd_render(const RenderArgs& a) {
  const Size size = parse_size(a.size);
  if (a.frames < 1) throw occull::InputError("--frames must be at least 1");
  const auto [first, last] = parse_frame_range(a.frame, a.frames);
  // `soc`: the frame with the CPU occlusion buffer the culler used beside it.
  const bool buffer_view = a.view == "soc";
  const occull::DebugView view = buffer_view ? occull::DebugView::color : occull::parse_debug_view(a.view);
  const occull::Options options = parse_options(a.opts);
  occull::gl::RendererOptions ropts;
  ropts.width = size.width;
  ropts.height = size.height;
  if (!(a.fps >= 0.0) || !(a.start >= 0.0))
    throw occull::InputError("--fps and --start must be numbers >= 0");
  occull::gl::ContextOptions copts;
  copts.debug = a.gl_debug;
  occull::Session session(a.scene, ropts, {}, copts);
  session.set_sampling({a.fps, a.start});
  session.set_depth(occull::parse_depth_mode(a.depth));
  const auto& path = session.path(a.path);
  if (last >= path.frames_that_fit(session.sampling()))
    throw occull::InputError(fmt::format("--frame {} at --fps {} from --start {} s lies past the end of path {} ({:.1f} s)",
                                         last, a.fps, a.start, path.name(), path.duration()));
  const std::string algo =
      a.algo.empty() ? std::string(occull::vfc_baseline(session.bundle().world != nullptr)) : a.algo;
  check_view_fits(view, algo);
  if (occull::find_algorithm(occull::parse_algorithm_spec(algo).name).harness_only)
    throw occull::InputError(fmt::format("--algo {} needs each frame's ground truth: bench runs it, render does not",
                                         algo));
  // As bench makes them: specs with options (chcpp:batch=20), nohc with the
  // calibrated profile (calibrated on first use).
  auto culler = session.make(algo, options);
  std::unique_ptr<occull::gl::Painter> painter;
  if (view != occull::DebugView::color)
    painter = std::make_unique<occull::gl::Painter>(session.bundle().scene, size.width, size.height);
  // Run the frames before the first too, so cullers with temporal state see
  // the same history they would in a benchmark.
  const bool range = first != last;
  for (int k = 0; k <= last; ++k) {
    occull::FrameLog log;
    const occull::View frame_view = session.view_at(path, k, a.frames);
    const occull::FrameStats stats =
        session.run_frame(*culler, frame_view, session.frame_time(path, k, a.frames), k >= first ? &log : nullptr);
    if (k < first) continue;
    std::vector<std::uint8_t> pixels = session.renderer().read_rgba();
    std::string legend;
    if (painter) {
      const auto frame_objects = session.recording().objects();
      const std::vector<occull::ObjectId> drawn(frame_objects.begin(), frame_objects.end());
      std::vector<occull::ObjectId> truth;
      if (view == occull::DebugView::overview)  // the verifier's view: what was missed
        for (const auto& v : session.truth_at(path, k, a.frames).visible) truth.push_back(v.id);
      const occull::DebugFrame frame{session.bundle().scene, frame_view, log, culler->regions(), drawn, truth};
      const occull::Picture picture =
          occull::make_picture(view, frame, float(size.width) / float(size.height));
      pixels = painter->paint(picture, pixels);
      for (const auto& l : picture.legend)
        legend += fmt::format("\n  {:>6}  {} (rgb {:.2f} {:.2f} {:.2f})", l.count, l.label, l.color.r, l.color.g,
                              l.color.b);
    }
    int image_width = size.width;
    if (buffer_view) {
      const occull::OcclusionBuffer* buffer = culler->occlusion_buffer();
      if (!buffer)
        throw occull::InputError(fmt::format("--view soc shows a CPU occlusion buffer and {} has none: use --algo soc, "
                                             "or chc, chcpp or nohc with cpu_test=on",
                                             algo));
      const std::vector<std::uint8_t> right = occull::occlusion_buffer_rgba(*buffer, size.width, size.height);
      std::vector<std::uint8_t> both(pixels.size() * 2);
      const std::size_t row = std::size_t(size.width) * 4;
      for (int y = 0; y < size.height; ++y) {
        std::copy_n(pixels.data() + std::size_t(y) * row, row, both.data() + std::size_t(y) * 2 * row);
        std::copy_n(right.data() + std::size_t(y) * row, row, both.data() + std::size_t(y) * 2 * row + row);
      }
      pixels = std::move(both);
      image_width = 2 * size.width;
      legend = fmt::format("\n  right: the occlusion buffer, {}x{} texels, {} covered (nearer brighter; empty: dark blue)",
                           buffer->width(), buffer->height(), buffer->covered_texels());
    }
    const std::string file = numbered(a.out, k, range);
    if (!stbi_write_png(file.c_str(), image_width, size.height, 4, pixels.data(), image_width * 4))
      throw occull::InputError(fmt::format("cannot write '{}'", file));
    fmt::print("wrote {} ({}x{}): {} / {} frame {} with {}, view {}: {} objects, {} triangles drawn, {} queries{}\n",
               file, image_width, size.height, a.scene, path.name(), k, algo, a.view, stats.objects_rendered,
               stats.triangles, stats.queries, legend);
  }
  session.release(*culler);
  return 0;
}

// The options of a run of frames that bench and sweep share; `per` names
// what the timed and warm-up frames are counted per.
void add_run_options(CLI::App* cmd, BenchArgs& a, const std::string& per) {
  cmd->add_option("--scene", a.scene, "scene spec name[:key=value,...] (see occull scenes)")->capture_default_str();
  cmd->add_option("--path", a.path, "camera path (default: the scene's first), or file:PATH to replay a recorded one");
  cmd->add_option("--frames", a.frames, "timed frames per " + per)->capture_default_str();
  cmd->add_option("--warmup", a.warmup, "untimed warm-up frames per " + per)->capture_default_str();
  cmd->add_option("--fps", a.fps,
                  "frames at this rate of path time, as a real-time walk renders them (0: spread the frames "
                  "over the whole path)")
      ->capture_default_str();
  cmd->add_option("--start", a.start, "with --fps: path time of the first frame, seconds")->capture_default_str();
  cmd->add_option("--size", a.size, "render size WIDTHxHEIGHT")->capture_default_str();
  cmd->add_option("--opt", a.opts, "algorithm option algo.key=value (repeatable)");
  cmd->add_option("--repeat", a.repeat, "run the whole set R times, interleaved; report medians")
      ->capture_default_str();
  cmd->add_option("--verify", a.verify, "check every frame against ground truth (on/off)")->capture_default_str();
  cmd->add_option("--json", a.json, "write the results as JSON to this file");
  cmd->add_option("--malloc", a.malloc_policy, kMallocHelp)->capture_default_str();
  cmd->add_flag("--gl-debug", a.gl_debug, kGlDebugHelp);
  cmd->add_option("--stall-guard", a.stall_guard,
                  "milliseconds a culler waits for a query result before taking it as visible, as engines "
                  "guard against a driver that never answers (0: wait; counted as stalled per frame)")
      ->capture_default_str();
  cmd->add_option("--watchdog", a.watchdog,
                  "seconds a frame may take before the run stops with exit 1, naming the frame (a hung GL "
                  "driver or device; 0: off)")
      ->capture_default_str();
}

struct SoakArgs {
  std::string scene = "city";
  std::string path;
  std::string algos = "chcpp,nohc,grid";
  std::int64_t frames = 100000;
  std::int64_t window = 10000;
  std::int64_t warmup = 1000;
  double fps = 30.0;
  std::string size = "320x180";
  std::vector<std::string> opts;
  std::string json;
  // glibc's defaults: the soak judges whether resident memory grows, and
  // under the engine policy it cannot shrink (it is the heap's high-water
  // mark, which a rare peak of the driver's memory raises without a leak).
  std::string malloc_policy = "system";
  bool gl_debug = false;
  double stall_guard = 0.0;
  double watchdog = occull::Session::kWatchdogSeconds;
};

// A looped walk per culler for many frames: what must stay flat (memory,
// the query pool, buffers) and how the frame time drifts, per window.
int cmd_soak(const SoakArgs& a) {
  occull::SoakConfig c;
  const std::string allocator = occull::apply_allocator_policy(occull::parse_allocator_policy(a.malloc_policy));
  c.scene = a.scene;
  c.path = a.path;
  c.algorithms = split_list(a.algos);
  c.frames = a.frames;
  c.window = a.window;
  c.warmup = a.warmup;
  c.fps = a.fps;
  const Size size = parse_size(a.size);
  c.renderer.width = size.width;
  c.renderer.height = size.height;
  c.context.debug = a.gl_debug;
  c.options = parse_options(a.opts);
  c.stall_guard_ms = a.stall_guard;
  c.watchdog_s = a.watchdog;
  const auto json = open_output(a.json);
  const bool tty = isatty(fileno(stderr)) != 0;
  const auto start = std::chrono::steady_clock::now();
  std::cout << "allocator: " << allocator << "\n";
  const auto progress = [&](const std::string& algo, std::int64_t k, std::int64_t n) {
    if (!tty && k % 5000 != 1 && k != n) return;
    const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    std::fprintf(stderr, "%s[%s] frame %lld/%lld, %.0f s%s", tty ? "\r" : "", algo.c_str(), (long long)k,
                 (long long)n, s, tty && k != n ? "   " : "\n");
    std::fflush(stderr);
  };
  // The table is printed as the run goes: rows of a run that dies stay.
  const occull::SoakResult result = occull::run_soak(c, progress, &std::cout);
  if (json) {
    occull::write_soak_json(result, *json);
    json->flush();
    check_written(*json, a.json);
  }
  return occull::soak_flat(result) ? 0 : kExitSoakLeak;
}

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
  std::sort(us.begin(), us.end());
  const auto at = [&](double q) { return us[std::min(us.size() - 1, std::size_t(q * double(us.size())))]; };
  fmt::print("grid {} ({} cells), {} views, fov {} deg, far {:.0f} cells, mode {}\n", a.dims,
             grid.cell_count(), a.views, a.fov, lens.far, a.mode);
  fmt::print("traversal per view: median {:.1f} us, p95 {:.1f} us, max {:.1f} us; {:.0f} cells in {:.0f} runs on average\n",
             at(0.5), at(0.95), us.back(), cells / a.views, runs / a.views);
  return 0;
}

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

namespace {

// The exit codes, as --help prints them and the README's table lists them.
constexpr std::pair<int, const char*> kExitCodes[] = {
    {0, "success"},
    {1, "internal error (a bug: please report it with the message), including a violated run-time invariant of the instrument, with `--gl-debug` a failing OpenGL call, and a frame past the `--watchdog` time"},
    {2, "bad input: unknown scene / path / algorithm / option (the message lists the valid ones), invalid number or size, a damaged level, model, path or profile file (the message names the file and the fault), an output file or folder that cannot be written"},
    {3, "no usable OpenGL 4.5: EGL or the driver is missing (the message says which package); `view`: no display, or built without its viewer"},
    {4, "`bench`, `osg`: verification failed — a conservative algorithm culled a visible object (the table, JSON and report are written first)"},
    {5, "`soak`: a leak — a figure more than 5 % above its first window and still growing (the table and JSON are written first)"},
};

std::string exit_code_table() {
  std::string out = "Exit codes:\n";
  for (const auto& [code, meaning] : kExitCodes) out += fmt::format("  {}  {}\n", code, meaning);
  return out;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"occull — occlusion culling with hardware occlusion queries, and the instrument "
               "that measures it."};
  app.footer(exit_code_table());
  app.require_subcommand(1);

  app.add_subcommand("info", "GL vendor, renderer, version, query counter bits, culling extensions");
  std::string list_maps;
  auto* sc = app.add_subcommand("scenes", "embedded scenes: parameters, camera paths, object and triangle counts");
  sc->add_option("--list-maps", list_maps, "list the Quake 3 maps inside a .pk3 archive");
  PathArgs path_args;
  auto* pa = app.add_subcommand("path", "write a scene's camera path to a text file (edit it, replay it with --path file:F)");
  pa->add_option("--scene", path_args.scene, "scene spec")->capture_default_str();
  pa->add_option("--path", path_args.path, "camera path (default: the scene's first)");
  pa->add_option("--out", path_args.out, "output file")->required();
  app.add_subcommand("algos", "culling algorithms and their options (--opt algo.key=value)");

  BenchArgs bench;
  auto* b = app.add_subcommand("bench", "fly a camera path with each algorithm and report frame times");
  add_run_options(b, bench, "algorithm");
  b->add_option("--algo", bench.algos,
                "comma-separated algorithms, each optionally with its own options as "
                "name:key=value:key=value (default: all; see occull algos)");
  b->add_option("--query-mode", bench.query_mode, "occlusion query target: samples, any, conservative")
      ->capture_default_str();
  b->add_option("--query-raster", bench.query_raster,
                "how query boxes stay conservative beyond sub-pixel snapping: margin (widen their outline "
                "by --query-margin px), hardware (conservative-raster extension, else margin), exact (neither)")
      ->capture_default_str();
  b->add_option("--query-margin", bench.query_margin, "with --query-raster margin: pixels to widen each query box's outline by")
      ->capture_default_str();
  b->add_option("--csv", bench.csv, "write one CSV row per algorithm, repeat and frame to this file");
  b->add_option("--report", bench.report, "write report.md, SVG charts, JSON and CSV into this folder")
      ->capture_default_str();
  b->add_flag("--no-report", bench.no_report, "do not write the report folder");
  b->add_flag("--model", bench.model,
              "also predict every frame with the NOHC cost model and print predicted vs measured");
  b->add_option("--bvh-leaf", bench.bvh_leaf, "most objects in a BVH leaf (binned SAH decides below that)")
      ->capture_default_str();
  b->add_option("--views", bench.views,
                "split screen: this many views side by side (each WIDTH/N wide), one path each (--path A,B; "
                "default: the scene's paths in turn); grid shares one grid and query cap between them")
      ->capture_default_str();
  b->add_option("--draw", bench.draw,
                "object submission: single (one draw per object), multi (one multi-draw per material run) or indirect (one multi-draw per render call over all materials: the draw path of hiz, commands written by the CPU)")
      ->capture_default_str();
  b->add_option("--depth", bench.depth, kDepthHelp)->capture_default_str();
  b->add_option("--engine-moves", bench.engine_moves,
                "fraction of the static objects moved every frame by engine calls (set_transform, not a Motion), "
                "around 2 m circles; the hierarchy and the cullers follow")
      ->capture_default_str();


  SweepArgs sweep;
  sweep.bench.algos = "grid";
  sweep.bench.frames = 60;
  sweep.bench.size = "320x180";
  auto* sw = app.add_subcommand(
      "sweep", "run one algorithm over every combination of option values (--vary) and tabulate frame time "
               "and popping per setting");
  sw->add_option("--algo", sweep.bench.algos, "the algorithm swept (one name; see occull algos)")->capture_default_str();
  sw->add_option("--vary", sweep.vary,
                 "an option and its values, key=v1,v2,... (repeatable; every combination runs, at most 64)")
      ->required();
  sw->add_option("--baseline", sweep.baseline, "comma-separated algorithms run beside the settings (empty: none)")
      ->capture_default_str();
  sw->add_option("--popping", sweep.popping,
                 "the best setting misses at most this percentage of the visible object-frames")
      ->capture_default_str();
  sw->add_option("--longest", sweep.longest, "... and no object for more than this many frames in a row")
      ->capture_default_str();
  add_run_options(sw, sweep.bench, "setting");

  CalibrateArgs calibrate;
  auto* suite_opt = b->add_option("--suite", bench.suite,
                                  "run a fixed list of scene/path pairs instead of one, with a table each and a summary "
                                  "over all (geometric mean and worst ratio to vfc and oracle per culler): default, quick");
  suite_opt->excludes(b->get_option("--scene"))->excludes(b->get_option("--path"));
  auto* cal = app.add_subcommand("calibrate",
                                 "measure the NOHC hardware cost model on this renderer and cache it");
  cal->add_option("--malloc", calibrate.malloc_policy, kMallocHelp)->capture_default_str();
  cal->add_option("--size", calibrate.size, "render size WIDTHxHEIGHT")->capture_default_str();
  cal->add_option("--repeats", calibrate.repeats, "rounds per measurement (median kept)")->capture_default_str();
  cal->add_option("--out", calibrate.out, "write the profile here instead of the per-user cache");
  cal->add_flag("--check", calibrate.check,
                "calibrate twice and report sanity checks (cost ordering, repeatability); writes nothing");

  RenderArgs render;
  auto* r = app.add_subcommand("render", "render a frame of a path with an algorithm to a PNG, as rendered or as a "
                                          "debug view of what the culler did");
  r->add_option("--scene", render.scene, "scene spec name[:key=value,...]")->capture_default_str();
  r->add_option("--path", render.path, "camera path (default: the scene's first), or file:PATH");
  r->add_option("--algo", render.algo, "algorithm (default: vfc, tilevfc on a tiled world)");
  r->add_option("--frame", render.frame,
                "frame index K (0-based) of --frames along the path, or a range A-B: one PNG per frame, "
                "numbered (out-0012.png)")
      ->capture_default_str();
  r->add_option("--frames", render.frames, "frames the path is divided into")->capture_default_str();
  r->add_option("--fps", render.fps, "frames at this rate of path time instead (0: divide the path)")
      ->capture_default_str();
  r->add_option("--start", render.start, "with --fps: path time of frame 0, seconds")->capture_default_str();
  r->add_option("--size", render.size, "image size WIDTHxHEIGHT")->capture_default_str();
  r->add_option("--out,--png", render.out, "output PNG file")->capture_default_str();
  std::string view_help = "what to draw:";
  for (const auto& v : occull::debug_views()) view_help += fmt::format(" {}: {};", v.name, v.summary);
  view_help += " soc: the frame with the CPU occlusion buffer the culler used beside it (soc; chc, chcpp, nohc with "
               "cpu_test=on)";
  r->add_option("--view", render.view, view_help)->capture_default_str();
  r->add_option("--opt", render.opts, "algorithm option algo.key=value (repeatable)");
  r->add_flag("--gl-debug", render.gl_debug, kGlDebugHelp);
  r->add_option("--depth", render.depth, kDepthHelp)->capture_default_str();

  occull::app::ViewArgs view_args;
  std::string view_size;
  auto* vw = app.add_subcommand("view",
                                "a window onto a scene and a culler: fly the camera, switch algorithms, options "
                                "and debug views, verify live, record the flight (needs a display; xvfb-run "
                                "without one)");
  vw->add_option("--scene", view_args.scene, "scene spec name[:key=value,...]")->capture_default_str();
  vw->add_option("--path", view_args.path, "the path whose start is the first pose; with --frames, the path flown");
  vw->add_option("--algo", view_args.algo, "algorithm at the start (default: vfc, tilevfc on a tiled world)");
  vw->add_option("--opt", view_args.opts, "option of that algorithm algo.key=value (repeatable)");
  vw->add_option("--view", view_args.view, view_help)->capture_default_str();
  vw->add_option("--size", view_size,
                 "window size WIDTHxHEIGHT (default: 640x360 on llvmpipe, which is too slow for more; the "
                 "display's size on a GPU)");
  vw->add_flag("--verify", view_args.verify, "ground truth every frame: misses in red, counted in the panel");
  vw->add_option("--frames", view_args.frames,
                 "scripted: fly --path for this many frames, then exit (tests, recordings); 0: interactive")
      ->capture_default_str();
  vw->add_option("--fps", view_args.fps, "scripted: frames at this rate of path time (0: spread over the path)")
      ->capture_default_str();
  vw->add_option("--screenshot", view_args.screenshot, "scripted: write the last frame's window to this PNG");
  vw->add_option("--record", view_args.record,
                 "record the flight from the start and write it to this path file at the end "
                 "(bench --path file:FILE replays it)");
  vw->add_flag("--no-ui", view_args.no_ui, "no panel over the view");
  vw->add_option("--depth", view_args.depth, kDepthHelp)->capture_default_str();

  SoakArgs soak;
  auto* so = app.add_subcommand("soak",
                                "loop a walk for many frames per culler and report memory, GL objects and frame "
                                "time per window (exit 5 when memory or the query pool grew)");
  so->add_option("--scene", soak.scene, "scene spec name[:key=value,...]; its dynamic objects move all along")
      ->capture_default_str();
  so->add_option("--path", soak.path, "camera path, looped (default: turn where the scene has it, else its first)");
  so->add_option("--algo", soak.algos, "comma-separated algorithms, run one after another")->capture_default_str();
  so->add_option("--frames", soak.frames, "measured frames per algorithm (a multiple of --window)")
      ->capture_default_str();
  so->add_option("--window", soak.window, "frames per reported row")->capture_default_str();
  so->add_option("--warmup", soak.warmup, "frames before the first window")->capture_default_str();
  so->add_option("--fps", soak.fps, "frames per second of path time (the path loops)")->capture_default_str();
  so->add_option("--size", soak.size, "render size WIDTHxHEIGHT")->capture_default_str();
  so->add_option("--opt", soak.opts, "algorithm option algo.key=value (repeatable)");
  so->add_option("--json", soak.json, "write the windows as JSON to this file");
  so->add_option("--malloc", soak.malloc_policy,
                 std::string(kMallocHelp) + "; soak's default is system: under engine the resident set it judges is "
                                            "the heap's high-water mark")
      ->capture_default_str();
  so->add_flag("--gl-debug", soak.gl_debug, kGlDebugHelp);
  so->add_option("--stall-guard", soak.stall_guard,
                 "milliseconds a culler waits for a query result before taking it as visible (0: wait)")
      ->capture_default_str();
  so->add_option("--watchdog", soak.watchdog, "seconds a frame may take before the run stops with exit 1 (0: off)")
      ->capture_default_str();

  TraverseArgs traverse;
  auto* tv = app.add_subcommand("traverse",
                                "time the grid's occlusion-order traversal on one core over random views "
                                "(far plane across the whole grid)");
  tv->add_option("--dims", traverse.dims, "grid cells XxYxZ")->capture_default_str();
  tv->add_option("--views", traverse.views, "random views timed")->capture_default_str();
  tv->add_option("--mode", traverse.mode, "frustum (the thesis' rasterization) or box (the frustum's bounding box)")
      ->capture_default_str();
  tv->add_option("--fov", traverse.fov, "vertical field of view, degrees (16:9 viewport)")->capture_default_str();
  tv->add_option("--seed", traverse.seed, "random seed of the views")->capture_default_str();

  UpkeepArgs upkeep;
  auto* up = app.add_subcommand("upkeep",
                                "time the hierarchy's upkeep on one core: random boxes, a fraction moved by the "
                                "engine every frame (set_transform), Bvh::refit timed, SAH cost against a fresh "
                                "build at the end");
  up->add_option("--objects", upkeep.objects, "objects in the scene")->capture_default_str();
  up->add_option("--moving", upkeep.moving, "fraction moved every frame")->capture_default_str();
  up->add_option("--frames", upkeep.frames, "frames")->capture_default_str();
  up->add_option("--seed", upkeep.seed, "random seed")->capture_default_str();

  occull::app::RasterArgs raster;
  auto* ra = app.add_subcommand("raster",
                                "time the CPU occlusion buffer's rasterizer (soc) on one core over the occluders a "
                                "camera path sees: vectorised against the scalar reference, polygons per millisecond");
  ra->add_option("--scene", raster.scene, "scene spec (see occull scenes)")->capture_default_str();
  ra->add_option("--path", raster.path, "camera path (default: the scene's first)");
  ra->add_option("--sizes", raster.sizes, "comma-separated buffer sizes WIDTHxHEIGHT")->capture_default_str();
  ra->add_option("--frames", raster.frames, "frames spread over the path")->capture_default_str();
  ra->add_option("--repeat", raster.repeat, "timings of each frame; the fastest counts")->capture_default_str();
  ra->add_option("--detail", raster.detail, "as soc.detail: polygons below 1/detail of their mesh's largest "
                                            "inscribed circle left out (0: all)")
      ->capture_default_str();

#ifdef OCCULL_OSG
  OsgArgs osg_args;
  osg_args.run.report.clear();
  auto* og = app.add_subcommand(
      "osg", "occull's cullers inside OpenSceneGraph beside OSG's own OcclusionQueryNode, in one headless OSG "
             "viewer, every frame checked against occull's ground truth");
  add_run_options(og, osg_args.run, "row");
  og->add_option("--rows", osg_args.rows,
                 "comma-separated rows (default: osg,oqn,oqn-strict,vfc,chcpp,nohc,grid):\n" +
                     osgOccull::describe_osg_rows());
  og->add_option("--threading", osg_args.threading,
                 "osgViewer threading model: single (SingleThreaded) or cull-draw (CullDrawThreadPerContext); "
                 "the models that draw while the next frame is culled are refused")
      ->capture_default_str();
  og->add_option("--report", osg_args.run.report, "write report.md, SVG charts, JSON and CSV into this folder");
  og->add_option("--file", osg_args.file,
                 "instead of --scene: a file OSG reads (.osgt, .osgb, .ive, .obj, .3ds, .flt, ...), flown on its path "
                 "orbit or through (--path), verified against the ground truth of its triangles");
  og->add_option("--png", osg_args.png,
                 "write each row's last frame (first repeat) as PREFIX-ROW.png: what OSG drew");
  og->add_option("--export", osg_args.export_file,
                 "write the scene as an OSG file (.osgt, .osgb, .ive, ...: any format OSG writes) and exit");
#endif

  // An unknown command: name it and list the valid ones (CLI11 would only
  // say that a subcommand is required).
  if (argc > 1 && argv[1][0] != '-') {
    std::string valid;
    bool known = false;
    for (const CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) {
      known = known || sub->get_name() == argv[1];
      valid += (valid.empty() ? "" : ", ") + sub->get_name();
    }
    if (!known) {
      std::cerr << "occull: unknown command '" << argv[1] << "'; valid commands: " << valid << "\n";
      return kExitInput;
    }
  }
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kExitInput;
  }

  try {
    const std::string cmd = app.get_subcommands().front()->get_name();
    if (cmd == "info") return cmd_info();
    if (cmd == "scenes") return list_maps.empty() ? cmd_scenes() : cmd_list_maps(list_maps);
    if (cmd == "path") return cmd_path(path_args);
    if (cmd == "algos") return cmd_algos();
    if (cmd == "bench") return cmd_bench(bench);
    if (cmd == "sweep") return cmd_sweep(sweep);
#ifdef OCCULL_OSG
    if (cmd == "osg") return cmd_osg(osg_args);
#endif
    if (cmd == "render") return cmd_render(render);
    if (cmd == "calibrate") return cmd_calibrate(calibrate);
    if (cmd == "traverse") return cmd_traverse(traverse);
    if (cmd == "upkeep") return cmd_upkeep(upkeep);
    if (cmd == "raster") return occull::app::cmd_raster(raster);
    if (cmd == "soak") return cmd_soak(soak);
    if (cmd == "view") {
      if (!view_size.empty()) {
        const Size size = parse_size(view_size);
        view_args.width = size.width;
        view_args.height = size.height;
      }
#ifdef OCCULL_VIEWER
      return occull::app::run_viewer(view_args);
#else
      std::cerr << "occull: this occull was built without its viewer: it needs GLFW and Dear ImGui "
                   "(apt-get install libglfw3-dev libimgui-dev, then make build)\n";
      return kExitNoGl;
#endif
    }
  } catch (const occull::InputError& e) {
    std::cerr << "occull: " << e.what() << "\n";
    return kExitInput;
  } catch (const occull::GlUnavailable& e) {
    std::cerr << "occull: no usable OpenGL: " << e.what() << "\n";
    return kExitNoGl;
  } catch (const occull::InvariantViolation& e) {
    std::cerr << "occull: " << e.what() << "\n";
    return kExitInternal;
  } catch (const occull::GlError& e) {
    std::cerr << "occull: " << e.what() << "\n";
    return kExitInternal;
  } catch (const std::exception& e) {
    std::cerr << "occull: internal error: " << e.what() << "\n";
    return kExitInternal;
  }
  return kExitInternal;
}
