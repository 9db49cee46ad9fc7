// The lab's Vulkan device: vk::Renderer on a headless Vulkan device
// (lavapipe here), the validation layer on when the lab asks for a debug
// context (--gl-debug, debug builds).
#include "occull/render_device.hpp"

#include "occull/error.hpp"
#include "occull/vk/context.hpp"
#include "occull/vk/renderer.hpp"

#include <fmt/format.h>

namespace occull {
namespace {

vk::RendererOptions vulkan_options(const gl::RendererOptions& o) {
  const gl::RendererOptions defaults;
  if (o.query_mode != defaults.query_mode)
    throw InputError("--api vulkan: its queries count samples (precise occlusion queries); "
                     "another query mode is OpenGL's only");
  if (o.draw != defaults.draw)
    throw InputError("--api vulkan: draws one object per draw; --draw multi and indirect are OpenGL's only");
  if (o.query_raster != defaults.query_raster)
    throw InputError("--api vulkan: keeps query boxes conservative by their margin; --query-raster is OpenGL's only");
  vk::RendererOptions v;
  v.width = o.width;
  v.height = o.height;
  v.write_ids = o.write_ids;
  v.cull_backfaces = o.cull_backfaces;
  v.background = o.background;
  v.query_margin_px = o.query_margin_px;
  return v;
}

class VulkanDevice final : public RenderDevice {
 public:
  VulkanDevice(const Scene& scene, const gl::RendererOptions& renderer, const gl::ContextOptions& context)
      : scene_(scene), options_(vulkan_options(renderer)) {
    context_options_.validation = context.debug;
#ifndef NDEBUG
    context_options_.validation = true;  // as a debug build's GL contexts are debug contexts
#endif
    context_ = vk::Context::create(context_options_);
    const vk::DeviceInfo& v = context_->info();
    info_.vendor = "Vulkan";
    info_.renderer = v.name;
    info_.version = fmt::format("Vulkan {} ({})", v.api_version, v.driver);
    info_.timestamp_bits = v.timestamp_bits;
    if (v.conditional_rendering) info_.culling_extensions.emplace_back("VK_EXT_conditional_rendering");
    if (v.draw_indirect_count) info_.culling_extensions.emplace_back("drawIndirectCount");
    renderer_ = std::make_unique<vk::Renderer>(*context_, scene_, options_);
  }
  ~VulkanDevice() override {
    renderer_.reset();
    context_.reset();
  }

  [[nodiscard]] Api api() const noexcept override { return Api::vulkan; }
  [[nodiscard]] Backend& backend() noexcept override { return *renderer_; }
  void begin_frame(const View& view) override { renderer_->begin_frame(view); }
  double end_frame() override { return renderer_->end_frame(); }
  [[nodiscard]] std::uint64_t unread_result(QueryId q) override { return renderer_->unread_result(q); }
  [[nodiscard]] std::size_t queries_in_flight() const noexcept override { return renderer_->queries_in_flight(); }
  [[nodiscard]] std::vector<gl::Renderer::ObjectPixels> visible_pixels(const View& view,
                                                                       std::span<const ObjectId> objects,
                                                                       gl::Renderer::PassImages* images) override {
    vk::Renderer::PassImages vk_images;
    std::vector<gl::Renderer::ObjectPixels> out;
    for (const auto& p : renderer_->visible_pixels(view, objects, images ? &vk_images : nullptr))
      out.push_back({p.id, p.pixels});
    if (images) {
      images->ids = std::move(vk_images.ids);
      images->depth = std::move(vk_images.depth);
    }
    return out;
  }
  [[nodiscard]] std::uint64_t samples_in_front(const View& view, std::span<const ObjectId> objects) override {
    return renderer_->samples_in_front(view, objects);
  }
  [[nodiscard]] std::vector<float> read_depth() override { return renderer_->read_depth(); }
  [[nodiscard]] std::vector<std::uint8_t> read_rgba() override { return renderer_->read_rgba(); }
  [[nodiscard]] gl::Renderer::Resources resources() const override {
    const vk::Renderer::Resources r = renderer_->resources();
    return {r.queries, r.queries_free, r.buffers, r.buffer_bytes};
  }
  void check(std::string_view where) override { context_->check(where); }
  [[nodiscard]] const gl::DeviceInfo& info() const noexcept override { return info_; }
  [[nodiscard]] int width() const noexcept override { return renderer_->width(); }
  [[nodiscard]] int height() const noexcept override { return renderer_->height(); }
  void reset() override {
    renderer_.reset();
    renderer_ = std::make_unique<vk::Renderer>(*context_, scene_, options_);
  }

 private:
  const Scene& scene_;
  vk::RendererOptions options_;
  vk::ContextOptions context_options_;
  std::unique_ptr<vk::Context> context_;
  gl::DeviceInfo info_;
  std::unique_ptr<vk::Renderer> renderer_;
};

}  // namespace

std::unique_ptr<RenderDevice> make_vulkan_device(const Scene& scene, const gl::RendererOptions& renderer,
                                                 const gl::ContextOptions& context) {
  return std::make_unique<VulkanDevice>(scene, renderer, context);
}

}  // namespace occull
