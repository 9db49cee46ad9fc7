// The reference renderer's state, shared by its files by job:
// renderer_resources.cpp (programs, buffers, targets), renderer.cpp (the
// Backend's frame passes) and renderer_truth.cpp (the untimed truth pass
// and the read-backs over the same resources).
// Internal to occull_gl.
#pragma once

#include "occull/gl/renderer.hpp"

#include "gl.hpp"
#include "scene_mesh.hpp"
#include "occull/error.hpp"

#include <fmt/format.h>

#include <array>
#include <memory>
#include <stdexcept>
#include <vector>

namespace occull::gl {
namespace detail {

struct MaterialData {
  glm::vec4 color;  // alpha 1 for opaque materials
  GLint lights = 0;  // shading cost: extra lights evaluated per fragment
};

// An object's shading as device draws read it (an instanced attribute).
struct ObjectShading {
  glm::vec4 color;
  GLint lights = 0;
  GLint pad[3] = {0, 0, 0};
};

// Layout of glMultiDrawElementsIndirect's commands.
struct DrawCommand {
  GLuint count, instance_count, first_index;
  GLint base_vertex;
  GLuint base_instance;
};

// Boxes per fill of the query-box stream buffer (192 KiB). A fill is fresh
// storage (orphaning): llvmpipe zero-fills it, and 1.5 MiB fills (65,536
// boxes) cost a 1.5 MiB memset a frame and, now and then, 384 page faults
// and 3-4 ms of kernel time in one frame.
constexpr GLsizeiptr kBoxCapacity = 1 << 13;

constexpr QueryId kNoQuery = ~QueryId(0);  // no query: flush() is not about one

// Device culling (renderer_device.cpp): made on the first DeviceCulling call.
struct DeviceState {
  GLuint cull_program = 0, pyramid_program = 0, draw_program = 0, draw_vao = 0;
  GLuint objects = 0;    // DeviceObject per object (see renderer_device.cpp)
  GLuint shading = 0;    // ObjectShading per object (its material's), an instanced attribute of device draws
  GLuint drawn = 0;      // per object: drawn in this frame (1) or not (0)
  GLuint commands = 0;   // 3 regions of one DrawCommand per object: phase 1, phase 2 opaque, phase 2 translucent
  GLuint counts = 0;     // commands written to each region (compacted draws)
  GLuint pyramid = 0;    // R32F, mip k is level k+1 of the pyramid (level 0 is the depth target)
  std::vector<std::array<int, 2>> level_size;  // pyramid levels from 0 (the depth target)
  std::vector<GLuint> visibility;  // Visibility -> buffer of a bit (uint) per object; 0 when free
  std::uint64_t uploaded_revision = 0;  // Scene::placement_revision() of the records on the device
  bool compact = false;  // glMultiDrawElementsIndirectCount available: commands compacted
  void (*draw_count)(GLenum, GLenum, const void*, GLintptr, GLsizei, GLsizei) = nullptr;
  bool in_frame = false;            // the frame's records, uniforms and cleared buffers are set
  bool translucent_pending = false; // phase 2 wrote translucent draws for end_frame
  std::array<GLuint, 6> stamps{};   // timestamps around the two cull dispatches and the pyramid build
  std::uint32_t stamps_written = 0; // bit k: stamps[k] was written this frame
  bool timestamps = false;          // the device has GL_TIMESTAMP
  bool pyramid_built = false;       // build_depth_pyramid() ran this frame
  GLint u_phase = -1, u_objects = -1, u_region = -1, u_view_proj = -1, u_planes = -1, u_viewport = -1,
        u_levels = -1, u_level_size = -1, u_clip = -1, u_compact = -1, u_texels = -1, u_eye = -1, u_subpixel = -1;
  GLint u_draw_view_proj = -1, u_draw_eye = -1, u_draw_background = -1, u_draw_fog = -1;
  GLint u_pyr_from_depth = -1, u_pyr_src_size = -1, u_pyr_dst_size = -1, u_pyr_reversed = -1;
};

}  // namespace detail

struct Renderer::Impl {
  const Scene& scene;
  RendererOptions options;
  GLenum target = GL_SAMPLES_PASSED;

  GLuint vertex_buffer = 0, index_buffer = 0, object_index_buffer = 0;
  GLuint object_buffer = 0;  // model matrices, read by the multi-draw program only
  std::vector<detail::MaterialData> materials;
  GLuint scene_vao = 0, scene_program = 0;
  GLint u_scene_view_proj = -1, u_color = -1, u_lights = -1, u_model = -1, u_object = -1, u_eye = -1,
        u_background = -1, u_fog = -1;
  GLuint cube_vertices = 0, box_buffer = 0;
  GLuint query_vao = 0, query_program = 0;
  GLint u_query_view_proj = -1, u_query_eye = -1, u_query_half_viewport = -1, u_query_margin = -1;
  QueryRaster query_raster = QueryRaster::margin;  // what is in effect (hardware falls back to margin)
  GLenum conservative_cap = 0;                     // GL_CONSERVATIVE_RASTERIZATION_{NV,INTEL} when present
  GLsizei query_vertices = 36;                     // faces only, or faces and silhouette bands
  float query_slope_px = 0.0f;                     // polygon-offset slope factor of query boxes
  // Every pass projects positions relative to the eye: its shaders take
  // world - eye first (small numbers near the camera, whatever the
  // coordinates' size) and then this matrix — the projection times the
  // view's rotation, computed in double. Projecting world positions with
  // view_proj directly rounds the depth of a surface 56 m away by 10-40
  // float units at coordinates of 2 km (the large terms of z and w cancel,
  // each rounded on its own), and query boxes then lose to the walls their
  // objects stand a millimetre in front of.
  [[nodiscard]] static glm::mat4 eye_relative(const View& v) { return glm::mat4(eye_relative_projection(v)); }
  glm::mat4 view_proj_relative{1.0f};  // eye_relative(view) of the current pass (prepare_pass)
  // The clip conventions of the pass's view: depth range, and with reversed-Z
  // the depth tests, the depth clear and the polygon offset turn around.
  ClipSpace clip;
  [[nodiscard]] GLenum depth_less() const { return clip.reversed_z ? GL_GREATER : GL_LESS; }
  [[nodiscard]] GLenum depth_less_equal() const { return clip.reversed_z ? GL_GEQUAL : GL_LEQUAL; }
  [[nodiscard]] float depth_far() const { return clip.reversed_z ? 0.0f : 1.0f; }
  GLuint fbo = 0, color_rb = 0, id_rb = 0;
  GLuint depth_texture = 0;  // a texture, not a renderbuffer: device culling builds its pyramid from it
  GLuint timer = 0;
  bool timer_supported = false;
  bool write_ids = true;

  std::vector<MeshRange> meshes;
  std::vector<GLuint> query_names;  // QueryId -> GL name (all of `target`)
  // Which queries the device has been handed (a flush since their issue):
  // polling or reading one that was not makes the driver flush.
  std::vector<std::uint64_t> query_serial;  // QueryId -> issue_serial when issued
  std::vector<std::uint8_t> query_live;     // QueryId -> issued and not yet read
  // Backend's precondition "q in flight", checked on every use of a query:
  // a query read twice would be freed twice and later handed to two users.
  void check_in_flight(QueryId q, const char* call) const {
    if (q >= query_live.size() || !query_live[q])
      throw UsageError(fmt::format("gl::Renderer::{}: query {} is not in flight ({})", call, q,
                                         q >= query_live.size() ? "never issued by this renderer"
                                                                : "already read, or issued by another renderer"));
  }
  std::uint64_t issue_serial = 0;           // queries issued so far
  std::uint64_t flushed_serial = 0;         // issue_serial at the last flush
  void note_flush_for(QueryId q, BackendStats& stats) {
    if (q != detail::kNoQuery && query_serial[q] <= flushed_serial) return;
    ++stats.flushes;
    flushed_serial = issue_serial;
  }
  std::vector<QueryId> free_queries;
  std::uint64_t uploaded_revision = 0;  // Scene::placement_revision() of the transforms on the device
  std::size_t object_capacity = 0;      // objects the per-object buffers hold
  std::size_t in_flight = 0;
  // Every buffer object the renderer owns.
  [[nodiscard]] std::array<GLuint, 7> buffer_names() const {
    return {vertex_buffer, index_buffer, object_index_buffer, object_buffer, cube_vertices, box_buffer,
            indirect_buffer};
  }
  GLsizeiptr box_offset = 0;  // next free box in the stream buffer

  enum class Mode { none, render, query } mode = Mode::none;
  MaterialId bound_material = ~0u;
  glm::vec3 eye{0.0f};
  float near_radius = 0.0f;
  bool query_culls_back = true;
  std::vector<ObjectId> opaque;
  std::vector<ObjectId> translucent;  // deferred to end_frame
  // Conditional draws of this frame whose query result is not known yet:
  // once it is, those whose query passed no samples count as skipped.
  struct ConditionalDraw {
    QueryId query;
    std::uint64_t serial;  // query_serial of the query when drawn
    std::size_t count;     // opaque objects drawn under it
  };
  std::vector<ConditionalDraw> conditional;
  // Query q's result is `samples`: settles the draws conditional on it.
  void settle_conditional(QueryId q, std::uint64_t samples, BackendStats& stats) {
    std::erase_if(conditional, [&](const ConditionalDraw& d) {
      if (d.query != q || d.serial != query_serial[q]) return false;
      if (samples == 0) stats.conditional_skipped += d.count;
      return true;
    });
  }
  GLuint truth_query = 0;             // GL_SAMPLES_PASSED, for visible_pixels only
  std::vector<std::uint32_t> pixel_counts;  // per object, scratch of visible_pixels
  View view;                          // of the current pass
  std::unique_ptr<detail::DeviceState> device;  // made by the first DeviceCulling call
  GLuint indirect_buffer = 0;         // multi-draw commands, refilled every frame
  GLsizeiptr indirect_capacity = 0, indirect_offset = 0;
  std::vector<detail::DrawCommand> commands;

  Impl(const Scene& s, const RendererOptions& o) : scene(s), options(o) {}

  void create_targets();
  void create_scene_buffers();
  void create_query_resources();
  void apply_draw_buffers() const;
  void establish_frame_state() const;
  void prepare_pass(const View& view);
  std::uint64_t samples_passing(std::span<const ObjectId> ids);
  void enter_render_state(BackendStats& stats);
  void enter_query_state(BackendStats& stats);
  void draw_objects(std::span<const ObjectId> ids, BackendStats& stats);
  void multi_draw(std::span<const ObjectId> ids);
  void indirect_draw(std::span<const ObjectId> ids, BackendStats& stats);
  // Binds the device draw program (made on first use) and its vertex array,
  // with this frame's uniforms; the render state's masks stay as they are.
  void use_device_draw();
  void upload_dynamic_transforms();
  // `objects` into `opaque` (cleared first) and `translucent` (appended to),
  // each in the order given.
  void split_translucent(std::span<const ObjectId> objects, std::vector<ObjectId>& translucent_out);
  // Binds the per-object index buffer as attribute 2 (one per instance) of `vao`.
  void add_object_attribute(GLuint vao) const;
  // The scene program and vertex array of device draws (material per object).
  // `shading_buffer` holds a detail::ObjectShading per object.
  void create_device_draw(GLuint& program, GLuint& vao, GLuint shading_buffer) const;
  // Device culling (renderer_device.cpp).
  void create_device();
  void destroy_device();
  void start_device_frame();
  void write_device_records(ObjectId id);
  void device_draw(int region, BackendStats& stats);
  void dispatch_cull(int phase, GLuint visibility);
  // The buffer of visibility `v`; UsageError naming `call` when there is none.
  GLuint visibility_buffer(DeviceCulling::Visibility v, const char* call) const;
  // Appends, ascending, the ids whose flag (one GLuint per object, written by
  // the cull shader) is set in `buffer`'s first `n`; waits for the device.
  void read_flags(GLuint buffer, std::size_t n, std::vector<ObjectId>& out) const;
  void draw_device_translucent();
  void stamp(int k);
  // `opaque` by material, stably (a front-to-back order within a material survives).
  void sort_opaque_by_material();
};


}  // namespace occull::gl
