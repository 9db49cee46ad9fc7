// occull — a headless OpenGL 4.5 context (EGL, no window, no X server), core
// profile unless asked for compatibility.
#pragma once

#include <array>
#include <memory>
#include <string>
#include <string_view>
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

/// How to create a Context.
struct ContextOptions {
  /// A debug context whose driver reports every failing GL call (KHR_debug,
  /// synchronous: the report is made inside the failing call, whose call
  /// stack is kept); Context::check() turns the first report into a
  /// GlError. Costs driver time: off for benchmarks. Always on in a debug
  /// build of occull (NDEBUG not defined when the library was compiled).
  bool debug = false;
  /// A compatibility-profile context (fixed-function calls allowed) instead
  /// of a core one: for renderers that need it, such as Debian's
  /// OpenSceneGraph (built for OpenGL 2 and its fixed-function pipeline).
  bool compatibility = false;
};

/// Owns an OpenGL 4.5 context (ContextOptions: core or compatibility) on the process's headless EGL display,
/// current on the creating thread for the object's lifetime. Not copyable;
/// one per thread. The display stays initialised after the last Context is
/// gone (see ~Context): the driver is loaded once per process.
class Context {
 public:
  /// Creates the context: Mesa's surfaceless platform first, the EGL device
  /// platform as fallback. Throws GlUnavailable with a message that names
  /// what is missing (EGL library, platform, OpenGL 4.5 core support).
  static std::unique_ptr<Context> create(const ContextOptions& options = {});
  ~Context();
  Context(const Context&) = delete;
  Context& operator=(const Context&) = delete;

  [[nodiscard]] DeviceInfo info() const;

  /// Makes this context current on the calling thread again, after other
  /// GL code (a window's context: occull view) had its own current. Throws
  /// GlUnavailable if EGL refuses.
  void make_current();
  /// Leaves the calling thread without a current EGL context, so another
  /// API's (GLX) may be made current.
  void release();

  /// Whether the driver reports failing calls (ContextOptions::debug).
  [[nodiscard]] bool debug() const noexcept { return debug_; }
  /// Throws GlError if a GL call on this context failed since the last
  /// check, naming `where` (the phase the caller was in), the driver's first
  /// report, how many followed, and the failing call's stack; then forgets
  /// them. Without debug output it does nothing. Cheap when nothing failed.
  void check(std::string_view where);

  /// What the driver reported (called by it, synchronously, on the thread
  /// of the failing call). Not for callers.
  void on_report(unsigned type, unsigned id, const char* message) noexcept;

 private:
  Context() = default;
  bool debug_ = false;
  int errors_ = 0;              // failed calls reported since the last check()
  std::string first_error_;     // the first one's report
  std::array<void*, 24> stack_{};  // the first one's call stack
  int stack_depth_ = 0;
  void* display_ = nullptr;
  void* context_ = nullptr;
  std::string platform_;
};

}  // namespace occull::gl
