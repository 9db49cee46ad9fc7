// occull — error types shared by the library and the tools.
#pragma once

#include <stdexcept>
#include <string>

namespace occull {

/// Bad input from a user: an unknown name, an invalid number, a corrupt file,
/// and values that can come from such input (a non-finite transform, a count
/// past occull::limits). The message says what is wrong and, for names,
/// lists the valid ones. Tools map it to exit code 2.
class InputError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A caller broke a documented precondition of occull's API: an id that
/// does not exist, a query not in flight, calls out of their order, a size
/// out of range. A bug in the calling program, not in its input: the message
/// names the call and the precondition. Checked wherever the check costs
/// little beside the call, never by assert alone (docs/library.md, "Errors").
/// Tools map it to exit code 1.
class UsageError : public std::logic_error {
 public:
  using std::logic_error::logic_error;
};

/// The platform cannot run the OpenGL reference renderer (no EGL display, no
/// OpenGL 4.5 core context). The message names what is missing and which
/// package or driver provides it. Tools map it to exit code 3.
class GlUnavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// The platform cannot run the Vulkan renderer (occull::vk): no Vulkan
/// loader, no device, or a device without what occull needs (a Vulkan 1.2
/// device with precise occlusion queries, depth clamping, independent blending
/// and host query reset). The message names what is missing and the package
/// that provides it. Tools map it to exit code 3, as GlUnavailable.
class VulkanUnavailable : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A Vulkan call failed (its VkResult is named), a validation layer reported
/// an error (vk::Context with validation on), or a shader module was
/// refused. A bug in occull or in the driver. Tools map it to exit code 1.
class VulkanError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// A run-time invariant of the measuring instrument failed (e.g. the ground
/// truth is empty while the frame shows objects): nothing it measured can be
/// trusted, so the run stops. The message names the invariant, the scene,
/// the path and the frame. Tools map it to exit code 1.
class InvariantViolation : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

/// An OpenGL call failed: the driver's debug output reported it (a context
/// created with ContextOptions::debug, occull --gl-debug, or any context of a
/// debug build; the message names the phase, the driver's report and the
/// call stack), the GL error flag was set, a shader did not compile or link,
/// or a framebuffer is incomplete. A bug in occull or in the driver. Tools
/// map it to exit code 1.
class GlError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

}  // namespace occull
