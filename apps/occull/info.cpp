// `occull info`: the GL device: vendor, renderer, version, query counter bits, culling extensions;
// and the Vulkan device `--api vulkan` would render on, where this build has Vulkan.
#include "cli.hpp"
#include "occull/error.hpp"
#include "occull/gl/context.hpp"
#include "occull/gl/renderer.hpp"
#ifdef OCCULL_HAVE_VULKAN
#include "occull/vk/context.hpp"
#endif

#include <fmt/format.h>

namespace occull::app {

namespace {

int cmd_info() {
  const auto context = occull::gl::Context::create();
  const auto d = context->info();
  fmt::print("vendor          {}\nrenderer        {}\nversion         {}\nGLSL            {}\n"
             "EGL platform    {}\n",
             d.vendor, d.renderer, d.version, d.glsl_version, d.egl_platform);
  fmt::print("query counter bits: GL_SAMPLES_PASSED {}, GL_ANY_SAMPLES_PASSED {}, GL_TIME_ELAPSED {}, "
             "GL_TIMESTAMP {}\n",
             d.samples_passed_bits, d.any_samples_passed_bits, d.time_elapsed_bits, d.timestamp_bits);
  fmt::print("occlusion queries (GL_SAMPLES_PASSED, GL_ANY_SAMPLES_PASSED[_CONSERVATIVE]), "
             "conditional rendering and timer queries are core in OpenGL 4.5.\n");
  fmt::print("query boxes are kept conservative by: {}\n",
             occull::gl::describe_query_raster(occull::gl::RendererOptions{}));
  fmt::print("culling-relevant extensions ({}):\n", d.culling_extensions.size());
  for (const auto& e : d.culling_extensions) fmt::print("  {}\n", e);
#ifdef OCCULL_HAVE_VULKAN
  try {
    const auto vk = occull::vk::Context::create();
    const occull::vk::DeviceInfo& v = vk->info();
    fmt::print("Vulkan (--api vulkan): {} | Vulkan {} | {}\n  conditional rendering {}, drawIndirectCount {}, "
               "timestamps {} bits\n",
               v.name, v.api_version, v.driver, v.conditional_rendering ? "yes" : "no",
               v.draw_indirect_count ? "yes" : "no", v.timestamp_bits);
  } catch (const occull::VulkanUnavailable& e) {
    fmt::print("Vulkan (--api vulkan): unavailable: {}\n", e.what());
  }
#else
  fmt::print("Vulkan (--api vulkan): not in this build (needs libvulkan-dev and glslc at build time)\n");
#endif
  return 0;
}

}  // namespace

Command add_info(CLI::App& app) {
  app.add_subcommand("info", "GL vendor, renderer, version, query counter bits, culling extensions; the Vulkan device");
  return cmd_info;
}

}  // namespace occull::app
