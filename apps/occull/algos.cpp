// `occull algos`: the culling algorithms and their options, from the registry.
#include "cli.hpp"
#include "occull/culler.hpp"

#include <fmt/format.h>

#include <algorithm>

namespace occull::app {

namespace {

int cmd_algos() {
  for (const auto& a : occull::algorithms()) {
    const bool has_threshold = std::any_of(a.options.begin(), a.options.end(),
                                           [](const occull::OptionInfo& o) { return o.key == "threshold"; });
    fmt::print("{:<10} {}{}\n", a.name, a.summary,
               !a.conservative ? " (may pop: not conservative)"
               : has_threshold ? " (conservative; threshold > 0 makes a run approximate)"
                               : " (conservative)");
    for (const auto& o : a.options)
      fmt::print("    --opt {}.{}={}  {}{}\n", a.name, o.key, o.default_value,
                 o.values.empty() ? "" : fmt::format("({}) ", o.values), o.help);
  }
  return 0;
}

}  // namespace

Command add_algos(CLI::App& app) {
  app.add_subcommand("algos", "culling algorithms and their options (--opt algo.key=value)");
  return cmd_algos;
}

}  // namespace occull::app
