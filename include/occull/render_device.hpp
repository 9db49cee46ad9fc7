// occull — the renderer a Session draws and measures with, whichever
// graphics API it speaks: OpenGL (gl::Renderer in a headless EGL context) or
// Vulkan (vk::Renderer on a headless Vulkan device). The lab's frames, its
// ground truth and its checks go through this interface only, so every
// command that runs frames (bench, render, soak) runs them through either.
#pragma once

#include "occull/backend.hpp"
#include "occull/gl/context.hpp"
#include "occull/gl/renderer.hpp"
#include "occull/scene.hpp"
#include "occull/view.hpp"

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace occull {

/// The graphics APIs the lab renders through.
enum class Api : std::uint8_t {
  gl,      ///< OpenGL 4.5 (occull::gl): the reference renderer
  vulkan,  ///< Vulkan 1.2 (occull::vk), where this build has it
};

/// "gl" or "vulkan".
[[nodiscard]] std::string_view api_name(Api api) noexcept;
/// The API named `name` ("gl", "opengl", "vulkan", "vk"). Throws InputError
/// listing the valid names, or saying that this build has no Vulkan.
[[nodiscard]] Api parse_api(std::string_view name);
/// Whether this build of the lab has the API (Vulkan: built when Debian's
/// libvulkan-dev and glslc were there).
[[nodiscard]] bool api_built(Api api) noexcept;

class RenderDevice {
 public:
  virtual ~RenderDevice() = default;

  [[nodiscard]] virtual Api api() const noexcept = 0;
  /// The renderer as cullers see it (valid until reset()).
  [[nodiscard]] virtual Backend& backend() noexcept = 0;
  /// As gl::Renderer's: a frame is begin_frame(), Backend calls, end_frame()
  /// (which waits for the device and returns its GPU time, ms).
  virtual void begin_frame(const View& view) = 0;
  virtual double end_frame() = 0;
  /// A query's result without ending its flight (RecordingBackend::finish_frame).
  [[nodiscard]] virtual std::uint64_t unread_result(QueryId q) = 0;
  [[nodiscard]] virtual std::size_t queries_in_flight() const noexcept = 0;

  /// The untimed truth pass (gl::Renderer::visible_pixels), its images with `images`.
  [[nodiscard]] virtual std::vector<gl::Renderer::ObjectPixels> visible_pixels(
      const View& view, std::span<const ObjectId> objects, gl::Renderer::PassImages* images) = 0;
  /// Samples of `objects` passing the depth test of the last pass (gl::Renderer::samples_in_front).
  [[nodiscard]] virtual std::uint64_t samples_in_front(const View& view, std::span<const ObjectId> objects) = 0;
  /// The depth image after a frame: canonical, bottom row first (gl::Renderer::read_depth).
  [[nodiscard]] virtual std::vector<float> read_depth() = 0;
  /// The colour image after a frame: RGBA8, top row first.
  [[nodiscard]] virtual std::vector<std::uint8_t> read_rgba() = 0;
  /// The objects the renderer holds (occull soak watches them grow).
  [[nodiscard]] virtual gl::Renderer::Resources resources() const = 0;

  /// Throws (GlError, VulkanError) when the driver or the validation layer
  /// reported a failing call since the last check, naming `where`.
  virtual void check(std::string_view where) = 0;
  /// What the device reports, in the lab's words (the reports' device line):
  /// for Vulkan, `renderer` is the device's name and `version` "Vulkan
  /// 1.3.230 (driver)".
  [[nodiscard]] virtual const gl::DeviceInfo& info() const noexcept = 0;
  [[nodiscard]] virtual int width() const noexcept = 0;
  [[nodiscard]] virtual int height() const noexcept = 0;

  /// Replaces the context and renderer by fresh ones (Session::reset_renderer).
  virtual void reset() = 0;
  /// The OpenGL renderer and context, or null for another API.
  [[nodiscard]] virtual gl::Renderer* gl_renderer() noexcept { return nullptr; }
  [[nodiscard]] virtual gl::Context* gl_context() noexcept { return nullptr; }
};

/// Creates the context and the renderer of `api` for `scene` (which outlives
/// them). Vulkan takes of `renderer` what it has (size, ids, back faces,
/// background, query margin) and throws InputError for an option it does
/// not have (another query mode, draw mode or query rasterisation), and
/// of `context` the debug flag (as the validation layer). Throws
/// GlUnavailable or VulkanUnavailable when the API cannot run here.
[[nodiscard]] std::unique_ptr<RenderDevice> make_render_device(Api api, const Scene& scene,
                                                               const gl::RendererOptions& renderer,
                                                               const gl::ContextOptions& context);

}  // namespace occull
