// occull — soak runs: one walk looped for a long time per culler, watching
// what must not grow (resident memory, the heap, the GL query pool and
// buffers) and how the frame time drifts, window by window.
#pragma once

#include "occull/culler.hpp"
#include "occull/gl/context.hpp"
#include "occull/gl/renderer.hpp"
#include "occull/lab.hpp"

#include <cstdint>
#include <functional>
#include <iosfwd>
#include <span>
#include <string>
#include <vector>

namespace occull {

struct SoakConfig {
  std::string scene = "city";  ///< scene spec (make_scene); its dynamic objects move all along
  std::string path;            ///< camera path, looped (empty: `turn` where the scene has one, else its first)
  std::vector<std::string> algorithms = {"chcpp", "nohc", "grid"};  ///< specs, run one after another
  std::int64_t frames = 100000;  ///< measured frames per algorithm, a whole number of windows
  std::int64_t window = 10000;   ///< frames per reported window, >= 1
  std::int64_t warmup = 1000;    ///< frames before the first window (caches, pools filling), >= 0
  double fps = 30.0;             ///< frame k is at k / fps seconds, the path's time modulo its duration; > 0
  gl::RendererOptions renderer;  ///< render size and query setup
  gl::ContextOptions context;    ///< e.g. debug output (--gl-debug)
  Api api = Api::gl;             ///< the graphics API frames render through (--api)
  Options options;               ///< algorithm options
  double stall_guard_ms = 0.0;   ///< Session::set_stall_guard
  double watchdog_s = Session::kWatchdogSeconds;
  /// Flat: the last window's end is within this share above the first's
  /// (resident memory, queries created and in use, buffer bytes); past it a
  /// figure still growing is a leak (soak_trend).
  double tolerance = 0.05;
};

/// One window of frames of one algorithm. Memory and GL figures are taken
/// at the window's end.
struct SoakWindow {
  std::int64_t first_frame = 0;  ///< counted from the end of the warm-up
  std::int64_t frames = 0;
  double median_ms = 0.0, p95_ms = 0.0, max_ms = 0.0;  ///< frame time (FrameStats::frame_ms)
  double queries_per_frame = 0.0;
  std::uint64_t resident_bytes = 0;   ///< MemoryUsage of the whole process
  std::uint64_t heap_held_bytes = 0;  ///< MemoryUsage::heap_held_bytes
  std::uint64_t heap_bytes = 0;       ///< MemoryUsage::heap_bytes
  gl::Renderer::Resources gl;        ///< the renderer's query pool and buffers
};

/// How one figure of a soak run went over its windows.
enum class SoakTrend : std::uint8_t {
  flat,     ///< within the tolerance of the first window all along
  plateau,  ///< grew past it, then stopped: a high-water mark reached (not a leak)
  growing,  ///< past it and still growing in each of the last windows: a leak
};

struct SoakRun {
  std::string algorithm;
  std::vector<SoakWindow> windows;
  double time_drift = 1.0;  ///< last window's median frame time over the first's
  SoakTrend memory = SoakTrend::flat;   ///< resident memory
  SoakTrend pool = SoakTrend::flat;     ///< queries the renderer created (the most ever in flight at once)
  SoakTrend in_use = SoakTrend::flat;   ///< queries not back in the pool at a window's end (held in flight)
  SoakTrend buffers = SoakTrend::flat;  ///< the renderer's buffer bytes
  /// No figure growing: what a soak passes on.
  [[nodiscard]] bool leak_free() const noexcept {
    return memory != SoakTrend::growing && pool != SoakTrend::growing && in_use != SoakTrend::growing &&
           buffers != SoakTrend::growing;
  }
};

/// A figure's trend over windows (its value at each window's end): flat
/// when the last is within `tolerance` (a share) above the first; else
/// growing when it rose from each window to the next over the last
/// min(3, windows - 1) of them, plateau when it did not. A leak grows a
/// figure with the frames; a pool or a heap that grew to the most a run ever
/// needed at once and stays there does not (the query pool is such a
/// high-water mark: a rare peak in flight adds a few queries once).
[[nodiscard]] SoakTrend soak_trend(std::span<const double> values, double tolerance);

/// Sets `run`'s trends from its windows. Memory is judged on the resident
/// set. Under glibc's defaults (the soak's `--malloc system`) the heap hands
/// freed memory at its top back; under the engine policy freed memory is
/// kept, so the resident set is the heap's high-water mark (heap held shows
/// its fragmentation): either way a leak keeps growing it, a peak does not.
/// The heap in use is reported but not judged (it swings by tens of MiB
/// with what the driver holds at the moment it is read).
void judge_soak_run(SoakRun& run, double tolerance);

struct SoakResult {
  SoakConfig config;
  std::string scene, path;  ///< the scene's and path's names
  double path_seconds = 0.0;
  std::string renderer;     ///< "renderer | version"
  std::vector<SoakRun> runs;
};

/// (algorithm, frames done, frames in all, counting the warm-up); called
/// every few hundred frames.
using SoakProgress = std::function<void(const std::string&, std::int64_t, std::int64_t)>;

/// Runs every algorithm of `config` for warmup + frames frames, each with a
/// fresh renderer, without verification (a soak watches growth; bench
/// verifies). With `live`, prints print_soak()'s table there as the run
/// goes, each row when its window ends (a run that dies keeps its rows).
/// Throws InputError for a bad config (frames not a positive multiple of
/// window, fps not > 0, unknown names), GlUnavailable.
[[nodiscard]] SoakResult run_soak(const SoakConfig& config, const SoakProgress& progress = {},
                                  std::ostream* live = nullptr);

/// A table per algorithm (a row per window) and a verdict line each, then
/// the verdict: soak_header, then per run soak_columns, soak_row per window
/// and soak_run_verdict, then soak_verdict.
void print_soak(const SoakResult& result, std::ostream& out);
[[nodiscard]] std::string soak_header(const SoakResult& result);
[[nodiscard]] std::string soak_columns(const std::string& algorithm);
[[nodiscard]] std::string soak_row(const SoakWindow& window);
[[nodiscard]] std::string soak_run_verdict(const SoakRun& run);
[[nodiscard]] std::string soak_verdict(const SoakResult& result);
/// The same as JSON ("format": "occull soak 1").
void write_soak_json(const SoakResult& result, std::ostream& out);
/// Whether no run leaks (SoakRun::leak_free): exit 5 of `occull soak` otherwise.
[[nodiscard]] bool soak_flat(const SoakResult& result) noexcept;

}  // namespace occull
