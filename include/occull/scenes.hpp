// occull — embedded procedural scenes and their camera paths.
//
// Every scene is generated in-process from its parameters (including a
// seed): the same spec gives the same scene, byte for byte.
#pragma once

#include "occull/motion.hpp"
#include "occull/scene.hpp"
#include "occull/tiles.hpp"
#include <memory>
#include "occull/view.hpp"

#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace occull {

struct SceneParamInfo {
  std::string key;
  double default_value = 0.0;
  double min = 0.0;
  double max = 0.0;
  bool integer = true;
  std::string help;
  /// When not empty, the parameter is one of these names (its value is the
  /// index of the name; min/max are 0 and choices.size() - 1).
  std::vector<std::string> choices;
};

struct SceneInfo {
  std::string name;
  std::string summary;
  std::vector<SceneParamInfo> params;
  std::vector<std::string> paths;  ///< camera path names, default first
};

/// A generated scene with its camera paths and lens.
struct SceneBundle {
  Scene scene;
  std::vector<CameraPath> paths;  ///< default first
  Lens lens;
  /// Where the scene's frame stands in the world, metres (the `offset`
  /// parameter: (offset, 0, offset)): its objects and paths are relative to
  /// it. A Session keeps its scene relative to a floating origin near the
  /// camera instead (Session::origin).
  glm::dvec3 origin{0.0};
  /// Set for a tiled world (tiles_city, ...): the scene holds its window of
  /// objects, and the owner calls world->follow(scene, eye) before each
  /// frame it renders (occull/tiles.hpp).
  std::shared_ptr<TiledWorld> world;
  /// The dynamic objects on their scripted motions (the city's traffic):
  /// animate(scene, scripted, t) moves them to time t.
  std::vector<ScriptedObject> scripted;

  /// The named path. Throws InputError listing the valid names.
  [[nodiscard]] const CameraPath& path(std::string_view name) const;
};

/// The embedded scenes, in presentation order.
[[nodiscard]] std::span<const SceneInfo> embedded_scenes();

/// Builds a scene from a spec "name[:key=value[,key=value...]]", e.g.
/// "city:blocks=6,seed=3"; or loads one: "q3:FILE.pk3:MAP" or "q3:FILE.bsp"
/// (a Quake 3 level, occull/q3bsp.hpp), "file:MODEL" (anything assimp reads). Throws InputError for an unknown scene (listing
/// the valid ones), an unknown parameter (listing that scene's) or a value
/// out of range.
[[nodiscard]] SceneBundle make_scene(std::string_view spec);

/// A model's lens and camera paths, from its scene's bounds: `orbit`
/// (circles it at 1.6 radii, looking at its centre) and `through` (flies
/// straight through its middle); near and far planes scaled to its size.
/// What `file:` scenes get, and models converted by their owner.
void add_model_views(SceneBundle& bundle);

}  // namespace occull
