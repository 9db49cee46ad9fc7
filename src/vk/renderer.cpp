// The Vulkan renderer's frame passes: drawing, occlusion queries and their
// reads (each read of a query not yet submitted submits the commands so
// far), conditional draws, the untimed truth pass and the read-backs.
#include "renderer_impl.hpp"
#include "../render/scoped_timer.hpp"

#include <glm/gtc/type_ptr.hpp>

#include <algorithm>
#include <cassert>
#include <chrono>
#include <cstring>

namespace occull::vk {
namespace {

using render::Clock;
using render::ms_since;
using render::ScopedTimer;

// The view's eye-relative projection (OpenGL clip conventions) in Vulkan's:
// depth from [-1, 1] to [0, 1] when the view uses OpenGL's range, in double
// as eye_relative_projection is; y unchanged (see vk::Renderer).
glm::mat4 vulkan_projection(const View& view) {
  glm::dmat4 p = eye_relative_projection(view);
  if (view.clip.depth == DepthRange::negative_one_to_one) {
    glm::dmat4 to_zero_one(1.0);
    to_zero_one[2][2] = 0.5;
    to_zero_one[3][2] = 0.5;
    p = to_zero_one * p;
  }
  return glm::mat4(p);
}

}  // namespace

void Renderer::Impl::split_translucent(std::span<const ObjectId> objects, std::vector<ObjectId>& translucent_out) {
  opaque.clear();
  for (ObjectId id : objects)
    (scene.material(scene.object(id).material).translucent ? translucent_out : opaque).push_back(id);
}

void Renderer::Impl::prepare_pass(const View& v, bool clear) {
  if (scene.meshes().size() > meshes.size())
    throw UsageError(fmt::format("vk::Renderer: the scene has {} meshes, {} more than when the renderer was made; "
                                 "meshes added later need a new renderer",
                                 scene.meshes().size(), scene.meshes().size() - meshes.size()));
  if (scene.objects().size() > object_capacity)
    throw UsageError(fmt::format("vk::Renderer: the scene has {} objects, {} more than when the renderer was made; "
                                 "objects added later need a new renderer (ids removed and reused are fine)",
                                 scene.objects().size(), scene.objects().size() - object_capacity));
  if (current.cmd) submit();  // a frame left without end_frame (an exception): its commands run and are dropped
  wait_all();  // the uniforms and box chunks are rewritten below and by this pass
  view = v;
  clip = v.clip;
  eye = v.eye;
  near_radius = near_plane_radius(v);
  detail::FrameUniforms u{};
  u.view_proj = vulkan_projection(v);
  u.eye = glm::vec4(v.eye, 1.0f);
  u.background = glm::vec4(options.background, 1.0f);
  u.half_viewport = {0.5f * float(options.width), 0.5f * float(options.height)};
  u.fog_distance = std::max(v.far, 1.0f);
  u.margin = query_vertices > 36 ? std::max(0.0f, options.query_margin_px) : 0.0f;
  std::memcpy(uniforms.mapped, &u, sizeof u);
  translucent.clear();
  conditional.clear();
  conditions_used = 0;
  box_chunk = 0;
  box_offset = 0;
  in_frame = true;
  begin_batch();
  if (timestamps) {
    vkResetQueryPool(vk.device, timestamps, 0, 2);
    vkCmdWriteTimestamp(current.cmd, VK_PIPELINE_STAGE_TOP_OF_PIPE_BIT, timestamps, 0);
    timed = true;
  }
  begin_pass(clear);
}

void Renderer::Impl::bind(VkPipeline p) {
  VkCommandBuffer cmd = recording();
  if (p == bound_pipeline) return;
  if (!bound_pipeline) {
    vkCmdBindDescriptorSets(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, pipeline_layout, 0, 1, &frame_set, 0, nullptr);
    bound_material = ~0u;
  }
  vkCmdBindPipeline(cmd, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
  bound_pipeline = p;
}

void Renderer::Impl::enter_render_state(BackendStats& stats) {
  VkCommandBuffer cmd = recording();  // a new batch or pass (after a submission) binds nothing
  if (mode == Mode::query) ++stats.state_changes;
  if (mode != Mode::render) {
    const VkDeviceSize zero = 0;
    vkCmdBindVertexBuffers(cmd, 0, 1, &vertices.buffer, &zero);
    vkCmdBindIndexBuffer(cmd, indices.buffer, 0, VK_INDEX_TYPE_UINT32);
  }
  mode = Mode::render;
}

void Renderer::Impl::enter_query_state(BackendStats& stats) {
  if (mode == Mode::render) ++stats.state_changes;
  mode = Mode::query;
}

void Renderer::Impl::draw_objects(std::span<const ObjectId> objects, BackendStats& stats, detail::PipelineKind kind) {
  if (objects.empty()) return;
  enter_render_state(stats);
  bind(pipeline({kind, clip.reversed_z, write_ids, options.cull_backfaces}));
  VkCommandBuffer cmd = current.cmd;
  detail::DrawConstants c{};
  for (ObjectId id : objects) {
    const Object& o = scene.object(id);
    if (o.material != bound_material) {
      bound_material = o.material;
      ++stats.material_changes;
    }
    const detail::MaterialData& m = materials[o.material];
    const detail::MeshRange& r = meshes[o.mesh];
    c.model = o.transform;
    c.color = m.color;
    c.object = id;
    c.lights = m.lights;
    vkCmdPushConstants(cmd, pipeline_layout, VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0, sizeof c, &c);
    vkCmdDrawIndexed(cmd, r.index_count, 1, r.first_index, r.base_vertex, 0);
    stats.triangles += o.triangles;
  }
  stats.draw_calls += objects.size();
  stats.objects_rendered += objects.size();
}

void Renderer::begin_frame(const View& view) {
  impl_->prepare_pass(view);
}

double Renderer::end_frame() {
  Impl& g = *impl_;
  if (!g.in_frame) throw UsageError("vk::Renderer::end_frame: no frame began (begin_frame)");
  if (!g.translucent.empty()) {
    std::sort(g.translucent.begin(), g.translucent.end(), [&](ObjectId a, ObjectId b) {
      const glm::vec3 da = g.scene.object(a).bounds.center() - g.eye;
      const glm::vec3 db = g.scene.object(b).bounds.center() - g.eye;
      return glm::dot(da, da) > glm::dot(db, db);
    });
    g.draw_objects(g.translucent, stats_, detail::PipelineKind::translucent);
    g.translucent.clear();
  }
  g.recording();  // the frame's last batch (a result read may have submitted the one before)
  g.end_pass();
  if (g.timed) vkCmdWriteTimestamp(g.current.cmd, VK_PIPELINE_STAGE_BOTTOM_OF_PIPE_BIT, g.timestamps, 1);
  g.submit();
  g.wait_all();
  g.in_frame = false;
  if (g.in_flight > 0) {  // the device is done with all of them: one read per pool
    std::vector<std::uint64_t> pairs(2 * detail::kQueriesPerPool);
    for (std::size_t pool = 0; pool < g.query_pools.size(); ++pool) {
      const VkResult r = vkGetQueryPoolResults(g.vk.device, g.query_pools[pool], 0, detail::kQueriesPerPool,
                                               pairs.size() * sizeof(std::uint64_t), pairs.data(),
                                               2 * sizeof(std::uint64_t),
                                               VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WITH_AVAILABILITY_BIT);
      if (r != VK_NOT_READY) check(r, "vkGetQueryPoolResults (the frame's queries)");
      for (std::uint32_t i = 0; i < detail::kQueriesPerPool; ++i) {
        const QueryId q = QueryId(pool * detail::kQueriesPerPool + i);
        if (q < g.query_live.size() && g.query_live[q] && pairs[2 * i + 1] != 0) g.query_known[q] = pairs[2 * i] + 1;
      }
    }
  }
  for (const Impl::ConditionalDraw& d : g.conditional) {
    std::uint64_t samples = 0;
    check(vkGetQueryPoolResults(g.vk.device, g.pool_of(d.query), Impl::index_of(d.query), 1, sizeof samples, &samples,
                                sizeof samples, VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
          "vkGetQueryPoolResults");
    if (samples == 0) stats_.conditional_skipped += d.count;
  }
  g.conditional.clear();
  double gpu_ms = 0.0;
  if (g.timed) {
    std::uint64_t stamps[2] = {0, 0};
    check(vkGetQueryPoolResults(g.vk.device, g.timestamps, 0, 2, sizeof stamps, stamps, sizeof(std::uint64_t),
                                VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
          "vkGetQueryPoolResults (timestamps)");
    const int bits = g.context.info().timestamp_bits;
    const std::uint64_t mask = bits >= 64 ? ~std::uint64_t(0) : (std::uint64_t(1) << bits) - 1;
    gpu_ms = double((stamps[1] - stamps[0]) & mask) * g.context.info().timestamp_period_ns * 1e-6;
    g.timed = false;
  }
  g.context.check("end of frame");
  return gpu_ms;
}

void Renderer::render(std::span<const ObjectId> objects) {
  Impl& g = *impl_;
  ScopedTimer timer(stats_.backend_ms);
  ++stats_.render_flushes;
  g.split_translucent(objects, g.translucent);
  std::stable_sort(g.opaque.begin(), g.opaque.end(),
                   [&](ObjectId a, ObjectId b) { return g.scene.object(a).material < g.scene.object(b).material; });
  g.draw_objects(g.opaque, stats_, detail::PipelineKind::scene);
}

bool Renderer::conditional_rendering() const { return bool(impl_->conditions.buffer); }

void Renderer::render_conditional(std::span<const ObjectId> objects, QueryId q, ConditionalWait wait) {
  (void)wait;  // Vulkan's conditional rendering always uses the result (see the header)
  Impl& g = *impl_;
  g.check_in_flight(q, "render_conditional");
  if (!g.conditions.buffer) return render(objects);
  ScopedTimer timer(stats_.backend_ms);
  ++stats_.render_flushes;
  g.split_translucent(objects, g.translucent);
  if (g.opaque.empty()) return;
  std::stable_sort(g.opaque.begin(), g.opaque.end(),
                   [&](ObjectId a, ObjectId b) { return g.scene.object(a).material < g.scene.object(b).material; });
  const std::uint32_t slots = std::uint32_t(g.conditions.size / 4);
  if (g.conditions_used == slots) return render(objects);  // out of slots this frame: draw them all
  const VkDeviceSize offset = VkDeviceSize(g.conditions_used++) * 4;
  g.conditional.push_back({q, g.opaque.size()});
  stats_.conditional_objects += g.opaque.size();
  // The result into the buffer the device reads: a copy outside the render
  // pass, then a barrier to the conditional-rendering stage, then a pass
  // that keeps the images.
  VkCommandBuffer cmd = g.recording();
  g.end_pass();
  vkCmdCopyQueryPoolResults(cmd, g.pool_of(q), Impl::index_of(q), 1, g.conditions.buffer, offset, 4,
                            VK_QUERY_RESULT_WAIT_BIT);
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_CONDITIONAL_RENDERING_READ_BIT_EXT;
  vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_CONDITIONAL_RENDERING_BIT_EXT, 0, 1,
                       &barrier, 0, nullptr, 0, nullptr);
  g.begin_pass(false);
  ++stats_.state_changes;  // a pass ended and began: the cost of acting on a result on the device
  VkConditionalRenderingBeginInfoEXT ci{VK_STRUCTURE_TYPE_CONDITIONAL_RENDERING_BEGIN_INFO_EXT};
  ci.buffer = g.conditions.buffer;
  ci.offset = offset;
  g.enter_render_state(stats_);
  g.bind(g.pipeline({detail::PipelineKind::scene, g.clip.reversed_z, g.write_ids, g.options.cull_backfaces}));
  g.vk.begin_conditional(cmd, &ci);
  g.draw_objects(g.opaque, stats_, detail::PipelineKind::scene);
  g.vk.end_conditional(cmd);
}

QueryId Renderer::issue_query(std::span<const Aabb> boxes) {
  Impl& g = *impl_;
  assert(!boxes.empty());
  ScopedTimer timer(stats_.backend_ms);
  g.enter_query_state(stats_);
  QueryId q;
  if (g.free_queries.empty()) {
    q = QueryId(g.query_live.size());
    if (q % detail::kQueriesPerPool == 0)
      g.query_pools.push_back(g.make_query_pool(VK_QUERY_TYPE_OCCLUSION, detail::kQueriesPerPool));
    g.query_live.push_back(0);
    g.query_batch.push_back(0);
    g.query_known.push_back(0);
  } else {
    q = g.free_queries.back();
    g.free_queries.pop_back();
    vkResetQueryPool(g.vk.device, g.pool_of(q), Impl::index_of(q), 1);  // read, so the device is done with it
  }
  ++g.in_flight;
  g.query_live[q] = 1;
  g.query_known[q] = 0;
  g.query_batch[q] = g.batch_serial;
  // A box around the eye shows only back faces: both sides for it.
  bool around_eye = false;
  for (const Aabb& b : boxes) around_eye = around_eye || b.grown(g.near_radius).contains(g.eye);
  g.bind(g.pipeline({detail::PipelineKind::query, g.clip.reversed_z, false, !around_eye}));
  VkCommandBuffer cmd = g.current.cmd;
  const VkDeviceSize zero = 0;
  vkCmdBindVertexBuffers(cmd, 0, 1, &g.cube.buffer, &zero);
  vkCmdBeginQuery(cmd, g.pool_of(q), Impl::index_of(q), VK_QUERY_CONTROL_PRECISE_BIT);
  std::size_t done = 0;
  VkBuffer bound_chunk = VK_NULL_HANDLE;
  while (done < boxes.size()) {
    if (g.box_offset == detail::kBoxChunk) ++g.box_chunk, g.box_offset = 0;
    if (g.box_chunk == g.box_chunks.size())
      g.box_chunks.push_back(g.make_buffer(detail::kBoxChunk * sizeof(Aabb), VK_BUFFER_USAGE_VERTEX_BUFFER_BIT));
    const detail::Buffer& chunk = g.box_chunks[g.box_chunk];
    const auto n = std::uint32_t(std::min<std::size_t>(boxes.size() - done, detail::kBoxChunk - g.box_offset));
    std::memcpy(static_cast<Aabb*>(chunk.mapped) + g.box_offset, boxes.data() + done, n * sizeof(Aabb));
    if (chunk.buffer != bound_chunk) {
      vkCmdBindVertexBuffers(cmd, 1, 1, &chunk.buffer, &zero);
      bound_chunk = chunk.buffer;
    }
    vkCmdDraw(cmd, g.query_vertices, n, 0, g.box_offset);
    g.box_offset += n;
    done += n;
  }
  vkCmdEndQuery(cmd, g.pool_of(q), Impl::index_of(q));
  ++stats_.queries;
  stats_.query_boxes += boxes.size();
  return q;
}

bool Renderer::result_available(QueryId q) {
  Impl& g = *impl_;
  g.check_in_flight(q, "result_available");
  ScopedTimer timer(stats_.backend_ms);
  if (g.query_known[q]) return true;
  if (g.query_batch[q] == g.batch_serial && g.current.cmd) {  // recorded, not submitted: hand it to the device
    g.submit();
    ++stats_.flushes;
  }
  std::uint64_t samples = 0;
  const VkResult r = vkGetQueryPoolResults(g.vk.device, g.pool_of(q), Impl::index_of(q), 1, sizeof samples, &samples,
                                           sizeof samples, VK_QUERY_RESULT_64_BIT);
  if (r != VK_NOT_READY) check(r, "vkGetQueryPoolResults");
  return r == VK_SUCCESS;
}

std::uint64_t Renderer::result(QueryId q) {
  Impl& g = *impl_;
  g.check_in_flight(q, "result");
  const auto t0 = Clock::now();
  std::uint64_t samples = 0;
  if (g.query_known[q]) {
    samples = g.query_known[q] - 1;
  } else {
    if (g.query_batch[q] == g.batch_serial && g.current.cmd) {
      g.submit();
      ++stats_.flushes;
    }
    VkResult r = vkGetQueryPoolResults(g.vk.device, g.pool_of(q), Impl::index_of(q), 1, sizeof samples, &samples,
                                       sizeof samples, VK_QUERY_RESULT_64_BIT);
    if (r == VK_NOT_READY) {
      ++stats_.blocking_waits;
      r = vkGetQueryPoolResults(g.vk.device, g.pool_of(q), Impl::index_of(q), 1, sizeof samples, &samples,
                                sizeof samples, VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT);
    }
    check(r, "vkGetQueryPoolResults");
  }
  const double ms = ms_since(t0);
  stats_.wait_ms += ms;
  stats_.backend_ms += ms;
  std::erase_if(g.conditional, [&](const Impl::ConditionalDraw& d) {
    if (d.query != q) return false;
    if (samples == 0) stats_.conditional_skipped += d.count;
    return true;
  });
  g.free_queries.push_back(q);
  g.query_live[q] = 0;
  --g.in_flight;
  return samples;
}

void Renderer::flush() {
  Impl& g = *impl_;
  ScopedTimer timer(stats_.backend_ms);
  if (!g.current.cmd) return;
  g.submit();
  ++stats_.flushes;
}

std::uint64_t Renderer::unread_result(QueryId q) {
  Impl& g = *impl_;
  g.check_in_flight(q, "unread_result");
  if (g.query_known[q]) return g.query_known[q] - 1;
  if (g.query_batch[q] == g.batch_serial && g.current.cmd) g.submit();
  std::uint64_t samples = 0;
  check(vkGetQueryPoolResults(g.vk.device, g.pool_of(q), Impl::index_of(q), 1, sizeof samples, &samples, sizeof samples,
                              VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
        "vkGetQueryPoolResults");
  return samples;
}

void Renderer::set_write_ids(bool on) { impl_->write_ids = on; }
std::size_t Renderer::queries_in_flight() const noexcept { return impl_->in_flight; }

std::vector<Renderer::ObjectPixels> Renderer::visible_pixels(const View& view, std::span<const ObjectId> objects,
                                                             PassImages* images) {
  Impl& g = *impl_;
  const BackendStats saved_stats = stats_;
  const bool saved_ids = g.write_ids;
  g.write_ids = true;
  begin_frame(view);
  std::vector<ObjectId> translucent;
  g.split_translucent(objects, translucent);  // in the order given
  g.draw_objects(g.opaque, stats_, detail::PipelineKind::scene);
  // Translucent objects: samples passing the depth test of the opaque ones,
  // one query each, read after the frame.
  if (!translucent.empty()) {
    if (translucent.size() > g.truth_capacity) {
      if (g.truth_pool) {
        g.submit();  // nothing recorded may use the old pool once it goes
        g.wait_all();
        vkDestroyQueryPool(g.vk.device, g.truth_pool, nullptr);
      }
      g.truth_capacity = std::uint32_t(std::max<std::size_t>(translucent.size(), 64));
      g.truth_pool = g.make_query_pool(VK_QUERY_TYPE_OCCLUSION, g.truth_capacity);
    } else {
      vkResetQueryPool(g.vk.device, g.truth_pool, 0, g.truth_capacity);
    }
    for (std::size_t i = 0; i < translucent.size(); ++i) {
      VkCommandBuffer cmd = g.recording();
      vkCmdBeginQuery(cmd, g.truth_pool, std::uint32_t(i), VK_QUERY_CONTROL_PRECISE_BIT);
      g.draw_objects(std::span<const ObjectId>(&translucent[i], 1), stats_, detail::PipelineKind::depth_test);
      vkCmdEndQuery(cmd, g.truth_pool, std::uint32_t(i));
    }
  }
  end_frame();
  std::vector<std::uint64_t> samples(translucent.size());
  if (!samples.empty())
    check(vkGetQueryPoolResults(g.vk.device, g.truth_pool, 0, std::uint32_t(samples.size()),
                                samples.size() * sizeof(std::uint64_t), samples.data(), sizeof(std::uint64_t),
                                VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
          "vkGetQueryPoolResults (truth)");
  std::vector<std::uint32_t> counts(g.scene.objects().size(), 0);
  std::vector<std::uint32_t> id_image = read_ids();
  for (std::uint32_t v : id_image)
    if (v != 0 && v <= counts.size()) ++counts[v - 1];
  if (images) {
    images->ids = std::move(id_image);
    images->depth = read_depth();
  }
  for (std::size_t i = 0; i < translucent.size(); ++i)
    counts[translucent[i]] = std::uint32_t(std::min<std::uint64_t>(samples[i], 0xffffffffu));
  std::vector<ObjectPixels> visible;
  for (ObjectId id = 0; id < counts.size(); ++id)
    if (counts[id] > 0) visible.push_back({id, counts[id]});
  g.write_ids = saved_ids;
  stats_ = saved_stats;
  return visible;
}

std::uint64_t Renderer::samples_in_front(const View& view, std::span<const ObjectId> objects) {
  Impl& g = *impl_;
  const BackendStats saved_stats = stats_;
  g.prepare_pass(view, false);
  if (!g.truth_pool) {
    g.truth_capacity = 64;
    g.truth_pool = g.make_query_pool(VK_QUERY_TYPE_OCCLUSION, g.truth_capacity);
  } else {
    vkResetQueryPool(g.vk.device, g.truth_pool, 0, 1);
  }
  VkCommandBuffer cmd = g.recording();
  vkCmdBeginQuery(cmd, g.truth_pool, 0, VK_QUERY_CONTROL_PRECISE_BIT);
  g.draw_objects(objects, stats_, detail::PipelineKind::depth_test);
  vkCmdEndQuery(cmd, g.truth_pool, 0);
  g.timed = false;  // an untimed pass: its start stamp is never read
  g.submit();
  g.wait_all();
  g.in_frame = false;
  std::uint64_t samples = 0;
  check(vkGetQueryPoolResults(g.vk.device, g.truth_pool, 0, 1, sizeof samples, &samples, sizeof samples,
                              VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
        "vkGetQueryPoolResults (samples in front)");
  stats_ = saved_stats;
  g.context.check("counting samples in front of the depth image");
  return samples;
}

Renderer::Resources Renderer::resources() const {
  const Impl& g = *impl_;
  Resources r;
  r.queries = g.query_pools.size() * detail::kQueriesPerPool;
  r.queries_free = r.queries - g.in_flight;
  const auto add = [&](const detail::Buffer& b) {
    if (!b.buffer) return;
    ++r.buffers;
    r.buffer_bytes += std::int64_t(b.size);
  };
  for (const detail::Buffer* b : {&g.vertices, &g.indices, &g.cube, &g.uniforms, &g.readback, &g.conditions}) add(*b);
  for (const detail::Buffer& b : g.box_chunks) add(b);
  return r;
}

std::vector<std::uint8_t> Renderer::Impl::read_image(const detail::Image& image, VkImageAspectFlags aspect,
                                                     VkImageLayout layout, VkPipelineStageFlags stage,
                                                     VkAccessFlags access) {
  if (in_frame) throw UsageError("vk::Renderer: images are read after end_frame(), not during a frame");
  run_once([&](VkCommandBuffer cmd) {
    VkImageMemoryBarrier b{VK_STRUCTURE_TYPE_IMAGE_MEMORY_BARRIER};
    b.srcAccessMask = access;
    b.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    b.oldLayout = layout;
    b.newLayout = VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL;
    b.srcQueueFamilyIndex = b.dstQueueFamilyIndex = VK_QUEUE_FAMILY_IGNORED;
    b.image = image.image;
    b.subresourceRange = {aspect, 0, 1, 0, 1};
    vkCmdPipelineBarrier(cmd, stage, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0, nullptr, 0, nullptr, 1, &b);
    VkBufferImageCopy copy{};
    copy.imageSubresource = {aspect, 0, 0, 1};
    copy.imageExtent = {std::uint32_t(options.width), std::uint32_t(options.height), 1};
    vkCmdCopyImageToBuffer(cmd, image.image, VK_IMAGE_LAYOUT_TRANSFER_SRC_OPTIMAL, readback.buffer, 1, &copy);
    std::swap(b.oldLayout, b.newLayout);
    b.srcAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    b.dstAccessMask = access;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, stage, 0, 0, nullptr, 0, nullptr, 1, &b);
    VkMemoryBarrier host{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    host.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    host.dstAccessMask = VK_ACCESS_HOST_READ_BIT;
    vkCmdPipelineBarrier(cmd, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_HOST_BIT, 0, 1, &host, 0, nullptr, 0,
                         nullptr);
  });
  const auto* p = static_cast<const std::uint8_t*>(readback.mapped);
  return {p, p + std::size_t(options.width) * std::size_t(options.height) * 4};
}

std::vector<std::uint32_t> Renderer::read_ids() {
  Impl& g = *impl_;
  const std::vector<std::uint8_t> bytes =
      g.read_image(g.ids, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                   VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
  std::vector<std::uint32_t> ids(bytes.size() / 4);
  std::memcpy(ids.data(), bytes.data(), bytes.size());
  g.context.check("reading the id image");
  return ids;
}

std::vector<float> Renderer::read_depth() {
  Impl& g = *impl_;
  const std::vector<std::uint8_t> bytes =
      g.read_image(g.depth, VK_IMAGE_ASPECT_DEPTH_BIT, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
                   VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT, VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT);
  std::vector<float> depth(bytes.size() / 4);
  std::memcpy(depth.data(), bytes.data(), bytes.size());
  if (g.clip.reversed_z)
    for (float& d : depth) d = 1.0f - d;
  g.context.check("reading the depth image");
  return depth;
}

std::vector<std::uint8_t> Renderer::read_rgba() {
  Impl& g = *impl_;
  const std::vector<std::uint8_t> bottom_first =
      g.read_image(g.color, VK_IMAGE_ASPECT_COLOR_BIT, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL,
                   VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT, VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT);
  const std::size_t row = std::size_t(g.options.width) * 4;
  std::vector<std::uint8_t> top_first(bottom_first.size());
  for (int y = 0; y < g.options.height; ++y)
    std::memcpy(top_first.data() + std::size_t(y) * row,
                bottom_first.data() + std::size_t(g.options.height - 1 - y) * row, row);
  g.context.check("reading the colour image");
  return top_first;
}

}  // namespace occull::vk
