// Internal to occull_vk: the Vulkan headers, the context's handles and
// checked calls.
#pragma once

#include "occull/error.hpp"
#include "occull/vk/context.hpp"

#include <vulkan/vulkan.h>

#include <string>
#include <string_view>

namespace occull::vk {

struct Context::Handles {
  VkInstance instance = VK_NULL_HANDLE;
  VkDebugUtilsMessengerEXT messenger = VK_NULL_HANDLE;
  VkPhysicalDevice physical = VK_NULL_HANDLE;
  VkDevice device = VK_NULL_HANDLE;
  VkQueue queue = VK_NULL_HANDLE;
  std::uint32_t queue_family = 0;
  VkPhysicalDeviceMemoryProperties memory{};
  // vkCmdBeginConditionalRenderingEXT and its end, when the extension is on.
  PFN_vkCmdBeginConditionalRenderingEXT begin_conditional = nullptr;
  PFN_vkCmdEndConditionalRenderingEXT end_conditional = nullptr;
  // What the validation layer reported (the messenger's callback counts).
  int errors = 0, warnings = 0, errors_checked = 0;
  std::string first_error;
};

/// The name of a VkResult ("VK_ERROR_DEVICE_LOST").
[[nodiscard]] std::string_view result_name(VkResult r) noexcept;

/// Throws VulkanError naming `call` and the result unless it is VK_SUCCESS.
inline void check(VkResult r, const char* call) {
  if (r != VK_SUCCESS) throw VulkanError(std::string("Vulkan: ") + call + " failed: " + std::string(result_name(r)));
}

}  // namespace occull::vk
