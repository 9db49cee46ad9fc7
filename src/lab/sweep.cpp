#include "occull/sweep.hpp"

#include "occull/culler.hpp"
#include "occull/error.hpp"
#include "report_internal.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <ostream>

namespace occull {
namespace {

std::vector<std::string> split(std::string_view text, char sep) {
  std::vector<std::string> out;
  std::size_t pos = 0;
  while (true) {
    const std::size_t end = std::min(text.find(sep, pos), text.size());
    out.emplace_back(text.substr(pos, end - pos));
    if (end == text.size()) return out;
    pos = end + 1;
  }
}

}  // namespace

SweepAxis parse_sweep_axis(std::string_view algorithm, std::string_view text) {
  const AlgorithmInfo& info = find_algorithm(algorithm);
  const std::size_t eq = text.find('=');
  if (eq == std::string_view::npos || eq == 0 || eq + 1 == text.size())
    throw InputError(fmt::format("--vary '{}': expected key=value,value,... (e.g. cap=1000,4000)", text));
  SweepAxis axis{std::string(text.substr(0, eq)), split(text.substr(eq + 1), ',')};
  const bool known = std::any_of(info.options.begin(), info.options.end(),
                                 [&](const OptionInfo& o) { return o.key == axis.key; });
  if (!known) {
    std::string valid;
    for (const OptionInfo& o : info.options) valid += (valid.empty() ? "" : ", ") + o.key;
    throw InputError(fmt::format("--vary {}: {} has no option '{}'; valid options: {}", text, info.name, axis.key,
                                 valid.empty() ? "(none)" : valid));
  }
  for (std::size_t i = 0; i < axis.values.size(); ++i) {
    const std::string& v = axis.values[i];
    if (v.empty()) throw InputError(fmt::format("--vary {}: empty value", text));
    if (v.find(':') != std::string::npos || v.find('=') != std::string::npos)
      throw InputError(fmt::format("--vary {}: value '{}' may not contain ':' or '='", text, v));
    if (std::find(axis.values.begin(), axis.values.begin() + long(i), v) != axis.values.begin() + long(i))
      throw InputError(fmt::format("--vary {}: value '{}' is listed twice", text, v));
  }
  return axis;
}

std::vector<std::string> sweep_specs(std::string_view algorithm, std::span<const SweepAxis> axes) {
  if (axes.empty()) throw InputError("a sweep needs at least one --vary key=value,...");
  std::size_t settings = 1;
  for (std::size_t i = 0; i < axes.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j)
      if (axes[j].key == axes[i].key) throw InputError(fmt::format("--vary {}: the key is varied twice", axes[i].key));
    settings *= axes[i].values.size();
    if (settings > kMaxSweepSettings)
      throw InputError(fmt::format("the sweep has more than {} settings (combinations of the --vary values); "
                                   "sweep fewer values at a time",
                                   kMaxSweepSettings));
  }
  std::vector<std::string> specs;
  std::vector<std::size_t> at(axes.size(), 0);  // odometer over the axes, the last fastest
  for (std::size_t n = 0; n < settings; ++n) {
    std::string spec(algorithm);
    for (std::size_t i = 0; i < axes.size(); ++i) spec += fmt::format(":{}={}", axes[i].key, axes[i].values[at[i]]);
    specs.push_back(std::move(spec));
    for (std::size_t i = axes.size(); i-- > 0;) {
      if (++at[i] < axes[i].values.size()) break;
      at[i] = 0;
    }
  }
  return specs;
}

std::vector<const AlgorithmSummary*> sweep_rows(const BenchResult& r, std::string_view algorithm,
                                                std::span<const SweepAxis> axes) {
  std::vector<const AlgorithmSummary*> rows;
  for (const std::string& spec : sweep_specs(algorithm, axes)) {
    const auto it = std::find_if(r.summaries.begin(), r.summaries.end(),
                                 [&](const AlgorithmSummary& a) { return a.name == spec; });
    if (it == r.summaries.end()) throw InvariantViolation("sweep: no result for setting " + spec);
    rows.push_back(&*it);
  }
  return rows;
}

const AlgorithmSummary* best_setting(std::span<const AlgorithmSummary* const> rows, const PoppingLimit& limit,
                                     bool verified) {
  if (!verified) return nullptr;
  const AlgorithmSummary* best = nullptr;
  for (const AlgorithmSummary* a : rows) {
    if (a->missed_share() > limit.share || a->longest_miss_frames > limit.longest_frames) continue;
    if (!best || a->frame_ms.mean < best->frame_ms.mean) best = a;
  }
  return best;
}

void print_sweep_table(const BenchResult& r, std::string_view algorithm, std::span<const SweepAxis> axes,
                       const PoppingLimit& limit, std::ostream& out) {
  const auto rows = sweep_rows(r, algorithm, axes);
  const auto specs = sweep_specs(algorithm, axes);
  out << fmt::format("sweep of {} over {} settings on {} / {}: {} frames at {}x{}, {} warm-up, {} repeat{}{}\n",
                     algorithm, rows.size(), r.scene, r.path, r.frames, r.width, r.height, r.warmup, r.repeat,
                     r.repeat == 1 ? "" : "s (medians)", r.verified ? "" : ", verification off (no popping figures)");
  out << fmt::format("device: {} | {} | occull {}\n\n", r.device.renderer, r.device.version, r.commit);

  std::vector<std::size_t> width;
  for (const SweepAxis& a : axes) {
    std::size_t w = a.key.size();
    for (const std::string& v : a.values) w = std::max(w, v.size());
    width.push_back(w);
  }
  std::string head;
  for (std::size_t i = 0; i < axes.size(); ++i) head += fmt::format("{:<{}} ", axes[i].key, width[i]);
  out << head
      << fmt::format("{:>8} {:>8} {:>8} {:>6} {:>8} {:>7} {:>7} {:>8} {:>8} {:>9}\n", "mean ms", "median", "p95",
                     "vs vfc", "queries", "capped", "missed", "of vis.", "longest", "wrong px");
  const AlgorithmSummary* best = best_setting(rows, limit, r.verified);
  for (std::size_t k = 0; k < rows.size(); ++k) {
    const AlgorithmSummary& a = *rows[k];
    const AlgorithmSpec spec = parse_algorithm_spec(specs[k]);
    std::string line;
    for (std::size_t i = 0; i < axes.size(); ++i)
      line += fmt::format("{:<{}} ", spec.options.values().at(std::string(algorithm) + "." + axes[i].key), width[i]);
    const auto verified = [&](auto v) { return r.verified ? fmt::format("{}", v) : std::string("-"); };
    out << line
        << fmt::format("{:>8.2f} {:>8.2f} {:>8.2f} {:>6} {:>8.1f} {:>6.0f}% {:>7} {:>7} {:>8} {:>9}{}\n",
                       a.frame_ms.mean, a.frame_ms.median, a.frame_ms.p95, detail::ratio_text(a.ratio_to_vfc),
                       a.queries_per_frame, 100.0 * a.capped_share, verified(a.missed_objects),
                       r.verified ? fmt::format("{:.2f}%", 100.0 * a.missed_share()) : std::string("-"),
                       verified(a.longest_miss_frames), verified(a.wrong_pixels), &a == best ? "  <- best" : "");
  }
  std::string others;
  for (const AlgorithmSummary& a : r.summaries)
    if (std::find(rows.begin(), rows.end(), &a) == rows.end())
      others += fmt::format("{}{} {:.2f} ms (vs vfc {})", others.empty() ? "" : ", ", a.name, a.frame_ms.mean,
                            detail::ratio_text(a.ratio_to_vfc));
  if (!others.empty()) out << "\nbeside it: " << others << "\n";
  out << "\n";
  if (!r.verified)
    out << "no best setting: without verification popping is unknown\n";
  else if (best)
    out << fmt::format("best: {} — the fastest setting that misses at most {:.2f}% of the visible object-frames "
                       "and no object for more than {} frames in a row\n",
                       best->name, 100.0 * limit.share, limit.longest_frames);
  else
    out << fmt::format("no setting misses at most {:.2f}% of the visible object-frames with no object missed for "
                       "more than {} frames in a row\n",
                       100.0 * limit.share, limit.longest_frames);
  out << "mean / median / p95: frame ms; vs vfc: mean over vfc's in the same run; queries: per frame; capped: "
         "frames at the query cap; missed: object-frames visible in the ground truth but not drawn (popping); "
         "of vis.: their share of the visible object-frames; longest: most frames in a row one object stayed "
         "missed; wrong px: their pixels.\n";
}

}  // namespace occull
