// occull — what a culler says about a frame: the figures every culler has,
// its algorithm's own counters, and what its owner measured.
#pragma once

#include <cstdint>
#include <functional>
#include <string_view>

namespace occull {

/// What every culler's Culler::render_frame() returns.
struct FrameResult {
  /// Object ids handed to Backend::render() and render_conditional() (an
  /// object drawn twice counts twice; 0 for `hiz`, whose draws the device
  /// writes: DeviceCulling::read_drawn).
  std::uint64_t objects_drawn = 0;
  /// Occlusion queries issued (Backend::issue_query() calls).
  std::uint64_t queries = 0;
  /// Hierarchy nodes the culler's traversal touched (grid cells for
  /// `grid`; the nodes of every tile's culler for the tiled-world cullers).
  std::uint64_t nodes_visited = 0;
  /// The culler's own CPU time: the wall time of render_frame() less the
  /// time the backend says it spent in its calls (BackendStats::backend_ms
  /// difference; a backend that does not count it leaves it in), ms.
  double cpu_ms = 0.0;
};

/// What the owner measured of a frame once it was complete
/// (Culler::frame_finished()). Only `frame_ms` is needed; the rest sharpens
/// what an adaptive culler (`auto`) learns.
struct FrameMeasure {
  double frame_ms = 0.0;  ///< CPU and GPU time of the whole frame, ms (0: not measured)
  double cpu_ms = 0.0;    ///< the culler's CPU time in it (FrameResult::cpu_ms), ms
  double wait_ms = 0.0;   ///< time blocked on query results (BackendStats::wait_ms difference), ms
  std::uint64_t draw_calls = 0;  ///< object draws (BackendStats::draw_calls difference)
  std::uint64_t triangles = 0;   ///< triangles drawn (BackendStats::triangles difference)
};

/// Receives an algorithm's own counters of a frame (Culler::visit_counters):
/// each counter's name — a string literal, valid for the program's life —
/// and its value. What each name means, its unit and how the lab combines
/// it: the lab's counter table (occull/counters.hpp, `frame_counters()`).
using CounterVisitor = std::function<void(std::string_view name, double value)>;

}  // namespace occull
