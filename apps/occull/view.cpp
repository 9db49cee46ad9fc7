// `occull view`: a window onto a scene and a culler (viewer.cpp; built with GLFW and Dear ImGui).
#include "cli.hpp"
#include "viewer.hpp"

#include <iostream>
#include <memory>

namespace occull::app {

Command add_view(CLI::App& app) {
  auto a = std::make_shared<ViewArgs>();
  auto size = std::make_shared<std::string>();
  auto* vw = app.add_subcommand("view",
                                "a window onto a scene and a culler: fly the camera, switch algorithms, options "
                                "and debug views, verify live, record the flight (needs a display; xvfb-run "
                                "without one)");
  vw->add_option("--scene", a->scene, "scene spec name[:key=value,...]")->capture_default_str();
  vw->add_option("--path", a->path, "the path whose start is the first pose; with --frames, the path flown");
  vw->add_option("--algo", a->algo, "algorithm at the start (default: vfc, tilevfc on a tiled world)");
  vw->add_option("--opt", a->opts, "option of that algorithm algo.key=value (repeatable)");
  vw->add_option("--view", a->view, debug_view_help())->capture_default_str();
  vw->add_option("--size", *size,
                 "window size WIDTHxHEIGHT (default: 640x360 on llvmpipe, which is too slow for more; the "
                 "display's size on a GPU)");
  vw->add_flag("--verify", a->verify, "ground truth every frame: misses in red, counted in the panel");
  vw->add_option("--frames", a->frames,
                 "scripted: fly --path for this many frames, then exit (tests, recordings); 0: interactive")
      ->capture_default_str();
  vw->add_option("--fps", a->fps, "scripted: frames at this rate of path time (0: spread over the path)")
      ->capture_default_str();
  vw->add_option("--screenshot", a->screenshot, "scripted: write the last frame's window to this PNG");
  vw->add_option("--record", a->record,
                 "record the flight from the start and write it to this path file at the end "
                 "(bench --path file:FILE replays it)");
  vw->add_flag("--no-ui", a->no_ui, "no panel over the view");
  vw->add_option("--depth", a->depth, kDepthHelp)->capture_default_str();
  return [a, size]() -> int {
    if (!size->empty()) {
      const Size s = parse_size(*size);
      a->width = s.width;
      a->height = s.height;
    }
#ifdef OCCULL_VIEWER
    return run_viewer(*a);
#else
    std::cerr << "occull: this occull was built without its viewer: it needs GLFW and Dear ImGui "
                 "(apt-get install libglfw3-dev libimgui-dev, then make build)\n";
    return kExitNoGl;
#endif
  };
}

}  // namespace occull::app
