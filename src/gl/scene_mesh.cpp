// Scene meshes in GL buffers: see scene_mesh.hpp.
#include "scene_mesh.hpp"

#include <algorithm>

namespace occull::gl {

SceneMesh build_scene_mesh(const Scene& scene) {
  SceneMesh out;
  std::size_t vertex_count = 0, index_count = 0;
  for (const Mesh& m : scene.meshes()) {
    vertex_count += m.positions.size();
    index_count += m.indices.size();
  }
  out.vertices.reserve(vertex_count * 6);
  out.indices.reserve(index_count);
  for (const Mesh& m : scene.meshes()) {
    MeshRange r;
    r.index_count = GLsizei(m.indices.size());
    r.first_index = out.indices.size();
    r.base_vertex = GLint(out.vertices.size() / 6);
    for (std::size_t i = 0; i < m.positions.size(); ++i) {
      out.vertices.insert(out.vertices.end(), {m.positions[i].x, m.positions[i].y, m.positions[i].z,
                                               m.normals[i].x, m.normals[i].y, m.normals[i].z});
    }
    out.indices.insert(out.indices.end(), m.indices.begin(), m.indices.end());
    out.ranges.push_back(r);
  }
  return out;
}

SceneMeshBuffers upload_scene_mesh(const SceneMesh& mesh) {
  SceneMeshBuffers b;
  glCreateBuffers(1, &b.vertex_buffer);
  glNamedBufferStorage(b.vertex_buffer, GLsizeiptr(std::max<std::size_t>(mesh.vertices.size(), 1) * 4),
                       mesh.vertices.empty() ? nullptr : mesh.vertices.data(), 0);
  glCreateBuffers(1, &b.index_buffer);
  glNamedBufferStorage(b.index_buffer, GLsizeiptr(std::max<std::size_t>(mesh.indices.size(), 1) * 4),
                       mesh.indices.empty() ? nullptr : mesh.indices.data(), 0);
  b.vao = make_scene_vao(b.vertex_buffer, b.index_buffer);
  return b;
}

GLuint make_scene_vao(GLuint vertex_buffer, GLuint index_buffer) {
  GLuint vao = 0;
  glCreateVertexArrays(1, &vao);
  glVertexArrayVertexBuffer(vao, 0, vertex_buffer, 0, 6 * sizeof(float));
  glVertexArrayAttribFormat(vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribFormat(vao, 1, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float));
  glVertexArrayAttribBinding(vao, 0, 0);
  glVertexArrayAttribBinding(vao, 1, 0);
  glEnableVertexArrayAttrib(vao, 0);
  glEnableVertexArrayAttrib(vao, 1);
  glVertexArrayElementBuffer(vao, index_buffer);
  return vao;
}

}  // namespace occull::gl
