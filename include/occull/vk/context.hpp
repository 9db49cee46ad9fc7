// occull — a headless Vulkan device (no window, no surface): the instance,
// one physical device and its graphics queue, for occull::vk::Renderer.
#pragma once

#include <cstdint>
#include <memory>
#include <string>
#include <string_view>
#include <vector>

namespace occull::vk {

/// What the device reports (occull info, the reports' device line).
struct DeviceInfo {
  std::string name;         ///< e.g. "llvmpipe (LLVM 15.0.6, 256 bits)"
  std::string api_version;  ///< the device's Vulkan version, "1.3.230"
  std::string driver;       ///< driver name and version, e.g. "llvmpipe | Mesa 22.3.6"
  bool conditional_rendering = false;  ///< VK_EXT_conditional_rendering (and enabled)
  bool draw_indirect_count = false;    ///< vkCmdDrawIndexedIndirectCount (Vulkan 1.2 feature drawIndirectCount)
  int timestamp_bits = 0;              ///< timestampValidBits of the graphics queue (0: no timestamps)
  double timestamp_period_ns = 0.0;    ///< nanoseconds per timestamp tick
  bool validation = false;             ///< the Khronos validation layer is on
};

struct ContextOptions {
  /// Turns on the Khronos validation layer (Debian's vulkan-validationlayers)
  /// and counts what it reports: check() throws VulkanError on any error.
  /// Creation throws VulkanUnavailable when the layer is not installed.
  /// Costs CPU time: off for benchmarks, on in the tests.
  bool validation = false;
  /// Pick the first device whose name contains this (empty: the first
  /// device, preferring a discrete or integrated GPU to a CPU device).
  std::string device_name;
};

/// Owns a Vulkan instance and logical device with one graphics queue. Not
/// copyable. Usable from one thread at a time (the renderer records and
/// submits on the caller's thread). Needs a Vulkan 1.2 device with
/// occlusionQueryPrecise, depthClamp, independentBlend and hostQueryReset
/// (lavapipe and every desktop GPU driver have them).
class Context {
 public:
  /// Throws VulkanUnavailable naming what is missing (the loader, a device,
  /// a feature, the validation layer) and the Debian package with it.
  static std::unique_ptr<Context> create(const ContextOptions& options = {});
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  [[nodiscard]] const DeviceInfo& info() const noexcept { return info_; }

  /// Errors the validation layer reported since creation (0 without validation).
  [[nodiscard]] int validation_errors() const noexcept;
  /// Warnings it reported (performance warnings included).
  [[nodiscard]] int validation_warnings() const noexcept;
  /// The first error's message (empty when none).
  [[nodiscard]] std::string first_validation_error() const;
  /// Throws VulkanError naming `where`, the first report and how many
  /// followed when the layer reported an error since the last check; then
  /// forgets them. Without validation it does nothing.
  void check(std::string_view where);

  /// The Vulkan handles, for occull::vk::Renderer (opaque here so that
  /// this header needs no Vulkan headers): VkInstance, VkPhysicalDevice,
  /// VkDevice, VkQueue, and the queue's family index.
  struct Handles;
  [[nodiscard]] const Handles& handles() const noexcept { return *handles_; }

 private:
  Context();
  std::unique_ptr<Handles> handles_;
  DeviceInfo info_;
};

}  // namespace occull::vk
