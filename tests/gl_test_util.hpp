// Test helper for GL tests: a small, fast render target.
#pragma once

#include "occull/gl/context.hpp"
#include "occull/gl/renderer.hpp"

#include <cstdint>
#include <set>
#include <vector>

namespace occull::test {

/// Renderer options for a width x height target without id writes (the
/// lab re-draws ids in its untimed truth pass).
inline gl::RendererOptions small_target(int width, int height) {
  gl::RendererOptions o;
  o.width = width;
  o.height = height;
  o.write_ids = false;
  return o;
}

/// Whether the GL driver is Mesa's llvmpipe: tests that pin its
/// rasterisation (a pixel it covers, a depth it gets wrong) run only there.
inline bool on_llvmpipe() {
  auto context = gl::Context::create();
  return context->info().renderer.find("llvmpipe") != std::string::npos;
}

/// The objects an id image (gl::Renderer::read_ids) shows.
inline std::set<ObjectId> ids_in(const std::vector<std::uint32_t>& pixels) {
  std::set<ObjectId> ids;
  for (std::uint32_t p : pixels)
    if (p != 0) ids.insert(p - 1);
  return ids;
}

}  // namespace occull::test
