// What occull's commands share: sizes, lists, on/off, options, output files.
#include "cli.hpp"

#include "occull/debug_view.hpp"
#include "occull/error.hpp"
#include "occull/input_limits.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstdio>

namespace occull::app {

Size parse_size(const std::string& text) {
  int w = 0, h = 0;
  char x = 0, extra = 0;
  if (std::sscanf(text.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X'))
    throw occull::InputError(fmt::format("--size '{}' is not WIDTHxHEIGHT (e.g. 1280x720)", text));
  occull::limits::check_viewport(w, h, "--size");
  return {w, h};
}

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> out;
  std::size_t pos = 0;
  while (pos <= text.size()) {
    const std::size_t comma = std::min(text.find(',', pos), text.size());
    std::string item = text.substr(pos, comma - pos);
    if (!item.empty()) out.push_back(item);
    pos = comma + 1;
  }
  return out;
}


bool parse_on_off(const std::string& flag, const std::string& s) {
  if (s == "on" || s == "true" || s == "yes" || s == "1") return true;
  if (s == "off" || s == "false" || s == "no" || s == "0") return false;
  throw occull::InputError(fmt::format("{} '{}': expected on or off", flag, s));
}


occull::Options parse_options(const std::vector<std::string>& opts) {
  occull::Options options;
  for (const auto& o : opts) options.set(o);
  occull::check_options(options);
  return options;
}

// Opens an output file before the (long) run, so a bad path fails at once.
std::unique_ptr<std::ofstream> open_output(const std::string& path) {
  if (path.empty()) return nullptr;
  auto f = std::make_unique<std::ofstream>(path, std::ios::binary);
  if (!*f) throw occull::InputError(fmt::format("cannot open '{}' for writing", path));
  return f;
}

void check_written(const std::ofstream& f, const std::string& path) {
  if (!f) throw occull::InputError(fmt::format("cannot write '{}'", path));
}

// `bench --suite NAME`: every entry of the suite with the same settings,

std::string debug_view_help() {
  std::string help = "what to draw:";
  for (const auto& v : occull::debug_views()) help += fmt::format(" {}: {};", v.name, v.summary);
  help += " soc: the frame with the CPU occlusion buffer the culler used beside it (soc; chc, chcpp, nohc with "
          "cpu_test=on)";
  return help;
}

}  // namespace occull::app
