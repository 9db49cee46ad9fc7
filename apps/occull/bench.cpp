// `occull bench`: a camera path flown with each algorithm, or a suite of them: tables, JSON, CSV, report.
#include "cli.hpp"
#include "run_options.hpp"

#include "occull/error.hpp"
#include "occull/report.hpp"
#include "occull/suite.hpp"

#include <fmt/format.h>

#include <cstdio>
#include <iostream>
#include <unistd.h>

namespace occull::app {

namespace {

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

}  // namespace

Command add_bench(CLI::App& app) {
  auto a = std::make_shared<BenchArgs>();
  auto* b = app.add_subcommand("bench", "fly a camera path with each algorithm and report frame times");
  add_run_options(b, *a, "algorithm");
  b->add_option("--algo", a->algos,
                "comma-separated algorithms, each optionally with its own options as "
                "name:key=value:key=value (default: all; see occull algos)");
  b->add_option("--query-mode", a->query_mode, "occlusion query target: samples, any, conservative")
      ->capture_default_str();
  b->add_option("--query-raster", a->query_raster,
                "how query boxes stay conservative beyond sub-pixel snapping: margin (widen their outline "
                "by --query-margin px), hardware (conservative-raster extension, else margin), exact (neither)")
      ->capture_default_str();
  b->add_option("--query-margin", a->query_margin, "with --query-raster margin: pixels to widen each query box's outline by")
      ->capture_default_str();
  b->add_option("--csv", a->csv, "write one CSV row per algorithm, repeat and frame to this file");
  b->add_option("--report", a->report, "write report.md, SVG charts, JSON and CSV into this folder")
      ->capture_default_str();
  b->add_flag("--no-report", a->no_report, "do not write the report folder");
  b->add_flag("--model", a->model,
              "also predict every frame with the NOHC cost model and print predicted vs measured");
  b->add_option("--bvh-leaf", a->bvh_leaf, "most objects in a BVH leaf (binned SAH decides below that)")
      ->capture_default_str();
  b->add_option("--views", a->views,
                "split screen: this many views side by side (each WIDTH/N wide), one path each (--path A,B; "
                "default: the scene's paths in turn); grid shares one grid and query cap between them")
      ->capture_default_str();
  b->add_option("--draw", a->draw,
                "object submission: single (one draw per object), multi (one multi-draw per material run) or indirect (one multi-draw per render call over all materials: the draw path of hiz, commands written by the CPU)")
      ->capture_default_str();
  b->add_option("--depth", a->depth, kDepthHelp)->capture_default_str();
  b->add_option("--engine-moves", a->engine_moves,
                "fraction of the static objects moved every frame by engine calls (set_transform, not a Motion), "
                "around 2 m circles; the hierarchy and the cullers follow")
      ->capture_default_str();
  auto* suite_opt = b->add_option("--suite", a->suite,
                                  "run a fixed list of scene/path pairs instead of one, with a table each and a summary "
                                  "over all (geometric mean and worst ratio to vfc and oracle per culler): default, quick");
  suite_opt->excludes(b->get_option("--scene"))->excludes(b->get_option("--path"));
  return [a] { return cmd_bench(*a); };
}

}  // namespace occull::app
