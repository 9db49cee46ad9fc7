// occull — option sweeps: one algorithm over every combination of a few
// option values, run as one interleaved benchmark (same frames, same
// ground truth, one baseline), tabulated as frame time and popping per
// setting, in the shape of Seletsky's Tables 5.x (Seletsky 2013).
#pragma once

#include "occull/lab.hpp"

#include <cstddef>
#include <cstdint>
#include <iosfwd>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace occull {

/// One swept option of an algorithm: its key (without the algorithm's
/// prefix) and the values to try, in order.
struct SweepAxis {
  std::string key;
  std::vector<std::string> values;
};

/// Most settings (combinations) one sweep may run.
inline constexpr std::size_t kMaxSweepSettings = 64;

/// Parses "key=v1,v2,..." as an axis of `algorithm`. Throws InputError when
/// the text is not of that form, a value is empty or repeated, or the
/// algorithm is unknown or has no such option (the message lists the valid
/// ones). Values are checked when the cullers are made (run_bench does
/// that before the slow part).
[[nodiscard]] SweepAxis parse_sweep_axis(std::string_view algorithm, std::string_view text);

/// Every combination as an algorithm spec ("grid:cap=250:cell=4"), the
/// last axis varying fastest. Throws InputError when there are no axes, a
/// key repeats, or the combinations exceed kMaxSweepSettings.
[[nodiscard]] std::vector<std::string> sweep_specs(std::string_view algorithm, std::span<const SweepAxis> axes);

/// What a setting may pop and still count (Seletsky 2013's grid issue: at most
/// 0.1 % of the visible object-frames missed, no object missed for more
/// than 3 frames in a row).
struct PoppingLimit {
  double share = 0.001;
  std::uint32_t longest_frames = 3;
};

/// The row (summary) of a bench result for each setting, in sweep_specs
/// order. Precondition: r ran every spec of sweep_specs(algorithm, axes).
[[nodiscard]] std::vector<const AlgorithmSummary*> sweep_rows(const BenchResult& r, std::string_view algorithm,
                                                              std::span<const SweepAxis> axes);

/// The fastest setting (lowest mean frame time) whose popping is within
/// `limit`, or nullptr when none is (or the run was not verified).
[[nodiscard]] const AlgorithmSummary* best_setting(std::span<const AlgorithmSummary* const> rows,
                                                   const PoppingLimit& limit, bool verified);

/// One row per setting: the swept values, mean / median / p95 frame ms, the
/// ratio to vfc, queries per frame, share of frames at the query cap,
/// missed object-frames and their share of the visible ones, longest miss,
/// wrong pixels; the baselines that ran beside it; then the fastest setting
/// within `limit`.
void print_sweep_table(const BenchResult& r, std::string_view algorithm, std::span<const SweepAxis> axes,
                       const PoppingLimit& limit, std::ostream& out);

}  // namespace occull
