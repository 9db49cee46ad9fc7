// Internal: loading `file:PATH` scenes through assimp.
#pragma once

#include "child_process.hpp"
#include "occull/input_limits.hpp"
#include "occull/scenes.hpp"

#include <cstdint>
#include <string>

namespace occull::scenes {

/// The limits of occull/input_limits.hpp for the child that imports a model.
inline ChildLimits model_import_limits() {
  return {limits::model_import_cpu_seconds, limits::model_import_wall_seconds, limits::model_import_bytes};
}

/// Loads a model file as a scene (paths `orbit`, `through`). assimp reads it
/// in a child process under `import_limits` (run_in_child). Throws
/// InputError naming the file when assimp cannot read it, or crashes, hangs
/// or passes a limit on it.
SceneBundle load_model_file(const std::string& path, std::uint32_t object_triangles = 1500,
                            const ChildLimits& import_limits = model_import_limits());

}  // namespace occull::scenes
