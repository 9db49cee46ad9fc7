// Summarising: runs of frames into one summary per algorithm (the
// counters as occull/counters.hpp declares them, and the figures derived
// from them).
#include "occull/lab.hpp"

#include "occull/counters.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <type_traits>

namespace occull {
namespace {

double median_of(std::vector<double> v) { return summarize(std::move(v)).median; }

// One repeat's figure of a counter from the sum, the largest value and the
// number of its frames (Counter::frames).
double run_figure(const Counter& c, double sum, double largest, double frames) {
  switch (c.frames) {
    case Combine::mean: return sum / frames;
    case Combine::sum: return sum;
    case Combine::max: return largest;
    default: return 0.0;
  }
}

// Puts a counter's figure into its summary member (Counter::summary).
void set_summary(const Counter& c, AlgorithmSummary& a, double value) {
  std::visit(
      [&](auto member) {
        if constexpr (!std::is_same_v<decltype(member), std::monostate>) {
          using T = std::remove_reference_t<decltype(a.*member)>;
          a.*member = static_cast<T>(value);
        }
      },
      c.summary);
}

}  // namespace

std::vector<AlgorithmSummary> summarize_runs(std::span<const AlgorithmRun> runs) {
  const std::span<const Counter> counters = frame_counters();
  // Per repeat: the mean frame time of each algorithm, for ratios within it.
  std::map<std::pair<int, std::string>, double> mean_ms;
  std::vector<std::string> names;
  for (const AlgorithmRun& r : runs) {
    std::vector<double> ms;
    for (const FrameStats& f : r.frames) ms.push_back(f.frame_ms);
    mean_ms[{r.repeat, r.name}] = summarize(ms).mean;
    if (std::find(names.begin(), names.end(), r.name) == names.end()) names.push_back(r.name);
  }
  const auto sum_of = [&](const std::vector<double>& sums, std::string_view name) {
    return sums[std::size_t(find_counter(name) - counters.data())];
  };

  std::vector<AlgorithmSummary> out;
  for (const std::string& name : names) {
    AlgorithmSummary a;
    a.name = name;
    // Each counter's figure per repeat (Counter::frames), then over the
    // repeats (Counter::repeats); the derived figures beside them.
    std::vector<std::vector<double>> counter_repeats(counters.size());
    std::map<std::string, std::vector<double>> per_repeat;
    for (const AlgorithmRun& r : runs) {
      if (r.name != name) continue;
      a.conservative = r.conservative;
      const double n = std::max<double>(1.0, double(r.frames.size()));
      std::vector<double> ms, sums(counters.size(), 0.0), largest(counters.size(), 0.0);
      std::uint64_t frames_missing = 0, worst = 0;
      for (const FrameStats& f : r.frames) {
        ms.push_back(f.frame_ms);
        for (std::size_t c = 0; c < counters.size(); ++c) {
          const double v = counter_value(counters[c], f);
          sums[c] += v;
          largest[c] = std::max(largest[c], v);
        }
        frames_missing += f.missed_objects > 0 ? 1 : 0;
        worst = std::max(worst, f.wrong_pixels);
      }
      for (std::size_t c = 0; c < counters.size(); ++c)
        if (counters[c].frames != Combine::none)
          counter_repeats[c].push_back(run_figure(counters[c], sums[c], largest[c], n));
      const Summary s = summarize(ms);
      per_repeat["mean"].push_back(s.mean);
      per_repeat["median"].push_back(s.median);
      per_repeat["p95"].push_back(s.p95);
      per_repeat["min"].push_back(s.min);
      per_repeat["max"].push_back(s.max);
      // Figures derived from two counters' sums over the run.
      const double tile_queries = sum_of(sums, "tile_queries"), instantiated = sum_of(sums, "tiles_instantiated");
      const double nodes = sum_of(sums, "nodes_visited");
      if (tile_queries > 0)
        per_repeat["tile_prediction_failure_share"].push_back(sum_of(sums, "tile_prediction_failures") / tile_queries);
      if (instantiated > 0)
        per_repeat["instantiate_ms_per_tile"].push_back(sum_of(sums, "instantiate_ms") / instantiated);
      if (nodes > 0) per_repeat["cpu_us_per_node"].push_back(1e3 * sum_of(sums, "cpu_ms") / nodes);
      if (r.repeat == 0) a.memory = r.memory;
      for (const FrameStats& f : r.frames)  // frames per candidate, turned into shares below
        if (f.auto_choice > 0 && f.auto_choice <= r.choices.size()) {
          if (a.auto_choices.empty())
            for (const std::string& c : r.choices) a.auto_choices.emplace_back(c, 0.0);
          a.auto_choices[f.auto_choice - 1].second += 1.0;
        }
      std::vector<double> errors;  // auto's prediction of the frame it ran, against the measure
      for (const FrameStats& f : r.frames)
        if (f.auto_predicted_ms > 0.0 && f.frame_ms > 0.0)
          errors.push_back(std::abs(f.auto_predicted_ms - f.frame_ms) / f.frame_ms);
      if (!errors.empty()) per_repeat["auto_prediction_error"].push_back(median_of(std::move(errors)));
      if (a.first_miss.empty()) a.first_miss = r.first_miss;
      // A view of a split-screen run compares with the same view of the baseline.
      const std::size_t view_at = r.name.find(" [view ");
      const std::string view = view_at == std::string::npos ? "" : r.name.substr(view_at);
      const auto ratio = [&](const char* base, const char* key) {
        const auto it = mean_ms.find({r.repeat, base + view});
        if (it != mean_ms.end() && it->second > 0) per_repeat[key].push_back(s.mean / it->second);
      };
      // The frustum-culling baseline: vfc, or tilevfc on a tiled world (a
      // run has one or the other: each refuses the other's scenes).
      const bool tiled_run = mean_ms.count({r.repeat, std::string(vfc_baseline(true)) + view}) > 0;
      ratio(std::string(vfc_baseline(tiled_run)).c_str(), "ratio_to_vfc");
      ratio("oracle", "ratio_to_oracle");
      // Correctness: the worst repeat's.
      a.frames_with_misses = std::max(a.frames_with_misses, frames_missing);
      a.worst_frame_wrong_pixels = std::max(a.worst_frame_wrong_pixels, worst);
      a.longest_miss_frames = std::max(a.longest_miss_frames, r.longest_miss_frames);
    }
    for (std::size_t c = 0; c < counters.size(); ++c) {
      const std::vector<double>& v = counter_repeats[c];
      if (v.empty()) continue;
      set_summary(counters[c], a,
                  counters[c].repeats == Combine::max ? *std::max_element(v.begin(), v.end()) : median_of(v));
    }
    const auto med = [&](const char* key) {
      const auto it = per_repeat.find(key);
      return it == per_repeat.end() ? 0.0 : median_of(it->second);
    };
    double chosen = 0.0;
    for (const auto& c : a.auto_choices) chosen += c.second;
    for (auto& c : a.auto_choices) c.second /= std::max(1.0, chosen);
    a.frame_ms = {.mean = med("mean"), .median = med("median"), .p95 = med("p95"), .min = med("min"), .max = med("max")};
    a.ratio_to_vfc = med("ratio_to_vfc");
    a.ratio_to_oracle = med("ratio_to_oracle");
    a.cpu_us_per_node = med("cpu_us_per_node");
    a.auto_prediction_error = med("auto_prediction_error");
    a.tile_prediction_failure_share = med("tile_prediction_failure_share");
    a.instantiate_ms_per_tile = med("instantiate_ms_per_tile");
    out.push_back(std::move(a));
  }
  return out;
}

std::vector<const AlgorithmSummary*> verification_failures(const BenchResult& result) {
  std::vector<const AlgorithmSummary*> failed;
  if (!result.verified) return failed;
  for (const AlgorithmSummary& a : result.summaries)
    if (a.conservative && a.missed_objects > 0) failed.push_back(&a);
  return failed;
}

}  // namespace occull
