// The reference renderer's DeviceCulling (occull/device_culling.hpp):
// two-phase depth-pyramid culling on the device.
//
// Buffers (made on the first DeviceCulling call, sized for the objects the
// renderer was made for):
//   objects    a DeviceObject per object: world box, draw command, flags
//              (drawable, translucent) and material; rewritten for objects
//              that move, are added or removed (the transforms the draw
//              program reads are the renderer's object buffer).
//   visibility a uint per object per Visibility (1: visible in its last phase 2).
//   drawn      a uint per object: drawn in this frame; cleared at its start.
//   commands   three regions of one DrawCommand per object: phase 1, phase 2
//              opaque, phase 2 translucent (drawn at end_frame, after every
//              opaque draw, with blending and no depth or id writes).
//   counts     the commands written to each region, when compacted.
//   pyramid    R32F; mip k holds level k+1 of the pyramid (level 0 is the
//              depth target itself). Its mip chain is allocated from the next
//              power of two of level 1's size, so each level, halving
//              rounding up (occull/depth_pyramid.hpp, rule 2), fits in its mip;
//              texels past a level's own size are never written or read.
//
// The shaders below follow src/core/depth_pyramid.cpp (the reference the
// unit tests break rule by rule) line for line: the reduction, the level,
// the 2×2 reads, the nearest corner, boxes reaching the eye, the depth
// tolerance. The frustum test is the CPU's (Frustum::classify) with a
// relative slack of 1e-5 on the outside, so the device never drops an
// object the CPU's frustum keeps.
//
// Synchronisation: compute writes to buffers read by indirect draws
// (GL_COMMAND_BARRIER_BIT) and by later dispatches
// (GL_SHADER_STORAGE_BARRIER_BIT); image stores of one pyramid level read by
// the next level's dispatch and by the cull (GL_SHADER_IMAGE_ACCESS_ and
// GL_TEXTURE_FETCH_BARRIER_BIT); the drawn flags read back
// (GL_BUFFER_UPDATE_BARRIER_BIT). Depth written by draws and read by a
// dispatch needs none (framebuffer writes are coherent with later commands).
//
// GL state: like every pass of the renderer, each call sets what it uses
// (program, buffers, textures, images, masks) and leaves the renderer's
// mode unset, so the next render() or issue_query() sets its own again.
#include "occull/gl/renderer.hpp"

#include "renderer_impl.hpp"
#include "gl.hpp"

#include <EGL/egl.h>
#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <chrono>
#include <stdexcept>

namespace occull::gl {
namespace {

using detail::DeviceState;
using detail::DrawCommand;

// std430 layout of the shaders' DeviceObject.
struct DeviceObject {
  glm::vec4 bmin, bmax;
  GLuint count, first;
  GLint base_vertex;
  GLuint flags;  // bit 0 drawable, bit 1 translucent
};
static_assert(sizeof(DeviceObject) == 48);
static_assert(sizeof(DrawCommand) == 20);  // std430 Command

constexpr int kMaxLevels = 16;

const char* kCullShader = R"(#version 450 core
layout(local_size_x = 64) in;
struct DeviceObject { vec4 bmin; vec4 bmax; uint count; uint first; int base_vertex; uint flags; };
struct Command { uint count; uint instances; uint first; int base_vertex; uint base_instance; };
layout(std430, binding = 1) readonly buffer DeviceObjects { DeviceObject objects[]; };
layout(std430, binding = 2) buffer Visibility { uint visible[]; };
layout(std430, binding = 3) buffer Drawn { uint drawn[]; };
layout(std430, binding = 4) writeonly buffer Commands { Command commands[]; };
layout(std430, binding = 5) buffer Counts { uint counts[]; };
layout(binding = 0) uniform sampler2D u_depth;    // pyramid level 0
layout(binding = 1) uniform sampler2D u_pyramid;  // mip k: level k + 1
uniform int u_phase;       // 1 or 2
uniform uint u_objects;    // objects in the scene; also the size of a command region
uniform uint u_region;     // commands per region
uniform mat4 u_view_proj;  // eye-relative (Impl::eye_relative)
uniform vec3 u_eye;
uniform vec4 u_planes[6];
uniform vec2 u_viewport;   // pixels
uniform int u_levels;
uniform ivec2 u_level_size[16];
uniform ivec2 u_clip;      // x: 1 for depth range [0, 1]; y: 1 for reversed-Z
uniform bool u_compact;
uniform int u_texels;      // texels per axis a test reads at most: 2, 4 or 8
uniform bool u_subpixel;   // the view is single-sampled at this size: boxes that hold no pixel centre are skipped

bool in_frustum(vec3 lo, vec3 hi) {
  for (int k = 0; k < 6; ++k) {
    vec4 p = u_planes[k];
    vec3 far_corner = mix(lo, hi, greaterThanEqual(p.xyz, vec3(0.0)));
    float slack = 1e-5 * (dot(abs(p.xyz), abs(far_corner)) + abs(p.w));
    if (dot(p.xyz, far_corner) + p.w < -slack) return false;
  }
  return true;
}

// Exact sub-pixel culling, by the rules of occull::holds_no_sample
// (occull/view.hpp): the box grown by 2^-20 of its coordinates, every corner
// beyond the near plane, the rectangle widened by 1/64 pixel, and no pixel
// centre in it. (In float here: the corners are taken relative to the eye as
// the scene's vertices are, which keeps the error far below the margin.)
bool holds_no_sample(vec3 lo, vec3 hi) {
  if (!u_subpixel) return false;
  float grow = exp2(-20.0) * max(max(max(abs(lo.x), abs(lo.y)), max(abs(lo.z), abs(hi.x))), max(abs(hi.y), abs(hi.z)));
  lo -= vec3(grow);
  hi += vec3(grow);
  vec2 rmin = vec2(1e30), rmax = vec2(-1e30);
  for (int i = 0; i < 8; ++i) {
    vec3 c = vec3((i & 1) != 0 ? hi.x : lo.x, (i & 2) != 0 ? hi.y : lo.y, (i & 4) != 0 ? hi.z : lo.z);
    vec4 h = u_view_proj * vec4(c - u_eye, 1.0);
    if (h.w <= 0.0) return false;
    bool beyond_near = u_clip.y != 0 ? h.z < h.w : h.z > (u_clip.x != 0 ? 0.0 : -1.0) * h.w;
    if (!beyond_near) return false;
    vec2 px = (h.xy / h.w * 0.5 + 0.5) * u_viewport;
    rmin = min(rmin, px);
    rmax = max(rmax, px);
  }
  vec2 first = max(vec2(0.0), ceil(rmin - 1.0 / 64.0 - 0.5));
  vec2 last = min(u_viewport - 1.0, floor(rmax + 1.0 / 64.0 - 0.5));
  return any(greaterThan(first, last));
}

// Larger is farther.
float key(float depth) { return u_clip.y != 0 ? -depth : depth; }
float level_texel(int level, ivec2 p) {
  return level == 0 ? texelFetch(u_depth, p, 0).r : texelFetch(u_pyramid, p, level - 1).r;
}

// Rules 3-9 of occull/depth_pyramid.hpp for one box.
bool whole_box_occluded(vec3 lo, vec3 hi) {
  vec2 rmin = vec2(1e30), rmax = vec2(-1e30);
  float nearest = 1e30;
  for (int i = 0; i < 8; ++i) {
    vec3 c = vec3((i & 1) != 0 ? hi.x : lo.x, (i & 2) != 0 ? hi.y : lo.y, (i & 4) != 0 ? hi.z : lo.z);
    vec4 h = u_view_proj * vec4(c - u_eye, 1.0);
    if (h.w <= 0.0) return false;  // behind the eye
    float z = h.z / h.w;
    bool before_near = u_clip.y != 0 ? z > 1.0 : z < (u_clip.x != 0 ? 0.0 : -1.0);
    if (before_near) return false;
    nearest = min(nearest, key(u_clip.x != 0 ? z : z * 0.5 + 0.5));
    vec2 px = (h.xy / h.w * 0.5 + 0.5) * u_viewport;
    rmin = min(rmin, px);
    rmax = max(rmax, px);
  }
  const float margin = 1.0 / 64.0;
  ivec2 size0 = u_level_size[0];
  // Rule 9: with one sample at each pixel's centre, only the pixels whose
  // centre the widened rectangle holds.
  float centre = u_subpixel ? 0.5 : 0.0;
  vec2 first = u_subpixel ? ceil(rmin - margin - centre) : floor(rmin - margin);
  ivec2 p0 = ivec2(clamp(first, vec2(-1.0), vec2(size0)));
  ivec2 p1 = ivec2(clamp(floor(rmax + margin - centre), vec2(-1.0), vec2(size0)));
  p0 = max(p0, ivec2(0));
  p1 = min(p1, size0 - 1);
  if (p0.x > p1.x || p0.y > p1.y) return true;  // off the image
  int extent = max(p1.x - p0.x + 1, p1.y - p0.y + 1);
  int level = extent <= 1 ? 0 : findMSB(uint(extent - 1)) + 1;
  level = clamp(level - findMSB(uint(u_texels)) + 1, 0, u_levels - 1);
  ivec2 t0 = p0 >> level;
  ivec2 t1 = min(min(p1 >> level, t0 + u_texels - 1), u_level_size[level] - 1);
  float farthest = -1e30;
  for (int y = t0.y; y <= t1.y; ++y)
    for (int x = t0.x; x <= t1.x; ++x) farthest = max(farthest, key(level_texel(level, ivec2(x, y))));
  return nearest > farthest + (4e-6 * abs(farthest) + 4e-7);
}

// Rule 10: a box rules 3-9 cannot hide, octant by octant, the one nearest
// the eye first.
bool occluded(vec3 lo, vec3 hi) {
  if (whole_box_occluded(lo, hi)) return true;
  vec3 mid = 0.5 * (lo + hi);
  bvec3 eye_upper = greaterThan(u_eye, mid);
  int nearest = (eye_upper.x ? 1 : 0) | (eye_upper.y ? 2 : 0) | (eye_upper.z ? 4 : 0);
  for (int i = 0; i < 8; ++i) {
    int o = i ^ nearest;
    bvec3 upper = bvec3((o & 1) != 0, (o & 2) != 0, (o & 4) != 0);
    if (!whole_box_occluded(mix(lo, mid, upper), mix(mid, hi, upper))) return false;
  }
  return true;
}

void emit(uint region, uint i, DeviceObject o, bool draw) {
  if (u_compact) {
    if (!draw) return;
    uint slot = atomicAdd(counts[region], 1u);
    commands[region * u_region + slot] = Command(o.count, 1u, o.first, o.base_vertex, i);
  } else {
    commands[region * u_region + i] = Command(o.count, draw ? 1u : 0u, o.first, o.base_vertex, i);
  }
}

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= u_objects) return;
  DeviceObject o = objects[i];
  bool translucent = (o.flags & 2u) != 0u;
  bool inside = (o.flags & 1u) != 0u && in_frustum(o.bmin.xyz, o.bmax.xyz) && !holds_no_sample(o.bmin.xyz, o.bmax.xyz);
  if (u_phase == 1) {
    bool draw = inside && !translucent && visible[i] != 0u;
    if (draw) drawn[i] = 1u;
    emit(0u, i, o, draw);
  } else {
    bool seen = inside && !occluded(o.bmin.xyz, o.bmax.xyz);
    visible[i] = seen ? 1u : 0u;
    bool draw = seen && drawn[i] == 0u;
    if (draw) drawn[i] = 1u;
    emit(1u, i, o, draw && !translucent);
    emit(2u, i, o, draw && translucent);
  }
}
)";

// One pyramid level from the one below: the farthest of each 2×2 (an odd
// edge's last texel alone).
const char* kPyramidShader = R"(#version 450 core
layout(local_size_x = 8, local_size_y = 8) in;
layout(binding = 0) uniform sampler2D u_depth;
layout(r32f, binding = 0) uniform readonly image2D u_src;
layout(r32f, binding = 1) uniform writeonly image2D u_dst;
uniform bool u_from_depth;
uniform ivec2 u_src_size;
uniform ivec2 u_dst_size;
uniform bool u_reversed;
float src(ivec2 p) { return u_from_depth ? texelFetch(u_depth, p, 0).r : imageLoad(u_src, p).r; }
float farther(float a, float b) { return u_reversed ? min(a, b) : max(a, b); }
void main() {
  ivec2 p = ivec2(gl_GlobalInvocationID.xy);
  if (p.x >= u_dst_size.x || p.y >= u_dst_size.y) return;
  ivec2 s0 = 2 * p;
  ivec2 s1 = min(s0 + 1, u_src_size - 1);
  float v = farther(farther(src(s0), src(ivec2(s1.x, s0.y))), farther(src(ivec2(s0.x, s1.y)), src(s1)));
  imageStore(u_dst, p, vec4(v));
}
)";

GLuint next_power_of_two(int n) {
  GLuint p = 1;
  while (p < GLuint(n)) p <<= 1;
  return p;
}

using Clock = std::chrono::steady_clock;
struct BackendTimer {  // adds the scope's wall time to backend_ms
  double& sink;
  Clock::time_point t0 = Clock::now();
  ~BackendTimer() { sink += std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }
};

}  // namespace

void Renderer::Impl::create_device() {
  device = std::make_unique<DeviceState>();
  DeviceState& d = *device;
  d.cull_program = make_compute_program("device cull", kCullShader);
  d.pyramid_program = make_compute_program("depth pyramid", kPyramidShader);
  const auto cull_uniform = [&](const char* name) { return glGetUniformLocation(d.cull_program, name); };
  d.u_phase = cull_uniform("u_phase");
  d.u_objects = cull_uniform("u_objects");
  d.u_region = cull_uniform("u_region");
  d.u_view_proj = cull_uniform("u_view_proj");
  d.u_eye = cull_uniform("u_eye");
  d.u_planes = cull_uniform("u_planes");
  d.u_viewport = cull_uniform("u_viewport");
  d.u_levels = cull_uniform("u_levels");
  d.u_level_size = cull_uniform("u_level_size");
  d.u_clip = cull_uniform("u_clip");
  d.u_compact = cull_uniform("u_compact");
  d.u_texels = cull_uniform("u_texels");
  d.u_subpixel = cull_uniform("u_subpixel");
  d.u_pyr_from_depth = glGetUniformLocation(d.pyramid_program, "u_from_depth");
  d.u_pyr_src_size = glGetUniformLocation(d.pyramid_program, "u_src_size");
  d.u_pyr_dst_size = glGetUniformLocation(d.pyramid_program, "u_dst_size");
  d.u_pyr_reversed = glGetUniformLocation(d.pyramid_program, "u_reversed");

  const std::size_t n = std::max<std::size_t>(object_capacity, 1);
  std::vector<DeviceObject> records(n, DeviceObject{});
  glCreateBuffers(1, &d.objects);
  glNamedBufferStorage(d.objects, GLsizeiptr(n * sizeof(DeviceObject)), records.data(), GL_DYNAMIC_STORAGE_BIT);
  glCreateBuffers(1, &d.shading);
  glNamedBufferStorage(d.shading, GLsizeiptr(n * sizeof(detail::ObjectShading)), nullptr, GL_DYNAMIC_STORAGE_BIT);
  create_device_draw(d.draw_program, d.draw_vao, d.shading);
  d.u_draw_view_proj = glGetUniformLocation(d.draw_program, "u_view_proj");
  d.u_draw_eye = glGetUniformLocation(d.draw_program, "u_eye");
  d.u_draw_background = glGetUniformLocation(d.draw_program, "u_background");
  d.u_draw_fog = glGetUniformLocation(d.draw_program, "u_fog_distance");
  for (ObjectId id = 0; id < scene.objects().size(); ++id) write_device_records(id);
  d.uploaded_revision = scene.placement_revision();
  glCreateBuffers(1, &d.drawn);
  glNamedBufferStorage(d.drawn, GLsizeiptr(n * 4), nullptr, 0);
  glCreateBuffers(1, &d.commands);
  glNamedBufferStorage(d.commands, GLsizeiptr(3 * n * sizeof(DrawCommand)), nullptr, 0);
  glCreateBuffers(1, &d.counts);
  glNamedBufferStorage(d.counts, 4 * sizeof(GLuint), nullptr, 0);

  // Level sizes halve rounding up down to 1×1; level 0 is the depth target.
  d.level_size.push_back({options.width, options.height});
  while (d.level_size.back()[0] > 1 || d.level_size.back()[1] > 1) {
    const auto [w, h] = d.level_size.back();
    d.level_size.push_back({(w + 1) / 2, (h + 1) / 2});
  }
  if (d.level_size.size() > kMaxLevels) throw UsageError("gl::Renderer: depth pyramid deeper than 16 levels");
  if (d.level_size.size() > 1) {
    const GLuint w = next_power_of_two(d.level_size[1][0]), h = next_power_of_two(d.level_size[1][1]);
    GLsizei mips = 1;
    while ((std::max(w, h) >> mips) > 0) ++mips;
    glCreateTextures(GL_TEXTURE_2D, 1, &d.pyramid);
    glTextureStorage2D(d.pyramid, mips, GL_R32F, GLsizei(w), GLsizei(h));
    glTextureParameteri(d.pyramid, GL_TEXTURE_MIN_FILTER, GL_NEAREST_MIPMAP_NEAREST);
    glTextureParameteri(d.pyramid, GL_TEXTURE_MAG_FILTER, GL_NEAREST);
  }

  GLint major = 0, minor = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &major);
  glGetIntegerv(GL_MINOR_VERSION, &minor);
  const char* entry = major * 10 + minor >= 46                       ? "glMultiDrawElementsIndirectCount"
                      : has_extension("GL_ARB_indirect_parameters") ? "glMultiDrawElementsIndirectCountARB"
                                                                     : nullptr;
  if (entry && options.device_draw_count)
    d.draw_count = reinterpret_cast<decltype(d.draw_count)>(eglGetProcAddress(entry));
  d.compact = d.draw_count != nullptr;
  GLint bits = 0;
  glGetQueryiv(GL_TIMESTAMP, GL_QUERY_COUNTER_BITS, &bits);
  d.timestamps = bits > 0;
  if (d.timestamps) glCreateQueries(GL_TIMESTAMP, GLsizei(d.stamps.size()), d.stamps.data());
  upload_dynamic_transforms();  // this frame's: prepare_pass ran before there was a device
  check_error("creating the device-culling resources");
}

void Renderer::Impl::destroy_device() {
  if (!device) return;
  DeviceState& d = *device;
  for (GLuint b : d.visibility)
    if (b) glDeleteBuffers(1, &b);
  const GLuint buffers[] = {d.objects, d.shading, d.drawn, d.commands, d.counts};
  glDeleteBuffers(5, buffers);
  if (d.pyramid) glDeleteTextures(1, &d.pyramid);
  if (d.timestamps) glDeleteQueries(GLsizei(d.stamps.size()), d.stamps.data());
  glDeleteVertexArrays(1, &d.draw_vao);
  for (GLuint p : {d.cull_program, d.pyramid_program, d.draw_program}) glDeleteProgram(p);
  device.reset();
}

void Renderer::Impl::write_device_records(ObjectId id) {
  const Object& o = scene.object(id);
  const bool drawable = scene.alive(id) && o.triangles > 0 && !o.bounds.empty();
  DeviceObject r{};
  if (drawable) {
    const MeshRange& m = meshes[o.mesh];
    r = {glm::vec4(o.bounds.min, 0.0f), glm::vec4(o.bounds.max, 0.0f), GLuint(m.index_count), GLuint(m.first_index),
         m.base_vertex,
         1u | (scene.material(o.material).translucent ? 2u : 0u)};
  }
  glNamedBufferSubData(device->objects, GLintptr(id * sizeof(DeviceObject)), sizeof(DeviceObject), &r);
  const detail::MaterialData& m = materials[o.material];
  const detail::ObjectShading shade{m.color, m.lights};
  glNamedBufferSubData(device->shading, GLintptr(id * sizeof(shade)), sizeof(shade), &shade);
}

// The frame's records, cleared flags and uniforms, once per frame.
void Renderer::Impl::start_device_frame() {
  if (!device) create_device();
  DeviceState& d = *device;
  if (d.in_frame) return;
  if (scene.objects().size() > object_capacity)
    throw UsageError("gl::Renderer: device culling over more objects than the renderer was made for");
  d.in_frame = true;
  d.pyramid_built = false;
  d.translucent_pending = false;
  d.stamps_written = 0;
  for (ObjectId id : scene.dynamic_objects()) write_device_records(id);
  d.uploaded_revision = scene.for_each_changed_since(d.uploaded_revision, [&](ObjectId id) { write_device_records(id); });
  glClearNamedBufferData(d.drawn, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);
  glClearNamedBufferData(d.counts, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);

  const GLuint p = d.cull_program;
  glProgramUniform1ui(p, d.u_objects, GLuint(scene.objects().size()));
  glProgramUniform1ui(p, d.u_region, GLuint(std::max<std::size_t>(object_capacity, 1)));
  glProgramUniformMatrix4fv(p, d.u_view_proj, 1, GL_FALSE, glm::value_ptr(view_proj_relative));
  glProgramUniform3fv(p, d.u_eye, 1, glm::value_ptr(view.eye));
  std::array<glm::vec4, 6> planes{};
  for (int k = 0; k < 6; ++k) planes[std::size_t(k)] = glm::vec4(view.frustum.plane(k).n, view.frustum.plane(k).d);
  glProgramUniform4fv(p, d.u_planes, 6, glm::value_ptr(planes[0]));
  glProgramUniform2f(p, d.u_viewport, float(options.width), float(options.height));
  glProgramUniform1i(p, d.u_levels, GLint(d.level_size.size()));
  glProgramUniform2iv(p, d.u_level_size, GLsizei(d.level_size.size()), d.level_size[0].data());
  glProgramUniform2i(p, d.u_clip, clip.depth == DepthRange::zero_to_one ? 1 : 0, clip.reversed_z ? 1 : 0);
  glProgramUniform1i(p, d.u_compact, d.compact ? 1 : 0);
  glProgramUniform1i(p, d.u_subpixel, view.samples == 1 && view.width == options.width && view.height == options.height);
  glProgramUniformMatrix4fv(d.draw_program, d.u_draw_view_proj, 1, GL_FALSE, glm::value_ptr(view_proj_relative));
  glProgramUniform3fv(d.draw_program, d.u_draw_eye, 1, glm::value_ptr(view.eye));
  glProgramUniform3fv(d.draw_program, d.u_draw_background, 1, glm::value_ptr(options.background));
  glProgramUniform1f(d.draw_program, d.u_draw_fog, std::max(view.far, 1.0f));
}

void Renderer::Impl::stamp(int k) {
  if (!device->timestamps) return;
  glQueryCounter(device->stamps[std::size_t(k)], GL_TIMESTAMP);
  device->stamps_written |= 1u << k;
}

void Renderer::Impl::dispatch_cull(int phase, GLuint visibility) {
  DeviceState& d = *device;
  glUseProgram(d.cull_program);
  glProgramUniform1i(d.cull_program, d.u_phase, phase);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 1, d.objects);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 2, visibility);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 3, d.drawn);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 4, d.commands);
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 5, d.counts);
  glBindTextureUnit(0, depth_texture);
  glBindTextureUnit(1, d.pyramid);
  const auto n = GLuint(scene.objects().size());
  if (n > 0) glDispatchCompute((n + 63) / 64, 1, 1);
  glMemoryBarrier(GL_COMMAND_BARRIER_BIT | GL_SHADER_STORAGE_BARRIER_BIT);
  glBindTextureUnit(0, 0);  // the depth target is drawn to next
  glBindTextureUnit(1, 0);
  mode = Mode::none;
}

void Renderer::Impl::use_device_draw() {
  start_device_frame();
  glUseProgram(device->draw_program);
  glBindVertexArray(device->draw_vao);
}

// Draws command region `region` (0: phase 1, 1: phase 2 opaque, 2: translucent).
void Renderer::Impl::device_draw(int region, BackendStats& stats) {
  DeviceState& d = *device;
  const bool blended = region == 2;
  enter_render_state(stats);
  use_device_draw();
  if (blended) {  // as the renderer's own translucent draws: no depth or id writes
    glDepthMask(GL_FALSE);
    glColorMaski(1, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
  }
  glBindBuffer(GL_DRAW_INDIRECT_BUFFER, d.commands);
  const auto per_region = std::max<std::size_t>(object_capacity, 1);
  const auto* offset = reinterpret_cast<const void*>(std::size_t(region) * per_region * sizeof(DrawCommand));
  if (d.compact) {
    glBindBuffer(GL_PARAMETER_BUFFER_ARB, d.counts);
    d.draw_count(GL_TRIANGLES, GL_UNSIGNED_INT, offset, GLintptr(region) * 4, GLsizei(scene.objects().size()), 0);
    glBindBuffer(GL_PARAMETER_BUFFER_ARB, 0);
  } else if (!scene.objects().empty()) {
    glMultiDrawElementsIndirect(GL_TRIANGLES, GL_UNSIGNED_INT, offset, GLsizei(scene.objects().size()), 0);
  }
  if (blended) {
    glDisable(GL_BLEND);
    glColorMaski(1, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_TRUE);
  }
  ++stats.render_flushes;
  mode = Mode::none;
}

void Renderer::Impl::draw_device_translucent() {
  // Not counted in the Backend's stats: end_frame() is not a Backend call.
  BackendStats ignored;
  device_draw(2, ignored);
  device->translucent_pending = false;
}

GLuint Renderer::Impl::visibility_buffer(DeviceCulling::Visibility v, const char* call) const {
  if (!device || v >= device->visibility.size() || device->visibility[v] == 0)
    throw UsageError(fmt::format("gl::Renderer::{}: visibility {} was not created by this renderer, or was "
                                       "destroyed",
                                       call, v));
  return device->visibility[v];
}

DeviceCulling::Visibility Renderer::create_visibility() {
  Impl& g = *impl_;
  if (!g.device) g.create_device();
  DeviceState& d = *g.device;
  const auto n = GLsizeiptr(std::max<std::size_t>(g.object_capacity, 1) * 4);
  GLuint buffer = 0;
  glCreateBuffers(1, &buffer);
  glNamedBufferStorage(buffer, n, nullptr, GL_DYNAMIC_STORAGE_BIT);  // set_visible writes it
  glClearNamedBufferData(buffer, GL_R32UI, GL_RED_INTEGER, GL_UNSIGNED_INT, nullptr);  // nothing visible yet
  const auto free_slot = std::find(d.visibility.begin(), d.visibility.end(), 0u);
  if (free_slot != d.visibility.end()) {
    *free_slot = buffer;
    return Visibility(free_slot - d.visibility.begin());
  }
  d.visibility.push_back(buffer);
  return Visibility(d.visibility.size() - 1);
}

void Renderer::destroy_visibility(Visibility v) {
  Impl& g = *impl_;
  GLuint buffer = g.visibility_buffer(v, "destroy_visibility");
  glDeleteBuffers(1, &buffer);
  g.device->visibility[v] = 0;
}

void Renderer::set_visible(Visibility v, std::span<const ObjectId> visible) {
  Impl& g = *impl_;
  const BackendTimer timer{stats_.backend_ms};
  const GLuint buffer = g.visibility_buffer(v, "set_visible");
  std::vector<GLuint> bits(std::max<std::size_t>(g.object_capacity, 1), 0u);
  for (ObjectId id : visible)
    if (id < bits.size()) bits[id] = 1u;
  glNamedBufferSubData(buffer, 0, GLsizeiptr(bits.size() * sizeof(GLuint)), bits.data());
}

void Renderer::read_visible(Visibility v, std::vector<ObjectId>& out) {
  Impl& g = *impl_;
  const BackendTimer timer{stats_.backend_ms};
  const GLuint buffer = g.visibility_buffer(v, "read_visible");
  g.read_flags(buffer, std::min(g.scene.objects().size(), g.object_capacity), out);  // no further than it holds
  check_error("reading back a visibility");
}

void Renderer::Impl::read_flags(GLuint buffer, std::size_t n, std::vector<ObjectId>& out) const {
  std::vector<GLuint> flags(n);
  glMemoryBarrier(GL_BUFFER_UPDATE_BARRIER_BIT);  // the cull shader wrote them
  if (n > 0) glGetNamedBufferSubData(buffer, 0, GLsizeiptr(n * sizeof(GLuint)), flags.data());
  for (ObjectId id = 0; id < n; ++id)
    if (flags[id]) out.push_back(id);
}

void Renderer::draw_previously_visible(Visibility v) {
  Impl& g = *impl_;
  const BackendTimer timer{stats_.backend_ms};
  const GLuint buffer = g.visibility_buffer(v, "draw_previously_visible");
  g.start_device_frame();
  g.stamp(0);
  g.dispatch_cull(1, buffer);
  g.stamp(1);
  g.device_draw(0, stats_);
}

void Renderer::build_depth_pyramid() {
  Impl& g = *impl_;
  const BackendTimer timer{stats_.backend_ms};
  g.start_device_frame();
  DeviceState& d = *g.device;
  g.stamp(2);
  glUseProgram(d.pyramid_program);
  glBindTextureUnit(0, g.depth_texture);
  glProgramUniform1i(d.pyramid_program, d.u_pyr_reversed, g.clip.reversed_z ? 1 : 0);
  for (std::size_t k = 1; k < d.level_size.size(); ++k) {
    const bool from_depth = k == 1;
    glBindImageTexture(0, d.pyramid, from_depth ? 0 : GLint(k) - 2, GL_FALSE, 0, GL_READ_ONLY, GL_R32F);
    glBindImageTexture(1, d.pyramid, GLint(k) - 1, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
    glProgramUniform1i(d.pyramid_program, d.u_pyr_from_depth, from_depth ? 1 : 0);
    glProgramUniform2iv(d.pyramid_program, d.u_pyr_src_size, 1, d.level_size[k - 1].data());
    glProgramUniform2iv(d.pyramid_program, d.u_pyr_dst_size, 1, d.level_size[k].data());
    glDispatchCompute(GLuint(d.level_size[k][0] + 7) / 8, GLuint(d.level_size[k][1] + 7) / 8, 1);
    glMemoryBarrier(GL_SHADER_IMAGE_ACCESS_BARRIER_BIT | GL_TEXTURE_FETCH_BARRIER_BIT);
  }
  glBindTextureUnit(0, 0);
  glBindImageTexture(0, 0, 0, GL_FALSE, 0, GL_READ_ONLY, GL_R32F);
  glBindImageTexture(1, 0, 0, GL_FALSE, 0, GL_WRITE_ONLY, GL_R32F);
  g.stamp(3);
  d.pyramid_built = true;
  g.mode = Impl::Mode::none;
}

void Renderer::draw_newly_visible(Visibility v, int texels) {
  Impl& g = *impl_;
  const BackendTimer timer{stats_.backend_ms};
  const GLuint buffer = g.visibility_buffer(v, "draw_newly_visible");
  g.start_device_frame();
  if (!g.device->pyramid_built)
    throw UsageError("gl::Renderer::draw_newly_visible: build_depth_pyramid() has not run in this frame");
  if (texels != 2 && texels != 4 && texels != 8 && texels != 16)
    throw UsageError(fmt::format("gl::Renderer::draw_newly_visible: {} texels per axis (2, 4, 8 or 16)", texels));
  glProgramUniform1i(g.device->cull_program, g.device->u_texels, texels);
  g.stamp(4);
  g.dispatch_cull(2, buffer);
  g.stamp(5);
  g.device_draw(1, stats_);
  g.device->translucent_pending = true;
}

DeviceCullingTimes Renderer::read_drawn(std::vector<ObjectId>& out) {
  Impl& g = *impl_;
  DeviceCullingTimes times;
  if (!g.device || !g.device->in_frame) return times;
  DeviceState& d = *g.device;
  g.read_flags(d.drawn, g.scene.objects().size(), out);
  const auto span_ms = [&](int a, int b) {
    const std::uint32_t both = (1u << a) | (1u << b);
    if ((d.stamps_written & both) != both) return 0.0;
    GLuint64 t0 = 0, t1 = 0;
    glGetQueryObjectui64v(d.stamps[std::size_t(a)], GL_QUERY_RESULT, &t0);
    glGetQueryObjectui64v(d.stamps[std::size_t(b)], GL_QUERY_RESULT, &t1);
    return t1 > t0 ? double(t1 - t0) * 1e-6 : 0.0;
  };
  times.pyramid_ms = span_ms(2, 3);
  times.cull_ms = span_ms(0, 1) + span_ms(4, 5);
  check_error("reading back the device's draws");
  return times;
}

bool Renderer::device_draws_compacted() const { return impl_->device && impl_->device->compact; }

std::vector<float> Renderer::read_depth_pyramid(int level) const {
  const Impl& g = *impl_;
  if (!g.device || level < 1 || std::size_t(level) >= g.device->level_size.size())
    throw UsageError(fmt::format("gl::Renderer::read_depth_pyramid: no level {}", level));
  const DeviceState& d = *g.device;
  // The level's own texels out of its (larger) mip.
  const auto [w, h] = d.level_size[std::size_t(level)];
  std::vector<float> out(std::size_t(w) * std::size_t(h));
  glMemoryBarrier(GL_TEXTURE_UPDATE_BARRIER_BIT);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  glPixelStorei(GL_PACK_ALIGNMENT, 4);
  glGetTextureSubImage(d.pyramid, level - 1, 0, 0, 0, w, h, 1, GL_RED, GL_FLOAT, GLsizei(out.size() * sizeof(float)),
                       out.data());
  check_error("reading the depth pyramid");
  return out;
}

}  // namespace occull::gl
