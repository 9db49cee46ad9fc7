// occull's command-line tool: what its commands share. Each command lives
// in a file of its own (info.cpp, bench.cpp, ...) and registers itself with
// add_<command>(); main.cpp runs the one named.
#pragma once

#include "occull/culler.hpp"

#include <CLI/CLI.hpp>

#include <fstream>
#include <functional>
#include <memory>
#include <string>
#include <vector>

namespace occull::app {

// Exit codes (main.cpp's kExitCodes says what each means; --help prints them).
inline constexpr int kExitInternal = 1;
inline constexpr int kExitInput = 2;
inline constexpr int kExitNoGl = 3;
inline constexpr int kExitVerificationFailed = 4;
inline constexpr int kExitSoakLeak = 5;

inline constexpr const char* kMallocHelp =
    "allocator policy of the process: engine (keep freed heap memory, as engines do, so driver batches do "
    "not page-fault it back in) or system (glibc's defaults)";
inline constexpr const char* kGlDebugHelp =
    "GL debug contexts: the driver checks every call, and a failing one stops the run with exit 1, "
    "naming the call and its stack (slower: not for timings)";
inline constexpr const char* kApiHelp =
    "graphics API the frames render through: gl (OpenGL 4.5, the reference renderer) or vulkan (Vulkan "
    "1.2 on the first device: lavapipe without a GPU; --gl-debug turns its validation layer on)";
inline constexpr const char* kDepthHelp =
    "depth convention of the views: standard (OpenGL's [-1, 1]) or reversed (reversed-Z in [0, 1] with an "
    "infinite far plane, as engines render); the truth and the verifier follow it";

/// A command once its options are parsed: runs it, returns the exit code.
/// Throws occull::InputError (exit 2), GlUnavailable (3) and the others
/// main.cpp maps.
using Command = std::function<int()>;

// Each adds its subcommand and options to `app` and returns what runs it;
// the options' values live in the returned function.
Command add_info(CLI::App& app);
Command add_scenes(CLI::App& app);
Command add_path(CLI::App& app);
Command add_algos(CLI::App& app);
Command add_bench(CLI::App& app);
Command add_sweep(CLI::App& app);
Command add_calibrate(CLI::App& app);
Command add_render(CLI::App& app);
Command add_view(CLI::App& app);
Command add_soak(CLI::App& app);
Command add_traverse(CLI::App& app);
Command add_upkeep(CLI::App& app);
Command add_raster(CLI::App& app);
#ifdef OCCULL_OSG
Command add_osg(CLI::App& app);
#endif

struct Size {
  int width = 1280;
  int height = 720;
};

/// "WIDTHxHEIGHT", checked against occull::limits. Throws InputError.
[[nodiscard]] Size parse_size(const std::string& text);
/// The non-empty items of a comma-separated list.
[[nodiscard]] std::vector<std::string> split_list(const std::string& text);
/// on/off (true/false, yes/no, 1/0) for option `flag`. Throws InputError.
[[nodiscard]] bool parse_on_off(const std::string& flag, const std::string& s);
/// --opt algo.key=value items, checked against the registry.
[[nodiscard]] occull::Options parse_options(const std::vector<std::string>& opts);
/// Opens an output file before the (long) run, so a bad path fails at once
/// (null for an empty path). Throws InputError.
[[nodiscard]] std::unique_ptr<std::ofstream> open_output(const std::string& path);
/// Throws InputError when writing `f` (opened on `path`) failed.
void check_written(const std::ofstream& f, const std::string& path);
/// The help of --view (render, view): every debug view.
[[nodiscard]] std::string debug_view_help();

}  // namespace occull::app
