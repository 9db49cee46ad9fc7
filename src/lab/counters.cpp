#include "occull/counters.hpp"

#include <algorithm>
#include <array>
#include <stdexcept>
#include <string>
#include <type_traits>

namespace occull {
namespace {

using C = Combine;
using S = AlgorithmSummary;
using B = BackendStats;
using F = FrameStats;
constexpr std::monostate none{};

// In frames.csv's column order. Columns: name, member, backend source,
// views, frames, repeats, JSON key, summary member, CSV decimals,
// null-unless-modelled, unit, help.
constexpr std::array kCounters = std::to_array<Counter>({
    {"frame_ms", &F::frame_ms, none, C::sum, C::none, C::none, "", none, 4, false, "ms",
     "wall time of the whole frame, closed by glFinish (summarised as frame_ms: mean, median, p95, max)"},
    {"cpu_ms", &F::cpu_ms, none, C::sum, C::mean, C::median, "cpu_ms_per_frame", &S::cpu_ms_per_frame, 4, false, "ms",
     "the culler's own CPU time (its render_frame minus the time inside backend calls)"},
    {"wait_ms", &F::wait_ms, &B::wait_ms, C::sum, C::mean, C::median, "wait_ms_per_frame", &S::wait_ms_per_frame, 4,
     false, "ms", "time blocked on query results"},
    {"gpu_ms", &F::gpu_ms, none, C::sum, C::mean, C::median, "gpu_ms_per_frame", &S::gpu_ms_per_frame, 4, false, "ms",
     "GPU time of the frame from timer queries (0 where the device has none)"},
    {"pyramid_ms", &F::pyramid_ms, &B::pyramid_ms, C::sum, C::mean, C::median, "pyramid_ms_per_frame",
     &S::pyramid_ms_per_frame, 4, false, "ms", "GPU time building depth pyramids (device culling: hiz; 0 without timer)"},
    {"device_cull_ms", &F::device_cull_ms, &B::device_cull_ms, C::sum, C::mean, C::median, "device_cull_ms_per_frame",
     &S::device_cull_ms_per_frame, 4, false, "ms",
     "GPU time of device culling's test-and-write-commands dispatches (hiz; 0 without timer)"},
    {"raster_ms", &F::raster_ms, none, C::sum, C::mean, C::median, "raster_ms_per_frame", &S::raster_ms_per_frame, 4,
     false, "ms", "CPU time rasterizing occluders into the occlusion buffer (soc; part of cpu_ms)"},
    {"test_ms", &F::test_ms, none, C::sum, C::mean, C::median, "test_ms_per_frame", &S::test_ms_per_frame, 4, false,
     "ms", "CPU time testing boxes against the occlusion buffer, estimated from one test in 8 (soc; part of cpu_ms)"},
    {"occluder_triangles", &F::occluder_triangles, none, C::sum, C::mean, C::median, "occluder_triangles_per_frame",
     &S::occluder_triangles_per_frame, -1, false, "count",
     "triangles rasterized into the occlusion buffer (soc; clipped, front faces)"},
    {"boxes_tested", &F::boxes_tested, none, C::sum, C::mean, C::median, "boxes_tested_per_frame",
     &S::boxes_tested_per_frame, -1, false, "count", "node and object boxes tested against the occlusion buffer (soc)"},
    {"buffer_texels", &F::buffer_texels, none, C::max, C::mean, C::median, "buffer_texels", &S::buffer_texels, -1,
     false, "count", "the occlusion buffer's width × height (soc)"},
    {"occluders_resting", &F::occluders_resting, none, C::sum, C::mean, C::median, "occluders_resting_per_frame",
     &S::occluders_resting_per_frame, -1, false, "count",
     "occluders not rasterized because they hid nothing lately (soc's rest option)"},
    {"auto_choice", &F::auto_choice, none, C::max, C::none, C::none, "", none, -1, false, "index",
     "auto: 1 + the index of the candidate it ran (results.json's auto_choices name them in order); 0 for the "
     "other cullers"},
    {"auto_tries", &F::auto_tries, none, C::sum, C::sum, C::median, "auto_tries", &S::auto_tries, -1, false, "0/1",
     "auto: 1 on the first frame of a try of a challenger"},
    {"auto_switches", &F::auto_switches, none, C::sum, C::sum, C::median, "auto_switches", &S::auto_switches, -1,
     false, "0/1", "auto: 1 on the first frame of a new culler kept (a challenger that won its try)"},
    {"auto_predicted_ms", &F::auto_predicted_ms, none, C::sum, C::none, C::none, "", none, 4, false, "ms",
     "auto: the frame time it predicted for the candidate it ran, before running it (0: no prediction); beside "
     "frame_ms, how well its model knows the candidates"},
    {"queries", &F::queries, &B::queries, C::sum, C::mean, C::median, "queries_per_frame", &S::queries_per_frame, -1,
     false, "count", "occlusion queries issued"},
    {"query_boxes", &F::query_boxes, &B::query_boxes, C::sum, C::none, C::none, "", none, -1, false, "count",
     "boxes drawn inside those queries"},
    {"multiqueries", &F::multiqueries, none, C::sum, C::mean, C::median, "multiqueries_per_frame",
     &S::multiqueries_per_frame, -1, false, "count", "queries covering more than one node (CHC++ multiqueries)"},
    {"failed_multiqueries", &F::failed_multiqueries, none, C::sum, C::mean, C::median,
     "failed_multiqueries_per_frame", &S::failed_multiqueries_per_frame, -1, false, "count",
     "multiqueries that came back visible (their nodes queried again one by one)"},
    {"query_batches", &F::query_batches, none, C::sum, C::mean, C::median, "query_batches_per_frame",
     &S::query_batches_per_frame, -1, false, "count", "batches of queries issued together"},
    {"state_changes", &F::state_changes, &B::state_changes, C::sum, C::mean, C::median, "state_changes_per_frame",
     &S::state_changes_per_frame, -1, false, "count", "switches between rendering and querying state"},
    {"material_changes", &F::material_changes, &B::material_changes, C::sum, C::none, C::none, "", none, -1, false,
     "count", "material binds while rendering"},
    {"render_flushes", &F::render_flushes, &B::render_flushes, C::sum, C::mean, C::median, "render_flushes_per_frame",
     &S::render_flushes_per_frame, -1, false, "count", "render-queue flushes (calls of Backend::render)"},
    {"draw_calls", &F::draw_calls, &B::draw_calls, C::sum, C::mean, C::median, "draw_calls_per_frame",
     &S::draw_calls_per_frame, -1, false, "count", "object draws"},
    {"triangles", &F::triangles, &B::triangles, C::sum, C::mean, C::median, "triangles_per_frame",
     &S::triangles_per_frame, -1, false, "count", "triangles submitted in object draws"},
    {"objects_rendered", &F::objects_rendered, &B::objects_rendered, C::sum, C::mean, C::median,
     "objects_rendered_per_frame", &S::objects_rendered_per_frame, -1, false, "count", "objects drawn"},
    {"nodes_visited", &F::nodes_visited, none, C::sum, C::mean, C::median, "nodes_visited_per_frame",
     &S::nodes_visited_per_frame, -1, false, "count", "hierarchy nodes the culler's traversal touched"},
    {"truth_objects", &F::truth_objects, none, C::sum, C::sum, C::max, "truth_object_frames", &S::truth_object_frames,
     -1, false, "count", "objects with a visible pixel in the frame's ground truth (verified runs)"},
    {"missed_objects", &F::missed_objects, none, C::sum, C::sum, C::max, "missed_objects", &S::missed_objects, -1,
     false, "count", "objects in the ground truth the culler did not draw: a visible object culled"},
    {"wrong_pixels", &F::wrong_pixels, none, C::sum, C::sum, C::max, "wrong_pixels", &S::wrong_pixels, -1, false,
     "count", "pixels the missed objects own in the ground truth"},
    {"depth_error_objects", &F::depth_error_objects, none, C::sum, C::sum, C::max, "depth_error_objects",
     &S::depth_error_objects, -1, false, "count",
     "objects of the ground truth not drawn that only the rasteriser's depth errors show (fragments nearer than "
     "their own box): not missed"},
    {"subpixel_objects", &F::subpixel_objects, none, C::sum, C::mean, C::median, "subpixel_objects_per_frame",
     &S::subpixel_objects_per_frame, -1, false, "count",
     "objects of the frustum whose boxes hold no pixel centre: they make no fragment, and every culler but vfc skips "
     "them (verified runs)"},
    {"extra_objects", &F::extra_objects, none, C::sum, C::mean, C::median, "extra_objects_per_frame",
     &S::extra_objects_per_frame, -1, false, "count", "objects drawn that the ground truth does not show (over-drawing)"},
    {"blocking_waits", &F::blocking_waits, &B::blocking_waits, C::sum, C::mean, C::median, "blocking_waits_per_frame",
     &S::blocking_waits_per_frame, -1, false, "count", "query reads that had to wait for the device"},
    {"model_ms", &F::model_ms, none, C::sum, C::mean, C::median, "model_ms_per_frame", &S::model_ms_per_frame, 4, true,
     "ms", "the NOHC cost model's prediction of the frame (--model)"},
    {"kernel_ms", &F::kernel_ms, none, C::sum, C::mean, C::median, "kernel_ms_per_frame", &S::kernel_ms_per_frame, 4,
     false, "ms", "CPU time the whole process (driver threads too) spent in the kernel during the frame"},
    {"minor_faults", &F::minor_faults, none, C::sum, C::mean, C::median, "minor_faults_per_frame",
     &S::minor_faults_per_frame, -1, false, "count", "page faults of the process served without I/O (allocator churn)"},
    {"major_faults", &F::major_faults, none, C::sum, C::mean, C::median, "major_faults_per_frame",
     &S::major_faults_per_frame, -1, false, "count", "page faults of the process that needed I/O"},
    {"flushes", &F::flushes, &B::flushes, C::sum, C::mean, C::median, "flushes_per_frame", &S::flushes_per_frame, -1,
     false, "count", "submissions to the device mid-frame (flush calls, polls or reads of queries not yet submitted)"},
    {"capped", &F::capped, none, C::max, C::mean, C::median, "capped_share", &S::capped_share, -1, false, "0/1",
     "1 when the frame reached the culler's per-frame query cap (grid)"},
    {"over_cap", &F::over_cap, none, C::sum, C::mean, C::median, "over_cap_per_frame", &S::over_cap_per_frame, -1,
     false, "count", "queries that were due but deferred by the query cap"},
    {"result_age", &F::result_age, none, C::mean, C::mean, C::median, "result_age_frames", &S::result_age_frames, 3,
     false, "frames", "mean age of the query answers that decided what to draw (1: last frame's)"},
    {"revealed", &F::revealed, none, C::sum, C::mean, C::median, "revealed_per_frame", &S::revealed_per_frame, -1,
     false, "count", "hidden cells found visible by this frame's query and drawn in the same frame"},
    {"conditional_objects", &F::conditional_objects, &B::conditional_objects, C::sum, C::mean, C::median,
     "conditional_objects_per_frame", &S::conditional_objects_per_frame, -1, false, "count",
     "objects drawn under conditional rendering (part of the draws)"},
    {"conditional_skipped", &F::conditional_skipped, &B::conditional_skipped, C::sum, C::mean, C::median,
     "conditional_skipped_per_frame", &S::conditional_skipped_per_frame, -1, false, "count",
     "of those, the ones the device skipped because their query found no samples"},
    {"stalled", &F::stalled, &B::stalled_results, C::sum, C::mean, C::median, "stalled_per_frame",
     &S::stalled_per_frame, -1, false, "count", "query results given up on and taken as visible (--stall-guard)"},
    {"tiles_rendered", &F::tiles_rendered, none, C::sum, C::mean, C::median, "tiles_rendered_per_frame",
     &S::tiles_rendered_per_frame, -1, false, "count", "tile instances drawn (tiled worlds)"},
    {"tile_queries", &F::tile_queries, none, C::sum, C::mean, C::median, "tile_queries_per_frame",
     &S::tile_queries_per_frame, -1, false, "count", "queries of the common box at a tile (tiles)"},
    {"tile_postponed", &F::tile_postponed, none, C::sum, C::mean, C::median, "tile_postponed_per_frame",
     &S::tile_postponed_per_frame, -1, false, "count",
     "tiles drawn on last frame's visibility while their query was pending"},
    {"tile_prediction_failures", &F::tile_prediction_failures, none, C::sum, C::none, C::none, "", none, -1, false,
     "count", "postponed tile queries still without a result at the frame's end (summarised as a share of tile_queries)"},
    {"tiles_instantiated", &F::tiles_instantiated, none, C::sum, C::sum, C::median, "tiles_instantiated",
     &S::tiles_instantiated, -1, false, "count", "tile instances (BVH instance, CHC++ context) created"},
    {"tiles_evicted", &F::tiles_evicted, none, C::sum, C::sum, C::median, "tiles_evicted", &S::tiles_evicted, -1,
     false, "count", "tile instances freed after the eviction time unused"},
    {"tile_cache", &F::tile_cache, none, C::sum, C::max, C::median, "tile_cache_max", &S::tile_cache_max, -1, false,
     "count", "tile instances held after the frame"},
    {"instantiate_ms", &F::instantiate_ms, none, C::sum, C::none, C::none, "", none, 4, false, "ms",
     "time spent creating tile instances (summarised per tile)"},
});

}  // namespace

std::span<const Counter> frame_counters() noexcept { return kCounters; }

const Counter* find_counter(std::string_view name) noexcept {
  for (const Counter& c : kCounters)
    if (c.name == name) return &c;
  return nullptr;
}

double counter_value(const Counter& counter, const FrameStats& frame) noexcept {
  return std::visit([&](auto member) { return double(frame.*member); }, counter.frame);
}

void copy_backend_counters(const BackendStats& during, FrameStats& frame) noexcept {
  for (const Counter& c : kCounters) {
    if (std::holds_alternative<std::monostate>(c.backend)) continue;
    std::visit(
        [&](auto to) {
          std::visit(
              [&](auto from) {
                if constexpr (!std::is_same_v<decltype(from), std::monostate>)
                  frame.*to = static_cast<std::remove_reference_t<decltype(frame.*to)>>(during.*from);
              },
              c.backend);
        },
        c.frame);
  }
}

void copy_culler_counters(const FrameResult& result, const Culler& culler, FrameStats& frame) {
  frame.nodes_visited = result.nodes_visited;
  frame.cpu_ms = result.cpu_ms;
  culler.visit_counters([&frame](std::string_view name, double value) { set_counter(frame, name, value); });
}

void set_counter(FrameStats& frame, std::string_view name, double value) {
  const Counter* c = find_counter(name);
  if (!c || !std::holds_alternative<std::monostate>(c->backend))
    throw std::logic_error("a culler reported the counter '" + std::string(name) + "', which " +
                           (c ? "the backend fills" : "the counter table (src/lab/counters.cpp) does not declare"));
  std::visit(
      [&](auto member) {
        using T = std::remove_reference_t<decltype(frame.*member)>;
        frame.*member = static_cast<T>(value);
      },
      c->frame);
}

FrameMeasure measure_of(const FrameStats& frame) noexcept {
  return {.frame_ms = frame.frame_ms,
          .cpu_ms = frame.cpu_ms,
          .wait_ms = frame.wait_ms,
          .draw_calls = frame.draw_calls,
          .triangles = frame.triangles};
}

void add_view(FrameStats& sum, const FrameStats& view) noexcept {
  for (const Counter& c : kCounters)
    std::visit(
        [&](auto member) {
          if (c.views == Combine::max)
            sum.*member = std::max(sum.*member, view.*member);
          else  // sum, and mean (divided by the views in finish_views)
            sum.*member += view.*member;
        },
        c.frame);
}

void finish_views(FrameStats& sum, int views) noexcept {
  for (const Counter& c : kCounters)
    if (c.views == Combine::mean)
      std::visit(
          [&](auto member) {
            using T = std::remove_reference_t<decltype(sum.*member)>;
            sum.*member = static_cast<T>(sum.*member / static_cast<T>(views));
          },
          c.frame);
}

}  // namespace occull
