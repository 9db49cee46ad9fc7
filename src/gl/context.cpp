#include "occull/gl/context.hpp"

#include "gl.hpp"
#include "occull/error.hpp"

#include <EGL/egl.h>
#include <EGL/eglext.h>
#include <fmt/format.h>

#include <cstdlib>
#include <cstring>
#include <cxxabi.h>
#include <execinfo.h>
#include <string_view>

namespace occull::gl {
namespace {

constexpr const char* kInstallHint =
    "install Mesa's EGL and OpenGL drivers (Debian: apt-get install libegl1 libopengl0 "
    "libgl1-mesa-dri; or run scripts/install-deps.sh) or a GPU driver with EGL";

bool has_extension(const char* list, std::string_view name) {
  if (!list) return false;
  std::string_view all(list);
  for (std::size_t pos = 0; pos < all.size();) {
    const std::size_t end = std::min(all.find(' ', pos), all.size());
    if (all.substr(pos, end - pos) == name) return true;
    pos = end + 1;
  }
  return false;
}

EGLDisplay open_display(std::string& platform) {
  const char* client = eglQueryString(EGL_NO_DISPLAY, EGL_EXTENSIONS);
  const auto get_platform_display = reinterpret_cast<PFNEGLGETPLATFORMDISPLAYEXTPROC>(
      eglGetProcAddress("eglGetPlatformDisplayEXT"));
  if (!get_platform_display)
    throw GlUnavailable(fmt::format("EGL has no eglGetPlatformDisplayEXT: {}", kInstallHint));
  EGLint major = 0, minor = 0;
  if (has_extension(client, "EGL_MESA_platform_surfaceless")) {
    EGLDisplay d = get_platform_display(EGL_PLATFORM_SURFACELESS_MESA, EGL_DEFAULT_DISPLAY, nullptr);
    if (d != EGL_NO_DISPLAY && eglInitialize(d, &major, &minor)) {
      platform = "surfaceless";
      return d;
    }
  }
  if (has_extension(client, "EGL_EXT_platform_device")) {
    const auto query_devices =
        reinterpret_cast<PFNEGLQUERYDEVICESEXTPROC>(eglGetProcAddress("eglQueryDevicesEXT"));
    EGLDeviceEXT devices[16];
    EGLint count = 0;
    if (query_devices && query_devices(16, devices, &count)) {
      for (EGLint i = 0; i < count; ++i) {
        EGLDisplay d = get_platform_display(EGL_PLATFORM_DEVICE_EXT, devices[i], nullptr);
        if (d != EGL_NO_DISPLAY && eglInitialize(d, &major, &minor)) {
          platform = "device";
          return d;
        }
      }
    }
  }
  throw GlUnavailable(fmt::format(
      "no headless EGL display (neither EGL_MESA_platform_surfaceless nor a usable "
      "EGL_EXT_platform_device): {}",
      kInstallHint));
}

#ifndef EGL_CONTEXT_OPENGL_DEBUG
#define EGL_CONTEXT_OPENGL_DEBUG 0x31B0
#endif

void GLAPIENTRY debug_callback(GLenum /*source*/, GLenum type, GLuint id, GLenum /*severity*/, GLsizei /*length*/,
                               const GLchar* message, const void* context) {
  static_cast<Context*>(const_cast<void*>(context))->on_report(type, id, message);
}

// "module(mangled+0x2f) [0x...]" as "module: demangled +0x2f" where the
// symbol demangles; as it was otherwise.
std::string readable_frame(const char* frame) {
  const std::string_view f(frame);
  const std::size_t open = f.find('('), plus = f.find('+', open), close = f.find(')', open);
  if (open == f.npos || plus == f.npos || close == f.npos || plus == open + 1 || plus > close) return std::string(f);
  const std::string mangled(f.substr(open + 1, plus - open - 1));
  int status = 0;
  char* name = abi::__cxa_demangle(mangled.c_str(), nullptr, nullptr, &status);
  std::string out = status == 0 && name ? fmt::format("{}: {} {}", f.substr(0, open), name, f.substr(plus, close - plus))
                                        : std::string(f);
  std::free(name);
  return out;
}

}  // namespace

std::unique_ptr<Context> Context::create(const ContextOptions& options) {
  std::unique_ptr<Context> self(new Context());
  self->debug_ = options.debug;
#ifndef NDEBUG
  self->debug_ = true;
#endif
  EGLDisplay display = open_display(self->platform_);
  self->display_ = display;
  if (!eglBindAPI(EGL_OPENGL_API)) {
    throw GlUnavailable(fmt::format("EGL cannot bind the desktop OpenGL API: {}", kInstallHint));
  }
  const EGLint config_attribs[] = {EGL_RENDERABLE_TYPE, EGL_OPENGL_BIT, EGL_NONE};
  EGLConfig config = nullptr;
  EGLint configs = 0;
  const bool no_config = has_extension(eglQueryString(display, EGL_EXTENSIONS),
                                       "EGL_KHR_no_config_context");
  if (!eglChooseConfig(display, config_attribs, &config, 1, &configs) || configs == 0) {
    if (!no_config)
      throw GlUnavailable(fmt::format("EGL offers no OpenGL config: {}", kInstallHint));
    config = nullptr;  // EGL_NO_CONFIG_KHR
  }
  const EGLint context_attribs[] = {EGL_CONTEXT_MAJOR_VERSION,       4,
                                    EGL_CONTEXT_MINOR_VERSION,       5,
                                    EGL_CONTEXT_OPENGL_PROFILE_MASK,
                                    options.compatibility ? EGL_CONTEXT_OPENGL_COMPATIBILITY_PROFILE_BIT
                                                          : EGL_CONTEXT_OPENGL_CORE_PROFILE_BIT,
                                    EGL_CONTEXT_OPENGL_DEBUG,        self->debug_ ? EGL_TRUE : EGL_FALSE,
                                    EGL_NONE};
  EGLContext context = eglCreateContext(display, config, EGL_NO_CONTEXT, context_attribs);
  if (context == EGL_NO_CONTEXT)
    throw GlUnavailable(fmt::format(
        "the driver cannot create an OpenGL 4.5 {} context (EGL error 0x{:x}); occull needs "
        "OpenGL 4.5: Mesa 20 or newer (llvmpipe works) or a GPU driver",
        options.compatibility ? "compatibility" : "core", eglGetError()));
  self->context_ = context;
  if (!eglMakeCurrent(display, EGL_NO_SURFACE, EGL_NO_SURFACE, context))
    throw GlUnavailable(fmt::format(
        "cannot make the context current without a surface (EGL error 0x{:x}; needs "
        "EGL_KHR_surfaceless_context)",
        eglGetError()));
  GLint gl_major = 0, gl_minor = 0;
  glGetIntegerv(GL_MAJOR_VERSION, &gl_major);
  glGetIntegerv(GL_MINOR_VERSION, &gl_minor);
  if (gl_major * 10 + gl_minor < 45)
    throw GlUnavailable(fmt::format("the context is OpenGL {}.{}; occull needs 4.5 core",
                                    gl_major, gl_minor));
  if (self->debug_) {
    // Synchronous: the driver reports inside the failing call, so its call
    // stack is the caller's.
    glEnable(GL_DEBUG_OUTPUT);
    glEnable(GL_DEBUG_OUTPUT_SYNCHRONOUS);
    glDebugMessageCallback(debug_callback, self.get());
    glDebugMessageControl(GL_DONT_CARE, GL_DONT_CARE, GL_DONT_CARE, 0, nullptr, GL_TRUE);
  }
  return self;
}

void Context::on_report(unsigned type, unsigned id, const char* message) noexcept {
  // Performance and portability notes are not failures.
  if (type != GL_DEBUG_TYPE_ERROR && type != GL_DEBUG_TYPE_UNDEFINED_BEHAVIOR) return;
  if (errors_++ > 0) return;
  try {
    first_error_ = fmt::format("{} (id {})", message ? message : "(no message)", id);
  } catch (...) {
    first_error_.clear();
  }
  stack_depth_ = backtrace(stack_.data(), int(stack_.size()));
}

void Context::check(std::string_view where) {
  if (errors_ == 0) return;
  std::string text = fmt::format("OpenGL error during {}: {}", where, first_error_);
  if (errors_ > 1) text += fmt::format(" (and {} more)", errors_ - 1);
  text += "; the failing call's stack:";
  char** names = backtrace_symbols(stack_.data(), stack_depth_);
  // The first frames are on_report and the callback: skipped.
  for (int i = 1; names && i < stack_depth_; ++i) text += fmt::format("\n  {}", readable_frame(names[i]));
  std::free(names);
  errors_ = 0;
  first_error_.clear();
  throw GlError(text);
}

void Context::make_current() {
  if (!eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, context_))
    throw GlUnavailable(fmt::format("cannot make occull's context current again (EGL error 0x{:x})", eglGetError()));
}

void Context::release() { eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT); }

Context::~Context() {
  if (display_) {
    // No work in flight when the context goes; a context that is not
    // current (Session's retired one) leaves the current one alone.
    if (eglGetCurrentContext() == context_) {
      glFinish();
      eglMakeCurrent(display_, EGL_NO_SURFACE, EGL_NO_SURFACE, EGL_NO_CONTEXT);
    }
    if (context_) eglDestroyContext(display_, context_);
    // No eglTerminate: the display is shared by every context of the process
    // (eglGetPlatformDisplay returns the same one), and terminating it makes
    // Mesa unload its driver. llvmpipe reloaded into a process whose LLVM
    // stays loaded runs its LLVM set-up again, and one occull bench in about
    // fifty then died of heap corruption. Initialising an initialised
    // display is a no-op, so the next Context reuses the loaded driver.
  }
}

DeviceInfo Context::info() const {
  DeviceInfo d;
  const auto str = [](GLenum e) {
    const auto* s = reinterpret_cast<const char*>(glGetString(e));
    return std::string(s ? s : "");
  };
  d.vendor = str(GL_VENDOR);
  d.renderer = str(GL_RENDERER);
  d.version = str(GL_VERSION);
  d.glsl_version = str(GL_SHADING_LANGUAGE_VERSION);
  d.egl_platform = platform_;
  const auto bits = [](GLenum target) {
    GLint b = 0;
    glGetQueryiv(target, GL_QUERY_COUNTER_BITS, &b);
    return int(b);
  };
  d.samples_passed_bits = bits(GL_SAMPLES_PASSED);
  d.any_samples_passed_bits = bits(GL_ANY_SAMPLES_PASSED);
  d.time_elapsed_bits = bits(GL_TIME_ELAPSED);
  d.timestamp_bits = bits(GL_TIMESTAMP);
  static constexpr std::string_view wanted[] = {
      "GL_ARB_occlusion_query2",           "GL_ARB_ES3_compatibility",
      "GL_ARB_conditional_render_inverted", "GL_NV_conditional_render",
      "GL_ARB_query_buffer_object",        "GL_ARB_timer_query",
      "GL_ARB_multi_draw_indirect",        "GL_ARB_indirect_parameters",
      "GL_ARB_shader_draw_parameters",     "GL_ARB_depth_clamp",
      "GL_NV_depth_buffer_float",          "GL_ARB_clip_control",
      "GL_ARB_direct_state_access",        "GL_ARB_base_instance",
      "GL_EXT_depth_bounds_test",          "GL_INTEL_conservative_rasterization",
      "GL_NV_conservative_raster",         "GL_ARB_compute_shader"};
  GLint n = 0;
  glGetIntegerv(GL_NUM_EXTENSIONS, &n);
  for (GLint i = 0; i < n; ++i) {
    const std::string_view ext(reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, GLuint(i))));
    for (std::string_view w : wanted)
      if (ext == w) d.culling_extensions.emplace_back(ext);
  }
  return d;
}

}  // namespace occull::gl
