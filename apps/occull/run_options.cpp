// The options of a run of frames (bench, sweep, osg) and what they do.
#include "run_options.hpp"

#include "occull/error.hpp"
#include "occull/lab.hpp"
#include "occull/process.hpp"
#include "occull/report.hpp"

#include <fmt/format.h>

#include <cstdio>

namespace occull::app {

namespace {

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


occull::gl::DrawMode parse_draw_mode(const std::string& s) {
  if (s == "single") return occull::gl::DrawMode::single;
  if (s == "multi") return occull::gl::DrawMode::multi;
  if (s == "indirect") return occull::gl::DrawMode::indirect;
  throw occull::InputError(fmt::format("unknown draw mode '{}'; valid modes: single, multi, indirect", s));
}

}  // namespace

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
  cmd->add_option("--api", a.api, kApiHelp)->capture_default_str();
  cmd->add_option("--stall-guard", a.stall_guard,
                  "milliseconds a culler waits for a query result before taking it as visible, as engines "
                  "guard against a driver that never answers (0: wait; counted as stalled per frame)")
      ->capture_default_str();
  cmd->add_option("--watchdog", a.watchdog,
                  "seconds a frame may take before the run stops with exit 1, naming the frame (a hung GL "
                  "driver or device; 0: off)")
      ->capture_default_str();
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
  c.api = occull::parse_api(a.api);
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

}  // namespace occull::app
