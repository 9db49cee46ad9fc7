// The Vulkan renderer's resources: memory, images, render passes, the
// pipelines (made on first use), query pools and command batches.
#include "renderer_impl.hpp"

#include "occull/input_limits.hpp"
#include "../render/query_box_mesh.hpp"

#include <algorithm>
#include <cstring>

namespace occull::vk {
namespace {

// SPIR-V of src/vk/shaders, compiled by glslc at build time.
const std::uint32_t kSceneVert[] = {
#include "scene.vert.inc"
};
const std::uint32_t kSceneFrag[] = {
#include "scene.frag.inc"
};
const std::uint32_t kQueryVert[] = {
#include "query.vert.inc"
};
const std::uint32_t kEmptyFrag[] = {
#include "empty.frag.inc"
};

constexpr VkFormat kColorFormat = VK_FORMAT_R8G8B8A8_UNORM;
constexpr VkFormat kIdFormat = VK_FORMAT_R32_UINT;
constexpr VkFormat kDepthFormat = VK_FORMAT_D32_SFLOAT;

using render::QueryVertex;

std::uint32_t memory_type(const VkPhysicalDeviceMemoryProperties& props, std::uint32_t bits, VkMemoryPropertyFlags want) {
  for (std::uint32_t i = 0; i < props.memoryTypeCount; ++i)
    if ((bits & (1u << i)) && (props.memoryTypes[i].propertyFlags & want) == want) return i;
  throw VulkanUnavailable("Vulkan: no memory type with the properties occull needs");
}

VkRenderPass make_render_pass(VkDevice device, bool clear) {
  VkAttachmentDescription a[3]{};
  const VkFormat formats[3] = {kColorFormat, kIdFormat, kDepthFormat};
  for (int i = 0; i < 3; ++i) {
    const VkImageLayout layout =
        i == 2 ? VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL : VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL;
    a[i].format = formats[i];
    a[i].samples = VK_SAMPLE_COUNT_1_BIT;
    a[i].loadOp = clear ? VK_ATTACHMENT_LOAD_OP_CLEAR : VK_ATTACHMENT_LOAD_OP_LOAD;
    a[i].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
    a[i].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
    a[i].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
    a[i].initialLayout = clear ? VK_IMAGE_LAYOUT_UNDEFINED : layout;
    a[i].finalLayout = layout;
  }
  const VkAttachmentReference color_refs[2] = {{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL},
                                               {1, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL}};
  const VkAttachmentReference depth_ref{2, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
  VkSubpassDescription sub{};
  sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
  sub.colorAttachmentCount = 2;
  sub.pColorAttachments = color_refs;
  sub.pDepthStencilAttachment = &depth_ref;
  // What came before (an earlier pass's writes, a read-back's copy, a
  // conditional draw's result copy) is done before this pass touches the images.
  VkSubpassDependency dep{};
  dep.srcSubpass = VK_SUBPASS_EXTERNAL;
  dep.dstSubpass = 0;
  dep.srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT |
                     VK_PIPELINE_STAGE_TRANSFER_BIT;
  dep.srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  dep.dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                     VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
  dep.dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_READ_BIT | VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT |
                      VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
  VkRenderPassCreateInfo info{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
  info.attachmentCount = 3;
  info.pAttachments = a;
  info.subpassCount = 1;
  info.pSubpasses = &sub;
  info.dependencyCount = 1;
  info.pDependencies = &dep;
  VkRenderPass pass = VK_NULL_HANDLE;
  check(vkCreateRenderPass(device, &info, nullptr, &pass), "vkCreateRenderPass");
  return pass;
}

VkShaderModule make_module(VkDevice device, const std::uint32_t* code, std::size_t bytes) {
  VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  info.codeSize = bytes;
  info.pCode = code;
  VkShaderModule m = VK_NULL_HANDLE;
  check(vkCreateShaderModule(device, &info, nullptr, &m), "vkCreateShaderModule");
  return m;
}

}  // namespace

detail::Buffer Renderer::Impl::make_buffer(VkDeviceSize size, VkBufferUsageFlags usage) const {
  detail::Buffer b;
  b.size = std::max<VkDeviceSize>(size, 16);
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = b.size;
  info.usage = usage;
  info.sharingMode = VK_SHARING_MODE_EXCLUSIVE;
  check(vkCreateBuffer(vk.device, &info, nullptr, &b.buffer), "vkCreateBuffer");
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(vk.device, b.buffer, &req);
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex = memory_type(vk.memory, req.memoryTypeBits,
                                      VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  check(vkAllocateMemory(vk.device, &alloc, nullptr, &b.memory), "vkAllocateMemory");
  check(vkBindBufferMemory(vk.device, b.buffer, b.memory, 0), "vkBindBufferMemory");
  check(vkMapMemory(vk.device, b.memory, 0, VK_WHOLE_SIZE, 0, &b.mapped), "vkMapMemory");
  return b;
}

void Renderer::Impl::destroy(detail::Buffer& b) const {
  if (b.buffer) vkDestroyBuffer(vk.device, b.buffer, nullptr);
  if (b.memory) vkFreeMemory(vk.device, b.memory, nullptr);  // unmaps
  b = {};
}

detail::Image Renderer::Impl::make_image(VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspect) const {
  detail::Image i;
  VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
  info.imageType = VK_IMAGE_TYPE_2D;
  info.format = format;
  info.extent = {std::uint32_t(options.width), std::uint32_t(options.height), 1};
  info.mipLevels = 1;
  info.arrayLayers = 1;
  info.samples = VK_SAMPLE_COUNT_1_BIT;
  info.tiling = VK_IMAGE_TILING_OPTIMAL;
  info.usage = usage;
  info.initialLayout = VK_IMAGE_LAYOUT_UNDEFINED;
  check(vkCreateImage(vk.device, &info, nullptr, &i.image), "vkCreateImage");
  VkMemoryRequirements req;
  vkGetImageMemoryRequirements(vk.device, i.image, &req);
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex = memory_type(vk.memory, req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
  check(vkAllocateMemory(vk.device, &alloc, nullptr, &i.memory), "vkAllocateMemory");
  check(vkBindImageMemory(vk.device, i.image, i.memory, 0), "vkBindImageMemory");
  VkImageViewCreateInfo view_info{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
  view_info.image = i.image;
  view_info.viewType = VK_IMAGE_VIEW_TYPE_2D;
  view_info.format = format;
  view_info.subresourceRange = {aspect, 0, 1, 0, 1};
  check(vkCreateImageView(vk.device, &view_info, nullptr, &i.view), "vkCreateImageView");
  return i;
}

void Renderer::Impl::destroy(detail::Image& i) const {
  if (i.view) vkDestroyImageView(vk.device, i.view, nullptr);
  if (i.image) vkDestroyImage(vk.device, i.image, nullptr);
  if (i.memory) vkFreeMemory(vk.device, i.memory, nullptr);
  i = {};
}

VkQueryPool Renderer::Impl::make_query_pool(VkQueryType type, std::uint32_t count) const {
  VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  info.queryType = type;
  info.queryCount = count;
  VkQueryPool pool = VK_NULL_HANDLE;
  check(vkCreateQueryPool(vk.device, &info, nullptr, &pool), "vkCreateQueryPool");
  vkResetQueryPool(vk.device, pool, 0, count);
  return pool;
}

void Renderer::Impl::create_resources() {
  VkDevice d = vk.device;
  const VkImageUsageFlags attachment_use = VK_IMAGE_USAGE_TRANSFER_SRC_BIT;
  color = make_image(kColorFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | attachment_use, VK_IMAGE_ASPECT_COLOR_BIT);
  ids = make_image(kIdFormat, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT | attachment_use, VK_IMAGE_ASPECT_COLOR_BIT);
  depth = make_image(kDepthFormat, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT | attachment_use, VK_IMAGE_ASPECT_DEPTH_BIT);
  clear_pass = make_render_pass(d, true);
  load_pass = make_render_pass(d, false);
  const VkImageView views[3] = {color.view, ids.view, depth.view};
  VkFramebufferCreateInfo fb{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
  fb.renderPass = clear_pass;  // compatible with load_pass
  fb.attachmentCount = 3;
  fb.pAttachments = views;
  fb.width = std::uint32_t(options.width);
  fb.height = std::uint32_t(options.height);
  fb.layers = 1;
  check(vkCreateFramebuffer(d, &fb, nullptr, &framebuffer), "vkCreateFramebuffer");

  // The scene: every mesh in one vertex buffer (position, normal) and one index buffer.
  std::size_t vertex_count = 0, index_count = 0;
  for (const Mesh& m : scene.meshes()) vertex_count += m.positions.size(), index_count += m.indices.size();
  vertices = make_buffer(vertex_count * 6 * sizeof(float), VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
  indices = make_buffer(index_count * sizeof(std::uint32_t), VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
  auto* v = static_cast<float*>(vertices.mapped);
  auto* idx = static_cast<std::uint32_t*>(indices.mapped);
  std::uint32_t first_index = 0;
  std::int32_t base_vertex = 0;
  for (const Mesh& m : scene.meshes()) {
    meshes.push_back({std::uint32_t(m.indices.size()), first_index, base_vertex});
    for (std::size_t i = 0; i < m.positions.size(); ++i) {
      const float f[6] = {m.positions[i].x, m.positions[i].y, m.positions[i].z,
                          m.normals[i].x,   m.normals[i].y,   m.normals[i].z};
      std::memcpy(v, f, sizeof f);
      v += 6;
    }
    std::memcpy(idx + first_index, m.indices.data(), m.indices.size() * sizeof(std::uint32_t));
    first_index += std::uint32_t(m.indices.size());
    base_vertex += std::int32_t(m.positions.size());
  }
  object_capacity = scene.objects().size();
  for (const Material& m : scene.materials()) {
    glm::vec4 c = m.color;
    if (!m.translucent) c.a = 1.0f;
    materials.push_back({c, std::max(0, m.shading_cost)});
  }

  const std::vector<QueryVertex> mesh = render::query_box_mesh();
  query_vertices = options.query_margin_px > 0.0f ? std::uint32_t(mesh.size()) : 36;
  query_slope_px = std::max(0.0f, options.query_margin_px);
  cube = make_buffer(mesh.size() * sizeof(QueryVertex), VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
  std::memcpy(cube.mapped, mesh.data(), mesh.size() * sizeof(QueryVertex));
  uniforms = make_buffer(sizeof(detail::FrameUniforms), VK_BUFFER_USAGE_UNIFORM_BUFFER_BIT);
  readback = make_buffer(VkDeviceSize(options.width) * VkDeviceSize(options.height) * 4, VK_BUFFER_USAGE_TRANSFER_DST_BIT);

  // Set 0: the pass's uniforms; push constants: the draw's.
  VkDescriptorSetLayoutBinding binding{0, VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1,
                                       VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, nullptr};
  VkDescriptorSetLayoutCreateInfo sl{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  sl.bindingCount = 1;
  sl.pBindings = &binding;
  check(vkCreateDescriptorSetLayout(d, &sl, nullptr, &set_layout), "vkCreateDescriptorSetLayout");
  const VkPushConstantRange push{VK_SHADER_STAGE_VERTEX_BIT | VK_SHADER_STAGE_FRAGMENT_BIT, 0,
                                 sizeof(detail::DrawConstants)};
  VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  pl.setLayoutCount = 1;
  pl.pSetLayouts = &set_layout;
  pl.pushConstantRangeCount = 1;
  pl.pPushConstantRanges = &push;
  check(vkCreatePipelineLayout(d, &pl, nullptr, &pipeline_layout), "vkCreatePipelineLayout");
  const VkDescriptorPoolSize pool_size{VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER, 1};
  VkDescriptorPoolCreateInfo dp{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  dp.maxSets = 1;
  dp.poolSizeCount = 1;
  dp.pPoolSizes = &pool_size;
  check(vkCreateDescriptorPool(d, &dp, nullptr, &descriptor_pool), "vkCreateDescriptorPool");
  VkDescriptorSetAllocateInfo da{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  da.descriptorPool = descriptor_pool;
  da.descriptorSetCount = 1;
  da.pSetLayouts = &set_layout;
  check(vkAllocateDescriptorSets(d, &da, &frame_set), "vkAllocateDescriptorSets");
  const VkDescriptorBufferInfo bi{uniforms.buffer, 0, sizeof(detail::FrameUniforms)};
  VkWriteDescriptorSet w{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET};
  w.dstSet = frame_set;
  w.descriptorCount = 1;
  w.descriptorType = VK_DESCRIPTOR_TYPE_UNIFORM_BUFFER;
  w.pBufferInfo = &bi;
  vkUpdateDescriptorSets(d, 1, &w, 0, nullptr);

  modules = {make_module(d, kSceneVert, sizeof kSceneVert), make_module(d, kSceneFrag, sizeof kSceneFrag),
             make_module(d, kQueryVert, sizeof kQueryVert), make_module(d, kEmptyFrag, sizeof kEmptyFrag)};

  VkCommandPoolCreateInfo cp{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  cp.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
  cp.queueFamilyIndex = vk.queue_family;
  check(vkCreateCommandPool(d, &cp, nullptr, &command_pool), "vkCreateCommandPool");
  if (context.info().timestamp_bits > 0) timestamps = make_query_pool(VK_QUERY_TYPE_TIMESTAMP, 2);
  if (context.info().conditional_rendering && options.conditional_rendering)
    conditions = make_buffer(4 * 4096, VK_BUFFER_USAGE_CONDITIONAL_RENDERING_BIT_EXT | VK_BUFFER_USAGE_TRANSFER_DST_BIT);
}

void Renderer::Impl::destroy_resources() {
  VkDevice d = vk.device;
  if (current.cmd) {  // a frame abandoned by an exception: finish it
    end_pass();
    submit();
  }
  wait_all();
  for (auto& [key, p] : pipelines) vkDestroyPipeline(d, p, nullptr);
  for (VkShaderModule m : modules)
    if (m) vkDestroyShaderModule(d, m, nullptr);
  for (const detail::Batch& b : idle_batches) vkDestroyFence(d, b.fence, nullptr);
  if (command_pool) vkDestroyCommandPool(d, command_pool, nullptr);
  for (VkQueryPool p : query_pools) vkDestroyQueryPool(d, p, nullptr);
  for (VkQueryPool p : {truth_pool, timestamps})
    if (p) vkDestroyQueryPool(d, p, nullptr);
  if (descriptor_pool) vkDestroyDescriptorPool(d, descriptor_pool, nullptr);
  if (pipeline_layout) vkDestroyPipelineLayout(d, pipeline_layout, nullptr);
  if (set_layout) vkDestroyDescriptorSetLayout(d, set_layout, nullptr);
  for (detail::Buffer* b : {&vertices, &indices, &cube, &uniforms, &readback, &conditions}) destroy(*b);
  for (detail::Buffer& b : box_chunks) destroy(b);
  if (framebuffer) vkDestroyFramebuffer(d, framebuffer, nullptr);
  for (VkRenderPass p : {clear_pass, load_pass})
    if (p) vkDestroyRenderPass(d, p, nullptr);
  for (detail::Image* i : {&color, &ids, &depth}) destroy(*i);
}

VkPipeline Renderer::Impl::pipeline(const detail::PipelineKey& key) {
  if (auto it = pipelines.find(key); it != pipelines.end()) return it->second;
  using detail::PipelineKind;
  const bool query = key.kind == PipelineKind::query;
  VkPipelineShaderStageCreateInfo stages[2]{};
  for (auto& s : stages) s.sType = VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, s.pName = "main";
  stages[0].stage = VK_SHADER_STAGE_VERTEX_BIT;
  stages[0].module = query ? modules[2] : modules[0];
  stages[1].stage = VK_SHADER_STAGE_FRAGMENT_BIT;
  stages[1].module = query || key.kind == PipelineKind::depth_test ? modules[3] : modules[1];

  VkVertexInputBindingDescription bindings[2]{};
  VkVertexInputAttributeDescription attributes[5]{};
  VkPipelineVertexInputStateCreateInfo input{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  if (query) {
    bindings[0] = {0, sizeof(QueryVertex), VK_VERTEX_INPUT_RATE_VERTEX};
    bindings[1] = {1, sizeof(Aabb), VK_VERTEX_INPUT_RATE_INSTANCE};
    for (std::uint32_t a = 0; a < 3; ++a)
      attributes[a] = {a, 0, VK_FORMAT_R32G32B32_SFLOAT, std::uint32_t(a * sizeof(glm::vec3))};
    attributes[3] = {3, 1, VK_FORMAT_R32G32B32_SFLOAT, 0};
    attributes[4] = {4, 1, VK_FORMAT_R32G32B32_SFLOAT, 3 * sizeof(float)};
    input.vertexBindingDescriptionCount = 2;
    input.vertexAttributeDescriptionCount = 5;
  } else {
    bindings[0] = {0, 6 * sizeof(float), VK_VERTEX_INPUT_RATE_VERTEX};
    attributes[0] = {0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0};
    attributes[1] = {1, 0, VK_FORMAT_R32G32B32_SFLOAT, 3 * sizeof(float)};
    input.vertexBindingDescriptionCount = 1;
    input.vertexAttributeDescriptionCount = 2;
  }
  input.pVertexBindingDescriptions = bindings;
  input.pVertexAttributeDescriptions = attributes;
  VkPipelineInputAssemblyStateCreateInfo assembly{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  const VkViewport viewport{0.0f, 0.0f, float(options.width), float(options.height), 0.0f, 1.0f};
  const VkRect2D scissor{{0, 0}, {std::uint32_t(options.width), std::uint32_t(options.height)}};
  VkPipelineViewportStateCreateInfo vp{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  vp.viewportCount = 1;
  vp.pViewports = &viewport;
  vp.scissorCount = 1;
  vp.pScissors = &scissor;
  VkPipelineRasterizationStateCreateInfo raster{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  raster.polygonMode = VK_POLYGON_MODE_FILL;
  raster.cullMode = key.cull ? VK_CULL_MODE_BACK_BIT : VK_CULL_MODE_NONE;
  // y is not flipped (images are stored as OpenGL's, bottom row first), so
  // OpenGL's counter-clockwise front faces are clockwise in Vulkan's
  // framebuffer coordinates, whose area sign is the opposite of OpenGL's.
  raster.frontFace = VK_FRONT_FACE_CLOCKWISE;
  raster.lineWidth = 1.0f;
  if (query) {
    // As gl::Renderer's query state: depth clamping (a box crossing the near
    // plane is not clipped away) and the box pulled toward the eye by 2 depth
    // units plus query_slope_px pixels of its own slope.
    raster.depthClampEnable = VK_TRUE;
    raster.depthBiasEnable = VK_TRUE;
    const float toward_eye = key.reversed_z ? 1.0f : -1.0f;
    raster.depthBiasConstantFactor = toward_eye * 2.0f;
    raster.depthBiasSlopeFactor = toward_eye * query_slope_px;
  }
  VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineDepthStencilStateCreateInfo ds{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  ds.depthTestEnable = VK_TRUE;
  ds.depthWriteEnable = key.kind == PipelineKind::scene ? VK_TRUE : VK_FALSE;
  if (query)
    ds.depthCompareOp = key.reversed_z ? VK_COMPARE_OP_GREATER_OR_EQUAL : VK_COMPARE_OP_LESS_OR_EQUAL;
  else
    ds.depthCompareOp = key.reversed_z ? VK_COMPARE_OP_GREATER : VK_COMPARE_OP_LESS;
  VkPipelineColorBlendAttachmentState blend[2]{};
  constexpr VkColorComponentFlags rgba = VK_COLOR_COMPONENT_R_BIT | VK_COLOR_COMPONENT_G_BIT |
                                         VK_COLOR_COMPONENT_B_BIT | VK_COLOR_COMPONENT_A_BIT;
  if (key.kind == PipelineKind::scene) {
    blend[0].colorWriteMask = rgba;
    blend[1].colorWriteMask = key.ids ? VK_COLOR_COMPONENT_R_BIT : 0;
  } else if (key.kind == PipelineKind::translucent) {
    blend[0].colorWriteMask = rgba;
    blend[0].blendEnable = VK_TRUE;
    blend[0].srcColorBlendFactor = VK_BLEND_FACTOR_SRC_ALPHA;
    blend[0].dstColorBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
    blend[0].colorBlendOp = VK_BLEND_OP_ADD;
    blend[0].srcAlphaBlendFactor = VK_BLEND_FACTOR_SRC_ALPHA;
    blend[0].dstAlphaBlendFactor = VK_BLEND_FACTOR_ONE_MINUS_SRC_ALPHA;
    blend[0].alphaBlendOp = VK_BLEND_OP_ADD;
  }
  VkPipelineColorBlendStateCreateInfo cb{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  cb.attachmentCount = 2;
  cb.pAttachments = blend;

  VkGraphicsPipelineCreateInfo info{VK_STRUCTURE_TYPE_GRAPHICS_PIPELINE_CREATE_INFO};
  info.stageCount = 2;
  info.pStages = stages;
  info.pVertexInputState = &input;
  info.pInputAssemblyState = &assembly;
  info.pViewportState = &vp;
  info.pRasterizationState = &raster;
  info.pMultisampleState = &ms;
  info.pDepthStencilState = &ds;
  info.pColorBlendState = &cb;
  info.layout = pipeline_layout;
  info.renderPass = clear_pass;  // compatible with load_pass
  VkPipeline p = VK_NULL_HANDLE;
  check(vkCreateGraphicsPipelines(vk.device, VK_NULL_HANDLE, 1, &info, nullptr, &p), "vkCreateGraphicsPipelines");
  pipelines.emplace(key, p);
  return p;
}

void Renderer::Impl::begin_batch() {
  if (idle_batches.empty()) {
    detail::Batch b;
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = command_pool;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    check(vkAllocateCommandBuffers(vk.device, &ai, &b.cmd), "vkAllocateCommandBuffers");
    VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    check(vkCreateFence(vk.device, &fi, nullptr, &b.fence), "vkCreateFence");
    idle_batches.push_back(b);
  }
  current = idle_batches.back();
  idle_batches.pop_back();
  check(vkResetCommandBuffer(current.cmd, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
  check(vkBeginCommandBuffer(current.cmd, &bi), "vkBeginCommandBuffer");
  bound_pipeline = VK_NULL_HANDLE;  // a new command buffer binds nothing
  mode = Mode::none;
  bound_material = ~0u;
}

void Renderer::Impl::begin_pass(bool clear) {
  VkClearValue clears[3]{};
  clears[0].color = {{options.background.r, options.background.g, options.background.b, 1.0f}};
  clears[1].color.uint32[0] = 0;
  clears[2].depthStencil = {clip.reversed_z ? 0.0f : 1.0f, 0};
  VkRenderPassBeginInfo rp{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
  rp.renderPass = clear ? clear_pass : load_pass;
  rp.framebuffer = framebuffer;
  rp.renderArea = {{0, 0}, {std::uint32_t(options.width), std::uint32_t(options.height)}};
  rp.clearValueCount = clear ? 3 : 0;
  rp.pClearValues = clears;
  vkCmdBeginRenderPass(current.cmd, &rp, VK_SUBPASS_CONTENTS_INLINE);
  in_pass = true;
  bound_pipeline = VK_NULL_HANDLE;
  mode = Mode::none;
}

void Renderer::Impl::end_pass() {
  if (!in_pass) return;
  vkCmdEndRenderPass(current.cmd);
  in_pass = false;
}

void Renderer::Impl::submit() {
  end_pass();
  check(vkEndCommandBuffer(current.cmd), "vkEndCommandBuffer");
  VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  si.commandBufferCount = 1;
  si.pCommandBuffers = &current.cmd;
  check(vkQueueSubmit(vk.queue, 1, &si, current.fence), "vkQueueSubmit");
  pending_batches.push_back(current);
  current = {};
  ++batch_serial;
}

void Renderer::Impl::wait_all() {
  if (pending_batches.empty()) return;
  std::vector<VkFence> fences;
  for (const detail::Batch& b : pending_batches) fences.push_back(b.fence);
  check(vkWaitForFences(vk.device, std::uint32_t(fences.size()), fences.data(), VK_TRUE, UINT64_MAX), "vkWaitForFences");
  check(vkResetFences(vk.device, std::uint32_t(fences.size()), fences.data()), "vkResetFences");
  idle_batches.insert(idle_batches.end(), pending_batches.begin(), pending_batches.end());
  pending_batches.clear();
}

VkCommandBuffer Renderer::Impl::recording() {
  if (!current.cmd) begin_batch();
  if (!in_pass) begin_pass(false);
  return current.cmd;
}

Renderer::Renderer(Context& context, const Scene& scene, const RendererOptions& options)
    : impl_((limits::check_viewport(options.width, options.height, "render target"),
             std::make_unique<Impl>(context, scene, options))) {
  impl_->write_ids = options.write_ids;
  try {
    impl_->create_resources();
  } catch (...) {
    impl_->destroy_resources();
    throw;
  }
  context.check("creating the Vulkan renderer");
}

Renderer::~Renderer() {
  impl_->destroy_resources();
}

int Renderer::width() const noexcept { return impl_->options.width; }
int Renderer::height() const noexcept { return impl_->options.height; }

}  // namespace occull::vk
