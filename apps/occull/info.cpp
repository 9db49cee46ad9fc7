// `occull info`: the GL device: vendor, renderer, version, query counter bits, culling extensions.
#include "cli.hpp"
#include "occull/gl/context.hpp"
#include "occull/gl/renderer.hpp"

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
  return 0;
}

}  // namespace

Command add_info(CLI::App& app) {
  app.add_subcommand("info", "GL vendor, renderer, version, query counter bits, culling extensions");
  return cmd_info;
}

}  // namespace occull::app
