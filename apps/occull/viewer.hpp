// occull view: a window onto a scene, a culler and its debug views (GLFW +
// Dear ImGui). Built when both are found (OCCULL_VIEWER); see viewer.cpp.
#pragma once

#include <string>
#include <vector>

namespace occull::app {

struct ViewArgs {
  std::string scene = "city";
  std::string path;          ///< the starting pose's path; with --frames, the path flown
  std::string algo;          ///< empty: the scene's frustum-culling baseline
  std::string view = "color";
  int width = 0, height = 0; ///< 0: 640x360 on llvmpipe, the display's size elsewhere
  std::vector<std::string> opts;
  int frames = 0;            ///< scripted: fly `path` for this many frames, then exit (0: interactive)
  double fps = 30.0;         ///< scripted: frames at this rate of path time (0: spread over the path)
  std::string screenshot;    ///< scripted: the last frame's window, as PNG
  std::string record;        ///< the flown path is written here (file:PATH for bench)
  bool verify = false;       ///< ground truth every frame, misses in red
  bool no_ui = false;        ///< no ImGui panel (screenshots of the view alone)
  std::string depth = "standard";  ///< standard or reversed (occull::parse_depth_mode)
};

/// Runs the viewer; returns the process's exit code. Throws InputError for
/// bad input and GlUnavailable when there is no display or no OpenGL.
int run_viewer(const ViewArgs& args);

}  // namespace occull::app
