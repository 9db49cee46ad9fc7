// The headless Vulkan device: instance (with the validation layer when
// asked), the physical device, and a logical device with one graphics queue
// and the features occull's renderer relies on.
#include "occull/vk/context.hpp"

#include "vk.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cstring>
#include <vector>

namespace occull::vk {

std::string_view result_name(VkResult r) noexcept {
  switch (r) {
#define OCCULL_VK_RESULT(x) \
  case x: return #x;
    OCCULL_VK_RESULT(VK_SUCCESS)
    OCCULL_VK_RESULT(VK_NOT_READY)
    OCCULL_VK_RESULT(VK_TIMEOUT)
    OCCULL_VK_RESULT(VK_INCOMPLETE)
    OCCULL_VK_RESULT(VK_ERROR_OUT_OF_HOST_MEMORY)
    OCCULL_VK_RESULT(VK_ERROR_OUT_OF_DEVICE_MEMORY)
    OCCULL_VK_RESULT(VK_ERROR_INITIALIZATION_FAILED)
    OCCULL_VK_RESULT(VK_ERROR_DEVICE_LOST)
    OCCULL_VK_RESULT(VK_ERROR_MEMORY_MAP_FAILED)
    OCCULL_VK_RESULT(VK_ERROR_LAYER_NOT_PRESENT)
    OCCULL_VK_RESULT(VK_ERROR_EXTENSION_NOT_PRESENT)
    OCCULL_VK_RESULT(VK_ERROR_FEATURE_NOT_PRESENT)
    OCCULL_VK_RESULT(VK_ERROR_INCOMPATIBLE_DRIVER)
    OCCULL_VK_RESULT(VK_ERROR_TOO_MANY_OBJECTS)
    OCCULL_VK_RESULT(VK_ERROR_FORMAT_NOT_SUPPORTED)
    OCCULL_VK_RESULT(VK_ERROR_FRAGMENTED_POOL)
    OCCULL_VK_RESULT(VK_ERROR_OUT_OF_POOL_MEMORY)
#undef OCCULL_VK_RESULT
    default: return "an unnamed VkResult";
  }
}

namespace {

constexpr const char* kValidationLayer = "VK_LAYER_KHRONOS_validation";

VKAPI_ATTR VkBool32 VKAPI_CALL on_message(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                          VkDebugUtilsMessageTypeFlagsEXT /*types*/,
                                          const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto& h = *static_cast<Context::Handles*>(user);
  if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) {
    if (h.errors++ == 0 && data && data->pMessage) h.first_error = data->pMessage;
  } else if (severity & VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT) {
    ++h.warnings;
  }
  return VK_FALSE;
}

bool has_layer(const char* name) {
  std::uint32_t n = 0;
  vkEnumerateInstanceLayerProperties(&n, nullptr);
  std::vector<VkLayerProperties> layers(n);
  vkEnumerateInstanceLayerProperties(&n, layers.data());
  return std::any_of(layers.begin(), layers.end(), [&](const VkLayerProperties& l) { return std::strcmp(l.layerName, name) == 0; });
}

bool has_device_extension(VkPhysicalDevice d, const char* name) {
  std::uint32_t n = 0;
  vkEnumerateDeviceExtensionProperties(d, nullptr, &n, nullptr);
  std::vector<VkExtensionProperties> ext(n);
  vkEnumerateDeviceExtensionProperties(d, nullptr, &n, ext.data());
  return std::any_of(ext.begin(), ext.end(), [&](const VkExtensionProperties& e) { return std::strcmp(e.extensionName, name) == 0; });
}

std::string version_string(std::uint32_t v) {
  return fmt::format("{}.{}.{}", VK_API_VERSION_MAJOR(v), VK_API_VERSION_MINOR(v), VK_API_VERSION_PATCH(v));
}

// The graphics queue family of `d`, or -1.
int graphics_family(VkPhysicalDevice d) {
  std::uint32_t n = 0;
  vkGetPhysicalDeviceQueueFamilyProperties(d, &n, nullptr);
  std::vector<VkQueueFamilyProperties> families(n);
  vkGetPhysicalDeviceQueueFamilyProperties(d, &n, families.data());
  for (std::uint32_t i = 0; i < n; ++i)
    if (families[i].queueFlags & VK_QUEUE_GRAPHICS_BIT) return int(i);
  return -1;
}

}  // namespace

Context::Context() : handles_(std::make_unique<Handles>()) {}

std::unique_ptr<Context> Context::create(const ContextOptions& options) {
  std::unique_ptr<Context> c(new Context());
  Handles& h = *c->handles_;

  std::uint32_t loader_version = VK_API_VERSION_1_0;
  if (vkEnumerateInstanceVersion(&loader_version) != VK_SUCCESS || loader_version < VK_API_VERSION_1_2)
    throw VulkanUnavailable(fmt::format("Vulkan: the loader offers Vulkan {}, occull needs 1.2 (libvulkan1 from Debian 12)",
                                        version_string(loader_version)));
  std::vector<const char*> layers, extensions;
  if (options.validation) {
    if (!has_layer(kValidationLayer))
      throw VulkanUnavailable("Vulkan: validation asked for, but VK_LAYER_KHRONOS_validation is not installed "
                              "(Debian: vulkan-validationlayers)");
    layers.push_back(kValidationLayer);
    extensions.push_back(VK_EXT_DEBUG_UTILS_EXTENSION_NAME);
  }
  VkApplicationInfo app{VK_STRUCTURE_TYPE_APPLICATION_INFO};
  app.pApplicationName = "occull";
  app.pEngineName = "occull";
  app.apiVersion = VK_API_VERSION_1_2;
  VkDebugUtilsMessengerCreateInfoEXT messenger{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  messenger.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
  messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT |
                          VK_DEBUG_UTILS_MESSAGE_TYPE_PERFORMANCE_BIT_EXT;
  messenger.pfnUserCallback = on_message;
  messenger.pUserData = &h;
  VkInstanceCreateInfo ici{VK_STRUCTURE_TYPE_INSTANCE_CREATE_INFO};
  ici.pApplicationInfo = &app;
  ici.enabledLayerCount = std::uint32_t(layers.size());
  ici.ppEnabledLayerNames = layers.data();
  ici.enabledExtensionCount = std::uint32_t(extensions.size());
  ici.ppEnabledExtensionNames = extensions.data();
  if (options.validation) ici.pNext = &messenger;  // reports during instance creation too
  if (const VkResult r = vkCreateInstance(&ici, nullptr, &h.instance); r != VK_SUCCESS)
    throw VulkanUnavailable(fmt::format("Vulkan: vkCreateInstance failed ({})", result_name(r)));
  if (options.validation) {
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(h.instance, "vkCreateDebugUtilsMessengerEXT"));
    if (!create || create(h.instance, &messenger, nullptr, &h.messenger) != VK_SUCCESS)
      throw VulkanUnavailable("Vulkan: the validation layer's messenger could not be made");
  }

  std::uint32_t count = 0;
  vkEnumeratePhysicalDevices(h.instance, &count, nullptr);
  std::vector<VkPhysicalDevice> devices(count);
  vkEnumeratePhysicalDevices(h.instance, &count, devices.data());
  if (devices.empty())
    throw VulkanUnavailable("Vulkan: no device (install Mesa's lavapipe: Debian's mesa-vulkan-drivers, "
                            "or a GPU's Vulkan driver)");
  // The named device; else a GPU before a CPU device.
  std::vector<std::string> names;
  VkPhysicalDevice chosen = VK_NULL_HANDLE;
  int chosen_rank = -1;
  for (VkPhysicalDevice d : devices) {
    VkPhysicalDeviceProperties p;
    vkGetPhysicalDeviceProperties(d, &p);
    names.emplace_back(p.deviceName);
    if (graphics_family(d) < 0 || p.apiVersion < VK_API_VERSION_1_2) continue;
    if (!options.device_name.empty()) {
      if (std::string_view(p.deviceName).find(options.device_name) != std::string_view::npos && !chosen) chosen = d;
      continue;
    }
    const int rank = p.deviceType == VK_PHYSICAL_DEVICE_TYPE_DISCRETE_GPU   ? 3
                     : p.deviceType == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU ? 2
                                                                              : 1;
    if (rank > chosen_rank) chosen = d, chosen_rank = rank;
  }
  if (!chosen)
    throw VulkanUnavailable(fmt::format("Vulkan: no Vulkan 1.2 device with a graphics queue{}; devices: {}",
                                        options.device_name.empty() ? "" : " named like '" + options.device_name + "'",
                                        fmt::join(names, ", ")));
  h.physical = chosen;
  h.queue_family = std::uint32_t(graphics_family(chosen));
  vkGetPhysicalDeviceMemoryProperties(chosen, &h.memory);

  VkPhysicalDeviceProperties props;
  vkGetPhysicalDeviceProperties(chosen, &props);
  VkPhysicalDeviceDriverProperties driver{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_DRIVER_PROPERTIES};
  VkPhysicalDeviceProperties2 props2{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
  props2.pNext = &driver;
  vkGetPhysicalDeviceProperties2(chosen, &props2);
  DeviceInfo& info = c->info_;
  info.name = props.deviceName;
  info.api_version = version_string(props.apiVersion);
  info.driver = fmt::format("{} | {}", driver.driverName, driver.driverInfo);
  info.timestamp_period_ns = props.limits.timestampPeriod;
  {
    std::uint32_t n = 0;
    vkGetPhysicalDeviceQueueFamilyProperties(chosen, &n, nullptr);
    std::vector<VkQueueFamilyProperties> families(n);
    vkGetPhysicalDeviceQueueFamilyProperties(chosen, &n, families.data());
    info.timestamp_bits = int(families[h.queue_family].timestampValidBits);
  }
  info.validation = options.validation;

  VkPhysicalDeviceConditionalRenderingFeaturesEXT conditional{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_CONDITIONAL_RENDERING_FEATURES_EXT};
  VkPhysicalDeviceVulkan12Features f12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  const bool conditional_ext = has_device_extension(chosen, VK_EXT_CONDITIONAL_RENDERING_EXTENSION_NAME);
  if (conditional_ext) f12.pNext = &conditional;
  VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  features.pNext = &f12;
  vkGetPhysicalDeviceFeatures2(chosen, &features);
  std::vector<std::string> missing;
  if (!features.features.occlusionQueryPrecise) missing.emplace_back("occlusionQueryPrecise");
  if (!features.features.depthClamp) missing.emplace_back("depthClamp");
  if (!features.features.independentBlend) missing.emplace_back("independentBlend");
  if (!f12.hostQueryReset) missing.emplace_back("hostQueryReset");
  if (!missing.empty())
    throw VulkanUnavailable(fmt::format("Vulkan: device '{}' lacks {}", info.name, fmt::join(missing, ", ")));

  // Only what is used is enabled.
  VkPhysicalDeviceConditionalRenderingFeaturesEXT enable_conditional{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_CONDITIONAL_RENDERING_FEATURES_EXT};
  enable_conditional.conditionalRendering = VK_TRUE;
  VkPhysicalDeviceVulkan12Features enable12{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_VULKAN_1_2_FEATURES};
  enable12.hostQueryReset = VK_TRUE;
  enable12.drawIndirectCount = f12.drawIndirectCount;
  info.draw_indirect_count = f12.drawIndirectCount == VK_TRUE;
  info.conditional_rendering = conditional_ext && conditional.conditionalRendering == VK_TRUE;
  if (info.conditional_rendering) enable12.pNext = &enable_conditional;
  VkPhysicalDeviceFeatures2 enable{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2};
  enable.pNext = &enable12;
  enable.features.occlusionQueryPrecise = VK_TRUE;
  enable.features.depthClamp = VK_TRUE;
  enable.features.independentBlend = VK_TRUE;
  enable.features.multiDrawIndirect = features.features.multiDrawIndirect;
  enable.features.drawIndirectFirstInstance = features.features.drawIndirectFirstInstance;

  const float priority = 1.0f;
  VkDeviceQueueCreateInfo qci{VK_STRUCTURE_TYPE_DEVICE_QUEUE_CREATE_INFO};
  qci.queueFamilyIndex = h.queue_family;
  qci.queueCount = 1;
  qci.pQueuePriorities = &priority;
  std::vector<const char*> device_extensions;
  if (info.conditional_rendering) device_extensions.push_back(VK_EXT_CONDITIONAL_RENDERING_EXTENSION_NAME);
  VkDeviceCreateInfo dci{VK_STRUCTURE_TYPE_DEVICE_CREATE_INFO};
  dci.pNext = &enable;
  dci.queueCreateInfoCount = 1;
  dci.pQueueCreateInfos = &qci;
  dci.enabledExtensionCount = std::uint32_t(device_extensions.size());
  dci.ppEnabledExtensionNames = device_extensions.data();
  if (const VkResult r = vkCreateDevice(chosen, &dci, nullptr, &h.device); r != VK_SUCCESS)
    throw VulkanUnavailable(fmt::format("Vulkan: vkCreateDevice on '{}' failed ({})", info.name, result_name(r)));
  vkGetDeviceQueue(h.device, h.queue_family, 0, &h.queue);
  if (info.conditional_rendering) {
    h.begin_conditional = reinterpret_cast<PFN_vkCmdBeginConditionalRenderingEXT>(
        vkGetDeviceProcAddr(h.device, "vkCmdBeginConditionalRenderingEXT"));
    h.end_conditional = reinterpret_cast<PFN_vkCmdEndConditionalRenderingEXT>(
        vkGetDeviceProcAddr(h.device, "vkCmdEndConditionalRenderingEXT"));
    if (!h.begin_conditional || !h.end_conditional) info.conditional_rendering = false;
  }
  return c;
}

Context::~Context() {
  Handles& h = *handles_;
  if (h.device) {
    vkDeviceWaitIdle(h.device);
    vkDestroyDevice(h.device, nullptr);
  }
  if (h.messenger) {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(h.instance, "vkDestroyDebugUtilsMessengerEXT"));
    if (destroy) destroy(h.instance, h.messenger, nullptr);
  }
  if (h.instance) vkDestroyInstance(h.instance, nullptr);
}

int Context::validation_errors() const noexcept { return handles_->errors; }
int Context::validation_warnings() const noexcept { return handles_->warnings; }
std::string Context::first_validation_error() const { return handles_->first_error; }

void Context::check(std::string_view where) {
  Handles& h = *handles_;
  if (h.errors == h.errors_checked) return;
  const int n = h.errors - h.errors_checked;
  h.errors_checked = h.errors;
  throw VulkanError(fmt::format("Vulkan validation, {}: {}{}", where, h.first_error,
                                n > 1 ? fmt::format(" (and {} more errors)", n - 1) : std::string()));
}

}  // namespace occull::vk
