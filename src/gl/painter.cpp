// Drawing the debug views' pictures: see occull/gl/painter.hpp.
#include "occull/gl/painter.hpp"

#include "gl.hpp"
#include "occull/input_limits.hpp"
#include "scene_mesh.hpp"
#include "occull/error.hpp"

#include <glm/gtc/type_ptr.hpp>

#include <array>
#include <stdexcept>

namespace occull::gl {
namespace {

// The frame's image, texel for pixel (top row first in the texture).
const char* kImageVertex = R"(#version 450 core
void main() {
  const vec2 p[3] = vec2[](vec2(-1.0, -1.0), vec2(3.0, -1.0), vec2(-1.0, 3.0));
  gl_Position = vec4(p[gl_VertexID], 0.0, 1.0);
}
)";
const char* kImageFragment = R"(#version 450 core
layout(binding = 0) uniform sampler2D u_image;
uniform int u_height;
out vec4 o_color;
void main() {
  o_color = texelFetch(u_image, ivec2(int(gl_FragCoord.x), u_height - 1 - int(gl_FragCoord.y)), 0);
}
)";

const char* kObjectVertex = R"(#version 450 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
uniform mat4 u_model;
uniform mat4 u_view_proj;
out vec3 v_normal;
void main() {
  v_normal = mat3(u_model) * a_normal;
  gl_Position = u_view_proj * (u_model * vec4(a_position, 1.0));
}
)";
const char* kObjectFragment = R"(#version 450 core
uniform vec3 u_color;
in vec3 v_normal;
out vec4 o_color;
void main() {
  const vec3 sun = normalize(vec3(0.45, 0.8, 0.35));
  float lit = 0.6 + 0.4 * abs(dot(normalize(v_normal), sun));
  o_color = vec4(u_color * lit, 1.0);
}
)";

const char* kBoxVertex = R"(#version 450 core
layout(location = 0) in vec3 a_corner;  // 0/1 per axis
layout(location = 1) in float a_shade;
layout(location = 2) in vec3 a_min;
layout(location = 3) in vec3 a_max;
layout(location = 4) in vec3 a_color;
uniform mat4 u_view_proj;
flat out vec3 v_color;
void main() {
  v_color = a_color * a_shade;
  gl_Position = u_view_proj * vec4(mix(a_min, a_max, a_corner), 1.0);
}
)";
const char* kFlatFragment = R"(#version 450 core
flat in vec3 v_color;
out vec4 o_color;
void main() { o_color = vec4(v_color, 1.0); }
)";

const char* kLineVertex = R"(#version 450 core
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_color;
uniform mat4 u_view_proj;
flat out vec3 v_color;
void main() {
  v_color = a_color;
  gl_Position = u_view_proj * vec4(a_position, 1.0);
}
)";

struct CubeVertex {
  glm::vec3 corner;
  float shade;
};
// A unit cube's faces, outward and counter-clockwise, with the shade of
// their axis (x 0.8, y 1.0, z 0.65).
std::vector<CubeVertex> cube() {
  static constexpr int faces[6][6] = {{0, 2, 3, 0, 3, 1}, {4, 5, 7, 4, 7, 6}, {0, 4, 6, 0, 6, 2},
                                      {1, 3, 7, 1, 7, 5}, {0, 1, 5, 0, 5, 4}, {2, 6, 7, 2, 7, 3}};
  static constexpr float shade[6] = {0.65f, 0.65f, 0.8f, 0.8f, 1.0f, 1.0f};
  std::vector<CubeVertex> v;
  for (int f = 0; f < 6; ++f)
    for (int i : faces[f]) v.push_back({glm::vec3(float(i & 1), float((i >> 1) & 1), float((i >> 2) & 1)), shade[f]});
  return v;
}

}  // namespace

struct Painter::Impl {
  const Scene& scene;
  int width, height;
  std::vector<MeshRange> meshes;
  SceneMeshBuffers mesh;
  GLuint image_program = 0, object_program = 0, box_program = 0, line_program = 0;
  GLint u_image_height = -1, u_object_model = -1, u_object_view_proj = -1, u_object_color = -1,
        u_box_view_proj = -1, u_line_view_proj = -1;
  GLuint empty_vao = 0, box_vao = 0, line_vao = 0;
  GLuint cube_buffer = 0, box_buffer = 0, line_buffer = 0;
  GLuint image = 0;
  GLuint fbo = 0, color_rb = 0, depth_rb = 0;

  Impl(const Scene& s, int w, int h) : scene(s), width(w), height(h) {}
  void draw(GLuint framebuffer, const Picture& picture, std::span<const std::uint8_t> frame);
};

Painter::Painter(const Scene& scene, int width, int height)
    : impl_((limits::check_viewport(width, height, "debug view"), std::make_unique<Impl>(scene, width, height))) {
  Impl& g = *impl_;
  const SceneMesh mesh = build_scene_mesh(scene);
  g.meshes = mesh.ranges;
  g.mesh = upload_scene_mesh(mesh);

  g.image_program = make_program("debug image", kImageVertex, kImageFragment);
  g.u_image_height = glGetUniformLocation(g.image_program, "u_height");
  g.object_program = make_program("debug object", kObjectVertex, kObjectFragment);
  g.u_object_model = glGetUniformLocation(g.object_program, "u_model");
  g.u_object_view_proj = glGetUniformLocation(g.object_program, "u_view_proj");
  g.u_object_color = glGetUniformLocation(g.object_program, "u_color");
  g.box_program = make_program("debug box", kBoxVertex, kFlatFragment);
  g.u_box_view_proj = glGetUniformLocation(g.box_program, "u_view_proj");
  g.line_program = make_program("debug line", kLineVertex, kFlatFragment);
  g.u_line_view_proj = glGetUniformLocation(g.line_program, "u_view_proj");

  glCreateVertexArrays(1, &g.empty_vao);
  const std::vector<CubeVertex> c = cube();
  glCreateBuffers(1, &g.cube_buffer);
  glNamedBufferStorage(g.cube_buffer, GLsizeiptr(c.size() * sizeof(CubeVertex)), c.data(), 0);
  glCreateBuffers(1, &g.box_buffer);
  glCreateVertexArrays(1, &g.box_vao);
  glVertexArrayVertexBuffer(g.box_vao, 0, g.cube_buffer, 0, sizeof(CubeVertex));
  glVertexArrayAttribFormat(g.box_vao, 0, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribFormat(g.box_vao, 1, 1, GL_FLOAT, GL_FALSE, sizeof(glm::vec3));
  for (GLuint a = 0; a < 2; ++a) glVertexArrayAttribBinding(g.box_vao, a, 0);
  glVertexArrayBindingDivisor(g.box_vao, 1, 1);
  for (GLuint a = 2; a < 5; ++a) {
    glVertexArrayAttribFormat(g.box_vao, a, 3, GL_FLOAT, GL_FALSE, (a - 2) * sizeof(glm::vec3));
    glVertexArrayAttribBinding(g.box_vao, a, 1);
  }
  for (GLuint a = 0; a < 5; ++a) glEnableVertexArrayAttrib(g.box_vao, a);
  glCreateBuffers(1, &g.line_buffer);
  glCreateVertexArrays(1, &g.line_vao);
  for (GLuint a = 0; a < 2; ++a) {
    glVertexArrayAttribFormat(g.line_vao, a, 3, GL_FLOAT, GL_FALSE, a * sizeof(glm::vec3));
    glVertexArrayAttribBinding(g.line_vao, a, 0);
    glEnableVertexArrayAttrib(g.line_vao, a);
  }

  glCreateTextures(GL_TEXTURE_2D, 1, &g.image);
  glTextureStorage2D(g.image, 1, GL_RGBA8, width, height);
  glCreateRenderbuffers(1, &g.color_rb);
  glNamedRenderbufferStorage(g.color_rb, GL_RGBA8, width, height);
  glCreateRenderbuffers(1, &g.depth_rb);
  glNamedRenderbufferStorage(g.depth_rb, GL_DEPTH_COMPONENT24, width, height);
  glCreateFramebuffers(1, &g.fbo);
  glNamedFramebufferRenderbuffer(g.fbo, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, g.color_rb);
  glNamedFramebufferRenderbuffer(g.fbo, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, g.depth_rb);
  if (glCheckNamedFramebufferStatus(g.fbo, GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw GlError("occull painter: offscreen framebuffer incomplete");
  check_error("creating the painter");
}

Painter::~Painter() {
  Impl& g = *impl_;
  glFinish();
  const GLuint buffers[] = {g.mesh.vertex_buffer, g.mesh.index_buffer, g.cube_buffer, g.box_buffer, g.line_buffer};
  glDeleteBuffers(5, buffers);
  const GLuint vaos[] = {g.mesh.vao, g.empty_vao, g.box_vao, g.line_vao};
  glDeleteVertexArrays(4, vaos);
  for (GLuint p : {g.image_program, g.object_program, g.box_program, g.line_program}) glDeleteProgram(p);
  glDeleteTextures(1, &g.image);
  glDeleteFramebuffers(1, &g.fbo);
  const GLuint rbs[] = {g.color_rb, g.depth_rb};
  glDeleteRenderbuffers(2, rbs);
}

int Painter::width() const noexcept { return impl_->width; }
int Painter::height() const noexcept { return impl_->height; }

void Painter::Impl::draw(GLuint framebuffer, const Picture& picture, std::span<const std::uint8_t> frame) {
  // Every piece of state the passes rely on (other GL code shares the context).
  glBindFramebuffer(GL_FRAMEBUFFER, framebuffer);
  glViewport(0, 0, width, height);
  glDepthRange(0.0, 1.0);
  for (GLenum cap : {GL_SCISSOR_TEST, GL_STENCIL_TEST, GL_BLEND, GL_RASTERIZER_DISCARD, GL_COLOR_LOGIC_OP,
                     GL_SAMPLE_ALPHA_TO_COVERAGE, GL_SAMPLE_COVERAGE, GL_SAMPLE_MASK, GL_FRAMEBUFFER_SRGB,
                     GL_PRIMITIVE_RESTART, GL_PRIMITIVE_RESTART_FIXED_INDEX, GL_POLYGON_OFFSET_FILL,
                     GL_DEPTH_CLAMP, GL_LINE_SMOOTH})
    glDisable(cap);
  for (GLenum i = 0; i < 8; ++i) glDisable(GL_CLIP_DISTANCE0 + i);
  glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  glFrontFace(GL_CCW);
  glCullFace(GL_BACK);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDepthMask(GL_TRUE);
  // The picture's clip conventions (a frame's view may be reversed-Z).
  glClipControl(GL_LOWER_LEFT,
                picture.clip.depth == DepthRange::zero_to_one ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
  glDepthFunc(picture.clip.reversed_z ? GL_GREATER : GL_LESS);
  glLineWidth(1.0f);
  glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);

  // Background.
  if (picture.frame_background) {
    if (frame.size() != std::size_t(width) * std::size_t(height) * 4)
      throw std::invalid_argument("Painter: the frame's image is not width*height RGBA8 pixels");
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glPixelStorei(GL_UNPACK_SKIP_ROWS, 0);
    glPixelStorei(GL_UNPACK_SKIP_PIXELS, 0);
    glTextureSubImage2D(image, 0, 0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, frame.data());
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    glUseProgram(image_program);
    glProgramUniform1i(image_program, u_image_height, height);
    glBindTextureUnit(0, image);
    glBindVertexArray(empty_vao);
    glDrawArrays(GL_TRIANGLES, 0, 3);
  } else {
    const glm::vec4 c(picture.clear, 1.0f);
    glClearColor(c.r, c.g, c.b, c.a);
    glClear(GL_COLOR_BUFFER_BIT);
  }
  glClearDepth(picture.clip.reversed_z ? 0.0 : 1.0);
  glClear(GL_DEPTH_BUFFER_BIT);

  // Objects, flat colours, both faces (a debug picture shows what is there).
  glEnable(GL_DEPTH_TEST);
  glDisable(GL_CULL_FACE);
  if (!picture.objects.empty()) {
    glUseProgram(object_program);
    glBindVertexArray(mesh.vao);
    glProgramUniformMatrix4fv(object_program, u_object_view_proj, 1, GL_FALSE, glm::value_ptr(picture.view_proj));
    for (const Picture::Paint& p : picture.objects) {
      const Object& o = scene.object(p.id);
      const MeshRange& r = meshes[o.mesh];
      glProgramUniformMatrix4fv(object_program, u_object_model, 1, GL_FALSE, glm::value_ptr(o.transform));
      glProgramUniform3fv(object_program, u_object_color, 1, glm::value_ptr(p.color));
      glDrawElementsBaseVertex(GL_TRIANGLES, r.index_count, GL_UNSIGNED_INT,
                               reinterpret_cast<const void*>(r.first_index * sizeof(std::uint32_t)), r.base_vertex);
    }
  }

  // Boxes, layer by layer: each over everything drawn before it,
  // depth-tested within itself.
  if (!picture.boxes.empty()) {
    glEnable(GL_CULL_FACE);
    std::vector<float> data;
    data.reserve(picture.boxes.size() * 9);
    for (const Picture::Box& b : picture.boxes)
      data.insert(data.end(), {b.box.min.x, b.box.min.y, b.box.min.z, b.box.max.x, b.box.max.y, b.box.max.z,
                               b.color.r, b.color.g, b.color.b});
    glNamedBufferData(box_buffer, GLsizeiptr(data.size() * sizeof(float)), data.data(), GL_STREAM_DRAW);
    glVertexArrayVertexBuffer(box_vao, 1, box_buffer, 0, 9 * sizeof(float));
    glUseProgram(box_program);
    glProgramUniformMatrix4fv(box_program, u_box_view_proj, 1, GL_FALSE, glm::value_ptr(picture.view_proj));
    glBindVertexArray(box_vao);
    for (std::size_t begin = 0; begin < picture.boxes.size();) {
      std::size_t end = begin;
      while (end < picture.boxes.size() && picture.boxes[end].layer == picture.boxes[begin].layer) ++end;
      glClear(GL_DEPTH_BUFFER_BIT);
      glDrawArraysInstancedBaseInstance(GL_TRIANGLES, 0, 36, GLsizei(end - begin), GLuint(begin));
      begin = end;
    }
  }

  // Lines over all.
  if (!picture.lines.empty()) {
    glDisable(GL_DEPTH_TEST);
    glDisable(GL_CULL_FACE);
    std::vector<float> data;
    data.reserve(picture.lines.size() * 12);
    for (const Picture::Line& l : picture.lines)
      data.insert(data.end(), {l.a.x, l.a.y, l.a.z, l.color.r, l.color.g, l.color.b,
                               l.b.x, l.b.y, l.b.z, l.color.r, l.color.g, l.color.b});
    glNamedBufferData(line_buffer, GLsizeiptr(data.size() * sizeof(float)), data.data(), GL_STREAM_DRAW);
    glVertexArrayVertexBuffer(line_vao, 0, line_buffer, 0, 6 * sizeof(float));
    glUseProgram(line_program);
    glProgramUniformMatrix4fv(line_program, u_line_view_proj, 1, GL_FALSE, glm::value_ptr(picture.view_proj));
    glBindVertexArray(line_vao);
    glDrawArrays(GL_LINES, 0, GLsizei(picture.lines.size() * 2));
  }
  check_error("painting a debug view");
}

std::vector<std::uint8_t> Painter::paint(const Picture& picture, std::span<const std::uint8_t> frame) {
  impl_->draw(impl_->fbo, picture, frame);
  return read_rgba_top_first(impl_->fbo, impl_->width, impl_->height);
}

void Painter::paint_into(std::uint32_t framebuffer, const Picture& picture, std::span<const std::uint8_t> frame) {
  impl_->draw(framebuffer, picture, frame);
}

}  // namespace occull::gl
