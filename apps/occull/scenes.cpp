// `occull scenes`: the embedded scenes with their parameters and paths, and the maps of an archive.
#include "cli.hpp"
#include "occull/q3bsp.hpp"
#include "occull/scenes.hpp"

#include <fmt/format.h>

namespace occull::app {

namespace {

int cmd_list_maps(const std::string& pk3) {
  const auto maps = occull::q3::list_maps(pk3);
  fmt::print("{} maps in {} (use --scene q3:{}:NAME):\n", maps.size(), pk3, pk3);
  for (const auto& m : maps) fmt::print("  {}\n", m);
  return 0;
}

int cmd_scenes() {
  for (const auto& info : occull::embedded_scenes()) {
    const auto bundle = occull::make_scene(info.name);
    fmt::print("{} — {}\n", info.name, info.summary);
    fmt::print("  default: {} objects ({} dynamic), {} triangles\n", bundle.scene.objects().size(),
               bundle.scene.dynamic_objects().size(), bundle.scene.triangle_count());
    fmt::print("  parameters ({}:key=value,...):\n", info.name);
    for (const auto& p : info.params) {
      if (!p.choices.empty()) {
        std::string names;
        for (const auto& c : p.choices) names += (names.empty() ? "" : " | ") + c;
        fmt::print("    {:<10} default {:<6} one of {}  {}\n", p.key,
                   p.choices.at(std::size_t(p.default_value)), names, p.help);
        continue;
      }
      fmt::print("    {:<10} default {:<6} range [{}, {}]  {}\n", p.key, p.default_value, p.min,
                 p.max, p.help);
    }
    fmt::print("  paths:\n");
    for (const auto& path : bundle.paths)
      fmt::print("    {:<10} {:.1f} s  {}\n", path.name(), path.duration(), path.description());
    fmt::print("\n");
  }
  fmt::print("q3:FILE.pk3:MAP, q3:FILE.bsp — a Quake 3 level (IBSP 46); path tour. "
             "occull scenes --list-maps FILE.pk3 lists the maps of an archive.\n"
             "file:MODEL — any model assimp reads (glTF 2, OBJ, ...); paths orbit, through.\n"
             "Any scene also takes --path file:PATH, a recorded path (see occull path).\n");
  return 0;
}

}  // namespace

Command add_scenes(CLI::App& app) {
  auto list_maps = std::make_shared<std::string>();
  auto* sc = app.add_subcommand("scenes", "embedded scenes: parameters, camera paths, object and triangle counts");
  sc->add_option("--list-maps", *list_maps, "list the Quake 3 maps inside a .pk3 archive");
  return [list_maps] { return list_maps->empty() ? cmd_scenes() : cmd_list_maps(*list_maps); };
}

}  // namespace occull::app
