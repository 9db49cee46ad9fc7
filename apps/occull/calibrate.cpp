// `occull calibrate`: the NOHC hardware cost model measured on this renderer and cached.
#include "cli.hpp"
#include "occull/error.hpp"
#include "occull/gl/calibrate.hpp"
#include "occull/gl/context.hpp"
#include "occull/process.hpp"
#include "occull/profile_io.hpp"

#include <fmt/format.h>

#include <cstdio>

namespace occull::app {

namespace {

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

}  // namespace

Command add_calibrate(CLI::App& app) {
  auto a = std::make_shared<CalibrateArgs>();
  auto* cal = app.add_subcommand("calibrate",
                                 "measure the NOHC hardware cost model on this renderer and cache it");
  cal->add_option("--malloc", a->malloc_policy, kMallocHelp)->capture_default_str();
  cal->add_option("--size", a->size, "render size WIDTHxHEIGHT")->capture_default_str();
  cal->add_option("--repeats", a->repeats, "rounds per measurement (median kept)")->capture_default_str();
  cal->add_option("--out", a->out, "write the profile here instead of the per-user cache");
  cal->add_flag("--check", a->check,
                "calibrate twice and report sanity checks (cost ordering, repeatability); writes nothing");
  return [a] { return cmd_calibrate(*a); };
}

}  // namespace occull::app
