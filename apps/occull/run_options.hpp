// The options of a run of frames that bench, sweep and osg share, and what
// they do with them.
#pragma once

#include "cli.hpp"

#include "occull/bench.hpp"
#include "occull/bvh.hpp"
#include "occull/gl/renderer.hpp"
#include "occull/session.hpp"

#include <fstream>
#include <string>
#include <string_view>
#include <vector>

namespace occull::app {

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
  std::string api = "gl";
  double stall_guard = 0.0;
  double watchdog = occull::Session::kWatchdogSeconds;
};

/// Progress on stderr: a line rewritten in place on a terminal, the last
/// frame of each run otherwise.
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

/// Adds the options of BenchArgs that bench and sweep share; `per` names
/// what the timed and warm-up frames are counted per.
void add_run_options(CLI::App* cmd, BenchArgs& a, const std::string& per);

/// The bench configuration of parsed arguments. Throws InputError.
[[nodiscard]] occull::BenchConfig bench_config(const BenchArgs& a);

/// Writes a bench's JSON and CSV (to the streams given, opened before the
/// run) and its report folder (when `report` is not empty).
void write_outputs(const occull::BenchResult& result, std::ofstream* json, const std::string& json_path,
                   std::ofstream* csv, const std::string& csv_path, const std::string& report);

}  // namespace occull::app
