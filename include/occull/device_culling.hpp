// occull — an optional Backend capability: culling and drawing on the device
// (GPU-driven two-phase depth-pyramid culling, the `hiz` culler).
//
// Every other culler decides on the CPU and hands the backend lists of
// objects. GPU-driven culling needs the device itself to test every object
// and to write its own draw commands, so a backend that offers it holds, on
// the device:
//   - every object's world box, draw command (its mesh's index range) and
//     material, kept current as objects move, are added or removed;
//   - one visibility bit per object and per culler (a Visibility), written by
//     one frame and read by the next;
//   - the frame's depth buffer as something a compute pass can read, and a
//     depth pyramid built from it (each texel the farthest depth of the
//     texels below it; see occull/depth_pyramid.hpp for the test's rules,
//     all ten: rule 9 for a single-sampled view of the target's size);
//   - indirect draws whose commands the device writes (no per-object work on
//     the CPU).
// An engine's backend offers it by returning itself (or a helper) from
// Backend::device_culling(); a backend without it returns null and `hiz`
// refuses it with a message.
#pragma once

#include "occull/scene.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace occull {

/// GPU times of a frame's device-culling passes, milliseconds (0 where the
/// device has no timer).
struct DeviceCullingTimes {
  double pyramid_ms = 0.0;  ///< building the depth pyramid
  double cull_ms = 0.0;     ///< the two test-and-write-commands dispatches
};

/// The device side of two-phase occlusion culling. A frame of `hiz` is:
///   draw_previously_visible(v); build_depth_pyramid(); draw_newly_visible(v);
/// between the renderer's frame start and end (for gl::Renderer:
/// begin_frame() and end_frame()), with the frame's view.
///
/// What is drawn: an object is drawn at most once a frame; translucent
/// objects are drawn after every opaque one (they never occlude) and never in
/// phase 1. Objects removed from the scene, without triangles or outside the
/// view's frustum are never drawn.
class DeviceCulling {
 public:
  /// One culler's visibility on the device: one bit per object, all clear
  /// when created (so a culler's first frame draws nothing in phase 1 and
  /// tests everything in phase 2 against an empty pyramid: all drawn).
  using Visibility = std::uint32_t;

  virtual ~DeviceCulling() = default;

  /// A new visibility, all objects not visible. Hand it back with
  /// destroy_visibility() before the backend goes.
  [[nodiscard]] virtual Visibility create_visibility() = 0;
  /// Frees `v`. Precondition: v from create_visibility(), not yet destroyed.
  virtual void destroy_visibility(Visibility v) = 0;

  /// Sets `v` to `visible` (every other object not visible), as if the last
  /// draw_newly_visible(v) had found exactly those visible: a culler taking
  /// over another's visibility (auto's hand-over). Ids past the scene are
  /// ignored. Precondition: v from create_visibility(), not yet destroyed.
  virtual void set_visible(Visibility v, std::span<const ObjectId> visible) = 0;
  /// Appends to `out`, ascending, the objects whose bit is set in `v`: what
  /// the last draw_newly_visible(v) found visible (or set_visible() set), for
  /// a culler handing its visibility over to another (auto's switch from
  /// `hiz` to a query culler). Reads the device's buffer back: it waits for
  /// the device. Precondition: v from create_visibility(), not yet destroyed.
  virtual void read_visible(Visibility v, std::vector<ObjectId>& out) = 0;
  /// Phase 1: draws every opaque object in the frustum whose bit is set in
  /// `v` (those found visible by the last draw_newly_visible(v)). Writes
  /// depth (and whatever else render() writes).
  virtual void draw_previously_visible(Visibility v) = 0;
  /// Builds the depth pyramid from the depth buffer as it stands (after
  /// phase 1). Each level's texel holds the farthest depth of the texels of
  /// the level below it that it covers; sizes halve rounding up, so an odd
  /// edge's last texel is kept.
  virtual void build_depth_pyramid() = 0;
  /// Phase 2: tests every object in the frustum against the pyramid, sets
  /// its bit in `v` to the outcome (visible or not), and draws those visible
  /// and not drawn yet this frame. Each test reads at most `texels` × `texels`
  /// texels (2, 4, 8 or 16; occull/depth_pyramid.hpp, rule 4): more reads at a
  /// finer level, a tighter test. Preconditions: build_depth_pyramid() ran
  /// in this frame, after the last draw that should occlude; texels is 2, 4,
  /// 8 or 16.
  virtual void draw_newly_visible(Visibility v, int texels) = 0;

  /// For instruments, after the frame: appends the objects the device drew
  /// in this frame (by either phase, each once, ascending) to `out`, and
  /// returns the GPU times of its passes. Waits for the device.
  virtual DeviceCullingTimes read_drawn(std::vector<ObjectId>& out) = 0;
};

}  // namespace occull
