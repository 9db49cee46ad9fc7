// occull — command-line tool: device info, scenes, algorithms, benchmarks
// and screenshots. Each command is a file of its own (cli.hpp lists them);
// this one runs the command named and maps its errors to exit codes.
//
// Exit codes: kExitCodes below (printed by --help; the README's table is
// tested equal to it).
#include "cli.hpp"

#include "occull/error.hpp"

#include <CLI/CLI.hpp>
#include <fmt/format.h>

#include <iostream>
#include <string>
#include <utility>
#include <vector>

namespace {

using namespace occull::app;

// The exit codes, as --help prints them and the README's table lists them.
constexpr std::pair<int, const char*> kExitCodes[] = {
    {0, "success"},
    {1, "internal error (a bug: please report it with the message), including a violated run-time invariant of the instrument, with `--gl-debug` a failing OpenGL call or a Vulkan validation error, and a frame past the `--watchdog` time"},
    {2, "bad input: unknown scene / path / algorithm / option (the message lists the valid ones), invalid number or size, a damaged level, model, path or profile file (the message names the file and the fault), an output file or folder that cannot be written"},
    {3, "no usable OpenGL 4.5 (EGL or the driver is missing), or with `--api vulkan` no usable Vulkan 1.2 device (the message says which package); `view`: no display, or built without its viewer"},
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
  // In the order --help lists them.
  const std::vector<std::pair<CLI::App*, Command>> commands = [&] {
    std::vector<std::pair<CLI::App*, Command>> out;
    const auto add = [&](Command (*adder)(CLI::App&)) {
      Command run = adder(app);
      out.emplace_back(app.get_subcommands([](CLI::App*) { return true; }).back(), std::move(run));
    };
    add(add_info);
    add(add_scenes);
    add(add_path);
    add(add_algos);
    add(add_bench);
    add(add_sweep);
    add(add_calibrate);
    add(add_render);
    add(add_view);
    add(add_soak);
    add(add_traverse);
    add(add_upkeep);
    add(add_raster);
#ifdef OCCULL_OSG
    add(add_osg);
#endif
    return out;
  }();

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
    for (const auto& [sub, run] : commands)
      if (sub->parsed()) return run();
  } catch (const occull::InputError& e) {
    std::cerr << "occull: " << e.what() << "\n";
    return kExitInput;
  } catch (const occull::GlUnavailable& e) {
    std::cerr << "occull: no usable OpenGL: " << e.what() << "\n";
    return kExitNoGl;
  } catch (const occull::VulkanUnavailable& e) {
    std::cerr << "occull: no usable Vulkan: " << e.what() << "\n";
    return kExitNoGl;
  } catch (const occull::VulkanError& e) {
    std::cerr << "occull: " << e.what() << "\n";
    return kExitInternal;
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
