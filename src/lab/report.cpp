#include "occull/report.hpp"

#include "occull/counters.hpp"

#include "occull/error.hpp"
#include "report_internal.hpp"
#include "svg_chart.hpp"

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <filesystem>
#include <fstream>
#include <ostream>
#include <sstream>
#include <type_traits>

namespace occull {
namespace {


// Per frame, the median over repeats of one figure of one algorithm.
std::vector<double> per_frame_median(const BenchResult& r, const std::string& name,
                                     double (*field)(const FrameStats&)) {
  std::vector<std::vector<double>> values;
  for (const AlgorithmRun& run : r.runs) {
    if (run.name != name) continue;
    if (values.size() < run.frames.size()) values.resize(run.frames.size());
    for (std::size_t k = 0; k < run.frames.size(); ++k) values[k].push_back(field(run.frames[k]));
  }
  std::vector<double> out;
  for (auto& v : values) out.push_back(summarize(v).median);
  return out;
}

detail::LineChart chart(const BenchResult& r, std::string title, std::string y_label,
                        double (*field)(const FrameStats&)) {
  detail::LineChart c;
  c.title = std::move(title);
  c.x_label = "frame";
  c.y_label = std::move(y_label);
  for (const AlgorithmSummary& a : r.summaries)
    c.series.push_back({a.name, per_frame_median(r, a.name, field)});
  return c;
}

std::string verification_text(const BenchResult& r) {
  if (!r.verified) return "verification off";
  return fmt::format("verification on (invariants held on every frame; truth covers {:.0f}% of the "
                     "pixels, {} triangles probed on the CPU)",
                     100.0 * double(r.truth_pixels) / std::max(1.0, double(r.width) * r.height * r.frames),
                     r.truth_probes);
}

// What verification concluded: failures of conservative runs, popping of the others.
std::vector<std::string> verdict_lines(const BenchResult& r) {
  std::vector<std::string> lines;
  if (!r.verified) return lines;
  std::string exact, popping;
  for (const AlgorithmSummary& a : r.summaries) {
    if (a.conservative) {
      exact += (exact.empty() ? "" : ", ") + a.name;
    } else {
      popping += fmt::format("{}{}: {} missed ({:.2f}% of the visible object-frames) over {} frames, longest {} frames{}",
                             popping.empty() ? "" : "; ", a.name, a.missed_objects, 100.0 * a.missed_share(),
                             a.frames_with_misses, a.longest_miss_frames,
                             a.first_miss.empty() ? "" : " (first, " + a.first_miss + ")");
    }
  }
  const auto failures = verification_failures(r);
  if (failures.empty()) {
    if (!exact.empty())
      lines.push_back(fmt::format("verification passed: the conservative algorithms ({}) missed no visible object", exact));
  } else {
    std::string which;
    for (const AlgorithmSummary* a : failures)
      which += fmt::format("{}{} missed {} visible objects in {} frames{}", which.empty() ? "" : "; ", a->name,
                           a->missed_objects, a->frames_with_misses,
                           a->first_miss.empty() ? "" : " (first, " + a->first_miss + ")");
    lines.push_back("verification FAILED: conservative algorithms culled visible objects: " + which);
  }
  if (!popping.empty())
    lines.push_back("not conservative (may pop by design; misses are popping, not failures): " + popping);
  std::string depth_errors;
  for (const AlgorithmSummary& a : r.summaries)
    if (a.depth_error_objects > 0)
      depth_errors += fmt::format("{}{} {}", depth_errors.empty() ? "" : ", ", a.name, a.depth_error_objects);
  if (!depth_errors.empty())
    lines.push_back("left out, not missed: objects the rasteriser showed only through depth errors (fragments nearer "
                    "than their own box; docs/lab.md): " + depth_errors);
  return lines;
}

std::string sampling_text(const BenchResult& r) {
  const std::string where =
      r.sampling.fps > 0.0
          ? fmt::format("frames at {:g} fps from {:.1f} s of the path ({:.1f} s long)", r.sampling.fps,
                        r.sampling.start_s, r.path_duration_s)
          : fmt::format("frames spread over the whole path ({:.1f} s, one every {:.2f} s; --fps F for a "
                        "real-time walk)",
                        r.path_duration_s, r.frames > 1 ? r.path_duration_s / double(r.frames - 1) : 0.0);
  return fmt::format("{}: the camera moves {:.2f} m and turns {:.1f} deg per frame (max {:.2f} m, {:.1f} deg)",
                     where, r.step_m_mean, r.turn_deg_mean, r.step_m_max, r.turn_deg_max);
}

std::string setup_line(const BenchResult& r) {
  const std::string index = r.tiled_world.empty()
                                ? fmt::format("BVH {} nodes in {:.1f} ms", r.bvh_nodes, r.bvh_build_ms)
                                : "objects and triangles of the placed cells";
  return fmt::format("scene {} ({} objects, {} triangles; {}), path {}, {} frames "
                     "at {}x{}, {} warm-up, {} repeat{}, {}\n{}{}",
                     r.scene, r.objects, r.triangles, index, r.path, r.frames,
                     r.width, r.height, r.warmup, r.repeat, r.repeat == 1 ? "" : "s", verification_text(r),
                     sampling_text(r), r.tiled_world.empty() ? "" : "\n" + r.tiled_world);
}

// What auto chose: each candidate's share of the frames, its tries and switches.
std::string auto_line(const BenchResult& r, const AlgorithmSummary& a) {
  std::string ran;
  for (const auto& [candidate, share] : a.auto_choices)
    ran += fmt::format("{}{} {:.0f}%", ran.empty() ? "" : ", ", candidate, 100.0 * share);
  const std::string predicted =
      a.auto_prediction_error > 0.0
          ? fmt::format("; each frame's cost predicted within {:.0f}% (median)", 100.0 * a.auto_prediction_error)
          : "";
  return fmt::format("{}: ran {} of the frames; {:.0f} tries of a challenger, {:.0f} switches{}{}", a.name, ran,
                     a.auto_tries, a.auto_switches, predicted, r.repeat > 1 ? " (median of the repeats)" : "");
}

// How much of the occlusion each culler captured, from the draws per frame:
// the share of the culling from the frustum baseline's draws down to the
// oracle's, and down to the box bound's (oracle:set=boxes) when it ran. An
// algorithm that draws more than the baseline (none: it culls nothing, not
// even by the frustum) is left out. Empty without the baseline and the
// oracle, on split-screen runs, or when the oracle culls nothing beyond the
// frustum.
std::string capture_line(const BenchResult& r) {
  const AlgorithmSummary *base = nullptr, *oracle = nullptr, *bound = nullptr;
  for (const AlgorithmSummary& a : r.summaries) {
    if (a.name.find(" [view ") != std::string::npos) return "";
    if (a.name == vfc_baseline(false) || a.name == vfc_baseline(true)) base = &a;
    if (a.name == "oracle" || a.name == "oracle:set=pixels") oracle = &a;
    if (a.name == "oracle:set=boxes") bound = &a;
  }
  if (!base || !oracle || base->objects_rendered_per_frame - oracle->objects_rendered_per_frame < 0.5) return "";
  const auto share = [&](const AlgorithmSummary& a, const AlgorithmSummary& to) {
    const double range = base->objects_rendered_per_frame - to.objects_rendered_per_frame;
    return range < 0.5 ? std::string("-")
                       : fmt::format("{:.2f}", (base->objects_rendered_per_frame - a.objects_rendered_per_frame) / range);
  };
  std::string shares;
  for (const AlgorithmSummary& a : r.summaries) {
    if (&a == base || &a == oracle || &a == bound) continue;
    if (a.objects_rendered_per_frame > base->objects_rendered_per_frame) continue;
    shares += fmt::format("{}{} {}{}", shares.empty() ? "" : ", ", a.name, share(a, *oracle),
                          bound ? " / " + share(a, *bound) : "");
  }
  if (shares.empty()) return "";
  return fmt::format("occlusion captured (share of the culling from {}'s draws down to the oracle's{}): {}",
                     base->name, bound ? " / down to the box bound's, oracle:set=boxes" : "", shares);
}

std::string misses_text(const BenchResult& r, std::uint64_t v) {
  return r.verified ? fmt::format("{}", v) : "-";
}

}  // namespace

void print_table(const BenchResult& r, std::ostream& out) {
  out << setup_line(r) << "\n";
  out << fmt::format("device: {} | {} | occull {}\nquery boxes: {}\n", r.device.renderer, r.device.version,
                     r.commit, r.query_geometry);
  if (!r.allocator.empty()) out << fmt::format("allocator: {}\n", r.allocator);
  if (!r.conditions.empty()) out << fmt::format("conditions: {}\n", r.conditions);
  out << "\n";
  std::size_t w = 10;
  for (const AlgorithmSummary& a : r.summaries) w = std::max(w, a.name.size());
  out << fmt::format("{:<{}} {:>8} {:>8} {:>8} {:>8} {:>6} {:>7} {:>8} {:>7} {:>7} {:>10} {:>7} {:>9}\n",
                     "algorithm", w, "mean ms", "median", "p95", "max", "vs vfc", "vs orcl", "queries",
                     "states", "draws", "triangles", "missed", "wrong px");
  for (const AlgorithmSummary& a : r.summaries) {
    out << fmt::format(
        "{:<{}} {:>8.2f} {:>8.2f} {:>8.2f} {:>8.2f} {:>6} {:>7} {:>8.1f} {:>7.1f} {:>7.0f} {:>10.0f} "
        "{:>7} {:>9}\n",
        a.name, w, a.frame_ms.mean, a.frame_ms.median, a.frame_ms.p95, a.frame_ms.max,
        detail::ratio_text(a.ratio_to_vfc), detail::ratio_text(a.ratio_to_oracle), a.queries_per_frame,
        a.state_changes_per_frame, a.draw_calls_per_frame, a.triangles_per_frame,
        misses_text(r, a.missed_objects), misses_text(r, a.wrong_pixels));
  }
  if (r.verified) out << "\n";
  for (const std::string& line : verdict_lines(r)) out << line << "\n";
  if (const std::string line = capture_line(r); !line.empty()) out << line << "\n";
  for (const AlgorithmSummary& a : r.summaries) {
    if (a.result_age_frames > 0 || a.capped_share > 0)
      out << fmt::format("{}: query cap reached in {:.0f}% of frames, {:.1f} queries deferred per frame, answers "
                         "used were {:.1f} frames old on average\n",
                         a.name, 100.0 * a.capped_share, a.over_cap_per_frame, a.result_age_frames);
    if (a.revealed_per_frame > 0)
      out << fmt::format("{}: {:.2f} hidden cells per frame found visible by their query and drawn in the same "
                         "frame (latency 0)\n",
                         a.name, a.revealed_per_frame);
    if (a.stalled_per_frame > 0)
      out << fmt::format("{}: {:.2f} query results per frame not there within the stall guard's time, taken as "
                         "visible\n",
                         a.name, a.stalled_per_frame);
    if (!a.auto_choices.empty()) out << auto_line(r, a) << "\n";
    if (a.conditional_objects_per_frame > 0)
      out << fmt::format("{}: {:.1f} objects per frame drawn under conditional rendering, {:.1f} of them skipped "
                         "by the device (their query found them hidden)\n",
                         a.name, a.conditional_objects_per_frame, a.conditional_skipped_per_frame);
  }
  if (std::any_of(r.summaries.begin(), r.summaries.end(), [](const AlgorithmSummary& a) { return a.tiles_rendered_per_frame > 0; })) {
    out << fmt::format("\ntiled world (per frame; instances and evictions over the run)\n{:<{}} {:>7} {:>8} {:>9} {:>9} {:>8} {:>8} {:>7} {:>9}\n",
                       "algorithm", w, "tiles", "t.query", "postponed", "failed %", "created", "evicted", "cache",
                       "ms/tile");
    for (const AlgorithmSummary& a : r.summaries) {
      if (a.tiles_rendered_per_frame <= 0) continue;
      out << fmt::format("{:<{}} {:>7.1f} {:>8.1f} {:>9.2f} {:>9.3f} {:>8.0f} {:>8.0f} {:>7.0f} {:>9.3f}\n", a.name, w,
                         a.tiles_rendered_per_frame, a.tile_queries_per_frame, a.tile_postponed_per_frame,
                         100.0 * a.tile_prediction_failure_share, a.tiles_instantiated, a.tiles_evicted,
                         a.tile_cache_max, a.instantiate_ms_per_tile);
    }
  }
  for (const AlgorithmSummary& a : r.summaries) {
    if (a.memory.size() < 2) continue;
    const MemorySample& first = a.memory.front();
    const MemorySample& last = a.memory.back();
    out << fmt::format("{}: memory after {}k frames {:.1f} MiB resident, {:.1f} MiB GL buffers; after {}k {:.1f} MiB "
                       "({:+.1f}%), {:.1f} MiB ({:+.1f}%)\n",
                       a.name, first.frame / 1000, first.rss_mb, first.gpu_mb, last.frame / 1000, last.rss_mb,
                       first.rss_mb > 0 ? 100.0 * (last.rss_mb / first.rss_mb - 1.0) : 0.0, last.gpu_mb,
                       first.gpu_mb > 0 ? 100.0 * (last.gpu_mb / first.gpu_mb - 1.0) : 0.0);
  }
  out << fmt::format("\nwhere the time goes (per frame)\n{:<{}} {:>7} {:>8} {:>8} {:>8} {:>7} {:>8} {:>8} {:>8} {:>7}\n",
                     "algorithm", w, "cpu ms", "us/node", "nodes", "wait ms", "waits", "flushes", "gpu ms",
                     "faults", "sys ms");
  for (const AlgorithmSummary& a : r.summaries)
    out << fmt::format("{:<{}} {:>7.3f} {:>8.3f} {:>8.0f} {:>8.3f} {:>7.1f} {:>8.1f} {:>8.2f} {:>8.0f} {:>7.2f}\n",
                       a.name, w, a.cpu_ms_per_frame, a.cpu_us_per_node, a.nodes_visited_per_frame,
                       a.wait_ms_per_frame, a.blocking_waits_per_frame, a.flushes_per_frame, a.gpu_ms_per_frame,
                       a.minor_faults_per_frame + a.major_faults_per_frame, a.kernel_ms_per_frame);
  if (r.modelled) {
    out << fmt::format("\ncost model (NOHC, profile {}): mean frame ms\n", r.profile_path);
    out << fmt::format("{:<{}} {:>9} {:>10} {:>8}\n", "algorithm", w, "measured", "predicted", "error");
    for (const AlgorithmSummary& a : r.summaries) {
      const double err = a.frame_ms.mean > 0 ? (a.model_ms_per_frame - a.frame_ms.mean) / a.frame_ms.mean : 0.0;
      out << fmt::format("{:<{}} {:>9.2f} {:>10.2f} {:>+7.0f}%\n", a.name, w, a.frame_ms.mean,
                         a.model_ms_per_frame, 100.0 * err);
    }
  }
  out << "\nframe ms: wall clock per frame (glFinish closes it)"
      << (r.repeat > 1 ? ", median over repeats" : "")
      << "; vs vfc / vs orcl: mean frame time over vfc's (tilevfc's on a tiled world) / oracle's in the same run.\n"
         "queries, states (render<->query switches), draws, triangles: per frame. missed: objects "
         "visible in the ground truth but not rendered, summed over frames; wrong px: their pixels.\n"
         "cpu ms: the culler's own CPU time (outside backend calls); us/node: that per visited hierarchy node; "
         "wait ms / waits: time and reads blocked on query results; flushes: submissions to the device mid-frame "
         "(flush calls, and polls or reads of queries not yet submitted, which make the driver flush); gpu ms: timer queries; faults, sys ms: page "
         "faults and kernel CPU time of the whole process (driver threads too), allocator churn rather than "
         "culling cost.\n";
}

nlohmann::ordered_json detail::bench_json(const BenchResult& r) {
  using nlohmann::ordered_json;
  ordered_json doc;
  doc["device"] = {{"vendor", r.device.vendor},
                   {"renderer", r.device.renderer},
                   {"version", r.device.version},
                   {"egl_platform", r.device.egl_platform}};
  doc["occull_commit"] = r.commit;
  doc["scene"] = {{"name", r.scene},
                  {"objects", r.objects},
                  {"triangles", r.triangles},
                  {"bvh_nodes", r.bvh_nodes},
                  {"tiled_world", r.tiled_world.empty() ? ordered_json() : ordered_json(r.tiled_world)},
                  {"bvh_build_ms", r.bvh_build_ms}};
  doc["path"] = r.path;
  doc["frames"] = r.frames;
  doc["sampling"] = {{"fps", r.sampling.fps},
                     {"start_s", r.sampling.start_s},
                     {"camera_step_m", {{"mean", r.step_m_mean}, {"max", r.step_m_max}}},
                     {"camera_turn_deg", {{"mean", r.turn_deg_mean}, {"max", r.turn_deg_max}}}};
  doc["warmup"] = r.warmup;
  doc["repeat"] = r.repeat;
  doc["verified"] = r.verified;
  doc["truth_probes"] = r.truth_probes;
  doc["truth_pixels"] = r.truth_pixels;
  doc["modelled"] = r.modelled;
  doc["hardware_profile"] = r.profile_path.empty() ? ordered_json() : ordered_json(r.profile_path);
  doc["size"] = {r.width, r.height};
  doc["query_geometry"] = r.query_geometry;
  doc["allocator"] = r.allocator;
  doc["conditions"] = r.conditions;
  ordered_json algos = ordered_json::array();
  for (const AlgorithmSummary& a : r.summaries) {
    algos.push_back({{"name", a.name},
                     {"conservative", a.conservative},
                     {"frame_ms",
                      {{"mean", a.frame_ms.mean},
                       {"median", a.frame_ms.median},
                       {"p95", a.frame_ms.p95},
                       {"max", a.frame_ms.max}}},
                     {"ratio_to_vfc", a.ratio_to_vfc > 0 ? ordered_json(a.ratio_to_vfc) : ordered_json()},
                     {"ratio_to_oracle",
                      a.ratio_to_oracle > 0 ? ordered_json(a.ratio_to_oracle) : ordered_json()},
                     {"cpu_us_per_node", a.cpu_us_per_node},
                     {"tile_prediction_failure_share", a.tile_prediction_failure_share},
                     {"instantiate_ms_per_tile", a.instantiate_ms_per_tile},
                     {"frames_with_misses", a.frames_with_misses},
                     {"worst_frame_wrong_pixels", a.worst_frame_wrong_pixels},
                     {"longest_miss_frames", a.longest_miss_frames},
                     {"first_miss", a.first_miss.empty() ? ordered_json() : ordered_json(a.first_miss)}});
    for (const Counter& c : frame_counters()) {
      if (c.key.empty()) continue;
      ordered_json value;  // null for a modelled figure of a run without --model
      if (!c.modelled || r.modelled)
        std::visit(
            [&](auto member) {
              if constexpr (!std::is_same_v<decltype(member), std::monostate>) value = a.*member;
            },
            c.summary);
      algos.back()[std::string(c.key)] = value;
    }
    ordered_json memory = ordered_json::array();
    for (const MemorySample& m : a.memory)
      memory.push_back({{"frame", m.frame}, {"rss_mb", m.rss_mb}, {"gpu_mb", m.gpu_mb}});
    algos.back()["memory"] = memory;
    ordered_json choices;  // null for the cullers other than auto
    for (const auto& [candidate, share] : a.auto_choices) choices[candidate] = share;
    algos.back()["auto_choices"] = choices;
    algos.back()["auto_prediction_error"] =
        a.auto_choices.empty() ? ordered_json(nullptr) : ordered_json(a.auto_prediction_error);
  }
  doc["algorithms"] = algos;
  return doc;
}

std::string detail::ratio_text(double r) { return r > 0 ? fmt::format("{:.2f}", r) : "-"; }

void write_json(const BenchResult& r, std::ostream& out) { out << detail::bench_json(r).dump(2) << "\n"; }

void write_csv(const BenchResult& r, std::ostream& out) {
  const std::span<const Counter> counters = frame_counters();
  out << "algorithm,repeat,frame";
  for (const Counter& c : counters) out << ',' << c.name;
  out << '\n';
  std::string row;
  for (const AlgorithmRun& run : r.runs) {
    for (std::size_t k = 0; k < run.frames.size(); ++k) {
      row = fmt::format("{},{},{}", run.name, run.repeat, k);
      for (const Counter& c : counters)
        std::visit(
            [&](auto member) {
              if (c.decimals < 0)
                fmt::format_to(std::back_inserter(row), ",{}", run.frames[k].*member);
              else
                fmt::format_to(std::back_inserter(row), ",{:.{}f}", double(run.frames[k].*member), c.decimals);
            },
            c.frame);
      out << row << '\n';
    }
  }
}

void prepare_report_folder(const std::string& dir) {
  namespace fs = std::filesystem;
  std::error_code ec;
  fs::create_directories(dir, ec);
  if (ec) throw InputError(fmt::format("cannot create report folder '{}': {}", dir, ec.message()));
  const fs::path probe = fs::path(dir) / ".occull-write-test";
  {
    std::ofstream f(probe);
    f << "x";
    if (!f) throw InputError(fmt::format("cannot write into report folder '{}'", dir));
  }
  fs::remove(probe, ec);
}

std::string detail::write_report_file(const std::string& dir, const std::string& name, const std::string& text) {
  const std::string path = (std::filesystem::path(dir) / name).string();
  std::ofstream f(path, std::ios::binary);
  f << text;
  if (!f) throw InputError(fmt::format("cannot write '{}'", path));
  return path;
}

std::vector<std::string> write_report(const BenchResult& r, const std::string& dir) {
  prepare_report_folder(dir);
  std::vector<std::string> written;
  const auto write = [&](const std::string& name, const std::string& text) {
    written.push_back(detail::write_report_file(dir, name, text));
  };

  const detail::LineChart frame_chart = chart(r, fmt::format("Frame time — {} / {}", r.scene, r.path),
                                              "frame time (ms)", [](const FrameStats& f) { return f.frame_ms; });
  write("frame_ms.svg", detail::render_svg(frame_chart));
  write("queries.svg", detail::render_svg(chart(r, fmt::format("Occlusion queries — {} / {}", r.scene, r.path),
                                                "queries per frame",
                                                [](const FrameStats& f) { return double(f.queries); })));
  write("triangles.svg", detail::render_svg(chart(r, fmt::format("Triangles rendered — {} / {}", r.scene, r.path),
                                                  "triangles per frame",
                                                  [](const FrameStats& f) { return double(f.triangles); })));
  std::ostringstream json, csv, table;
  write_json(r, json);
  write("results.json", json.str());
  write_csv(r, csv);
  write("frames.csv", csv.str());

  std::string md = "# occull benchmark report\n\n## Set-up\n\n";
  md += fmt::format("- renderer: {} ({}), OpenGL {}\n", r.device.renderer, r.device.vendor, r.device.version);
  md += fmt::format("- scene: `{}` — {} objects, {} triangles (BVH {} nodes)\n", r.scene, r.objects,
                    r.triangles, r.bvh_nodes);
  md += fmt::format("- path: `{}`, {} frames at {}×{}, {} warm-up frames per algorithm\n", r.path, r.frames,
                    r.width, r.height, r.warmup);
  md += fmt::format("- {}\n", sampling_text(r));
  md += fmt::format("- repeats: {} (algorithms interleaved; figures are medians over repeats)\n", r.repeat);
  md += fmt::format("- {}\n", verification_text(r));
  md += fmt::format("- query boxes: {}\n", r.query_geometry);
  if (!r.allocator.empty()) md += fmt::format("- allocator: {}\n", r.allocator);
  if (!r.conditions.empty()) md += fmt::format("- conditions: {}\n", r.conditions);
  md += fmt::format("- occull commit: `{}`\n\n## Results\n\n", r.commit);
  md += "| algorithm | mean ms | median | p95 | max | vs vfc | vs oracle | queries | state changes | "
        "draws | triangles | missed | frames w/ miss | wrong px | longest miss | extra objects | "
        "wait ms | cpu ms | cpu us/node | page faults | sys ms |\n";
  md += "|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
  for (const AlgorithmSummary& a : r.summaries) {
    md += fmt::format("| {} | {:.2f} | {:.2f} | {:.2f} | {:.2f} | {} | {} | {:.1f} | {:.1f} | {:.0f} | {:.0f} | "
                      "{} | {} | {} | {} | {:.1f} | {:.3f} | {:.3f} | {:.3f} | {:.0f} | {:.2f} |\n",
                      a.name, a.frame_ms.mean, a.frame_ms.median, a.frame_ms.p95, a.frame_ms.max,
                      detail::ratio_text(a.ratio_to_vfc), detail::ratio_text(a.ratio_to_oracle), a.queries_per_frame,
                      a.state_changes_per_frame, a.draw_calls_per_frame, a.triangles_per_frame,
                      misses_text(r, a.missed_objects), misses_text(r, a.frames_with_misses),
                      misses_text(r, a.wrong_pixels), misses_text(r, a.longest_miss_frames),
                      a.extra_objects_per_frame, a.wait_ms_per_frame, a.cpu_ms_per_frame, a.cpu_us_per_node,
                      a.minor_faults_per_frame + a.major_faults_per_frame, a.kernel_ms_per_frame);
  }
  md += "\n";
  for (const std::string& line : verdict_lines(r)) md += "**" + line + "**\n\n";
  if (const std::string line = capture_line(r); !line.empty()) md += line + "\n\n";
  for (const AlgorithmSummary& a : r.summaries)
    if (!a.auto_choices.empty()) md += auto_line(r, a) + "\n\n";
  md += "Frame times are wall clock, each frame closed by `glFinish`; ratios compare means measured in "
        "the same run. *missed* counts objects visible in the ground truth (object-id buffer of "
        "everything in the frustum) that the algorithm did not render, summed over frames; *wrong px* "
        "are their pixels; *longest miss* is the longest run of frames one object stayed missed; *extra "
        "objects* were rendered without being visible (the culling's inefficiency).\n\n";
  md += "![frame time per frame](frame_ms.svg)\n\n![queries per frame](queries.svg)\n\n"
        "![triangles per frame](triangles.svg)\n\n";
  md += "Raw data: [results.json](results.json), [frames.csv](frames.csv).\n\n";
  md += "## What each frame counts\n\nOne column of frames.csv per counter; the summary's JSON key says how the "
        "run's frames and the repeats reduce it.\n\n| frames.csv | unit | summary (results.json) | what it counts |\n"
        "|---|---|---|---|\n";
  for (const Counter& c : frame_counters()) {
    const char* frames = c.frames == Combine::mean ? "mean per frame" : c.frames == Combine::sum ? "sum over frames"
                                                                      : "largest frame";
    const char* repeats = c.repeats == Combine::max ? "worst repeat" : "median over repeats";
    md += fmt::format("| `{}` | {} | {} | {} |\n", c.name, c.unit,
                      c.key.empty() ? std::string("-") : fmt::format("`{}`: {}, {}", c.key, frames, repeats), c.help);
  }
  write("report.md", md);
  return written;
}

}  // namespace occull
