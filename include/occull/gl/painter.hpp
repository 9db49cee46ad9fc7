// occull — draws the debug views' pictures (occull/debug_view.hpp) with
// OpenGL: headless into its own target (occull render --view), or into a
// window's framebuffer (occull view).
#pragma once

#include "occull/debug_view.hpp"
#include "occull/scene.hpp"

#include <cstdint>
#include <memory>
#include <span>
#include <vector>

namespace occull::gl {

/// Draws Pictures of one scene. Holds its own copy of the scene's meshes
/// (uploaded once; objects are drawn at their current transforms), its
/// programs and an offscreen RGBA8 + depth target of width x height.
///
/// Drawing: the background (the frame's image, or the picture's clear
/// colour), then objects in their flat colour lit by a fixed sun
/// (depth-tested), then boxes in their colour with a fixed shade per face
/// axis (x 0.8, y 1.0, z 0.65; front faces only, depth-tested among
/// themselves), then lines of one pixel over everything.
///
/// GL state: like the renderer, the painter owns no context state between
/// calls; each paint sets the framebuffer, viewport and every capability,
/// program, vertex array and mask its passes rely on.
///
/// Preconditions: a gl::Context is current on the calling thread for the
/// painter's whole life; `scene` outlives it and keeps its meshes.
class Painter {
 public:
  /// Throws InputError for a size outside [1, limits::viewport_side].
  Painter(const Scene& scene, int width, int height);
  ~Painter();
  Painter(const Painter&) = delete;
  Painter& operator=(const Painter&) = delete;

  /// Draws `picture` into the painter's target and returns it as RGBA8,
  /// width*height pixels, top row first (as Renderer::read_rgba). `frame` is
  /// the frame's own image in that layout, used when
  /// picture.frame_background (precondition: width*height*4 bytes then).
  [[nodiscard]] std::vector<std::uint8_t> paint(const Picture& picture, std::span<const std::uint8_t> frame);

  /// The same into framebuffer `framebuffer` (0: the window's), over its
  /// viewport (0, 0, width, height) of the painter's size. Precondition: it
  /// has a depth attachment (a window: a depth buffer).
  void paint_into(std::uint32_t framebuffer, const Picture& picture, std::span<const std::uint8_t> frame);

  [[nodiscard]] int width() const noexcept;
  [[nodiscard]] int height() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace occull::gl
