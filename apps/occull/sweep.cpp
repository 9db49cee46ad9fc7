// `occull sweep`: one algorithm over every combination of option values, a table per setting.
#include "cli.hpp"
#include "run_options.hpp"

#include "occull/error.hpp"
#include "occull/report.hpp"
#include "occull/sweep.hpp"

#include <fmt/format.h>

#include <iostream>

namespace occull::app {

namespace {

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

}  // namespace

Command add_sweep(CLI::App& app) {
  auto a = std::make_shared<SweepArgs>();
  a->bench.algos = "grid";
  a->bench.frames = 60;
  a->bench.size = "320x180";
  auto* sw = app.add_subcommand(
      "sweep", "run one algorithm over every combination of option values (--vary) and tabulate frame time "
               "and popping per setting");
  sw->add_option("--algo", a->bench.algos, "the algorithm swept (one name; see occull algos)")->capture_default_str();
  sw->add_option("--vary", a->vary,
                 "an option and its values, key=v1,v2,... (repeatable; every combination runs, at most 64)")
      ->required();
  sw->add_option("--baseline", a->baseline, "comma-separated algorithms run beside the settings (empty: none)")
      ->capture_default_str();
  sw->add_option("--popping", a->popping,
                 "the best setting misses at most this percentage of the visible object-frames")
      ->capture_default_str();
  sw->add_option("--longest", a->longest, "... and no object for more than this many frames in a row")
      ->capture_default_str();
  add_run_options(sw, a->bench, "setting");
  return [a] { return cmd_sweep(*a); };
}

}  // namespace occull::app
