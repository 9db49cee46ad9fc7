// `occull raster`: the CPU occlusion buffer's rasterizer timed on one core.
#pragma once

#include <string>

namespace occull::app {

struct RasterArgs {
  std::string scene = "city";
  std::string path;  // empty: the scene's first
  std::string sizes = "320x180,1280x720";
  int frames = 50;
  int repeat = 5;
  double detail = 8.0;  // as soc.detail
};

/// Rasterizes the occluders a camera path sees into buffers of each size,
/// the vectorised loops against the scalar reference, and prints polygons
/// per millisecond (the best of `repeat` timings of each frame). Throws
/// InputError for a bad scene, path, size or count.
int cmd_raster(const RasterArgs& args);

}  // namespace occull::app
