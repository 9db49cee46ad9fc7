// occull soak: a looped walk per culler for many frames, a row per window
// of what must stay flat (memory, the query pool, buffers) and how the
// frame time drifts.
#include "occull/soak.hpp"

#include "occull/error.hpp"
#include "occull/process.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <cmath>
#include <ostream>

namespace occull {
namespace {

double mib(std::uint64_t bytes) { return double(bytes) / double(1 << 20); }

// A trend's JSON name and its words in the verdict line.
struct TrendWords {
  std::string_view name, text;
};
TrendWords words(SoakTrend t) {
  switch (t) {
    case SoakTrend::plateau: return {"plateau", "grew, then stopped: a high-water mark"};
    case SoakTrend::growing: return {"growing", "STILL GROWING: a leak"};
    case SoakTrend::flat: break;
  }
  return {"flat", "flat"};
}

void check(const SoakConfig& c) {
  if (c.window < 1) throw InputError(fmt::format("soak window {}: must be at least 1 frame", c.window));
  if (c.frames < c.window || c.frames % c.window != 0)
    throw InputError(fmt::format("soak frames {}: must be a positive multiple of the window ({} frames)", c.frames,
                                 c.window));
  if (c.warmup < 0) throw InputError(fmt::format("soak warm-up {}: must be >= 0 frames", c.warmup));
  if (!(c.fps > 0.0) || !std::isfinite(c.fps)) throw InputError(fmt::format("soak fps {}: must be > 0", c.fps));
  if (!(c.tolerance >= 0.0)) throw InputError(fmt::format("soak tolerance {}: must be >= 0", c.tolerance));
  if (c.algorithms.empty()) throw InputError("soak: no algorithms");
}

void soak_one(Session& session, SoakRun& run, const SoakConfig& c, const CameraPath& path,
              const SoakProgress& progress, std::ostream* live) {
  const std::string& name = run.algorithm;
  session.reset_renderer();
  session.set_stall_guard(c.stall_guard_ms);
  auto culler = session.make(name, c.options);
  if (live) *live << soak_columns(name) << std::flush;
  const double loop = path.duration();
  const std::int64_t total = c.warmup + c.frames;
  std::vector<double> ms;
  ms.reserve(std::size_t(c.window));
  std::uint64_t queries = 0;
  for (std::int64_t k = 0; k < total; ++k) {
    const double t = double(k) / c.fps;
    const double on_path = loop > 0.0 ? std::fmod(t, loop) : 0.0;
    const View view = session.view_of(path.sample(path.keys().front().time + on_path));
    const FrameStats s = session.run_frame(*culler, view, t);
    if (progress && (k % 500 == 0 || k + 1 == total)) progress(name, k + 1, total);
    if (k < c.warmup) continue;
    ms.push_back(s.frame_ms);
    queries += s.queries;
    if (std::int64_t(ms.size()) < c.window) continue;
    SoakWindow w;
    w.first_frame = k + 1 - c.warmup - c.window;
    w.frames = c.window;
    const Summary sum = summarize(ms);
    w.median_ms = sum.median;
    w.p95_ms = sum.p95;
    w.max_ms = sum.max;
    w.queries_per_frame = double(queries) / double(c.window);
    const MemoryUsage m = memory_usage();
    w.resident_bytes = m.resident_bytes;
    w.heap_held_bytes = m.heap_held_bytes;
    w.heap_bytes = m.heap_bytes;
    w.gl = session.render_device().resources();
    run.windows.push_back(w);
    if (live) *live << soak_row(w) << std::flush;
    ms.clear();
    queries = 0;
  }
  session.release(*culler);
  session.check_queries_returned(name);
  judge_soak_run(run, c.tolerance);
  if (live) *live << soak_run_verdict(run) << std::flush;
}

}  // namespace

SoakTrend soak_trend(std::span<const double> values, double tolerance) {
  if (values.size() < 2) return SoakTrend::flat;
  const double first = values.front(), last = values.back();
  // A figure the OS or C library did not give (0) is not judged; a count
  // that starts at 0 (no query held) is judged by its rises alone.
  if (first < 0.0 || last <= first * (1.0 + tolerance) || (first == 0.0 && last == 0.0)) return SoakTrend::flat;
  const std::size_t steps = std::min<std::size_t>(3, values.size() - 1);
  for (std::size_t i = values.size() - steps; i < values.size(); ++i)
    if (!(values[i] > values[i - 1])) return SoakTrend::plateau;
  return SoakTrend::growing;
}

void judge_soak_run(SoakRun& run, double tolerance) {
  if (run.windows.empty()) return;
  const SoakWindow& a = run.windows.front();
  const SoakWindow& b = run.windows.back();
  run.time_drift = a.median_ms > 0.0 ? b.median_ms / a.median_ms : 1.0;
  const auto trend = [&](auto figure) {
    std::vector<double> v;
    for (const SoakWindow& w : run.windows) v.push_back(double(figure(w)));
    return soak_trend(v, tolerance);
  };
  run.memory = trend([](const SoakWindow& w) { return w.resident_bytes; });
  run.pool = trend([](const SoakWindow& w) { return w.gl.queries; });
  run.in_use = trend([](const SoakWindow& w) { return w.gl.queries - w.gl.queries_free; });
  run.buffers = trend([](const SoakWindow& w) { return w.gl.buffer_bytes; });
}

SoakResult run_soak(const SoakConfig& config, const SoakProgress& progress, std::ostream* live) {
  check(config);
  for (const auto& name : config.algorithms) (void)parse_algorithm_spec(name, config.options);
  Session session(config.scene, config.renderer, {}, config.context, config.api);
  session.set_watchdog(config.watchdog_s);
  std::string path_name = config.path;
  if (path_name.empty())
    for (const CameraPath& p : session.bundle().paths)
      if (p.name() == "turn") path_name = p.name();
  const CameraPath& path = session.path(path_name);
  SoakResult result;
  result.config = config;
  result.scene = session.bundle().scene.name();
  result.path = path.name();
  result.path_seconds = path.duration();
  result.renderer = session.renderer_key();
  for (const auto& name : config.algorithms) (void)session.make(name, config.options);  // options, profile: early
  if (live) *live << soak_header(result) << std::flush;
  result.runs.reserve(config.algorithms.size());
  for (const auto& name : config.algorithms) {
    result.runs.push_back({name, {}, 1.0});
    soak_one(session, result.runs.back(), config, path, progress, live);
  }
  if (live) *live << soak_verdict(result) << std::flush;
  return result;
}

std::string soak_header(const SoakResult& result) {
  const SoakConfig& c = result.config;
  return fmt::format("soak: {} / {} ({:.1f} s, looped) at {} fps, {}x{}, {} warm-up + {} frames per algorithm, "
                     "windows of {}\nrenderer: {}\n",
                     result.scene, result.path, result.path_seconds, c.fps, c.renderer.width, c.renderer.height,
                     c.warmup, c.frames, c.window, result.renderer);
}

std::string soak_columns(const std::string& algorithm) {
  return fmt::format("\n{}\n{:>9} {:>9} {:>8} {:>8} {:>9} {:>9} {:>9} {:>9} {:>8} {:>8} {:>9}\n", algorithm,
                     "frames", "median ms", "p95 ms", "max ms", "queries/f", "RSS MiB", "held MiB", "heap MiB",
                     "queries", "free", "buf MiB");
}

std::string soak_row(const SoakWindow& w) {
  return fmt::format("{:>9} {:>9.3f} {:>8.3f} {:>8.2f} {:>9.1f} {:>9.1f} {:>9.1f} {:>9.1f} {:>8} {:>8} {:>9.2f}\n",
                     fmt::format("{}k", double(w.first_frame + w.frames) / 1000.0), w.median_ms, w.p95_ms, w.max_ms,
                     w.queries_per_frame, mib(w.resident_bytes), mib(w.heap_held_bytes), mib(w.heap_bytes),
                     w.gl.queries, w.gl.queries_free,
                     mib(std::uint64_t(w.gl.buffer_bytes)));
}

std::string soak_run_verdict(const SoakRun& r) {
  if (r.windows.empty()) return {};
  const SoakWindow& a = r.windows.front();
  const SoakWindow& b = r.windows.back();
  const auto growth = [](std::uint64_t first, std::uint64_t last) {
    return first ? 100.0 * (double(last) / double(first) - 1.0) : 0.0;
  };
  return fmt::format("{}: memory {} (RSS {:+.1f}%; heap held {:+.1f}%, not judged); query pool {} ({} -> {}); "
                     "queries held at a window's end {} ({} -> {}); buffers {}; median frame time x{:.3f}, last "
                     "window vs first\n",
                     r.algorithm, words(r.memory).text, growth(a.resident_bytes, b.resident_bytes),
                     growth(a.heap_held_bytes, b.heap_held_bytes), words(r.pool).text, a.gl.queries, b.gl.queries,
                     words(r.in_use).text, a.gl.queries - a.gl.queries_free, b.gl.queries - b.gl.queries_free,
                     words(r.buffers).text, r.time_drift);
}

std::string soak_verdict(const SoakResult& result) {
  return fmt::format("\nverdict: {} (a leak: a figure more than {:.0f}% above its first window's and still growing "
                     "over the last windows; one that grew to a high-water mark and stays there is not)\n",
                     soak_flat(result) ? "no leak" : "LEAK", 100.0 * result.config.tolerance);
}

bool soak_flat(const SoakResult& result) noexcept {
  for (const SoakRun& r : result.runs)
    if (!r.leak_free()) return false;
  return true;
}

void print_soak(const SoakResult& result, std::ostream& out) {
  out << soak_header(result);
  for (const SoakRun& r : result.runs) {
    out << soak_columns(r.algorithm);
    for (const SoakWindow& w : r.windows) out << soak_row(w);
    out << soak_run_verdict(r);
  }
  out << soak_verdict(result);
}

void write_soak_json(const SoakResult& result, std::ostream& out) {
  using nlohmann::json;
  const SoakConfig& c = result.config;
  json doc;
  doc["format"] = "occull soak 1";
  doc["scene"] = result.scene;
  doc["path"] = result.path;
  doc["path_seconds"] = result.path_seconds;
  doc["renderer"] = result.renderer;
  doc["size"] = {c.renderer.width, c.renderer.height};
  doc["fps"] = c.fps;
  doc["warmup"] = c.warmup;
  doc["frames"] = c.frames;
  doc["window"] = c.window;
  doc["tolerance"] = c.tolerance;
  doc["flat"] = soak_flat(result);
  json runs = json::array();
  for (const SoakRun& r : result.runs) {
    json windows = json::array();
    for (const SoakWindow& w : r.windows)
      windows.push_back({{"first_frame", w.first_frame}, {"frames", w.frames}, {"median_ms", w.median_ms},
                         {"p95_ms", w.p95_ms}, {"max_ms", w.max_ms}, {"queries_per_frame", w.queries_per_frame},
                         {"resident_bytes", w.resident_bytes}, {"heap_held_bytes", w.heap_held_bytes},
                         {"heap_bytes", w.heap_bytes},
                         {"gl_queries", w.gl.queries}, {"gl_queries_free", w.gl.queries_free},
                         {"gl_buffers", w.gl.buffers}, {"gl_buffer_bytes", w.gl.buffer_bytes}});
    runs.push_back({{"algorithm", r.algorithm}, {"memory", words(r.memory).name}, {"pool", words(r.pool).name},
                    {"in_use", words(r.in_use).name}, {"buffers", words(r.buffers).name},
                    {"leak_free", r.leak_free()}, {"time_drift", r.time_drift}, {"windows", windows}});
  }
  doc["runs"] = runs;
  out << doc.dump(2) << "\n";
}

}  // namespace occull
