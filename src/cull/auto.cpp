// `auto`: the adaptive culler. No culler wins everywhere: where occlusion is
// scarce (open ground, small maps, thousands of tiny meshes) queries cost
// more than they save and plain view-frustum culling is fastest; in a city
// CHC++ or NOHC save most of the frame. `auto` runs one of its candidates
// per frame for its view, learns what each costs here from the frames it
// measured (Culler::frame_finished: the owner's frame time, or else its own
// time in render_frame), and keeps the cheapest with hysteresis
// (AutoSchedule). Every candidate is conservative, so `auto` is.
//
// Each candidate keeps its own temporal state; one that was not run for a
// while finds its coherence stale and rebuilds it in its first frame back;
// that frame counts against it, and switching needs a margin.
#include "auto.hpp"

#include "cullers.hpp"
#include "occull/error.hpp"
#include "traversal.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>

namespace occull::detail {

AutoSchedule::AutoSchedule(AutoConfig config, std::size_t candidates)
    : config_(std::move(config)), count_(candidates), cost_(candidates, 0.0), losses_(candidates, 0),
      next_try_(candidates, 0) {
  start_trial(0);
}

void AutoSchedule::start_trial(std::size_t c) {
  running_ = c;
  in_trial_ = true;
  trial_frame_ = 0;
  samples_.clear();
}

void AutoSchedule::end_trial() {
  std::vector<double> s = samples_;
  std::nth_element(s.begin(), s.begin() + std::ptrdiff_t(s.size() / 2), s.end());
  const double measured = s.empty() ? 0.0 : s[s.size() / 2];
  const std::size_t c = running_;
  cost_[c] = measured;
  in_trial_ = false;
  if (initial_) {
    if (c + 1 < count_) {
      start_trial(c + 1);
      return;
    }
    initial_ = false;
    current_ = std::size_t(std::min_element(cost_.begin(), cost_.end()) - cost_.begin());
    for (std::size_t i = 0; i < count_; ++i) next_try_[i] = frame_ + std::uint64_t(config_.period);
  } else if (c != current_) {
    if (measured < cost_[current_] * (1.0 - config_.margin)) {
      current_ = c;
      losses_[c] = 0;
      ++switches_;
    } else {
      losses_[c] = std::min<std::uint32_t>(losses_[c] + 1, 4);
    }
    next_try_[c] = frame_ + (std::uint64_t(config_.period) << losses_[c]);
  }
  running_ = current_;
}

void AutoSchedule::finished(double cost_ms) {
  ++frame_;
  if (in_trial_) {
    // The first frame after a switch also rebuilds the candidate's stale
    // temporal state: a real cost of switching, so it is counted.
    samples_.push_back(cost_ms);
    // A try whose frame already costs more than twice the best known one
    // ends at once: in a dense city one frame of plain frustum culling can
    // cost as much as a dozen of CHC++'s.
    double best = 0.0;
    for (std::size_t i = 0; i < count_; ++i)
      if (i != running_ && cost_[i] > 0.0 && (best == 0.0 || cost_[i] < best)) best = cost_[i];
    const bool hopeless = best > 0.0 && cost_ms > 2.0 * best;
    if (++trial_frame_ >= config_.trial || hopeless) end_trial();
    return;
  }
  // The current culler: a running cost, so it follows the scene.
  cost_[current_] += config_.smoothing * (cost_ms - cost_[current_]);
  // Time to try a challenger? The one waiting longest past its turn.
  std::size_t best = count_;
  for (std::size_t i = 0; i < count_; ++i)
    if (i != current_ && next_try_[i] <= frame_ && (best == count_ || next_try_[i] < next_try_[best])) best = i;
  if (best != count_) start_trial(best);
}

namespace {

// How much there is to draw in a view, whoever culls it: the triangles of
// the objects in the frustum plus a triangle-equivalent per draw. Frame
// costs are compared per unit of it, so that candidates tried on different
// frames of a walk (a crowded street, then an open square) are compared on
// what they did with the frame rather than on what the frame held.
constexpr double kTrianglesPerDraw = 64.0;

class AutoCuller final : public Culler {
 public:
  AutoCuller(const SceneIndex& index, std::vector<std::unique_ptr<Culler>> candidates, const AutoConfig& config)
      : index_(index), candidates_(std::move(candidates)), schedule_(config, candidates_.size()) {}

  FrameStats cull(const View& view, Backend& backend) override {
    if (awaiting_feedback_) schedule_.finished(own_ms_ / content_);  // the owner did not call frame_finished
    in_frustum_.clear();
    FrameStats ignored;
    collect_in_frustum_front_to_back(index_, view, in_frustum_, ignored);
    double triangles = 0.0;
    for (ObjectId id : in_frustum_) triangles += double(index_.scene.object(id).triangles);
    content_ = std::max(1.0, triangles + kTrianglesPerDraw * double(in_frustum_.size()));
    running_ = schedule_.next();
    const auto t0 = std::chrono::steady_clock::now();
    FrameStats s = candidates_[running_]->render_frame(view, backend);
    own_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    awaiting_feedback_ = true;
    return s;
  }

  void frame_finished(const FrameStats& measured) override {
    candidates_[running_]->frame_finished(measured);
    if (!awaiting_feedback_) return;
    awaiting_feedback_ = false;
    schedule_.finished((measured.frame_ms > 0.0 ? measured.frame_ms : own_ms_) / content_);
  }

  void release(Backend& backend) override {
    for (auto& c : candidates_) c->release(backend);
  }
  [[nodiscard]] std::size_t queries_held() const override {
    std::size_t n = 0;
    for (const auto& c : candidates_) n += c->queries_held();
    return n;
  }

 private:
  SceneIndex index_;
  std::vector<ObjectId> in_frustum_;
  double content_ = 1.0;
  std::vector<std::unique_ptr<Culler>> candidates_;
  AutoSchedule schedule_;
  std::size_t running_ = 0;
  double own_ms_ = 0.0;
  bool awaiting_feedback_ = false;
};

}  // namespace

Registration auto_registration() {
  using C = AutoConfig;
  static const ConfigTable<C> table =
      ConfigTable<C>()
          .text("candidates", &C::candidates,
                "cullers to choose among, joined by +, tried in this order (by default nohc only where a profile is at "
                "hand, as occull bench has)")
          .integer("trial", &C::trial, 1, 1000,
                   "frames a candidate runs when tried (its cost: their median, per unit of frame content)")
          .integer("period", &C::period, 1, 1000000,
                   "frames between tries of a challenger (doubled after each lost try, up to 16x)")
          .real("margin", &C::margin, 0.0, 0.9,
                "a challenger must be this much cheaper to take over (frame times of one culler vary more than 5 % "
                "between frames)");
  return registered(
      {"auto", "adaptive: runs the cheapest of chcpp, vfc and nohc for this view, learnt from the measured frame "
               "times, with hysteresis"},
      table, [](const SceneIndex& index, const C& c, const Options& o, const CullerContext& context) {
        std::vector<std::string> names;
        for (std::string_view rest = c.candidates; !rest.empty();) {
          const auto plus = rest.find('+');
          names.emplace_back(rest.substr(0, plus));
          rest = plus == std::string_view::npos ? std::string_view{} : rest.substr(plus + 1);
        }
        // nohc needs a calibrated profile; without one the default candidates leave it out.
        if (!o.has("auto.candidates") && !o.has("nohc.profile") && !has_nohc_profile(context))
          std::erase(names, "nohc");
        if (names.empty()) throw InputError("option auto.candidates: no candidate given (e.g. chcpp+vfc+nohc)");
        std::vector<std::unique_ptr<Culler>> cullers;
        for (const std::string& name : names) {
          if (name == "auto" || name == "oracle")
            throw InputError(fmt::format("option auto.candidates: '{}' cannot be a candidate", name));
          cullers.push_back(make_culler(name, index, o, context));
        }
        return std::make_unique<AutoCuller>(index, std::move(cullers), c);
      });
}

}  // namespace occull::detail
