// occull — the interface between a culler and a renderer.
//
// An engine integrates occull by implementing Backend over its own render
// queue; occull ships an OpenGL 4.5 implementation (occull/gl/renderer.hpp).
// Cullers never touch a graphics API: they only call these functions.
#pragma once

#include "occull/geometry.hpp"
#include "occull/scene.hpp"

#include <cstdint>
#include <span>

namespace occull {

class DeviceCulling;

/// Handle of an occlusion query in flight. Valid from issue_query() until
/// result() returns; the backend may reuse the number afterwards.
using QueryId = std::uint32_t;

/// Counters a backend keeps from its creation on (monotonic). Per-frame
/// figures are differences of two snapshots (operator-).
struct BackendStats {
  std::uint64_t draw_calls = 0;        ///< object draws
  std::uint64_t triangles = 0;         ///< triangles submitted in object draws
  std::uint64_t objects_rendered = 0;  ///< objects drawn (== draw_calls for one draw per object)
  std::uint64_t render_flushes = 0;    ///< calls of render() (render-queue flushes)
  std::uint64_t queries = 0;           ///< occlusion queries issued
  std::uint64_t query_boxes = 0;       ///< boxes drawn inside those queries
  std::uint64_t state_changes = 0;     ///< switches between rendering and querying state
  std::uint64_t material_changes = 0;  ///< material binds while rendering
  std::uint64_t blocking_waits = 0;    ///< result() calls that had to wait (not available yet)
  /// Submissions to the device: flush() calls, and polls or reads of a
  /// query issued after the last one (drivers flush for those). Each ends
  /// a command batch; on llvmpipe each costs a thread wake-up and memory churn.
  std::uint64_t flushes = 0;
  std::uint64_t conditional_objects = 0;  ///< opaque objects drawn by render_conditional()
  std::uint64_t conditional_skipped = 0;  ///< ... of them whose query passed no samples (device skipped them)
  std::uint64_t stalled_results = 0;   ///< results given up on and taken as visible (StallGuard)
  double wait_ms = 0.0;                ///< wall time blocked inside result(), milliseconds
  double backend_ms = 0.0;             ///< wall time inside any Backend call, milliseconds
  /// GPU time of device culling (DeviceCulling), milliseconds: building
  /// depth pyramids, and the test-and-write-commands dispatches. Objects the
  /// device drew are known only once read back, so these two and the draw
  /// counters of device draws are counted by whoever reads them
  /// (RecordingBackend::finish_frame); the GL renderer alone leaves them 0.
  double pyramid_ms = 0.0;
  double device_cull_ms = 0.0;

  friend BackendStats operator-(const BackendStats& a, const BackendStats& b) noexcept {
    return {a.draw_calls - b.draw_calls,       a.triangles - b.triangles,
            a.objects_rendered - b.objects_rendered, a.render_flushes - b.render_flushes,
            a.queries - b.queries,             a.query_boxes - b.query_boxes,
            a.state_changes - b.state_changes, a.material_changes - b.material_changes,
            a.blocking_waits - b.blocking_waits, a.flushes - b.flushes,
            a.conditional_objects - b.conditional_objects, a.conditional_skipped - b.conditional_skipped,
            a.stalled_results - b.stalled_results,
            a.wait_ms - b.wait_ms,             a.backend_ms - b.backend_ms,
            a.pyramid_ms - b.pyramid_ms,       a.device_cull_ms - b.device_cull_ms};
  }
};

/// What the device does with a conditional draw (Backend::render_conditional)
/// whose query has no result yet.
enum class ConditionalWait : std::uint8_t {
  wait,     ///< waits for the result (GL_QUERY_WAIT): exact, may stall the device
  no_wait,  ///< draws anyway (GL_QUERY_NO_WAIT): never stalls, skips only known-hidden draws
};

/// What reading a query's result costs in the frame that issued it: how a
/// backend says what its reads cost (Backend::result_reads). docs/library.md,
/// "Vulkan and other explicit APIs".
enum class ResultReads : std::uint8_t {
  /// Results can be polled and read mid-frame; polling or reading a query
  /// the device has not been handed makes the driver flush (OpenGL).
  in_frame,
  /// A result exists only once the commands that issued its query were
  /// submitted and ran. Polling or reading a query recorded since the last
  /// submission submits everything recorded so far (the render pass ends,
  /// the next commands begin another) and a read then waits for the device
  /// (Vulkan, Direct3D 12, Metal). Each counts in BackendStats::flushes, the
  /// waiting in wait_ms. Engines on these APIs read results of earlier frames
  /// only: chc:reads=earlier.
  after_submit,
};

class Backend {
 public:
  virtual ~Backend() = default;

  /// Render-queue flush: draws these objects with the current view. The
  /// backend may reorder them (e.g. sort by material); opaque objects are in
  /// the depth buffer before any later issue_query() is evaluated.
  /// Translucent objects may be deferred to the end of the frame (they never
  /// occlude). Precondition: every id is a valid object of the scene.
  virtual void render(std::span<const ObjectId> objects) = 0;

  /// Starts one occlusion query over the union of `boxes` (world space),
  /// tested against the depth buffer as it stands after every earlier
  /// render(); the boxes themselves write neither colour nor depth.
  /// Preconditions: boxes non-empty, none empty. Never blocks.
  virtual QueryId issue_query(std::span<const Aabb> boxes) = 0;

  /// True when result(q) would not block. Never blocks. Precondition: q in flight.
  virtual bool result_available(QueryId q) = 0;

  /// Number of samples (pixels without multisampling) of the query's boxes
  /// that passed the depth test. Blocks until known, then frees q.
  /// Precondition: q in flight.
  virtual std::uint64_t result(QueryId q) = 0;

  /// Whether render_conditional() can skip draws on the device. A backend
  /// without conditional rendering draws everything there (as render()).
  [[nodiscard]] virtual bool conditional_rendering() const { return false; }

  /// Conditional rendering: render(objects), except that on the device the
  /// draws take effect only if query `q` had samples pass; with
  /// ConditionalWait::no_wait the device may draw while the result is not
  /// known yet. Lets a culler act on a query in the same frame without
  /// reading it on the CPU. Translucent objects are deferred and drawn
  /// unconditionally. The query stays in flight: the caller still reads it
  /// with result(). Preconditions: as render(); q issued and not yet read.
  /// The default (no conditional rendering) draws them all.
  virtual void render_conditional(std::span<const ObjectId> objects, QueryId q, ConditionalWait wait) {
    (void)q;
    (void)wait;
    render(objects);
  }

  /// What reading a result in the frame that issued its query costs here
  /// (the default: in_frame, as OpenGL). A decorator forwards its inner
  /// backend's.
  [[nodiscard]] virtual ResultReads result_reads() const { return ResultReads::in_frame; }

  /// Asks the device to start work submitted so far without waiting for it
  /// (glFlush); helps queries finish while the culler does other work.
  virtual void flush() {}

  /// Optional capability: culling and drawing on the device (GPU-driven
  /// culling, occull/device_culling.hpp), or null when the backend has none
  /// (the default). A decorator forwards its inner backend's. The object
  /// belongs to the backend and lives as long as it.
  [[nodiscard]] virtual DeviceCulling* device_culling() { return nullptr; }

  [[nodiscard]] virtual BackendStats stats() const = 0;
};

}  // namespace occull
