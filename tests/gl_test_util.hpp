// Test helper for GL tests: a small, fast render target.
#pragma once

#include "occull/gl/renderer.hpp"

namespace occull::test {

/// Renderer options for a width x height target without id writes (the
/// harness re-draws ids in its untimed truth pass).
inline gl::RendererOptions small_target(int width, int height) {
  gl::RendererOptions o;
  o.width = width;
  o.height = height;
  o.write_ids = false;
  return o;
}

}  // namespace occull::test
