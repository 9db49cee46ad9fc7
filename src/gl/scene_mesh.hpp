// Internal: every mesh of a scene in one interleaved vertex array (position,
// normal) and one index array, as the renderer and the painter upload them.
#pragma once

#include "gl.hpp"
#include "occull/scene.hpp"

#include <cstddef>
#include <vector>

namespace occull::gl {

/// Where mesh m lies in the arrays: draw with glDrawElementsBaseVertex.
struct MeshRange {
  GLsizei index_count = 0;
  std::size_t first_index = 0;
  GLint base_vertex = 0;
};

struct SceneMesh {
  std::vector<float> vertices;         ///< 6 floats per vertex: position, normal
  std::vector<std::uint32_t> indices;  ///< per mesh, relative to its base vertex
  std::vector<MeshRange> ranges;       ///< per MeshId
};
[[nodiscard]] SceneMesh build_scene_mesh(const Scene& scene);

/// Immutable buffers of `mesh` (at least 4 bytes each, so an empty scene
/// has valid names) and a vertex array reading them: attribute 0 the
/// position, 1 the normal, from binding 0; the index buffer attached.
struct SceneMeshBuffers {
  GLuint vertex_buffer = 0, index_buffer = 0, vao = 0;
};
[[nodiscard]] SceneMeshBuffers upload_scene_mesh(const SceneMesh& mesh);
/// A vertex array over the buffers upload_scene_mesh() made: attribute 0
/// the position, 1 the normal, the index buffer bound.
[[nodiscard]] GLuint make_scene_vao(GLuint vertex_buffer, GLuint index_buffer);

}  // namespace occull::gl
