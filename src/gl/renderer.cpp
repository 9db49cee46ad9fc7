#include "occull/gl/renderer.hpp"

#include "renderer_impl.hpp"
#include "../render/scoped_timer.hpp"
#include "gl.hpp"
#include "scene_mesh.hpp"

#include <glm/gtc/type_ptr.hpp>

#include <fmt/format.h>

#include <algorithm>
#include <cassert>
#include <chrono>
#include <stdexcept>

namespace occull::gl {
namespace {

using detail::DrawCommand;
using detail::kNoQuery;
using detail::kBoxCapacity;
using detail::MaterialData;

using render::Clock;
using render::ms_since;
using render::ScopedTimer;


// Under --draw multi, material runs shorter than this are drawn one object
// at a time (see draw_objects).
constexpr std::size_t kMinMultiDrawRun = 16;

}  // namespace


void Renderer::Impl::split_translucent(std::span<const ObjectId> objects, std::vector<ObjectId>& translucent_out) {
  opaque.clear();
  for (ObjectId id : objects)
    (scene.material(scene.object(id).material).translucent ? translucent_out : opaque).push_back(id);
}

void Renderer::Impl::sort_opaque_by_material() {
  std::stable_sort(opaque.begin(), opaque.end(), [&](ObjectId a, ObjectId b) {
    return scene.object(a).material < scene.object(b).material;
  });
}


// Every piece of context state the renderer's passes rely on and that no
// pass sets itself. Other GL code in the same context (another renderer,
// an engine's own passes) may have changed any of it, and deleting a GL
// object unbinds it from every binding point, so this runs at the start of
// every frame — never only at construction.
void Renderer::Impl::establish_frame_state() const {
  glBindFramebuffer(GL_FRAMEBUFFER, fbo);
  glViewport(0, 0, options.width, options.height);
  glDepthRange(0.0, 1.0);
  glClipControl(GL_LOWER_LEFT, clip.depth == DepthRange::zero_to_one ? GL_ZERO_TO_ONE : GL_NEGATIVE_ONE_TO_ONE);
  // Capabilities that would drop or alter fragments, clears or samples.
  for (GLenum cap : {GL_SCISSOR_TEST, GL_STENCIL_TEST, GL_BLEND, GL_RASTERIZER_DISCARD,
                     GL_COLOR_LOGIC_OP, GL_SAMPLE_ALPHA_TO_COVERAGE, GL_SAMPLE_COVERAGE,
                     GL_SAMPLE_MASK, GL_FRAMEBUFFER_SRGB, GL_PRIMITIVE_RESTART,
                     GL_PRIMITIVE_RESTART_FIXED_INDEX})
    glDisable(cap);
  for (GLenum i = 0; i < 8; ++i) glDisable(GL_CLIP_DISTANCE0 + i);  // shaders write none
  if (conservative_cap) glDisable(conservative_cap);
  glEnable(GL_DEPTH_TEST);
  glPolygonMode(GL_FRONT_AND_BACK, GL_FILL);
  glFrontFace(GL_CCW);
  glCullFace(GL_BACK);
  // Buffers read by the shaders, and targets that change what GL calls do:
  // a bound query buffer makes glGetQueryObject write into it instead of
  // returning the result.
  glBindBufferBase(GL_SHADER_STORAGE_BUFFER, 0, object_buffer);
  glBindBuffer(GL_QUERY_BUFFER, 0);
  glBindBuffer(GL_DRAW_INDIRECT_BUFFER, indirect_buffer);
}

void Renderer::Impl::enter_render_state(BackendStats& stats) {
  if (mode == Mode::render) return;
  if (mode == Mode::query) ++stats.state_changes;
  mode = Mode::render;
  glUseProgram(scene_program);
  glBindVertexArray(scene_vao);
  glColorMask(GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
  glDepthMask(GL_TRUE);
  glDepthFunc(depth_less());
  glDisable(GL_DEPTH_CLAMP);
  glDisable(GL_POLYGON_OFFSET_FILL);
  // The query pass culls back faces: set culling both ways.
  if (options.cull_backfaces) glEnable(GL_CULL_FACE); else glDisable(GL_CULL_FACE);
  if (conservative_cap) glDisable(conservative_cap);
}

void Renderer::Impl::enter_query_state(BackendStats& stats) {
  if (mode == Mode::query) return;
  if (mode == Mode::render) ++stats.state_changes;
  mode = Mode::query;
  glUseProgram(query_program);
  glBindVertexArray(query_vao);
  glColorMask(GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
  glDepthMask(GL_FALSE);
  glDepthFunc(depth_less_equal());
  glEnable(GL_DEPTH_CLAMP);
  glEnable(GL_POLYGON_OFFSET_FILL);
  // Toward the eye by 2 depth units, plus the depth change of query_slope_px
  // pixels along the face's own slope: a box face coplanar with its object
  // (a decal on the ground) interpolates depth from other vertex positions,
  // which snapping moves by a fraction of a pixel; at grazing angles that
  // fraction is worth more depth than any constant offset.
  const float toward_eye = clip.reversed_z ? 1.0f : -1.0f;
  glPolygonOffset(toward_eye * query_slope_px, toward_eye * 2.0f);
  glEnable(GL_CULL_FACE);  // front faces cover every visible pixel of a box the eye is outside of
  query_culls_back = true;
  if (conservative_cap) glEnable(conservative_cap);
}

void Renderer::Impl::draw_objects(std::span<const ObjectId> ids, BackendStats& stats) {
  enter_render_state(stats);
  if (options.draw == DrawMode::indirect) return indirect_draw(ids, stats);
  for (std::size_t begin = 0; begin < ids.size();) {
    // One run of objects with the same material: one material bind, then
    // either one multi-draw or one draw per object.
    const MaterialId material = scene.object(ids[begin]).material;
    std::size_t end = begin + 1;
    while (end < ids.size() && scene.object(ids[end]).material == material) ++end;
    if (material != bound_material) {
      const MaterialData& m = materials[material];
      glUniform4fv(u_color, 1, glm::value_ptr(m.color));
      glUniform1i(u_lights, m.lights);
      bound_material = material;
      ++stats.material_changes;
    }
    const auto run = ids.subspan(begin, end - begin);
    if (options.draw == DrawMode::multi && run.size() >= kMinMultiDrawRun) {
      multi_draw(run);
    } else if (options.draw == DrawMode::multi) {
      // A short run: a buffer upload and an indirect draw cost more than the
      // draws they replace. The multi-draw program reads the object index
      // from the instance attribute, so each object is its own base instance.
      for (ObjectId id : run) {
        const MeshRange& r = meshes[scene.object(id).mesh];
        glDrawElementsInstancedBaseVertexBaseInstance(
            GL_TRIANGLES, r.index_count, GL_UNSIGNED_INT,
            reinterpret_cast<const void*>(r.first_index * sizeof(std::uint32_t)), 1, r.base_vertex, id);
      }
    } else {
      for (ObjectId id : run) {
        const Object& o = scene.object(id);
        const MeshRange& r = meshes[o.mesh];
        glUniformMatrix4fv(u_model, 1, GL_FALSE, glm::value_ptr(o.transform));
        glUniform1ui(u_object, id);
        glDrawElementsBaseVertex(GL_TRIANGLES, r.index_count, GL_UNSIGNED_INT,
                                 reinterpret_cast<const void*>(r.first_index * sizeof(std::uint32_t)),
                                 r.base_vertex);
      }
    }
    for (ObjectId id : run) stats.triangles += scene.object(id).triangles;
    stats.draw_calls += run.size();
    stats.objects_rendered += run.size();
    begin = end;
  }
}

void Renderer::Impl::multi_draw(std::span<const ObjectId> ids) {
  commands.clear();
  for (ObjectId id : ids) {
    const MeshRange& r = meshes[scene.object(id).mesh];
    commands.push_back({GLuint(r.index_count), 1, GLuint(r.first_index), r.base_vertex, id});
  }
  const auto bytes = GLsizeiptr(commands.size() * sizeof(DrawCommand));
  if (indirect_offset + bytes > indirect_capacity) {
    indirect_capacity = std::max(indirect_capacity, 2 * bytes);
    glNamedBufferData(indirect_buffer, indirect_capacity, nullptr, GL_STREAM_DRAW);
    indirect_offset = 0;
  }
  glNamedBufferSubData(indirect_buffer, indirect_offset, bytes, commands.data());
  glBindBuffer(GL_DRAW_INDIRECT_BUFFER, indirect_buffer);  // device draws bind their own
  glMultiDrawElementsIndirect(GL_TRIANGLES, GL_UNSIGNED_INT,
                              reinterpret_cast<const void*>(indirect_offset), GLsizei(commands.size()),
                              0);
  indirect_offset += bytes;
}

// DrawMode::indirect: every object of `ids` in one multi-draw with the device
// draw program (renderer_device.cpp), in the order given. The caller has set
// the pass's masks and depth state (enter_render_state and what it changes
// after); only the program and vertex array change here.
void Renderer::Impl::indirect_draw(std::span<const ObjectId> ids, BackendStats& stats) {
  if (ids.empty()) return;
  use_device_draw();
  multi_draw(ids);
  for (ObjectId id : ids) stats.triangles += scene.object(id).triangles;
  stats.draw_calls += ids.size();
  stats.objects_rendered += ids.size();
}

void Renderer::Impl::upload_dynamic_transforms() {
  if (options.draw == DrawMode::single && !device) return;  // single draws pass each matrix with its draw
  for (ObjectId id : scene.dynamic_objects()) {
    glNamedBufferSubData(object_buffer, GLintptr(id * sizeof(glm::mat4)), sizeof(glm::mat4),
                         glm::value_ptr(scene.object(id).transform));
  }
  // Placed anew (a tiled world's window moved) or moved by the engine.
  uploaded_revision = scene.for_each_changed_since(uploaded_revision, [&](ObjectId id) {
    glNamedBufferSubData(object_buffer, GLintptr(id * sizeof(glm::mat4)), sizeof(glm::mat4),
                         glm::value_ptr(scene.object(id).transform));
  });
}


// Context state, camera and per-frame bookkeeping of a pass over `view`;
// the targets keep what they hold.
void Renderer::Impl::prepare_pass(const View& v) {
  view = v;
  clip = view.clip;
  if (device) device->in_frame = false;
  if (scene.meshes().size() > meshes.size())
    throw UsageError(fmt::format("gl::Renderer: the scene has {} meshes, {} more than when the renderer was made; "
                                       "meshes added later need a new renderer",
                                       scene.meshes().size(), scene.meshes().size() - meshes.size()));
  if (scene.objects().size() > object_capacity)
    throw UsageError(fmt::format("gl::Renderer: the scene has {} objects, {} more than when the renderer was "
                                       "made; objects added later need a new renderer (ids removed and reused are fine)",
                                       scene.objects().size(), scene.objects().size() - object_capacity));
  establish_frame_state();
  upload_dynamic_transforms();
  view_proj_relative = eye_relative(view);
  glProgramUniformMatrix4fv(scene_program, u_scene_view_proj, 1, GL_FALSE, glm::value_ptr(view_proj_relative));
  glProgramUniformMatrix4fv(query_program, u_query_view_proj, 1, GL_FALSE, glm::value_ptr(view_proj_relative));
  glProgramUniform3fv(query_program, u_query_eye, 1, glm::value_ptr(view.eye));
  glProgramUniform3fv(scene_program, u_eye, 1, glm::value_ptr(view.eye));
  glProgramUniform3fv(scene_program, u_background, 1, glm::value_ptr(options.background));
  glProgramUniform1f(scene_program, u_fog, std::max(view.far, 1.0f));
  eye = view.eye;
  near_radius = near_plane_radius(view);
  translucent.clear();
  conditional.clear();
  bound_material = ~0u;
  // Start in render state without counting it as a change.
  mode = Mode::none;
  BackendStats ignored;
  enter_render_state(ignored);
}

void Renderer::begin_frame(const View& view) {
  Impl& g = *impl_;
  g.prepare_pass(view);
  const glm::vec4 bg(g.options.background, 1.0f);
  glClearNamedFramebufferfv(g.fbo, GL_COLOR, 0, glm::value_ptr(bg));
  const GLuint zero[4] = {0, 0, 0, 0};
  if (g.write_ids) glClearNamedFramebufferuiv(g.fbo, GL_COLOR, 1, zero);
  const float far = g.depth_far();
  glClearNamedFramebufferfv(g.fbo, GL_DEPTH, 0, &far);
  // The query boxes of the last frame stay with its draws: this frame's
  // first box takes fresh storage (orphaning, in the query's upload), and a
  // frame without queries takes none (a fill is zeroed by llvmpipe).
  if (g.box_offset > 0) g.box_offset = kBoxCapacity;
  if (g.indirect_offset > 0) g.indirect_offset = g.indirect_capacity;  // the same for draw commands
  if (g.timer_supported) glBeginQuery(GL_TIME_ELAPSED, g.timer);
}

double Renderer::end_frame() {
  Impl& g = *impl_;
  if (!g.translucent.empty()) {
    // Back to front by distance of the box centre; no depth or id writes.
    std::sort(g.translucent.begin(), g.translucent.end(), [&](ObjectId a, ObjectId b) {
      const glm::vec3 da = g.scene.object(a).bounds.center() - g.eye;
      const glm::vec3 db = g.scene.object(b).bounds.center() - g.eye;
      return glm::dot(da, da) > glm::dot(db, db);
    });
    g.enter_render_state(stats_);
    glDepthMask(GL_FALSE);
    glColorMaski(1, GL_FALSE, GL_FALSE, GL_FALSE, GL_FALSE);
    glEnable(GL_BLEND);
    glBlendFunc(GL_SRC_ALPHA, GL_ONE_MINUS_SRC_ALPHA);
    g.draw_objects(g.translucent, stats_);
    glDisable(GL_BLEND);
    glColorMaski(1, GL_TRUE, GL_TRUE, GL_TRUE, GL_TRUE);
    glDepthMask(GL_TRUE);
    g.translucent.clear();
  }
  if (g.device && g.device->translucent_pending) g.draw_device_translucent();
  if (g.timer_supported) glEndQuery(GL_TIME_ELAPSED);
  glFinish();
  // Conditional draws whose query the culler has not read: the device is
  // done, so their results are there (read without freeing the query).
  glBindBuffer(GL_QUERY_BUFFER, 0);
  for (const Impl::ConditionalDraw& d : g.conditional) {
    assert(d.serial == g.query_serial[d.query]);  // not read, so not reissued
    GLuint64 samples = 0;
    glGetQueryObjectui64v(g.query_names[d.query], GL_QUERY_RESULT, &samples);
    if (samples == 0) stats_.conditional_skipped += d.count;
  }
  g.conditional.clear();
  double gpu_ms = 0.0;
  if (g.timer_supported) {
    GLuint64 ns = 0;
    glGetQueryObjectui64v(g.timer, GL_QUERY_RESULT, &ns);
    gpu_ms = double(ns) * 1e-6;
  }
  check_error("end of frame");
  return gpu_ms;
}

void Renderer::render(std::span<const ObjectId> objects) {
  Impl& g = *impl_;
  ScopedTimer timer(stats_.backend_ms);
  ++stats_.render_flushes;
  g.split_translucent(objects, g.translucent);
  if (g.options.draw != DrawMode::indirect) g.sort_opaque_by_material();  // one draw for all materials
  if (!g.opaque.empty()) g.draw_objects(g.opaque, stats_);
}

void Renderer::render_conditional(std::span<const ObjectId> objects, QueryId q, ConditionalWait wait) {
  Impl& g = *impl_;
  g.check_in_flight(q, "render_conditional");
  ScopedTimer timer(stats_.backend_ms);
  ++stats_.render_flushes;
  g.split_translucent(objects, g.translucent);  // translucent ones: deferred, drawn in any case
  if (g.opaque.empty()) return;
  g.sort_opaque_by_material();
  g.conditional.push_back({q, g.query_serial[q], g.opaque.size()});
  stats_.conditional_objects += g.opaque.size();
  g.enter_render_state(stats_);
  glBeginConditionalRender(g.query_names[q], wait == ConditionalWait::wait ? GL_QUERY_WAIT : GL_QUERY_NO_WAIT);
  g.draw_objects(g.opaque, stats_);
  glEndConditionalRender();
}

QueryId Renderer::issue_query(std::span<const Aabb> boxes) {
  Impl& g = *impl_;
  assert(!boxes.empty());
  ScopedTimer timer(stats_.backend_ms);
  g.enter_query_state(stats_);
  QueryId q;
  if (g.free_queries.empty()) {
    GLuint name = 0;
    glCreateQueries(g.target, 1, &name);
    q = QueryId(g.query_names.size());
    g.query_names.push_back(name);
    g.query_serial.push_back(0);
    g.query_live.push_back(0);
  } else {
    q = g.free_queries.back();
    g.free_queries.pop_back();
  }
  ++g.in_flight;
  g.query_live[q] = 1;
  g.query_serial[q] = ++g.issue_serial;
  // A box around the eye shows only back faces: draw both sides for it.
  bool around_eye = false;
  for (const Aabb& b : boxes) around_eye = around_eye || b.grown(g.near_radius).contains(g.eye);
  if (around_eye == g.query_culls_back) {
    if (around_eye) glDisable(GL_CULL_FACE); else glEnable(GL_CULL_FACE);
    g.query_culls_back = !around_eye;
  }
  const GLuint name = g.query_names[q];
  glBeginQuery(g.target, name);
  std::size_t done = 0;
  while (done < boxes.size()) {
    if (g.box_offset == kBoxCapacity) {
      glNamedBufferData(g.box_buffer, kBoxCapacity * GLsizeiptr(sizeof(Aabb)), nullptr,
                        GL_STREAM_DRAW);
      g.box_offset = 0;
    }
    const auto n = std::min<std::size_t>(boxes.size() - done, std::size_t(kBoxCapacity - g.box_offset));
    glNamedBufferSubData(g.box_buffer, g.box_offset * GLsizeiptr(sizeof(Aabb)),
                         GLsizeiptr(n * sizeof(Aabb)), boxes.data() + done);
    glDrawArraysInstancedBaseInstance(GL_TRIANGLES, 0, g.query_vertices, GLsizei(n), GLuint(g.box_offset));
    g.box_offset += GLsizeiptr(n);
    done += n;
  }
  glEndQuery(g.target);
  ++stats_.queries;
  stats_.query_boxes += boxes.size();
  return q;
}

bool Renderer::result_available(QueryId q) {
  Impl& g = *impl_;
  g.check_in_flight(q, "result_available");
  ScopedTimer timer(stats_.backend_ms);
  GLuint available = GL_FALSE;
  g.note_flush_for(q, stats_);
  glBindBuffer(GL_QUERY_BUFFER, 0);  // results may be read between frames too
  glGetQueryObjectuiv(g.query_names[q], GL_QUERY_RESULT_AVAILABLE, &available);
  return available == GL_TRUE;
}

std::uint64_t Renderer::result(QueryId q) {
  Impl& g = *impl_;
  g.check_in_flight(q, "result");
  const auto t0 = Clock::now();
  GLuint available = GL_FALSE;
  g.note_flush_for(q, stats_);
  glBindBuffer(GL_QUERY_BUFFER, 0);  // results may be read between frames too
  glGetQueryObjectuiv(g.query_names[q], GL_QUERY_RESULT_AVAILABLE, &available);
  if (available != GL_TRUE) ++stats_.blocking_waits;
  GLuint64 samples = 0;
  glGetQueryObjectui64v(g.query_names[q], GL_QUERY_RESULT, &samples);
  const double ms = ms_since(t0);
  stats_.wait_ms += ms;
  stats_.backend_ms += ms;
  if (!g.conditional.empty()) g.settle_conditional(q, samples, stats_);
  g.free_queries.push_back(q);
  g.query_live[q] = 0;
  --g.in_flight;
  return samples;
}

void Renderer::flush() {
  ScopedTimer timer(stats_.backend_ms);
  impl_->note_flush_for(kNoQuery, stats_);
  glFlush();
}

void Renderer::set_write_ids(bool on) {
  impl_->write_ids = on;
  impl_->apply_draw_buffers();
}



std::uint64_t Renderer::unread_result(QueryId q) {
  Impl& g = *impl_;
  g.check_in_flight(q, "unread_result");
  GLuint64 samples = 0;
  glBindBuffer(GL_QUERY_BUFFER, 0);
  glGetQueryObjectui64v(g.query_names[q], GL_QUERY_RESULT, &samples);
  return samples;
}





std::size_t Renderer::queries_in_flight() const noexcept { return impl_->in_flight; }

}  // namespace occull::gl
