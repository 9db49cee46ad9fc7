// The Vulkan renderer's state, shared by its files by job:
// renderer_resources.cpp (memory, images, pipelines, the command batches)
// and renderer.cpp (the frame passes, queries, the truth pass, read-backs).
// Internal to occull_vk.
#pragma once

#include "occull/vk/renderer.hpp"

#include "vk.hpp"
#include "occull/error.hpp"

#include <fmt/format.h>

#include <array>
#include <map>
#include <vector>

namespace occull::vk {
namespace detail {

// A buffer in host-visible, coherent memory, mapped for its whole life.
struct Buffer {
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  void* mapped = nullptr;
  VkDeviceSize size = 0;
};

struct Image {
  VkImage image = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkImageView view = VK_NULL_HANDLE;
};

// Where mesh m lies in the shared vertex and index buffers.
struct MeshRange {
  std::uint32_t index_count = 0, first_index = 0;
  std::int32_t base_vertex = 0;
};

// The pass's uniform block (shaders/frame.glsl), std140.
struct FrameUniforms {
  glm::mat4 view_proj;
  glm::vec4 eye;
  glm::vec4 background;
  glm::vec2 half_viewport;
  float fog_distance;
  float margin;
};

// The push constants of a scene draw (shaders/scene.vert), 88 bytes.
struct DrawConstants {
  glm::mat4 model;
  glm::vec4 color;
  std::uint32_t object;
  std::int32_t lights;
};

struct MaterialData {
  glm::vec4 color;  // alpha 1 for opaque materials
  std::int32_t lights = 0;
};

// The pipelines, made on first use by what differs between them.
enum class PipelineKind : std::uint8_t {
  scene,        // opaque objects: depth test less, writes colour, depth (and ids)
  translucent,  // blended over, no depth or id writes
  depth_test,   // scene geometry writing nothing (the truth's sample counts)
  query,        // query boxes: writing nothing, depth less-or-equal, clamped, offset toward the eye
};
struct PipelineKey {
  PipelineKind kind = PipelineKind::scene;
  bool reversed_z = false;
  bool ids = true;    // scene: writes the id image
  bool cull = true;   // back faces culled
  friend auto operator<=>(const PipelineKey&, const PipelineKey&) = default;
};

// A command buffer and the fence of its submission.
struct Batch {
  VkCommandBuffer cmd = VK_NULL_HANDLE;
  VkFence fence = VK_NULL_HANDLE;
};

// Query boxes per chunk of the box buffer; more chunks are made as a frame needs them.
constexpr std::uint32_t kBoxChunk = 1 << 13;
// Queries per pool; more pools are made as needed.
constexpr std::uint32_t kQueriesPerPool = 1024;

}  // namespace detail

struct Renderer::Impl {
  Context& context;
  const Context::Handles& vk;
  const Scene& scene;
  RendererOptions options;

  VkRenderPass clear_pass = VK_NULL_HANDLE;  // clears the images (a frame's start)
  VkRenderPass load_pass = VK_NULL_HANDLE;   // keeps them (after a submission or a copy inside a frame)
  detail::Image color, ids, depth;
  VkFramebuffer framebuffer = VK_NULL_HANDLE;
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  VkPipelineLayout pipeline_layout = VK_NULL_HANDLE;
  VkDescriptorPool descriptor_pool = VK_NULL_HANDLE;
  VkDescriptorSet frame_set = VK_NULL_HANDLE;
  std::array<VkShaderModule, 4> modules{};  // scene.vert, scene.frag, query.vert, empty.frag
  std::map<detail::PipelineKey, VkPipeline> pipelines;

  detail::Buffer vertices, indices, cube, uniforms, readback, conditions;
  std::vector<detail::Buffer> box_chunks;
  std::size_t box_chunk = 0;
  std::uint32_t box_offset = 0;  // in box_chunks[box_chunk]
  std::uint32_t query_vertices = 36;
  float query_slope_px = 0.0f;
  std::vector<detail::MeshRange> meshes;
  std::vector<detail::MaterialData> materials;
  std::size_t object_capacity = 0;

  VkCommandPool command_pool = VK_NULL_HANDLE;
  std::vector<detail::Batch> idle_batches;     // ready to record
  std::vector<detail::Batch> pending_batches;  // submitted, not yet known done
  detail::Batch current{};                     // recording; cmd null when none
  bool in_pass = false;                        // current is inside a render pass
  bool in_frame = false;                       // between prepare_pass and the pass's end (end_frame)
  std::uint64_t batch_serial = 1;              // serial of `current` (the next one to submit)

  // Queries: QueryId q is query q % kQueriesPerPool of pool q / kQueriesPerPool.
  std::vector<VkQueryPool> query_pools;
  std::vector<std::uint64_t> query_batch;  // QueryId -> batch_serial it was recorded in
  std::vector<std::uint8_t> query_live;    // QueryId -> issued and not yet read
  // QueryId -> its result + 1 once known, 0 until then: end_frame reads the
  // results of every query in flight in one call per pool (results of
  // earlier frames, as engines read them, then cost no call of their own).
  std::vector<std::uint64_t> query_known;
  std::vector<QueryId> free_queries;
  std::size_t in_flight = 0;
  VkQueryPool truth_pool = VK_NULL_HANDLE;  // the truth pass's translucent tests
  std::uint32_t truth_capacity = 0;
  VkQueryPool timestamps = VK_NULL_HANDLE;  // frame start and end
  bool timed = false;                       // this frame wrote its start stamp

  // The pass in recording.
  View view;
  ClipSpace clip;
  glm::vec3 eye{0.0f};
  float near_radius = 0.0f;
  bool write_ids = true;
  VkPipeline bound_pipeline = VK_NULL_HANDLE;
  enum class Mode { none, render, query } mode = Mode::none;
  MaterialId bound_material = ~0u;
  std::vector<ObjectId> opaque, translucent;
  struct ConditionalDraw {
    QueryId query;
    std::size_t count;
  };
  std::vector<ConditionalDraw> conditional;
  std::uint32_t conditions_used = 0;  // 4-byte slots of `conditions` this frame

  Impl(Context& c, const Scene& s, const RendererOptions& o) : context(c), vk(c.handles()), scene(s), options(o) {}

  void check_in_flight(QueryId q, const char* call) const {
    if (q >= query_live.size() || !query_live[q])
      throw UsageError(fmt::format("vk::Renderer::{}: query {} is not in flight ({})", call, q,
                                   q >= query_live.size() ? "never issued by this renderer"
                                                          : "already read, or issued by another renderer"));
  }
  [[nodiscard]] VkQueryPool pool_of(QueryId q) const { return query_pools[q / detail::kQueriesPerPool]; }
  [[nodiscard]] static std::uint32_t index_of(QueryId q) { return q % detail::kQueriesPerPool; }

  // renderer_resources.cpp
  void create_resources();
  void destroy_resources();
  [[nodiscard]] detail::Buffer make_buffer(VkDeviceSize size, VkBufferUsageFlags usage) const;
  void destroy(detail::Buffer& b) const;
  [[nodiscard]] detail::Image make_image(VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspect) const;
  void destroy(detail::Image& i) const;
  [[nodiscard]] VkPipeline pipeline(const detail::PipelineKey& key);
  [[nodiscard]] VkQueryPool make_query_pool(VkQueryType type, std::uint32_t count) const;

  // Command batches: recording starts a batch (and, in a frame, a render
  // pass that keeps the images); submit() ends and submits it; wait_all()
  // waits for every submitted one.
  void begin_batch();
  void begin_pass(bool clear);
  void end_pass();
  void submit();
  void wait_all();
  // The batch recording inside a render pass (begun if there is none).
  VkCommandBuffer recording();
  // One command buffer run to completion outside any frame (read-backs).
  template <class Record>
  void run_once(Record&& record);

  // renderer.cpp
  // Waits for the last pass, sets the uniforms and begins recording a pass
  // that clears the images, or keeps them (`clear` false).
  void prepare_pass(const View& v, bool clear = true);
  void enter_render_state(BackendStats& stats);
  void enter_query_state(BackendStats& stats);
  void bind(VkPipeline p);
  void draw_objects(std::span<const ObjectId> objects, BackendStats& stats, detail::PipelineKind kind);
  void split_translucent(std::span<const ObjectId> objects, std::vector<ObjectId>& translucent_out);
  std::vector<std::uint8_t> read_image(const detail::Image& image, VkImageAspectFlags aspect, VkImageLayout layout,
                                       VkPipelineStageFlags stage, VkAccessFlags access);
};

template <class Record>
void Renderer::Impl::run_once(Record&& record) {
  begin_batch();
  record(current.cmd);
  submit();
  wait_all();
}

}  // namespace occull::vk
