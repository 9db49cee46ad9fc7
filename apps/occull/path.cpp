// `occull path`: a scene's camera path written to a text file, to edit and replay.
#include "cli.hpp"
#include "occull/error.hpp"
#include "occull/scenes.hpp"

#include <fmt/format.h>

namespace occull::app {

namespace {

struct PathArgs {
  std::string scene = "city";
  std::string path;
  std::string out;
};

int cmd_path(const PathArgs& a) {
  if (a.out.empty()) throw occull::InputError("--out FILE is required");
  const occull::SceneBundle bundle = occull::make_scene(a.scene);
  const occull::CameraPath& path = a.path.empty() ? bundle.paths.front() : bundle.path(a.path);
  occull::write_path_file(path, a.out);
  fmt::print("wrote {} ({} poses, {:.1f} s) of {} / {}; replay it with --path file:{}\n", a.out,
             path.keys().size(), path.duration(), a.scene, path.name(), a.out);
  return 0;
}

}  // namespace

Command add_path(CLI::App& app) {
  auto a = std::make_shared<PathArgs>();
  auto* pa = app.add_subcommand("path", "write a scene's camera path to a text file (edit it, replay it with --path file:F)");
  pa->add_option("--scene", a->scene, "scene spec")->capture_default_str();
  pa->add_option("--path", a->path, "camera path (default: the scene's first)");
  pa->add_option("--out", a->out, "output file")->required();
  return [a] { return cmd_path(*a); };
}

}  // namespace occull::app
