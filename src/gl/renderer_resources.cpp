// The reference renderer's scene resources: its programs, buffers, query
// mesh and render targets, made once with the renderer and freed with it,
// and what they amount to (resources()). The frame passes that use them are
// in renderer.cpp, the truth pass in renderer_truth.cpp.
#include "occull/gl/renderer.hpp"

#include "renderer_impl.hpp"
#include "gl.hpp"
#include "occull/input_limits.hpp"
#include "scene_mesh.hpp"
#include "occull/error.hpp"
#include "../render/query_box_mesh.hpp"

#include <glm/gtc/type_ptr.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <string_view>

namespace occull::gl {
namespace {

using detail::kBoxCapacity;
using detail::MaterialData;

// The scene pass. Per-draw data is fetched once per draw, never per vertex
// or fragment: with one draw per object the object's matrix and id are
// uniforms set with the draw (as scene-graph engines do); under
// OCCULL_MULTI_DRAW (one multi-draw per material run) they come from the
// object buffer, indexed by the instance attribute. The material is a
// uniform in both: every draw or multi-draw covers one material. Device
// draws (OCCULL_INSTANCE_ATTRIBUTES, renderer_device.cpp) cover many
// materials: the object's matrix, colour and lights are instanced vertex
// attributes (each command's base instance is its object), fetched once per
// instance rather than read from a buffer per vertex (which a software
// rasteriser pays per vertex lane) and handed to the fragments flat.
const char* kSceneVertex = R"(
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
#if defined(OCCULL_INSTANCE_ATTRIBUTES)
layout(location = 2) in uint a_object;
layout(location = 3) in mat4 a_model;  // locations 3 to 6
layout(location = 7) in vec4 a_color;
layout(location = 8) in int a_lights;
flat out uint v_object;
flat out vec4 v_color;
flat out int v_lights;
#elif defined(OCCULL_MULTI_DRAW)
layout(location = 2) in uint a_object;
layout(std430, binding = 0) readonly buffer Objects { mat4 models[]; };
flat out uint v_object;
#else
uniform mat4 u_model;
#endif
uniform mat4 u_view_proj;  // eye-relative: projection times the view's rotation (Impl::eye_relative)
uniform vec3 u_eye;
out vec3 v_world;
out vec3 v_normal;
void main() {
#if defined(OCCULL_INSTANCE_ATTRIBUTES)
  mat4 m = a_model;
  v_object = a_object;
  v_color = a_color;
  v_lights = a_lights;
#elif defined(OCCULL_MULTI_DRAW)
  mat4 m = models[a_object];
  v_object = a_object;
#else
  mat4 m = u_model;
#endif
  vec4 world = m * vec4(a_position, 1.0);
  v_world = world.xyz;
  v_normal = mat3(m) * a_normal;
  gl_Position = u_view_proj * vec4(world.xyz - u_eye, 1.0);
}
)";

// Shading cost: `lights` extra point lights, placed around the fragment by a
// fixed pattern, each evaluated with a full Blinn-Phong term.
const char* kSceneFragment = R"(
#ifdef OCCULL_INSTANCE_ATTRIBUTES
flat in vec4 v_color;
flat in int v_lights;
#define MATERIAL_COLOR v_color
#define MATERIAL_LIGHTS v_lights
#else
uniform vec4 u_color;
uniform int u_lights;
#define MATERIAL_COLOR u_color
#define MATERIAL_LIGHTS u_lights
#endif
uniform vec3 u_eye;
uniform vec3 u_background;
uniform float u_fog_distance;
#if defined(OCCULL_MULTI_DRAW) || defined(OCCULL_INSTANCE_ATTRIBUTES)
flat in uint v_object;
#else
uniform uint u_object;
#endif
in vec3 v_world;
in vec3 v_normal;
layout(location = 0) out vec4 o_color;
layout(location = 1) out uint o_id;
void main() {
  vec3 n = normalize(v_normal);
  vec3 to_eye = normalize(u_eye - v_world);
  const vec3 sun = normalize(vec3(0.45, 0.8, 0.35));
  float diffuse = max(dot(n, sun), 0.0);
  float sky = 0.5 + 0.5 * n.y;
  vec4 color = MATERIAL_COLOR;
  int lights = MATERIAL_LIGHTS;
  vec3 c = color.rgb * (0.25 + 0.25 * sky + 0.6 * diffuse);
  for (int i = 0; i < lights; ++i) {
    float fi = float(i);
    vec3 light = v_world + vec3(sin(fi * 1.7) * 8.0, 4.0 + 2.0 * cos(fi * 2.3), cos(fi * 1.3) * 8.0);
    vec3 l = light - v_world;
    float d2 = dot(l, l);
    l *= inversesqrt(d2);
    vec3 h = normalize(l + to_eye);
    float spec = pow(max(dot(n, h), 0.0), 32.0);
    c += (color.rgb * max(dot(n, l), 0.0) + vec3(spec)) * (0.4 / (1.0 + 0.08 * d2)) / float(lights);
  }
  float fog = clamp(length(u_eye - v_world) / u_fog_distance, 0.0, 1.0);
  c = mix(c, u_background, fog * fog * 0.6);
  o_color = vec4(c, color.a);
#if defined(OCCULL_MULTI_DRAW) || defined(OCCULL_INSTANCE_ATTRIBUTES)
  o_id = v_object + 1u;
#else
  o_id = u_object + 1u;
#endif
}
)";

// Query boxes (their depth offset is set in enter_query_state): the box's
// faces (a_band.x == 0), then a band along each of
// its 12 edges (a_band.x == 1) that is widened to u_margin pixels on either
// side, and lengthened by as much at both ends, when the edge lies on the
// box's silhouette — between a face that faces the eye and one that does
// not, a face of zero area never facing it (a zero-thickness box). The band
// keeps the depth of its edge: it widens the box's outline on screen without
// moving it toward the eye. Other bands collapse to zero area.
const char* kQueryVertex = R"(#version 450 core
layout(location = 0) in vec3 a_p;     // the box corner of this vertex (0/1 per axis); a band's first end
layout(location = 1) in vec3 a_q;     // a band's second end
layout(location = 2) in vec3 a_band;  // x: 1 on a band; y: 1 at the second end; z: side, -1 or +1
layout(location = 3) in vec3 a_min;
layout(location = 4) in vec3 a_max;
uniform mat4 u_view_proj;      // eye-relative (Impl::eye_relative)
uniform vec3 u_eye;
uniform vec2 u_half_viewport;  // pixels
uniform float u_margin;        // pixels

// Component i of v, without indexing (llvmpipe turns a dynamic index into
// memory addressing; selects are plain arithmetic).
float pick(vec3 v, int i) { return i == 0 ? v.x : (i == 1 ? v.y : v.z); }

// The face on `axis` at its max (hi) or min side faces the eye and has area.
bool facing(int axis, bool hi, vec3 extent) {
  bool faces = hi ? pick(u_eye, axis) > pick(a_max, axis) : pick(u_eye, axis) < pick(a_min, axis);
  return faces && pick(extent, (axis + 1) % 3) > 0.0 && pick(extent, (axis + 2) % 3) > 0.0;
}

void main() {
  vec4 a = u_view_proj * vec4(mix(a_min, a_max, a_p) - u_eye, 1.0);
  if (a_band.x == 0.0) {
    gl_Position = a;
    return;
  }
  vec4 b = u_view_proj * vec4(mix(a_min, a_max, a_q) - u_eye, 1.0);
  bool at_b = a_band.y > 0.5;
  int e = a_p.x != a_q.x ? 0 : (a_p.y != a_q.y ? 1 : 2);  // the edge's axis
  int f = (e + 1) % 3, g = (e + 2) % 3;                   // its two faces' axes
  vec3 extent = a_max - a_min;
  const float min_w = 1e-5;
  bool silhouette = facing(f, pick(a_p, f) > 0.5, extent) != facing(g, pick(a_p, g) > 0.5, extent);
  if (u_margin <= 0.0 || !silhouette || max(a.w, b.w) <= min_w) {
    gl_Position = at_b ? b : a;  // a band of zero area
    return;
  }
  // The part of the edge in front of the eye.
  if (a.w < min_w) a = mix(a, b, (min_w - a.w) / (b.w - a.w));
  if (b.w < min_w) b = mix(b, a, (min_w - b.w) / (a.w - b.w));
  vec2 d = (b.xy / b.w - a.xy / a.w) * u_half_viewport;
  float len = length(d);
  vec2 t = len > 1e-6 ? d / len : vec2(1.0, 0.0);
  vec2 n = vec2(-t.y, t.x);  // with t, counter-clockwise: the band is front-facing
  vec4 here = at_b ? b : a;
  vec2 offset = u_margin * (a_band.z * n + (at_b ? t : -t));
  here.xy += offset / u_half_viewport * here.w;
  gl_Position = here;
}
)";

const char* kQueryFragment = R"(#version 450 core
void main() {}
)";


GLenum query_target(QueryMode mode) {
  switch (mode) {
    case QueryMode::any_samples_passed: return GL_ANY_SAMPLES_PASSED;
    case QueryMode::any_samples_passed_conservative: return GL_ANY_SAMPLES_PASSED_CONSERVATIVE;
    case QueryMode::samples_passed: break;
  }
  return GL_SAMPLES_PASSED;
}

using render::QueryVertex;

}  // namespace

void Renderer::Impl::create_targets() {
  glCreateRenderbuffers(1, &color_rb);
  glNamedRenderbufferStorage(color_rb, GL_RGBA8, options.width, options.height);
  glCreateTextures(GL_TEXTURE_2D, 1, &depth_texture);
  glTextureStorage2D(depth_texture, 1, GL_DEPTH_COMPONENT32F, options.width, options.height);
  glTextureParameteri(depth_texture, GL_TEXTURE_MIN_FILTER, GL_NEAREST);  // one level: complete without mipmaps
  glTextureParameteri(depth_texture, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  glTextureParameteri(depth_texture, GL_TEXTURE_COMPARE_MODE, GL_NONE);   // read as depth values
  glCreateRenderbuffers(1, &id_rb);
  glNamedRenderbufferStorage(id_rb, GL_R32UI, options.width, options.height);
  glCreateFramebuffers(1, &fbo);
  glNamedFramebufferRenderbuffer(fbo, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, color_rb);
  glNamedFramebufferRenderbuffer(fbo, GL_COLOR_ATTACHMENT1, GL_RENDERBUFFER, id_rb);
  glNamedFramebufferTexture(fbo, GL_DEPTH_ATTACHMENT, depth_texture, 0);
  apply_draw_buffers();
  const GLenum status = glCheckNamedFramebufferStatus(fbo, GL_FRAMEBUFFER);
  if (status != GL_FRAMEBUFFER_COMPLETE)
    throw GlError("occull renderer: offscreen framebuffer incomplete (status 0x" +
                             std::to_string(status) + ")");
}

void Renderer::Impl::apply_draw_buffers() const {
  const GLenum both[] = {GL_COLOR_ATTACHMENT0, GL_COLOR_ATTACHMENT1};
  const GLenum color_only[] = {GL_COLOR_ATTACHMENT0, GL_NONE};
  glNamedFramebufferDrawBuffers(fbo, 2, write_ids ? both : color_only);
}

void Renderer::Impl::create_scene_buffers() {
  // One interleaved vertex buffer and one index buffer for every mesh.
  const SceneMesh mesh = build_scene_mesh(scene);
  meshes = mesh.ranges;
  const SceneMeshBuffers buffers = upload_scene_mesh(mesh);
  vertex_buffer = buffers.vertex_buffer;
  index_buffer = buffers.index_buffer;
  scene_vao = buffers.vao;

  // Object index per instance: drawing object i with base instance i makes
  // the vertex shader see a_object == i.
  const auto objects = scene.objects();
  std::vector<std::uint32_t> object_index(std::max<std::size_t>(objects.size(), 1));
  for (std::uint32_t i = 0; i < object_index.size(); ++i) object_index[i] = i;
  glCreateBuffers(1, &object_index_buffer);
  glNamedBufferStorage(object_index_buffer, GLsizeiptr(object_index.size() * 4),
                       object_index.data(), 0);

  std::vector<glm::mat4> models(std::max<std::size_t>(objects.size(), 1), glm::mat4(1.0f));
  for (std::size_t i = 0; i < objects.size(); ++i) models[i] = objects[i].transform;
  glCreateBuffers(1, &object_buffer);
  glNamedBufferStorage(object_buffer, GLsizeiptr(models.size() * sizeof(glm::mat4)), models.data(),
                       GL_DYNAMIC_STORAGE_BIT);
  object_capacity = objects.size();
  uploaded_revision = scene.placement_revision();

  for (const Material& m : scene.materials()) {
    glm::vec4 color = m.color;
    if (!m.translucent) color.a = 1.0f;
    materials.push_back({color, std::max(0, m.shading_cost)});
  }

  if (options.draw == DrawMode::multi) add_object_attribute(scene_vao);

  const std::string header = options.draw == DrawMode::multi ? "#version 450 core\n#define OCCULL_MULTI_DRAW 1\n"
                                                 : "#version 450 core\n";
  scene_program = make_program("scene", header + kSceneVertex, header + kSceneFragment);
  u_scene_view_proj = glGetUniformLocation(scene_program, "u_view_proj");
  u_color = glGetUniformLocation(scene_program, "u_color");
  u_lights = glGetUniformLocation(scene_program, "u_lights");
  u_model = glGetUniformLocation(scene_program, "u_model");    // -1 under multi-draw
  u_object = glGetUniformLocation(scene_program, "u_object");  // -1 under multi-draw
  u_eye = glGetUniformLocation(scene_program, "u_eye");
  u_background = glGetUniformLocation(scene_program, "u_background");
  u_fog = glGetUniformLocation(scene_program, "u_fog_distance");
}

void Renderer::Impl::add_object_attribute(GLuint vao) const {
  glVertexArrayVertexBuffer(vao, 1, object_index_buffer, 0, sizeof(std::uint32_t));
  glVertexArrayBindingDivisor(vao, 1, 1);
  glVertexArrayAttribIFormat(vao, 2, 1, GL_UNSIGNED_INT, 0);
  glVertexArrayAttribBinding(vao, 2, 1);
  glEnableVertexArrayAttrib(vao, 2);
}

void Renderer::Impl::create_device_draw(GLuint& program, GLuint& vao, GLuint shading_buffer) const {
  const std::string header = "#version 450 core\n#define OCCULL_INSTANCE_ATTRIBUTES 1\n";
  program = make_program("device draw", header + kSceneVertex, header + kSceneFragment);
  vao = make_scene_vao(vertex_buffer, index_buffer);
  add_object_attribute(vao);
  // Binding 2: the object's model matrix (the object buffer), one per instance.
  glVertexArrayVertexBuffer(vao, 2, object_buffer, 0, sizeof(glm::mat4));
  glVertexArrayBindingDivisor(vao, 2, 1);
  for (GLuint column = 0; column < 4; ++column) {
    glVertexArrayAttribFormat(vao, 3 + column, 4, GL_FLOAT, GL_FALSE, column * sizeof(glm::vec4));
    glVertexArrayAttribBinding(vao, 3 + column, 2);
    glEnableVertexArrayAttrib(vao, 3 + column);
  }
  // Binding 3: its colour and lights (detail::MaterialData), one per instance.
  glVertexArrayVertexBuffer(vao, 3, shading_buffer, 0, sizeof(detail::ObjectShading));
  glVertexArrayBindingDivisor(vao, 3, 1);
  glVertexArrayAttribFormat(vao, 7, 4, GL_FLOAT, GL_FALSE, offsetof(detail::ObjectShading, color));
  glVertexArrayAttribIFormat(vao, 8, 1, GL_INT, offsetof(detail::ObjectShading, lights));
  for (GLuint a : {7u, 8u}) {
    glVertexArrayAttribBinding(vao, a, 3);
    glEnableVertexArrayAttrib(vao, a);
  }
}

QueryRaster effective_query_raster(QueryRaster requested) {
  if (requested != QueryRaster::hardware) return requested;
  return has_extension("GL_NV_conservative_raster") || has_extension("GL_INTEL_conservative_rasterization")
             ? QueryRaster::hardware
             : QueryRaster::margin;
}

std::string describe_query_raster(const RendererOptions& options) {
  switch (effective_query_raster(options.query_raster)) {
    case QueryRaster::hardware:
      return fmt::format("hardware conservative rasterization ({}), depth pulled {:g} px of its slope toward the eye",
                         has_extension("GL_NV_conservative_raster") ? "GL_NV_conservative_raster"
                                                                    : "GL_INTEL_conservative_rasterization",
                         options.query_margin_px);
    case QueryRaster::exact: return "exact boxes, no margin (can miss one-pixel objects)";
    case QueryRaster::margin: break;
  }
  GLint bits = 0;
  glGetIntegerv(GL_SUBPIXEL_BITS, &bits);
  return fmt::format("outline widened by {0:g} px and depth pulled {0:g} px of its slope toward the eye "
                     "(rasteriser snaps vertices to 1/{1} px){2}",
                     options.query_margin_px, 1 << std::clamp(bits, 0, 30),
                     options.query_raster == QueryRaster::hardware ? "; no conservative-raster extension" : "");
}

void Renderer::Impl::create_query_resources() {
  query_raster = effective_query_raster(options.query_raster);
  if (query_raster == QueryRaster::hardware)
    conservative_cap = has_extension("GL_NV_conservative_raster") ? GL_CONSERVATIVE_RASTERIZATION_NV
                                                                  : GL_CONSERVATIVE_RASTERIZATION_INTEL;
  const std::vector<QueryVertex> mesh = render::query_box_mesh();
  query_vertices = query_raster == QueryRaster::margin && options.query_margin_px > 0.0f ? GLsizei(mesh.size()) : 36;
  query_slope_px = query_raster == QueryRaster::exact ? 0.0f : std::max(0.0f, options.query_margin_px);
  glCreateBuffers(1, &cube_vertices);
  glNamedBufferStorage(cube_vertices, GLsizeiptr(mesh.size() * sizeof(QueryVertex)), mesh.data(), 0);
  glCreateBuffers(1, &indirect_buffer);
  glCreateBuffers(1, &box_buffer);
  glNamedBufferData(box_buffer, kBoxCapacity * GLsizeiptr(sizeof(Aabb)), nullptr, GL_STREAM_DRAW);
  static_assert(sizeof(Aabb) == 6 * sizeof(float), "Aabb is uploaded as two vec3");

  glCreateVertexArrays(1, &query_vao);
  glVertexArrayVertexBuffer(query_vao, 0, cube_vertices, 0, sizeof(QueryVertex));
  for (GLuint a = 0; a < 3; ++a) {
    glVertexArrayAttribFormat(query_vao, a, 3, GL_FLOAT, GL_FALSE, a * sizeof(glm::vec3));
    glVertexArrayAttribBinding(query_vao, a, 0);
    glEnableVertexArrayAttrib(query_vao, a);
  }
  glVertexArrayVertexBuffer(query_vao, 1, box_buffer, 0, sizeof(Aabb));
  glVertexArrayBindingDivisor(query_vao, 1, 1);
  glVertexArrayAttribFormat(query_vao, 3, 3, GL_FLOAT, GL_FALSE, 0);
  glVertexArrayAttribFormat(query_vao, 4, 3, GL_FLOAT, GL_FALSE, 3 * sizeof(float));
  glVertexArrayAttribBinding(query_vao, 3, 1);
  glVertexArrayAttribBinding(query_vao, 4, 1);
  glEnableVertexArrayAttrib(query_vao, 3);
  glEnableVertexArrayAttrib(query_vao, 4);

  query_program = make_program("query", kQueryVertex, kQueryFragment);
  u_query_view_proj = glGetUniformLocation(query_program, "u_view_proj");
  u_query_eye = glGetUniformLocation(query_program, "u_eye");
  u_query_half_viewport = glGetUniformLocation(query_program, "u_half_viewport");
  u_query_margin = glGetUniformLocation(query_program, "u_margin");
  glProgramUniform2f(query_program, u_query_half_viewport, 0.5f * float(options.width), 0.5f * float(options.height));
  glProgramUniform1f(query_program, u_query_margin,
                     query_vertices > 36 ? std::max(0.0f, options.query_margin_px) : 0.0f);

  GLint bits = 0;
  glGetQueryiv(GL_TIME_ELAPSED, GL_QUERY_COUNTER_BITS, &bits);
  timer_supported = bits > 0;
  if (timer_supported) glCreateQueries(GL_TIME_ELAPSED, 1, &timer);
  glCreateQueries(GL_SAMPLES_PASSED, 1, &truth_query);
}

Renderer::Renderer(const Scene& scene, const RendererOptions& options)
    : impl_((limits::check_viewport(options.width, options.height, "render target"),
             std::make_unique<Impl>(scene, options))) {
  impl_->target = query_target(options.query_mode);
  impl_->write_ids = options.write_ids;
  impl_->create_targets();
  impl_->create_scene_buffers();
  impl_->create_query_resources();
  // No context state is set here: begin_frame() establishes all of it.
  check_error("creating the renderer");
}

Renderer::~Renderer() {
  Impl& g = *impl_;
  glFinish();  // nothing of ours may still be in flight when its objects go
  g.destroy_device();
  if (!g.query_names.empty())
    glDeleteQueries(GLsizei(g.query_names.size()), g.query_names.data());
  if (g.timer) glDeleteQueries(1, &g.timer);
  glDeleteQueries(1, &g.truth_query);
  const auto buffers = g.buffer_names();
  glDeleteBuffers(GLsizei(buffers.size()), buffers.data());
  const GLuint vaos[] = {g.scene_vao, g.query_vao};
  glDeleteVertexArrays(2, vaos);
  glDeleteProgram(g.scene_program);
  glDeleteProgram(g.query_program);
  glDeleteFramebuffers(1, &g.fbo);
  const GLuint rbs[] = {g.color_rb, g.id_rb};
  glDeleteRenderbuffers(2, rbs);
  glDeleteTextures(1, &g.depth_texture);
}

Renderer::Resources Renderer::resources() const {
  const Impl& g = *impl_;
  Resources r;
  r.queries = g.query_names.size();
  r.queries_free = g.free_queries.size();
  std::vector<GLuint> buffers;
  for (const GLuint b : g.buffer_names()) buffers.push_back(b);
  if (g.device) {  // device culling's, and each culler's visibility
    const detail::DeviceState& d = *g.device;
    buffers.insert(buffers.end(), {d.objects, d.shading, d.drawn, d.commands, d.counts});
    for (const GLuint v : d.visibility)
      if (v) buffers.push_back(v);
  }
  for (const GLuint b : buffers) {
    GLint64 size = 0;
    glGetNamedBufferParameteri64v(b, GL_BUFFER_SIZE, &size);
    r.buffer_bytes += size;
    ++r.buffers;
  }
  return r;
}
int Renderer::width() const noexcept { return impl_->options.width; }
int Renderer::height() const noexcept { return impl_->options.height; }

}  // namespace occull::gl
