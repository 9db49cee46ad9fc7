// Internal: generators of the embedded scenes.
#pragma once

#include "occull/scenes.hpp"

#include <map>
#include <string>

namespace occull::scenes {

/// Every parameter of a scene, defaults filled in, checked against its range.
using Params = std::map<std::string, double>;

SceneInfo city_info();
SceneBundle make_city(const Params& params);

SceneInfo field_info();
SceneBundle make_field(const Params& params);

SceneInfo track_info();
SceneBundle make_track(const Params& params);

SceneInfo adversarial_info();
SceneBundle make_adversarial(const Params& params);

}  // namespace occull::scenes
