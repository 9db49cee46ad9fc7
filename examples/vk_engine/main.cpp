// A small engine on Vulkan that culls with occull: its own device, images,
// pipelines, buffers and draw loop (not occull's renderer), its crates moved
// by its game logic every frame, a reversed-Z view with an infinite far plane
// and y flipped by the viewport, as Vulkan engines render, and CHC++ (or
// any culler, --algo) deciding what to draw.
//
// Its Backend says what its reads cost (ResultReads::after_submit): a result
// read in the frame that issued its query ends the render pass, submits the
// commands so far and waits; the next draws begin a pass that keeps the images.
// With --algo chc:reads=earlier the culler reads only answers of earlier
// frames and nothing is submitted mid-frame.
//
// It checks itself: after every frame, occull's ground truth (an id-image pass
// of occull::vk::Renderer over a copy of the scene with vertices, on a device
// of its own) lists the objects with a visible pixel, and each must be among
// those the culler drew — for a culler that is not conservative, what it left
// out is counted as popping. The validation layer is on (--validation off
// turns it off); any error it reports fails the run. Exit 0: no object missed
// by a conservative culler, no validation error, no query left in flight;
// 1: otherwise; 2: bad arguments; 3: no usable Vulkan.
//
//   occull_example_vk_engine [--algo SPEC] [--frames N] [--size WxH] [--validation on|off]
//                            [--no-mid-frame-submissions]
#include <occull/configs.hpp>
#include <occull/culler.hpp>
#include <occull/error.hpp>
#include <occull/vk/context.hpp>
#include <occull/vk/renderer.hpp>

#include <vulkan/vulkan.h>

#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <stdexcept>
#include <string>
#include <vector>

namespace {

const std::uint32_t kDrawVert[] = {
#include "draw.vert.inc"
};
const std::uint32_t kDrawFrag[] = {
#include "draw.frag.inc"
};
const std::uint32_t kBoxVert[] = {
#include "box.vert.inc"
};
const std::uint32_t kBoxFrag[] = {
#include "box.frag.inc"
};

void vk_check(VkResult r, const char* what) {
  if (r != VK_SUCCESS) throw std::runtime_error(std::string(what) + " failed (VkResult " + std::to_string(int(r)) + ")");
}

// ---------------------------------------------------------------------------
// The engine's device: instance, device, queue, and what it counts of the
// validation layer's reports.

int g_validation_errors = 0;

VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                          VkDebugUtilsMessageTypeFlagsEXT, const VkDebugUtilsMessengerCallbackDataEXT* d,
                                          void*) {
  if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
    ++g_validation_errors;
    std::fprintf(stderr, "validation: %s\n", d->pMessage);
  }
  return VK_FALSE;
}

struct Device {
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  std::uint32_t family = 0;
  VkPhysicalDeviceMemoryProperties memory{};

  explicit Device(bool validation) {
    VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
    app.pApplicationName = "occull example engine";
    app.apiVersion = VK_API_VERSION_1_2;
    const char* layer = "VK_LAYER_KHRONOS_validation";
    const char* extension = VK_EXT_DEBUG_UTILS_EXTENSION_NAME;
    VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
    ici.pApplicationInfo = &app;
    if (validation) {
      ici.enabledLayerCount = 1;
      ici.ppEnabledLayerNames = &layer;
      ici.enabledExtensionCount = 1;
      ici.ppEnabledExtensionNames = &extension;
    }
    if (vkCreateInstance(&ici, nullptr, &instance) != VK_SUCCESS)
      throw occull::VulkanUnavailable("no Vulkan instance (with the validation layer, when asked)");
    if (validation) {
      VkDebugUtilsMessengerCreateInfoEXT m{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
      m.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
      m.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
      m.pfnUserCallback = on_message;
      auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
      vk_check(create(instance, &m, nullptr, &messenger), "vkCreateDebugUtilsMessengerEXT");
    }
    std::uint32_t n = 1;
    if (vkEnumeratePhysicalDevices(instance, &n, &physical) < 0 || n == 0)
      throw occull::VulkanUnavailable("no Vulkan device (Debian: mesa-vulkan-drivers)");
    vkGetPhysicalDeviceMemoryProperties(physical, &memory);
    std::uint32_t families = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &families, nullptr);
    std::vector<VkQueueFamilyProperties> props(families);
    vkGetPhysicalDeviceQueueFamilyProperties(physical, &families, props.data());
    while (family < families && !(props[family].queueFlags & VK_QUEUE_GRAPHICS_BIT)) ++family;
    if (family == families) throw occull::VulkanUnavailable("no graphics queue");
    const float priority = 1.0f;
    VkDeviceQueueCreateInfo q{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
    q.queueFamilyIndex = family;
    q.queueCount = 1;
    q.pQueuePriorities = &priority;
    VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
    f12.hostQueryReset = VK_TRUE;  // queries reset from the CPU, outside any command buffer
    VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
    features.pNext = &f12;
    features.features.occlusionQueryPrecise = VK_TRUE;  // sample counts, not 0/1
    features.features.depthClamp = VK_TRUE;             // a box crossing the near plane still counts
    VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
    dci.pNext = &features;
    dci.queueCreateInfoCount = 1;
    dci.pQueueCreateInfos = &q;
    if (vkCreateDevice(physical, &dci, nullptr, &device) != VK_SUCCESS)
      throw occull::VulkanUnavailable("the device lacks precise occlusion queries, depth clamping or host query reset");
    vkGetDeviceQueue(device, family, 0, &queue);
  }
  ~Device() {
    vkDestroyDevice(device, nullptr);
    if (messenger) {
      auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
          vkGetInstanceProcAddr(instance, "vkDestroyDebugUtilsMessengerEXT"));
      destroy(instance, messenger, nullptr);
    }
    vkDestroyInstance(instance, nullptr);
  }
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;

  [[nodiscard]] std::uint32_t memory_type(std::uint32_t bits, VkMemoryPropertyFlags want) const {
    for (std::uint32_t i = 0; i < memory.memoryTypeCount; ++i)
      if ((bits & (1u << i)) && (memory.memoryTypes[i].propertyFlags & want) == want) return i;
    throw std::runtime_error("no suitable memory type");
  }
};

// A buffer in host-visible memory, filled once; freed with its owner.
struct Buffer {
  const Device& d;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  explicit Buffer(const Device& device) : d(device) {}
  ~Buffer() {
    vkDestroyBuffer(d.device, buffer, nullptr);
    vkFreeMemory(d.device, memory, nullptr);
  }
  Buffer(const Buffer&) = delete;
  Buffer& operator=(const Buffer&) = delete;
};

void fill_buffer(Buffer& b, const void* data, std::size_t bytes, VkBufferUsageFlags usage) {
  const Device& d = b.d;
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = bytes;
  info.usage = usage;
  vk_check(vkCreateBuffer(d.device, &info, nullptr, &b.buffer), "vkCreateBuffer");
  VkMemoryRequirements req;
  vkGetBufferMemoryRequirements(d.device, b.buffer, &req);
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = req.size;
  alloc.memoryTypeIndex =
      d.memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT);
  vk_check(vkAllocateMemory(d.device, &alloc, nullptr, &b.memory), "vkAllocateMemory");
  vk_check(vkBindBufferMemory(d.device, b.buffer, b.memory, 0), "vkBindBufferMemory");
  void* p = nullptr;
  vk_check(vkMapMemory(d.device, b.memory, 0, VK_WHOLE_SIZE, 0, &p), "vkMapMemory");
  std::memcpy(p, data, bytes);
  vkUnmapMemory(d.device, b.memory);
}

// ---------------------------------------------------------------------------
// The engine's data: meshes on the device, objects with a model matrix.

struct CpuMesh {
  std::vector<glm::vec3> positions, normals;
  std::vector<std::uint32_t> indices;
};

// A unit cube [-0.5, 0.5]^3, each face a grid of 8 x 8 quads (outward, counter-clockwise).
CpuMesh make_cube() {
  CpuMesh m;
  const auto face = [&](glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d) {
    const glm::vec3 n = glm::normalize(glm::cross(b - a, c - a));
    constexpr std::uint32_t kGrid = 8;
    const auto base = std::uint32_t(m.positions.size());
    for (std::uint32_t i = 0; i <= kGrid; ++i)
      for (std::uint32_t j = 0; j <= kGrid; ++j) {
        const float u = float(i) / kGrid, v = float(j) / kGrid;
        m.positions.push_back(glm::mix(glm::mix(a, b, v), glm::mix(d, c, v), u));
        m.normals.push_back(n);
      }
    for (std::uint32_t i = 0; i < kGrid; ++i)
      for (std::uint32_t j = 0; j < kGrid; ++j) {
        const std::uint32_t k = base + i * (kGrid + 1) + j, up = k + 1, next = k + kGrid + 1;
        m.indices.insert(m.indices.end(), {k, up, next + 1, k, next + 1, next});
      }
  };
  const float h = 0.5f;
  face({-h, -h, h}, {-h, h, h}, {h, h, h}, {h, -h, h});      // +z
  face({h, -h, -h}, {h, h, -h}, {-h, h, -h}, {-h, -h, -h});  // -z
  face({h, -h, h}, {h, h, h}, {h, h, -h}, {h, -h, -h});      // +x
  face({-h, -h, -h}, {-h, h, -h}, {-h, h, h}, {-h, -h, h});  // -x
  face({-h, h, h}, {-h, h, -h}, {h, h, -h}, {h, h, h});      // +y
  face({-h, -h, -h}, {-h, -h, h}, {h, -h, h}, {h, -h, -h});  // -y
  return m;
}

// ---------------------------------------------------------------------------
// The engine's frame: a colour and a depth image, a render pass that clears
// them and one that keeps them (after a submission inside the frame).
class Frame {
 public:
  Frame(const Device& d, int width, int height) : d_(d), width_(width), height_(height) {
    make_image(VK_FORMAT_R8G8B8A8_UNORM, VK_IMAGE_USAGE_COLOR_ATTACHMENT_BIT, VK_IMAGE_ASPECT_COLOR_BIT, 0);
    make_image(VK_FORMAT_D32_SFLOAT, VK_IMAGE_USAGE_DEPTH_STENCIL_ATTACHMENT_BIT, VK_IMAGE_ASPECT_DEPTH_BIT, 1);
    for (int keep = 0; keep < 2; ++keep) {
      VkAttachmentDescription a[2]{};
      for (int i = 0; i < 2; ++i) {
        const VkImageLayout layout =
            i == 0 ? VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL : VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL;
        a[i].format = i == 0 ? VK_FORMAT_R8G8B8A8_UNORM : VK_FORMAT_D32_SFLOAT;
        a[i].samples = VK_SAMPLE_COUNT_1_BIT;
        a[i].loadOp = keep ? VK_ATTACHMENT_LOAD_OP_LOAD : VK_ATTACHMENT_LOAD_OP_CLEAR;
        a[i].storeOp = VK_ATTACHMENT_STORE_OP_STORE;
        a[i].stencilLoadOp = VK_ATTACHMENT_LOAD_OP_DONT_CARE;
        a[i].stencilStoreOp = VK_ATTACHMENT_STORE_OP_DONT_CARE;
        a[i].initialLayout = keep ? layout : VK_IMAGE_LAYOUT_UNDEFINED;
        a[i].finalLayout = layout;
      }
      const VkAttachmentReference colour{0, VK_IMAGE_LAYOUT_COLOR_ATTACHMENT_OPTIMAL};
      const VkAttachmentReference depth{1, VK_IMAGE_LAYOUT_DEPTH_STENCIL_ATTACHMENT_OPTIMAL};
      VkSubpassDescription sub{};
      sub.pipelineBindPoint = VK_PIPELINE_BIND_POINT_GRAPHICS;
      sub.colorAttachmentCount = 1;
      sub.pColorAttachments = &colour;
      sub.pDepthStencilAttachment = &depth;
      VkSubpassDependency dep{};  // the pass before (this frame's, or the last frame's) is done with the images
      dep.srcSubpass = VK_SUBPASS_EXTERNAL;
      dep.srcStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
      dep.srcAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
      dep.dstStageMask = VK_PIPELINE_STAGE_COLOR_ATTACHMENT_OUTPUT_BIT | VK_PIPELINE_STAGE_EARLY_FRAGMENT_TESTS_BIT |
                         VK_PIPELINE_STAGE_LATE_FRAGMENT_TESTS_BIT;
      dep.dstAccessMask = VK_ACCESS_COLOR_ATTACHMENT_WRITE_BIT | VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_READ_BIT |
                          VK_ACCESS_DEPTH_STENCIL_ATTACHMENT_WRITE_BIT;
      VkRenderPassCreateInfo info{VK_STRUCTURE_TYPE_RENDER_PASS_CREATE_INFO};
      info.attachmentCount = 2;
      info.pAttachments = a;
      info.subpassCount = 1;
      info.pSubpasses = &sub;
      info.dependencyCount = 1;
      info.pDependencies = &dep;
      vk_check(vkCreateRenderPass(d.device, &info, nullptr, &passes_[keep]), "vkCreateRenderPass");
    }
    VkFramebufferCreateInfo fb{VK_STRUCTURE_TYPE_FRAMEBUFFER_CREATE_INFO};
    fb.renderPass = passes_[0];
    fb.attachmentCount = 2;
    fb.pAttachments = views_;
    fb.width = std::uint32_t(width);
    fb.height = std::uint32_t(height);
    fb.layers = 1;
    vk_check(vkCreateFramebuffer(d.device, &fb, nullptr, &framebuffer_), "vkCreateFramebuffer");
  }
  ~Frame() {
    vkDestroyFramebuffer(d_.device, framebuffer_, nullptr);
    for (VkRenderPass p : passes_) vkDestroyRenderPass(d_.device, p, nullptr);
    for (int i = 0; i < 2; ++i) {
      vkDestroyImageView(d_.device, views_[i], nullptr);
      vkDestroyImage(d_.device, images_[i], nullptr);
      vkFreeMemory(d_.device, memories_[i], nullptr);
    }
  }
  Frame(const Frame&) = delete;
  Frame& operator=(const Frame&) = delete;

  [[nodiscard]] VkRenderPass pass(bool keep) const { return passes_[keep ? 1 : 0]; }
  // Begins a pass over the images: cleared (reversed-Z: depth 0 is the far end) or kept.
  void begin(VkCommandBuffer cmd, bool keep) const {
    VkClearValue clear[2]{};
    clear[0].color = {{0.5f, 0.6f, 0.7f, 1.0f}};
    clear[1].depthStencil = {0.0f, 0};
    VkRenderPassBeginInfo rp{VK_STRUCTURE_TYPE_RENDER_PASS_BEGIN_INFO};
    rp.renderPass = pass(keep);
    rp.framebuffer = framebuffer_;
    rp.renderArea = {{0, 0}, {std::uint32_t(width_), std::uint32_t(height_)}};
    rp.clearValueCount = keep ? 0 : 2;
    rp.pClearValues = clear;
    vkCmdBeginRenderPass(cmd, &rp, VK_SUBPASS_CONTENTS_INLINE);
  }

 private:
  // Image `slot` (0 colour, 1 depth) with its memory and view.
  void make_image(VkFormat format, VkImageUsageFlags usage, VkImageAspectFlags aspect, int slot) {
    VkImageCreateInfo info{VK_STRUCTURE_TYPE_IMAGE_CREATE_INFO};
    info.imageType = VK_IMAGE_TYPE_2D;
    info.format = format;
    info.extent = {std::uint32_t(width_), std::uint32_t(height_), 1};
    info.mipLevels = info.arrayLayers = 1;
    info.samples = VK_SAMPLE_COUNT_1_BIT;
    info.tiling = VK_IMAGE_TILING_OPTIMAL;
    info.usage = usage;
    vk_check(vkCreateImage(d_.device, &info, nullptr, &images_[slot]), "vkCreateImage");
    VkMemoryRequirements req;
    vkGetImageMemoryRequirements(d_.device, images_[slot], &req);
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = d_.memory_type(req.memoryTypeBits, VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT);
    vk_check(vkAllocateMemory(d_.device, &alloc, nullptr, &memories_[slot]), "vkAllocateMemory");
    vk_check(vkBindImageMemory(d_.device, images_[slot], memories_[slot], 0), "vkBindImageMemory");
    VkImageViewCreateInfo view{VK_STRUCTURE_TYPE_IMAGE_VIEW_CREATE_INFO};
    view.image = images_[slot];
    view.viewType = VK_IMAGE_VIEW_TYPE_2D;
    view.format = format;
    view.subresourceRange = {aspect, 0, 1, 0, 1};
    vk_check(vkCreateImageView(d_.device, &view, nullptr, &views_[slot]), "vkCreateImageView");
  }

  const Device& d_;
  int width_, height_;
  VkImage images_[2]{};
  VkDeviceMemory memories_[2]{};
  VkImageView views_[2]{};
  VkRenderPass passes_[2]{};
  VkFramebuffer framebuffer_ = VK_NULL_HANDLE;
};

VkShaderModule module(const Device& d, const std::uint32_t* code, std::size_t bytes) {
  VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  info.codeSize = bytes;
  info.pCode = code;
  VkShaderModule m = VK_NULL_HANDLE;
  vk_check(vkCreateShaderModule(d.device, &info, nullptr, &m), "vkCreateShaderModule");
  return m;
}

// The two pipelines: objects (depth test greater, reversed-Z), and query
// boxes (greater-or-equal, writing nothing, both faces — the eye may be
// inside a box —, depth clamped at the near plane and pulled toward the eye).
VkPipeline make_pipeline(const Device& d, VkRenderPass pass, VkPipelineLayout layout, bool boxes, int width,
                         int height) {
  const VkShaderModule vs = boxes ? module(d, kBoxVert, sizeof kBoxVert) : module(d, kDrawVert, sizeof kDrawVert);
  const VkShaderModule fs = boxes ? module(d, kBoxFrag, sizeof kBoxFrag) : module(d, kDrawFrag, sizeof kDrawFrag);
  VkPipelineShaderStageCreateInfo stages[2]{};
  stages[0] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_VERTEX_BIT, vs, "main", nullptr};
  stages[1] = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO, nullptr, 0, VK_SHADER_STAGE_FRAGMENT_BIT, fs, "main", nullptr};
  const VkVertexInputBindingDescription binding{0, 6 * sizeof(float), VK_VERTEX_INPUT_RATE_VERTEX};
  const VkVertexInputAttributeDescription attributes[2] = {{0, 0, VK_FORMAT_R32G32B32_SFLOAT, 0},
                                                           {1, 0, VK_FORMAT_R32G32B32_SFLOAT, 3 * sizeof(float)}};
  VkPipelineVertexInputStateCreateInfo input{VK_STRUCTURE_TYPE_PIPELINE_VERTEX_INPUT_STATE_CREATE_INFO};
  if (!boxes) {
    input.vertexBindingDescriptionCount = 1;
    input.pVertexBindingDescriptions = &binding;
    input.vertexAttributeDescriptionCount = 2;
    input.pVertexAttributeDescriptions = attributes;
  }
  VkPipelineInputAssemblyStateCreateInfo assembly{VK_STRUCTURE_TYPE_PIPELINE_INPUT_ASSEMBLY_STATE_CREATE_INFO};
  assembly.topology = VK_PRIMITIVE_TOPOLOGY_TRIANGLE_LIST;
  // y up, as the projection expects: the viewport flips it (a negative height).
  const VkViewport viewport{0.0f, float(height), float(width), -float(height), 0.0f, 1.0f};
  const VkRect2D scissor{{0, 0}, {std::uint32_t(width), std::uint32_t(height)}};
  VkPipelineViewportStateCreateInfo vp{VK_STRUCTURE_TYPE_PIPELINE_VIEWPORT_STATE_CREATE_INFO};
  vp.viewportCount = vp.scissorCount = 1;
  vp.pViewports = &viewport;
  vp.pScissors = &scissor;
  VkPipelineRasterizationStateCreateInfo raster{VK_STRUCTURE_TYPE_PIPELINE_RASTERIZATION_STATE_CREATE_INFO};
  raster.polygonMode = VK_POLYGON_MODE_FILL;
  raster.cullMode = boxes ? VK_CULL_MODE_NONE : VK_CULL_MODE_BACK_BIT;
  raster.frontFace = VK_FRONT_FACE_COUNTER_CLOCKWISE;  // with the flipped viewport, as OpenGL's
  raster.lineWidth = 1.0f;
  raster.depthClampEnable = boxes ? VK_TRUE : VK_FALSE;
  raster.depthBiasEnable = boxes ? VK_TRUE : VK_FALSE;
  raster.depthBiasConstantFactor = 2.0f;  // toward the eye under reversed-Z
  raster.depthBiasSlopeFactor = 1.0f;
  VkPipelineMultisampleStateCreateInfo ms{VK_STRUCTURE_TYPE_PIPELINE_MULTISAMPLE_STATE_CREATE_INFO};
  ms.rasterizationSamples = VK_SAMPLE_COUNT_1_BIT;
  VkPipelineDepthStencilStateCreateInfo ds{VK_STRUCTURE_TYPE_PIPELINE_DEPTH_STENCIL_STATE_CREATE_INFO};
  ds.depthTestEnable = VK_TRUE;
  ds.depthWriteEnable = boxes ? VK_FALSE : VK_TRUE;
  ds.depthCompareOp = boxes ? VK_COMPARE_OP_GREATER_OR_EQUAL : VK_COMPARE_OP_GREATER;
  VkPipelineColorBlendAttachmentState blend{};
  blend.colorWriteMask = boxes ? 0 : 0xf;
  VkPipelineColorBlendStateCreateInfo cb{VK_STRUCTURE_TYPE_PIPELINE_COLOR_BLEND_STATE_CREATE_INFO};
  cb.attachmentCount = 1;
  cb.pAttachments = &blend;
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
  info.layout = layout;
  info.renderPass = pass;
  VkPipeline p = VK_NULL_HANDLE;
  vk_check(vkCreateGraphicsPipelines(d.device, VK_NULL_HANDLE, 1, &info, nullptr, &p), "vkCreateGraphicsPipelines");
  vkDestroyShaderModule(d.device, vs, nullptr);
  vkDestroyShaderModule(d.device, fs, nullptr);
  return p;
}

// ---------------------------------------------------------------------------
// The engine's side of occull: draw what occull asks for, run occlusion
// queries over boxes, and say what a read costs here.
class EngineBackend final : public occull::Backend {
 public:
  EngineBackend(const Device& d, const Frame& frame, const std::vector<glm::mat4>& models, VkBuffer vertices,
                VkBuffer indices, std::uint32_t index_count, int width, int height)
      : d_(d), frame_(frame), models_(models), vertices_(vertices), indices_(indices), index_count_(index_count) {
    const VkPushConstantRange push{VK_SHADER_STAGE_VERTEX_BIT, 0, 128};
    VkPipelineLayoutCreateInfo pl{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
    pl.pushConstantRangeCount = 1;
    pl.pPushConstantRanges = &push;
    vk_check(vkCreatePipelineLayout(d.device, &pl, nullptr, &layout_), "vkCreatePipelineLayout");
    draw_ = make_pipeline(d, frame.pass(false), layout_, false, width, height);
    boxes_ = make_pipeline(d, frame.pass(false), layout_, true, width, height);
    VkCommandPoolCreateInfo cp{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
    cp.flags = VK_COMMAND_POOL_CREATE_RESET_COMMAND_BUFFER_BIT;
    cp.queueFamilyIndex = d.family;
    vk_check(vkCreateCommandPool(d.device, &cp, nullptr, &pool_), "vkCreateCommandPool");
    VkQueryPoolCreateInfo qp{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    qp.queryType = VK_QUERY_TYPE_OCCLUSION;
    qp.queryCount = kQueries;
    vk_check(vkCreateQueryPool(d.device, &qp, nullptr, &queries_), "vkCreateQueryPool");
    for (occull::QueryId q = kQueries; q-- > 0;) free_.push_back(q);
    issued_in_.assign(kQueries, 0);
    live_.assign(kQueries, false);
  }
  ~EngineBackend() override {
    vkDeviceWaitIdle(d_.device);
    for (VkFence f : fences_) vkDestroyFence(d_.device, f, nullptr);
    vkDestroyCommandPool(d_.device, pool_, nullptr);
    vkDestroyQueryPool(d_.device, queries_, nullptr);
    vkDestroyPipeline(d_.device, draw_, nullptr);
    vkDestroyPipeline(d_.device, boxes_, nullptr);
    vkDestroyPipelineLayout(d_.device, layout_, nullptr);
  }
  EngineBackend(const EngineBackend&) = delete;
  EngineBackend& operator=(const EngineBackend&) = delete;

  // The engine's frame: begin records into a pass that clears; end submits and waits.
  void begin_frame(const glm::mat4& view_proj) {
    view_proj_ = view_proj;
    begin_commands(false);
  }
  void end_frame() {
    submit();
    wait();
  }

  void render(std::span<const occull::ObjectId> ids) override {
    use(draw_);
    const VkDeviceSize zero = 0;
    vkCmdBindVertexBuffers(cmd_, 0, 1, &vertices_, &zero);
    vkCmdBindIndexBuffer(cmd_, indices_, 0, VK_INDEX_TYPE_UINT32);
    for (occull::ObjectId id : ids) {
      const glm::mat4 constants[2] = {view_proj_, models_[id]};
      vkCmdPushConstants(cmd_, layout_, VK_SHADER_STAGE_VERTEX_BIT, 0, sizeof constants, constants);
      vkCmdDrawIndexed(cmd_, index_count_, 1, 0, 0, 0);
      ++stats_.draw_calls;
      ++stats_.objects_rendered;
    }
    ++stats_.render_flushes;
  }

  occull::QueryId issue_query(std::span<const occull::Aabb> boxes) override {
    if (free_.empty()) throw std::runtime_error("EngineBackend: more queries in flight than its pool holds");
    const occull::QueryId q = free_.back();
    free_.pop_back();
    live_[q] = true;
    issued_in_[q] = submission_;
    vkResetQueryPool(d_.device, queries_, q, 1);  // read before, so the device is done with it (hostQueryReset)
    use(boxes_);
    vkCmdBeginQuery(cmd_, queries_, q, VK_QUERY_CONTROL_PRECISE_BIT);
    for (const occull::Aabb& b : boxes) {
      // A hair larger than the box: rasterisers snap vertices to sub-pixels.
      const glm::vec3 margin = 0.002f * (b.max - b.min) + glm::vec3(0.002f);
      struct {
        glm::mat4 view_proj;
        glm::vec4 lo, hi;
      } constants{view_proj_, glm::vec4(b.min - margin, 1.0f), glm::vec4(b.max + margin, 1.0f)};
      vkCmdPushConstants(cmd_, layout_, VK_SHADER_STAGE_VERTEX_BIT, 0, sizeof constants, &constants);
      vkCmdDraw(cmd_, 36, 1, 0, 0);
    }
    vkCmdEndQuery(cmd_, queries_, q);
    ++stats_.queries;
    stats_.query_boxes += boxes.size();
    return q;
  }

  // A result exists once its commands were submitted and ran: a read of a
  // query recorded since the last submission submits what was recorded
  // (ending the pass; the next draws begin one that keeps the images).
  [[nodiscard]] occull::ResultReads result_reads() const override { return occull::ResultReads::after_submit; }

  bool result_available(occull::QueryId q) override {
    check(q);
    if (issued_in_[q] == submission_) resubmit();
    std::uint64_t samples = 0;
    return vkGetQueryPoolResults(d_.device, queries_, q, 1, sizeof samples, &samples, sizeof samples,
                                 VK_QUERY_RESULT_64_BIT) == VK_SUCCESS;
  }

  std::uint64_t result(occull::QueryId q) override {
    check(q);
    if (issued_in_[q] == submission_) resubmit();
    std::uint64_t samples = 0;
    vk_check(vkGetQueryPoolResults(d_.device, queries_, q, 1, sizeof samples, &samples, sizeof samples,
                                   VK_QUERY_RESULT_64_BIT | VK_QUERY_RESULT_WAIT_BIT),
             "vkGetQueryPoolResults");
    live_[q] = false;
    free_.push_back(q);
    return samples;
  }

  void flush() override {
    if (cmd_) resubmit();
  }
  [[nodiscard]] occull::BackendStats stats() const override { return stats_; }
  [[nodiscard]] std::size_t queries_in_flight() const { return kQueries - free_.size(); }

 private:
  static constexpr std::uint32_t kQueries = 4096;

  void use(VkPipeline p) {
    if (!cmd_) begin_commands(true);
    if (bound_ != p) vkCmdBindPipeline(cmd_, VK_PIPELINE_BIND_POINT_GRAPHICS, p);
    bound_ = p;
  }
  void begin_commands(bool keep) {
    VkCommandBufferAllocateInfo ai{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    ai.commandPool = pool_;
    ai.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    ai.commandBufferCount = 1;
    if (spare_.empty()) {
      VkCommandBuffer c = VK_NULL_HANDLE;
      vk_check(vkAllocateCommandBuffers(d_.device, &ai, &c), "vkAllocateCommandBuffers");
      spare_.push_back(c);
    }
    cmd_ = spare_.back();
    spare_.pop_back();
    vk_check(vkResetCommandBuffer(cmd_, 0), "vkResetCommandBuffer");
    VkCommandBufferBeginInfo bi{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    bi.flags = VK_COMMAND_BUFFER_USAGE_ONE_TIME_SUBMIT_BIT;
    vk_check(vkBeginCommandBuffer(cmd_, &bi), "vkBeginCommandBuffer");
    frame_.begin(cmd_, keep);
    bound_ = VK_NULL_HANDLE;
  }
  void submit() {
    if (!cmd_) return;
    vkCmdEndRenderPass(cmd_);
    vk_check(vkEndCommandBuffer(cmd_), "vkEndCommandBuffer");
    VkFenceCreateInfo fi{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
    VkFence fence = VK_NULL_HANDLE;
    vk_check(vkCreateFence(d_.device, &fi, nullptr, &fence), "vkCreateFence");
    VkSubmitInfo si{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    si.commandBufferCount = 1;
    si.pCommandBuffers = &cmd_;
    vk_check(vkQueueSubmit(d_.queue, 1, &si, fence), "vkQueueSubmit");
    fences_.push_back(fence);
    submitted_.push_back(cmd_);
    cmd_ = VK_NULL_HANDLE;
    ++submission_;
  }
  void resubmit() {  // mid-frame: what was recorded goes to the device; recording goes on after it
    submit();
    ++stats_.flushes;
  }
  void wait() {
    if (fences_.empty()) return;
    vk_check(vkWaitForFences(d_.device, std::uint32_t(fences_.size()), fences_.data(), VK_TRUE, UINT64_MAX),
             "vkWaitForFences");
    for (VkFence f : fences_) vkDestroyFence(d_.device, f, nullptr);
    fences_.clear();
    spare_.insert(spare_.end(), submitted_.begin(), submitted_.end());
    submitted_.clear();
  }
  void check(occull::QueryId q) const {
    if (q >= live_.size() || !live_[q]) throw std::logic_error("EngineBackend: query not in flight");
  }

  const Device& d_;
  const Frame& frame_;
  const std::vector<glm::mat4>& models_;
  VkBuffer vertices_, indices_;
  std::uint32_t index_count_;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline draw_ = VK_NULL_HANDLE, boxes_ = VK_NULL_HANDLE, bound_ = VK_NULL_HANDLE;
  VkCommandPool pool_ = VK_NULL_HANDLE;
  VkCommandBuffer cmd_ = VK_NULL_HANDLE;
  std::vector<VkCommandBuffer> spare_, submitted_;
  std::vector<VkFence> fences_;
  std::uint64_t submission_ = 1;  // the submission being recorded
  VkQueryPool queries_ = VK_NULL_HANDLE;
  std::vector<std::uint64_t> issued_in_;
  std::vector<bool> live_;
  std::vector<occull::QueryId> free_;
  glm::mat4 view_proj_{1.0f};
  occull::BackendStats stats_;
};

// Reversed-Z with an infinite far plane: depth = near / distance.
glm::mat4 reversed_infinite(float fov_y, float aspect, float near) {
  glm::mat4 p(0.0f);
  const float f = 1.0f / std::tan(fov_y / 2.0f);
  p[0][0] = f / aspect;
  p[1][1] = f;
  p[2][3] = -1.0f;
  p[3][2] = near;
  return p;
}

struct Args {
  std::string algo = "chcpp:batch=20";
  int frames = 120;
  int width = 320, height = 180;
  bool validation = true;
  bool no_mid_frame_submissions = false;  // fail if anything was submitted mid-frame
};

Args parse(int argc, char** argv) {
  Args a;
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--algo" && i + 1 < argc) {
      a.algo = argv[++i];
    } else if (arg == "--frames" && i + 1 < argc) {
      a.frames = std::atoi(argv[++i]);
    } else if (arg == "--size" && i + 1 < argc) {
      if (std::sscanf(argv[++i], "%dx%d", &a.width, &a.height) != 2) throw occull::InputError("--size WIDTHxHEIGHT");
    } else if (arg == "--validation" && i + 1 < argc) {
      const std::string v = argv[++i];
      if (v != "on" && v != "off") throw occull::InputError("--validation on|off");
      a.validation = v == "on";
    } else if (arg == "--no-mid-frame-submissions") {
      a.no_mid_frame_submissions = true;
    } else if (arg == "--help" || arg == "-h") {
      std::printf("occull_example_vk_engine [--algo SPEC] [--frames N] [--size WxH] [--validation on|off] "
                  "[--no-mid-frame-submissions]: a small Vulkan engine culling with occull (chcpp:batch=20 by "
                  "default), checked against occull's ground truth (exit 0: nothing missed by a conservative culler, "
                  "no validation error, and with the last flag nothing submitted mid-frame)\n");
      std::exit(0);
    } else {
      throw occull::InputError("unknown argument " + arg +
                               " (--algo SPEC, --frames N, --size WxH, --validation on|off, "
                               "--no-mid-frame-submissions, --help)");
    }
  }
  if (a.frames < 1 || a.width < 16 || a.height < 16 || a.width > 4096 || a.height > 4096)
    throw occull::InputError("--frames must be >= 1 and --size within 16x16 .. 4096x4096");
  return a;
}

int run(const Args& args) {
  Device device(args.validation);
  Frame frame(device, args.width, args.height);
  const CpuMesh cube = make_cube();
  std::vector<float> interleaved;
  for (std::size_t i = 0; i < cube.positions.size(); ++i)
    interleaved.insert(interleaved.end(), {cube.positions[i].x, cube.positions[i].y, cube.positions[i].z,
                                           cube.normals[i].x, cube.normals[i].y, cube.normals[i].z});
  Buffer vertices(device), indices(device);
  fill_buffer(vertices, interleaved.data(), interleaved.size() * sizeof(float), VK_BUFFER_USAGE_VERTEX_BUFFER_BIT);
  fill_buffer(indices, cube.indices.data(), cube.indices.size() * 4, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);

  // occull's view of the engine's objects: boxes and triangle counts; the
  // truth's copy of the scene has the vertices, ids in step.
  occull::Scene scene("vk engine");
  const occull::MaterialId material = scene.add_material({});
  const occull::MeshId mesh = scene.add_mesh(occull::MeshInfo{{glm::vec3(-0.5f), glm::vec3(0.5f)},
                                                              std::uint32_t(cube.indices.size() / 3), 6.0});
  occull::Scene truth_scene("vk engine truth");
  const occull::MaterialId truth_material = truth_scene.add_material({});
  const occull::MeshId truth_mesh = truth_scene.add_mesh(occull::Mesh{cube.positions, cube.normals, cube.indices});
  std::vector<glm::mat4> models;
  const auto box = [](glm::vec3 centre, glm::vec3 size) {
    return glm::scale(glm::translate(glm::mat4(1.0f), centre), size);
  };
  const auto add = [&](const glm::mat4& model, occull::OccluderClass cls) {
    const occull::ObjectId id = scene.add_object(mesh, material, model, cls);
    truth_scene.add_object(truth_mesh, truth_material, model, cls);
    models.push_back(model);
    return id;
  };
  // A town: ground, 10 x 10 blocks of buildings, crates driving along the streets.
  add(box({0, -0.5f, 0}, {400, 1, 400}), occull::OccluderClass::always);
  for (int bx = -5; bx < 5; ++bx)
    for (int bz = -5; bz < 5; ++bz) {
      const float h = 6.0f + float((bx * 7 + bz * 13 + 100) % 9) * 3.0f;
      add(box({float(bx) * 20.0f + 10.0f, h / 2.0f, float(bz) * 20.0f + 10.0f}, {12, h, 12}),
          occull::OccluderClass::always);
    }
  std::vector<occull::ObjectId> crates;
  for (int i = 0; i < 60; ++i) crates.push_back(add(glm::mat4(1.0f), occull::OccluderClass::never));

  occull::Bvh bvh = occull::Bvh::build(scene);
  auto culler = occull::make_culler(args.algo, {scene, bvh});
  const bool conservative = occull::is_conservative(occull::parse_algorithm_spec(args.algo));
  EngineBackend backend(device, frame, models, vertices.buffer, indices.buffer, std::uint32_t(cube.indices.size()),
                        args.width, args.height);

  // occull's ground truth on a device of its own (validation as the engine's).
  occull::vk::ContextOptions truth_context_options;
  truth_context_options.validation = args.validation;
  auto truth_context = occull::vk::Context::create(truth_context_options);
  occull::vk::RendererOptions truth_options;
  truth_options.width = args.width;
  truth_options.height = args.height;
  occull::vk::Renderer truth(*truth_context, truth_scene, truth_options);

  std::uint64_t missed = 0, drawn = 0, visible = 0, queries = 0, framed = 0;
  for (int f = 0; f < args.frames; ++f) {
    const float t = float(f) / 30.0f;
    for (std::size_t i = 0; i < crates.size(); ++i) {  // game logic
      const float street = float(int(i % 10) - 5) * 20.0f;
      const float along = std::fmod(float(i) * 14.8f + t * (4.0f + float(i % 5)), 200.0f) - 100.0f;
      const glm::vec3 at = i % 2 ? glm::vec3(street, 1.0f, along) : glm::vec3(along, 1.0f, street);
      models[crates[i]] = box(at, {2, 2, 2});
      scene.set_transform(crates[i], models[crates[i]]);
      truth_scene.set_transform(crates[i], models[crates[i]]);
    }
    const glm::vec3 eye(-0.5f, 1.7f, -90.0f + t * 6.0f);
    const float yaw = 0.6f * std::sin(t * 0.7f);
    const glm::mat4 view_matrix = glm::lookAt(eye, eye + glm::vec3(std::sin(yaw), -0.05f, std::cos(yaw)), {0, 1, 0});
    const glm::mat4 proj = reversed_infinite(1.0f, float(args.width) / float(args.height), 0.1f);
    const occull::View view = occull::make_view(view_matrix, proj, args.width, args.height,
                                                {occull::DepthRange::zero_to_one, /*reversed_z=*/true});
    bvh.refit(scene);
    backend.begin_frame(view.view_proj);
    const occull::FrameResult result = culler->render_frame(view, backend);
    backend.end_frame();
    queries += result.queries;
    const std::span<const occull::ObjectId> drawn_set = culler->drawn_objects();
    drawn += drawn_set.size();

    std::vector<occull::ObjectId> in_frustum;
    for (occull::ObjectId id = 0; id < truth_scene.objects().size(); ++id)
      if (view.frustum.classify(truth_scene.object(id).bounds) != occull::Containment::outside) in_frustum.push_back(id);
    framed += in_frustum.size();
    for (const auto& v : truth.visible_pixels(view, in_frustum)) {
      ++visible;
      if (!std::binary_search(drawn_set.begin(), drawn_set.end(), v.id)) {
        ++missed;
        if (conservative) std::printf("frame %d: object %u visible (%u pixels) but not drawn\n", f, v.id, v.pixels);
      }
    }
  }
  culler->release(backend);
  const std::size_t left = backend.queries_in_flight();
  const occull::BackendStats s = backend.stats();
  truth_context->check("the ground truth");
  std::printf("vk engine (%s): %d frames at %dx%d, %zu objects; per frame %.1f drawn, %.1f visible, %.1f queries, "
              "%.1f submissions mid-frame; missed %llu object-frames%s; %zu queries left in flight\n",
              args.algo.c_str(), args.frames, args.width, args.height, scene.objects().size(),
              double(drawn) / args.frames, double(visible) / args.frames, double(queries) / args.frames,
              double(s.flushes) / args.frames, (unsigned long long)missed,
              conservative ? "" : " (not conservative: popping)", left);
  if (visible == 0) {
    std::printf("vk engine: the truth saw nothing: the check would prove nothing\n");
    return 1;
  }
  // Not drawing the whole frustum: the town hides most of itself (a check that drawing everything fails).
  const bool culls = double(drawn) < 0.8 * double(framed);
  if (!culls) std::printf("vk engine: drew %llu objects of %llu in the frustum: it does not cull\n",
                          (unsigned long long)drawn, (unsigned long long)framed);
  const bool latency_ok = !args.no_mid_frame_submissions || s.flushes == 0;
  if (!latency_ok) std::printf("vk engine: %llu submissions mid-frame\n", (unsigned long long)s.flushes);
  return (missed == 0 || !conservative) && left == 0 && culls && latency_ok ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
  try {
    int code = run(parse(argc, argv));  // every Vulkan object is gone when it returns
    std::printf("vk engine: %d validation errors\n", g_validation_errors);
    if (g_validation_errors > 0) code = 1;
    return code;
  } catch (const occull::InputError& e) {
    std::fprintf(stderr, "occull_example_vk_engine: %s\n", e.what());
    return 2;
  } catch (const occull::VulkanUnavailable& e) {
    std::fprintf(stderr, "occull_example_vk_engine: %s\n", e.what());
    return 3;
  }
}
