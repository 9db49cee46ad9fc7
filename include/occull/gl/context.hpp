// occull — a headless OpenGL 4.5 core context (EGL, no window, no X server).
#pragma once

#include <memory>
#include <string>
#include <vector>

namespace occull::gl {

/// What the current device reports (occull info).
struct DeviceInfo {
  std::string vendor;
  std::string renderer;
  std::string version;
  std::string glsl_version;
  std::string egl_platform;           ///< "surfaceless" or "device"
  int samples_passed_bits = 0;        ///< GL_QUERY_COUNTER_BITS of GL_SAMPLES_PASSED
  int any_samples_passed_bits = 0;
  int time_elapsed_bits = 0;
  int timestamp_bits = 0;
  /// Culling-relevant extensions present (occlusion queries themselves are
  /// core in 4.5 and not listed as extensions).
  std::vector<std::string> culling_extensions;
};

/// Owns an OpenGL 4.5 core context on the process's headless EGL display,
/// current on the creating thread for the object's lifetime. Not copyable;
/// one per thread. The display stays initialised after the last Context is
/// gone (see ~Context): the driver is loaded once per process.
class Context {
 public:
  /// Creates the context: Mesa's surfaceless platform first, the EGL device
  /// platform as fallback. Throws GlUnavailable with a message that names
  /// what is missing (EGL library, platform, OpenGL 4.5 core support).
  static std::unique_ptr<Context> create();
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  [[nodiscard]] DeviceInfo info() const;

 private:
  Context() = default;
  void* display_ = nullptr;
  void* context_ = nullptr;
  std::string platform_;
};

}  // namespace occull::gl
