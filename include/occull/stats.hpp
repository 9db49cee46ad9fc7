// occull — the lab's record of one frame (not the core's: a culler returns
// occull/frame_result.hpp's FrameResult and reports its own counters).
#pragma once

#include <cstdint>

namespace occull {

/// What one frame of one culler cost, as the lab records it: the culler's
/// FrameResult and its algorithm's counters (Culler::visit_counters, each
/// into the member of its name: copy_culler_counters), the backend's
/// counters, the timings and the verification. Times in milliseconds. Every member has its
/// row in occull/counters.hpp (how it is summarised, its JSON key and CSV
/// column); a member without one fails Counters.EveryFrameStatsMemberHasARow.
struct FrameStats {
  // Timings.
  double frame_ms = 0.0;  ///< wall time of the whole frame, closed by glFinish
  double cpu_ms = 0.0;    ///< culler's own CPU time (frame time inside render_frame minus backend calls)
  double wait_ms = 0.0;   ///< time blocked on query results
  double gpu_ms = 0.0;    ///< GPU time from timer queries (0 when unavailable)
  double model_ms = 0.0;  ///< the NOHC cost model's prediction of this frame (occull bench --model)
  double kernel_ms = 0.0; ///< CPU time the whole process spent in the kernel during the frame
  double pyramid_ms = 0.0;      ///< GPU time building depth pyramids (device culling: hiz)
  double device_cull_ms = 0.0;  ///< GPU time of device culling's test-and-write-commands dispatches
  double raster_ms = 0.0;  ///< CPU time rasterizing occluders into the occlusion buffer (soc; part of cpu_ms)
  double test_ms = 0.0;    ///< CPU time testing boxes against the occlusion buffer, estimated from one test in 8 (soc; part of cpu_ms)

  // What the operating system did during the frame (whole process, driver
  // threads included): page faults are allocator churn, not algorithm cost.
  std::uint64_t minor_faults = 0;
  std::uint64_t major_faults = 0;

  // Culler counters.
  std::uint64_t nodes_visited = 0;        ///< hierarchy nodes the traversal touched
  std::uint64_t multiqueries = 0;         ///< queries covering more than one node
  std::uint64_t failed_multiqueries = 0;  ///< multiqueries that came back visible
  std::uint64_t query_batches = 0;        ///< batches of queries issued together
  // Query cap (grid): whether this frame reached the per-frame cap, how many
  // cells were due a query the cap deferred, and how old (in frames) the
  // visibility answers were that decided what to draw, on average.
  std::uint64_t capped = 0;      ///< 1 when the frame reached the culler's query cap, else 0
  std::uint64_t over_cap = 0;    ///< queries due but deferred by the cap
  double result_age = 0.0;       ///< mean frames since the query behind each answer used was issued
  std::uint64_t revealed = 0;    ///< hidden cells whose query found them visible and were drawn in its frame

  // CPU occlusion buffer (soc).
  std::uint64_t occluder_triangles = 0;  ///< triangles rasterized into the buffer (after clipping, front faces)
  std::uint64_t boxes_tested = 0;        ///< node and object boxes tested against the buffer
  std::uint64_t buffer_texels = 0;       ///< the buffer's width × height
  std::uint64_t occluders_resting = 0;   ///< occluders left out for hiding nothing lately (soc's rest)

  // The adaptive culler (auto): which candidate ran, and its decisions.
  std::uint32_t auto_choice = 0;   ///< 1 + index in Culler::choices() of the candidate auto ran this frame; 0: not auto
  std::uint64_t auto_tries = 0;    ///< 1 on the first frame of a try of a challenger (not the culler auto keeps)
  std::uint64_t auto_switches = 0; ///< 1 on the first frame of a new culler kept (it won its try)
  /// Its cost for this frame's candidate, predicted before running it: the
  /// candidate's last measured cost per unit of frame content times this
  /// frame's content, ms (0: none yet, or a frame after a camera cut).
  double auto_predicted_ms = 0.0;

  // Tiled worlds (tilevfc, pertile, tiles; Gomez et al. 2013).
  std::uint64_t tiles_rendered = 0;      ///< tile instances drawn (culled inside by their own culler, if any)
  std::uint64_t tile_queries = 0;        ///< queries of the common box at a tile (tiles)
  std::uint64_t tile_postponed = 0;      ///< tiles drawn on last frame's visibility while their query was pending (Algorithm 3)
  std::uint64_t tile_prediction_failures = 0;  ///< postponed queries still without a result at the frame's end (Algorithm 4)
  std::uint64_t tiles_instantiated = 0;  ///< tile instances (BVH instance, CHC++ context) created in the frame
  std::uint64_t tiles_evicted = 0;       ///< ... and freed, unused for the eviction time
  std::uint64_t tile_cache = 0;          ///< tile instances held after the frame
  double instantiate_ms = 0.0;           ///< time spent creating tile instances in the frame
  // Backend counters (differences over the frame).
  std::uint64_t queries = 0;
  std::uint64_t query_boxes = 0;
  std::uint64_t state_changes = 0;
  std::uint64_t blocking_waits = 0;  ///< query reads that had to wait for the device
  std::uint64_t flushes = 0;         ///< submissions to the device (BackendStats::flushes)
  std::uint64_t material_changes = 0;
  std::uint64_t render_flushes = 0;
  std::uint64_t draw_calls = 0;
  std::uint64_t triangles = 0;
  std::uint64_t objects_rendered = 0;
  std::uint64_t conditional_objects = 0;  ///< objects drawn under conditional rendering (in objects_rendered)
  std::uint64_t conditional_skipped = 0;  ///< ... that the device skipped: their query found no samples
  std::uint64_t stalled = 0;     ///< query results given up on and taken as visible (StallGuard, --stall-guard)

  // Verification against the frame's ground truth (all 0 when not verified).
  std::uint32_t truth_objects = 0;   ///< objects with a visible pixel in the ground truth
  std::uint32_t missed_objects = 0;  ///< in the truth, not rendered: a visible object culled
  std::uint64_t wrong_pixels = 0;    ///< pixels the missed objects own in the truth image
  std::uint32_t extra_objects = 0;   ///< rendered, not in the truth: culling inefficiency
  /// In the truth and not rendered, but visible only through the
  /// rasteriser's depth errors (fragments nearer than the object's own box):
  /// not missed (Session::verify_frame).
  std::uint32_t depth_error_objects = 0;
  /// Objects in the frustum whose boxes hold no pixel centre
  /// (holds_no_sample, occull/view.hpp): they make no fragment, and every
  /// culler but vfc skips them (exact sub-pixel culling). A property of the
  /// view, counted by the verifier.
  std::uint32_t subpixel_objects = 0;
};

}  // namespace occull
