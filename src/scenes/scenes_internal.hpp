// Internal: generators of the embedded scenes.
#pragma once

#include "occull/scenes.hpp"

#include <map>
#include <string>

namespace occull::scenes {

/// Every parameter of a scene, defaults filled in, checked against its range.
using Params = std::map<std::string, double>;

/// An embedded scene's spec "name[:key=value,...]", parsed: the scene and
/// every parameter (defaults filled in, each checked against its range).
struct ParsedSpec {
  const SceneInfo* info = nullptr;
  Params params;
  SceneBundle (*make)(const Params&) = nullptr;
};
/// Throws InputError naming the fault (an unknown scene lists the valid
/// ones, an unknown parameter the scene's). Precondition: spec is not a
/// q3: or file: spec.
[[nodiscard]] ParsedSpec parse_spec(std::string_view spec);

SceneInfo city_info();
SceneBundle make_city(const Params& params);

SceneInfo field_info();
SceneBundle make_field(const Params& params);

SceneInfo track_info();
SceneBundle make_track(const Params& params);

SceneInfo adversarial_info();
SceneBundle make_adversarial(const Params& params);
SceneInfo tiles_city_info();
SceneBundle make_tiles_city(const Params& params);
SceneInfo tiles_forest_info();
SceneBundle make_tiles_forest(const Params& params);
SceneInfo tiles_hybrid_info();
SceneBundle make_tiles_hybrid(const Params& params);

}  // namespace occull::scenes
