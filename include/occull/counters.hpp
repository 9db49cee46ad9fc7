// occull — every per-frame counter of the lab, declared once.
//
// One row per FrameStats member says where the counter comes from (the
// backend's counters; the culler's FrameResult or, by the row's name, its
// algorithm's counters (Culler::visit_counters); or the lab), how the views of a
// split-screen frame combine it, how a run's frames and the repeats reduce
// it to the summary figure (the AlgorithmSummary member and JSON key of the
// same row), how frames.csv prints it, and what it means. The lab's
// per-frame copy, the split-screen sums, summarize_runs(), the JSON, the CSV
// columns and the report's legend are all loops over this table: adding a
// counter is its FrameStats member (and the code that counts it: an
// algorithm reports it by the row's name), a row here and, if it has a
// summary figure, that AlgorithmSummary member.
#pragma once

#include "occull/backend.hpp"
#include "occull/bench.hpp"
#include "occull/culler.hpp"
#include "occull/stats.hpp"

#include <cstdint>
#include <span>
#include <string_view>
#include <variant>

namespace occull {

/// How values of a counter combine at one level (views of a split-screen
/// frame; frames of a run; repeats of a run).
enum class Combine : std::uint8_t {
  none,    ///< not combined at this level (no summary figure)
  sum,     ///< added up
  mean,    ///< the sum over the count (a run's frames: per frame)
  max,     ///< the largest (a repeat: the worst)
  median,  ///< the middle value (a repeat: robust to one noisy run)
};

/// One per-frame counter.
struct Counter {
  using FrameMember = std::variant<std::uint64_t FrameStats::*, std::uint32_t FrameStats::*, double FrameStats::*>;
  using BackendMember = std::variant<std::monostate, std::uint64_t BackendStats::*, double BackendStats::*>;
  using SummaryMember = std::variant<std::monostate, double AlgorithmSummary::*, std::uint64_t AlgorithmSummary::*>;

  std::string_view name;  ///< the FrameStats member's name; frames.csv's column; an algorithm's counter of that name
  FrameMember frame;      ///< the FrameStats member
  /// The BackendStats counter whose difference over the frame it is
  /// (std::monostate: the culler or the lab fills it).
  BackendMember backend;
  Combine views;    ///< the views of a split-screen frame into the frame: sum, max or mean
  Combine frames;   ///< a run's frames into the run's figure: mean (per frame), sum, max; none: no summary
  Combine repeats;  ///< the repeats' figures into the summary: median, or max (the worst repeat)
  std::string_view key;   ///< the summary's JSON key, the name of `summary` (empty when frames is none)
  SummaryMember summary;  ///< where summarize_runs() puts the figure
  int decimals;           ///< frames.csv: digits after the point; -1 for an integer
  bool modelled;          ///< the summary is null in the JSON unless the run was modelled (--model)
  std::string_view unit;  ///< of one frame's value: "ms", "count", "0/1", "frames"
  std::string_view help;  ///< what it counts, for a person
};

/// The table, in frames.csv's column order (after algorithm, repeat, frame).
[[nodiscard]] std::span<const Counter> frame_counters() noexcept;

/// The row named `name` (its FrameStats member), or nullptr.
[[nodiscard]] const Counter* find_counter(std::string_view name) noexcept;

/// The value of `counter` in `frame`, as a double.
[[nodiscard]] double counter_value(const Counter& counter, const FrameStats& frame) noexcept;

/// Copies every backend counter of the frame (`during`: the backend's
/// stats at the end minus those at the start) into `frame`.
void copy_backend_counters(const BackendStats& during, FrameStats& frame) noexcept;

/// Copies what a culler says of its frame into `frame`: the result's
/// nodes_visited and cpu_ms, and each counter `culler` visits
/// (Culler::visit_counters) into the row of its name. Throws
/// std::logic_error naming a counter the table has no row for, or one the
/// backend fills (an algorithm's counter left undeclared: a bug).
void copy_culler_counters(const FrameResult& result, const Culler& culler, FrameStats& frame);

/// Sets the row `name` of `frame` to `value` (an algorithm's counter, as
/// copy_culler_counters() does). Throws as it does.
void set_counter(FrameStats& frame, std::string_view name, double value);

/// What `frame` says of it to a culler that learns from it
/// (Culler::frame_finished).
[[nodiscard]] FrameMeasure measure_of(const FrameStats& frame) noexcept;

/// Adds one view's figures to a split-screen frame's `sum` (Counter::views);
/// after the last view, finish_views() turns the means' sums into means.
void add_view(FrameStats& sum, const FrameStats& view) noexcept;
void finish_views(FrameStats& sum, int views) noexcept;

}  // namespace occull
