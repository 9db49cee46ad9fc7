// `occull soak`: a looped walk per culler for many frames: memory, GL objects and frame time per window.
#include "cli.hpp"
#include "occull/process.hpp"
#include "occull/session.hpp"
#include "occull/soak.hpp"

#include <chrono>
#include <cstdio>
#include <iostream>
#include <unistd.h>

namespace occull::app {

namespace {

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
  std::string api = "gl";
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
  c.api = occull::parse_api(a.api);
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

}  // namespace

Command add_soak(CLI::App& app) {
  auto a = std::make_shared<SoakArgs>();
  auto* so = app.add_subcommand("soak",
                                "loop a walk for many frames per culler and report memory, GL objects and frame "
                                "time per window (exit 5 when memory or the query pool grew)");
  so->add_option("--scene", a->scene, "scene spec name[:key=value,...]; its dynamic objects move all along")
      ->capture_default_str();
  so->add_option("--path", a->path, "camera path, looped (default: turn where the scene has it, else its first)");
  so->add_option("--algo", a->algos, "comma-separated algorithms, run one after another")->capture_default_str();
  so->add_option("--frames", a->frames, "measured frames per algorithm (a multiple of --window)")
      ->capture_default_str();
  so->add_option("--window", a->window, "frames per reported row")->capture_default_str();
  so->add_option("--warmup", a->warmup, "frames before the first window")->capture_default_str();
  so->add_option("--fps", a->fps, "frames per second of path time (the path loops)")->capture_default_str();
  so->add_option("--size", a->size, "render size WIDTHxHEIGHT")->capture_default_str();
  so->add_option("--opt", a->opts, "algorithm option algo.key=value (repeatable)");
  so->add_option("--json", a->json, "write the windows as JSON to this file");
  so->add_option("--malloc", a->malloc_policy,
                 std::string(kMallocHelp) + "; soak's default is system: under engine the resident set it judges is "
                                            "the heap's high-water mark")
      ->capture_default_str();
  so->add_flag("--gl-debug", a->gl_debug, kGlDebugHelp);
  so->add_option("--api", a->api, kApiHelp)->capture_default_str();
  so->add_option("--stall-guard", a->stall_guard,
                 "milliseconds a culler waits for a query result before taking it as visible (0: wait)")
      ->capture_default_str();
  so->add_option("--watchdog", a->watchdog, "seconds a frame may take before the run stops with exit 1 (0: off)")
      ->capture_default_str();
  return [a] { return cmd_soak(*a); };
}

}  // namespace occull::app
