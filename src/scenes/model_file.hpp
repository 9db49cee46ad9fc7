// Internal: loading `file:PATH` scenes through assimp.
#pragma once

#include "occull/scenes.hpp"

#include <cstdint>
#include <string>

namespace occull::scenes {

/// Loads a model file as a scene (paths `orbit`, `through`). Throws
/// InputError naming the file when assimp cannot read it.
SceneBundle load_model_file(const std::string& path, std::uint32_t object_triangles = 1500);

}  // namespace occull::scenes
