// The lab's OpenGL device: gl::Renderer in a headless EGL context.
#include "occull/render_device.hpp"

#include "occull/error.hpp"

#include <fmt/format.h>

namespace occull {
namespace {

class GlDevice final : public RenderDevice {
 public:
  GlDevice(const Scene& scene, const gl::RendererOptions& renderer, const gl::ContextOptions& context)
      : scene_(scene), renderer_options_(renderer), context_options_(context) {
    context_ = gl::Context::create(context_options_);
    info_ = context_->info();
    renderer_ = std::make_unique<gl::Renderer>(scene_, renderer_options_);
  }
  ~GlDevice() override {
    renderer_.reset();  // GL objects go before the context
    context_.reset();
    retired_.reset();
  }

  [[nodiscard]] Api api() const noexcept override { return Api::gl; }
  [[nodiscard]] Backend& backend() noexcept override { return *renderer_; }
  void begin_frame(const View& view) override { renderer_->begin_frame(view); }
  double end_frame() override { return renderer_->end_frame(); }
  [[nodiscard]] std::uint64_t unread_result(QueryId q) override { return renderer_->unread_result(q); }
  [[nodiscard]] std::size_t queries_in_flight() const noexcept override { return renderer_->queries_in_flight(); }
  [[nodiscard]] std::vector<gl::Renderer::ObjectPixels> visible_pixels(const View& view,
                                                                       std::span<const ObjectId> objects,
                                                                       gl::Renderer::PassImages* images) override {
    return renderer_->visible_pixels(view, objects, images);
  }
  [[nodiscard]] std::uint64_t samples_in_front(const View& view, std::span<const ObjectId> objects) override {
    return renderer_->samples_in_front(view, objects);
  }
  [[nodiscard]] std::vector<float> read_depth() override { return renderer_->read_depth(); }
  [[nodiscard]] std::vector<std::uint8_t> read_rgba() override { return renderer_->read_rgba(); }
  [[nodiscard]] gl::Renderer::Resources resources() const override { return renderer_->resources(); }
  void check(std::string_view where) override { context_->check(where); }
  [[nodiscard]] const gl::DeviceInfo& info() const noexcept override { return info_; }
  [[nodiscard]] int width() const noexcept override { return renderer_->width(); }
  [[nodiscard]] int height() const noexcept override { return renderer_->height(); }

  // The replaced context stays, idle, until the next replacement: destroyed
  // right after its last frame, llvmpipe's rasterizer threads could still be
  // leaving that frame (Session::reset_renderer).
  void reset() override {
    renderer_.reset();
    retired_.reset();
    retired_ = std::move(context_);
    context_ = gl::Context::create(context_options_);
    renderer_ = std::make_unique<gl::Renderer>(scene_, renderer_options_);
  }
  [[nodiscard]] gl::Renderer* gl_renderer() noexcept override { return renderer_.get(); }
  [[nodiscard]] gl::Context* gl_context() noexcept override { return context_.get(); }

 private:
  const Scene& scene_;
  gl::RendererOptions renderer_options_;
  gl::ContextOptions context_options_;
  std::unique_ptr<gl::Context> retired_;
  std::unique_ptr<gl::Context> context_;
  gl::DeviceInfo info_;
  std::unique_ptr<gl::Renderer> renderer_;
};

}  // namespace

// render_device_vk.cpp, where this build has Vulkan.
std::unique_ptr<RenderDevice> make_vulkan_device(const Scene& scene, const gl::RendererOptions& renderer,
                                                 const gl::ContextOptions& context);

std::string_view api_name(Api api) noexcept { return api == Api::vulkan ? "vulkan" : "gl"; }

bool api_built(Api api) noexcept {
#ifdef OCCULL_HAVE_VULKAN
  (void)api;
  return true;
#else
  return api == Api::gl;
#endif
}

Api parse_api(std::string_view name) {
  if (name == "gl" || name == "opengl") return Api::gl;
  if (name == "vulkan" || name == "vk") {
    if (!api_built(Api::vulkan))
      throw InputError("api vulkan: this build of occull has no Vulkan renderer (it needs libvulkan-dev and glslc "
                       "at build time: scripts/install-deps.sh installs them)");
    return Api::vulkan;
  }
  throw InputError(fmt::format("api '{}': not one of gl, vulkan", name));
}

std::unique_ptr<RenderDevice> make_render_device(Api api, const Scene& scene, const gl::RendererOptions& renderer,
                                                 const gl::ContextOptions& context) {
  if (api == Api::vulkan) {
#ifdef OCCULL_HAVE_VULKAN
    return make_vulkan_device(scene, renderer, context);
#else
    (void)parse_api("vulkan");  // throws, saying why
#endif
  }
  return std::make_unique<GlDevice>(scene, renderer, context);
}

}  // namespace occull
