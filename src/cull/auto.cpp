// `auto`: the adaptive culler. No culler wins everywhere: where occlusion is
// scarce (open ground, small maps, thousands of tiny meshes) queries cost
// more than they save and plain view-frustum culling is fastest; in a city
// CHC++, CHC, NOHC, the CPU occlusion buffer or the depth pyramid save most
// of the frame, and which of them is cheapest depends on the scene and the
// device. `auto` runs one of its candidates per frame for its view, learns
// what each costs here from the frames it measured (Culler::frame_finished:
// the owner's frame time, or else its own time in render_frame), per unit
// of frame content, and keeps the cheapest with hysteresis (AutoSchedule,
// auto.hpp). Every candidate is conservative, so `auto` is.
//
// Switching, and what it keeps warm. A candidate that did not run last
// frame holds the temporal state of its own last frame (a temporal culler
// counts its own frames: to it, its last frame was the one before). The
// policy (hand_over below):
//   - Back after at most kFreshFrames frames (the current after a try of
//     another), a candidate goes on from its own state: a few frames old,
//     it is tighter than a challenger's (measured: CHC++ handed a cold
//     NOHC's visible set spent 6 frames at up to 3x its cost getting rid of
//     the extra objects, a CHC++ visible leaf being queried again only
//     after some frames).
//   - Back after longer, or never run, a Resumable candidate (chc, chcpp,
//     nohc, hiz) is handed the visibility of the frame before: the objects
//     the previous candidate drew (Culler::drawn_objects(), the visible set
//     every culler shares), when that one culled by occlusion (not vfc).
//     chc, chcpp, nohc rebuild their node states from it as after a
//     rebuilt hierarchy (carry_over); hiz's phase 1 draws it. Conservative
//     whatever the set says: queries or the depth pyramid test what it
//     calls hidden. hiz's visible set stays on the device: it is read back
//     for the hand-over (Resumable::last_visible; one wait for the device,
//     on a switch only). Without it a query culler tried after hiz started
//     cold, drew the whole frustum for some frames and lost its try
//     (city/street 1280x720 at 30 fps on llvmpipe: chcpp's try 74 and
//     45 ms, its own cost 30, hiz 41: auto kept hiz). After vfc (it drew
//     the whole frustum) there is nothing to hand over, and the candidate
//     resumes from its own state.
//   - soc and vfc keep no visibility across frames: nothing to keep warm
//     (soc's nodes shown last frame only spare it tests).
//   - What a switch still costs is priced in: every frame a candidate runs
//     is measured, the first one of a try included.
//
// The model, and where it fails. A candidate's cost is one number: its
// frame time per unit of frame content (FrustumContent below), from the
// frames it ran; the running one's is corrected every frame (smoothing),
// the others' are their last try's. The prediction of a frame is that
// number times the frame's content. It fails:
//   - where the occluded share of the frustum changes along the path: the
//     content counts the frustum, not what hides what, so a try on an open
//     stretch and the current's cost in a street are not alike (spread
//     frames: `city:blocks=20` at 1280x720 kept soc at 1.21x chcpp);
//   - in a try's two frames, which are few against the machine's noise
//     (spikes are left out, AutoSchedule; drift of 10-30 % is not);
//   - for a candidate's first frames: start-up (the renderer creates its
//     device state at its first hiz frame: 9-13 ms on llvmpipe, small maps)
//     and a cold state (CHC's first frame queries everything) count as its
//     cost, unless the frame is more than twice the try's other (a spike);
//   - for vfc's estimate, which counts every fixed cost of the frame as
//     drawing and so errs high in the frame whose exact content it is
//     priced on (every kExactEvery frames); in the frames after, its view's
//     content is older than the frame's. So it skips tries where vfc would
//     lose by far, and only in a frame whose exact content it was priced on,
//     where even so it is below the current's cost of that same frame by the
//     margin, switches to vfc without a try (field at 1280x720: soc kept at
//     1.12x vfc, the two within 8 % in every try). Measured, when it could
//     switch on later frames too and against the current's running cost (a
//     mean over other views): city / street at 1280x720 with spread frames
//     ran vfc 27 % of its frames at 2x soc's cost.
#include "auto.hpp"

#include "cullers.hpp"
#include "occull/error.hpp"
#include "traversal.hpp"
#include "core/format.hpp"

#include <algorithm>
#include <array>
#include <chrono>

namespace occull::detail {
namespace {

// A frame above this times the lowest of its try, or the current's running
// cost, is a spike of the machine rather than a cost of the candidate
// (auto.hpp).
constexpr double kSpike = 2.0;

// A try's frame above this times the reference (the current's cost, in the
// start's round the cheapest measured) ends the try at once: far beyond any
// spike of the machine seen (4-5x: llvmpipe's page-fault storms), and where
// one more such frame is what auto loses most (CHC's try on an H200's open
// field: 76 and 70 ms against 1.5).
constexpr double kFar = 8.0;

}  // namespace

AutoSchedule::AutoSchedule(AutoConfig config, std::size_t candidates)
    : config_(std::move(config)), count_(candidates), cost_(candidates, 0.0), estimate_(candidates, 0.0),
      estimated_in_(candidates, 0),
      losses_(candidates, 0), next_try_(candidates, 0), disabled_(candidates, false), starts_up_(candidates, false),
      credit_ms_(cap_ms()) {}

double AutoSchedule::cap_ms() const { return config_.budget / 2.0 * 1000.0; }

bool AutoSchedule::affordable(std::size_t c) const {
  if (initial_) return true;  // the start's round is outside the budget
  if (config_.budget <= 0.0) return false;
  const double current = cost_[current_];
  if (current <= 0.0 || ms_per_cost_ <= 0.0) return credit_ms_ >= 0.0;
  const double expected = cost_[c] > 0.0 ? cost_[c] : config_.cut * current;
  return credit_ms_ >= std::max(0.0, expected - current) * ms_per_cost_;
}

double AutoSchedule::pay(double cost, double ms) {
  if (ms > 0.0 && cost > 0.0) ms_per_cost_ = ms / cost;
  if (initial_) return 0.0;  // the start's round is outside the budget: the credit stays full
  credit_ms_ = std::min(cap_ms(), credit_ms_ + config_.budget / 2.0 * std::max(0.0, ms));
  const double current = cost_[current_];
  if (!in_trial_ || current <= 0.0 || cost <= 0.0) return 0.0;
  // A frame of a try: what it cost above the current's cost of this frame's content.
  const double excess = std::max(0.0, ms * (1.0 - current / cost));
  credit_ms_ -= excess;
  spent_ms_ += excess;
  return excess;
}

void AutoSchedule::starts_up(std::size_t c) { starts_up_[c] = true; }

void AutoSchedule::start_trial(std::size_t c) {
  running_ = c;
  in_trial_ = true;
  restarted_ = false;
  trial_frame_ = 0;
  samples_.clear();
  if (!cold_) ++tries_;
}

void AutoSchedule::disable(std::size_t c) {
  disabled_[c] = true;
  const auto first_enabled = [&] {
    return std::size_t(std::find(disabled_.begin(), disabled_.end(), false) - disabled_.begin());
  };
  if (cold_) {  // before the first frame: the first candidate that may run starts
    if (running_ == c) running_ = first_enabled();
    return;
  }
  if (!initial_ && current_ == c) {  // the cheapest measured of the others is kept
    current_ = count_;
    for (std::size_t i = 0; i < count_; ++i)
      if (!disabled_[i] && cost_[i] > 0.0 && (current_ == count_ || cost_[i] < cost_[current_])) current_ = i;
    if (current_ == count_) current_ = first_enabled();
  }
  if (running_ != c) return;
  in_trial_ = false;  // it was about to run: what comes after it does
  if (initial_)
    after_initial(c);
  else
    running_ = current_;
}

void AutoSchedule::no_cold_frame() {
  if (!cold_) return;
  cold_ = false;
  start_trial(running_);
}

void AutoSchedule::estimate(std::size_t c, double cost, bool of_this_view) {
  estimate_[c] = cost;
  if (of_this_view) estimated_in_[c] = frame_ + 1;  // the frame the next finished() or unmeasured() counts
}

double AutoSchedule::reference(std::size_t c) const {
  if (!initial_) return cost_[current_];
  double best = 0.0;  // the start's round: the cheapest of the others measured so far
  for (std::size_t i = 0; i < count_; ++i)
    if (i != c && cost_[i] > 0.0 && (best == 0.0 || cost_[i] < best)) best = cost_[i];
  return best;
}

bool AutoSchedule::hopeless(std::size_t c) const {
  const double against = reference(c);
  return estimate_[c] > 0.0 && against > 0.0 && estimate_[c] > config_.skip * against;
}

void AutoSchedule::lost(std::size_t c, std::uint32_t by) {
  losses_[c] = std::min<std::uint32_t>(losses_[c] + by, 5);
  next_try_[c] = frame_ + (std::uint64_t(config_.period) << (losses_[c] - 1));  // period x 1, 2, 4, 8, 16
}

double AutoSchedule::try_cost() const {
  if (samples_.empty()) return 0.0;
  const double lowest = *std::min_element(samples_.begin(), samples_.end());
  double sum = 0.0;
  int counted = 0;
  for (double s : samples_)
    if (s <= kSpike * lowest) {  // above: a spike of the machine, not of the candidate
      sum += s;
      ++counted;
    }
  return sum / double(counted);
}

void AutoSchedule::end_trial() {
  const double measured = try_cost();
  const std::size_t c = running_;
  in_trial_ = false;
  if (initial_) {
    cost_[c] = measured;
    after_initial(c);
    return;
  }
  if (measured < cost_[current_] * (1.0 - config_.margin)) {
    take_over(c, measured);
  } else {
    const bool by_far = cost_[current_] > 0.0 && measured > config_.cut * cost_[current_];
    cost_[c] = measured;
    lost(c, by_far ? 3 : 1);  // lost by far: as three lost tries (its next in 4 x period frames at least)
  }
  running_ = current_;
}

void AutoSchedule::take_over(std::size_t c, double cost) {
  next_try_[current_] = frame_ + std::uint64_t(config_.period);
  cost_[c] = cost;
  current_ = c;
  losses_[c] = 0;
  ++switches_;
  switched_ = true;
}

std::size_t AutoSchedule::estimated_cheaper(double than) const {
  std::size_t best = count_;
  for (std::size_t i = 0; i < count_; ++i)
    if (i != current_ && !disabled_[i] && estimated_in_[i] == frame_ && estimate_[i] > 0.0 &&
        estimate_[i] < (1.0 - config_.margin) * than && (best == count_ || estimate_[i] < estimate_[best]))
      best = i;
  return best;
}

void AutoSchedule::after_initial(std::size_t c) {
  for (std::size_t n = c + 1; n < count_; ++n) {
    if (disabled_[n]) continue;
    if (hopeless(n)) continue;  // skipped, not lost: checked again after the round
    start_trial(n);
    return;
  }
  // Every candidate measured (or skipped): keep the cheapest.
  initial_ = false;
  current_ = count_;
  for (std::size_t i = 0; i < count_; ++i)
    if (!disabled_[i] && cost_[i] > 0.0 && (current_ == count_ || cost_[i] < cost_[current_])) current_ = i;
  if (current_ == count_)  // nothing measured (every try disabled at once): the first that may run
    current_ = std::size_t(std::find(disabled_.begin(), disabled_.end(), false) - disabled_.begin());
  // The others lost their try of the round: by far (more than cut x) as three lost tries, as a try cut short.
  for (std::size_t i = 0; i < count_; ++i)
    if (i != current_ && cost_[i] > 0.0) lost(i, cost_[i] > config_.cut * cost_[current_] ? 3 : 1);
  running_ = current_;
}

void AutoSchedule::choose_next() {
  // The due try waiting longest that may start. A hopeless one is skipped
  // (an estimate is no measure: it is checked again next frame, at no
  // cost), one the budget's credit does not cover waits for it.
  std::size_t due = count_;
  for (std::size_t i = 0; i < count_; ++i)
    if (i != current_ && !disabled_[i] && next_try_[i] <= frame_ && (due == count_ || next_try_[i] < next_try_[due]) &&
        !hopeless(i) && affordable(i))
      due = i;
  if (due != count_) start_trial(due);
}

void AutoSchedule::unmeasured() {
  if (cold_) {  // the first frame is not counted anyway
    finished(0.0);
    return;
  }
  ++frame_;
  switched_ = false;
  if (in_trial_ && trial_frame_ == 0) restarted_ = true;  // the try goes on: its first frame has run
}

void AutoSchedule::finished(double cost, double ms) {
  ++frame_;
  switched_ = false;
  if (cold_) {  // every culler's first frame builds its state from nothing: not a measure of it
    cold_ = false;
    start_trial(running_);
    return;
  }
  const double excess = pay(cost, ms);
  if (in_trial_) {
    samples_.push_back(cost);
    ++trial_frame_;
    // Lost by far: every frame of the try above cut x the reference; one
    // frame decides only when it is no spike against the candidate's last
    // measure (a loser tried again) or above kFar x the reference (but in
    // the first try of a candidate that starts up), else two do (the
    // start's round).
    const double against = reference(running_), lowest = *std::min_element(samples_.begin(), samples_.end());
    const bool far = against > 0.0 && cost > kFar * against && !(starts_up_[running_] && cost_[running_] == 0.0);
    const bool confirmed = trial_frame_ >= 2 || (cost_[running_] > 0.0 && cost <= kSpike * cost_[running_]) || far;
    const bool cut = confirmed && against > 0.0 && lowest > config_.cut * against;
    // Out of credit: the credit left would not cover another such frame.
    const bool spent = excess > 0.0 && credit_ms_ < excess;
    if (trial_frame_ >= config_.trial || cut || spent) end_trial();
    return;
  }
  // The current culler: a running cost, so it follows the scene; a spike
  // counts as kSpike x that cost. Never measured (kept because every other
  // was disabled), it starts from this frame.
  double& running = cost_[current_];
  running = running > 0.0 ? running + config_.smoothing * (std::min(cost, kSpike * running) - running) : cost;
  // An estimate of this frame's view errs high (auto.cpp): below the
  // current's cost of the same view by the margin (and its running cost:
  // not against a spike), the candidate is cheaper and takes over without
  // a try. Other estimates only skip tries.
  if (const std::size_t cheaper = estimated_cheaper(std::min(cost, running)); cheaper != count_) {
    take_over(cheaper, estimate_[cheaper]);
    running_ = current_;
    return;
  }
  choose_next();
}

namespace {

// How much there is to draw in a view, whoever culls it: the triangles of
// the objects in the frustum plus a triangle-equivalent per draw. Frame
// costs are compared per unit of it, so that candidates tried on different
// frames of a walk (a crowded street, then an open square) are compared on
// what they did with the frame rather than on what the frame held.
constexpr double kTrianglesPerDraw = 64.0;

// Subtrees of at most this many objects count whole when the frustum cuts them.
constexpr std::uint32_t kWholeSubtree = 8;

// The frustum's exact content is measured every this many frames.
constexpr std::uint64_t kExactEvery = 8;

// vfc's estimate: the median of the cost per unit drawn of this many last frames.
constexpr std::size_t kPriceFrames = 5;

// A candidate back after at most this many frames goes on from its own state.
constexpr std::uint64_t kFreshFrames = 4;

// The content of every subtree, so that a node inside the frustum counts at
// once: measuring a view costs a frustum traversal down to the nodes its
// planes cut, not a walk over every object in it. Roughly (`exact` false),
// a subtree of at most kWholeSubtree objects that the planes cut counts
// whole: a scale for comparing frames, the same whoever culls, whose
// traversal stops a few levels above the leaves (auto's own CPU time per
// frame); exactly, the objects of the leaves the planes cut are tested.
class FrustumContent {
 public:
  explicit FrustumContent(const SceneIndex& index) : index_(index) {}

  /// Triangles + kTrianglesPerDraw x objects in the view's frustum (at
  /// least 1), roughly or exactly.
  double operator()(const View& view, bool exact) {
    refresh();
    double content = 0.0;
    add(Bvh::root(), Frustum::all_planes, view, exact ? 0 : kWholeSubtree, content);
    return std::max(1.0, content);
  }

 private:
  static double of(const Object& o) { return double(o.triangles) + kTrianglesPerDraw; }

  void refresh() {
    const Bvh& bvh = index_.bvh;
    if (known_ && generation_ == bvh.generation() && layout_ == index_.scene.layout_revision()) return;
    known_ = true;
    generation_ = bvh.generation();
    layout_ = index_.scene.layout_revision();
    subtree_.assign(bvh.size(), 0.0);
    // Children come after their parent (Bvh::left(n) is n + 1): sum upwards.
    for (NodeId n = NodeId(bvh.size()); n-- > 0;) {
      if (bvh.is_leaf(n))
        for (ObjectId id : bvh.objects(n)) subtree_[n] += of(index_.scene.object(id));
      if (bvh.node(n).parent != kNoNode) subtree_[bvh.node(n).parent] += subtree_[n];
    }
  }

  void add(NodeId n, std::uint32_t planes, const View& view, std::uint32_t whole, double& content) const {
    const Bvh& bvh = index_.bvh;
    if (bvh.node(n).object_count == 0) return;
    if (planes != 0 && view.frustum.classify(bvh.node(n).bounds, planes) == Containment::outside) return;
    if (planes == 0 || bvh.node(n).object_count <= whole) {  // inside, or small: the whole subtree
      content += subtree_[n];
      return;
    }
    if (bvh.is_leaf(n)) {
      for (ObjectId id : bvh.objects(n)) {
        const Object& o = index_.scene.object(id);
        std::uint32_t mask = planes;
        if (o.bounds.empty() || view.frustum.classify(o.bounds, mask) == Containment::outside) continue;
        content += of(o);
      }
      return;
    }
    add(Bvh::left(n), planes, view, whole, content);
    add(bvh.right(n), planes, view, whole, content);
  }

  SceneIndex index_;
  std::vector<double> subtree_;
  std::uint64_t generation_ = 0;
  std::uint64_t layout_ = 0;
  bool known_ = false;
};

// A camera cut: between two frames the view turned by more than
// kCutDegrees or its eye moved more than kCutShare of the scene's diagonal
// (a jump to another place, not a walk: a walk at 30 fps moves well under
// 1 %). After one, temporal cullers start over (their last frame says
// nothing of this one), so the cut's frame and the next kCutFrames - 1
// are not measured: a try there would judge a culler by its restart.
constexpr float kCutDegrees = 30.0f;
constexpr float kCutShare = 0.05f;
constexpr int kCutFrames = 2;
// ... unless the view has jumped at every one of the last kSlideshow
// frames: then jumps are how it moves (frames spread over a path, a
// slideshow), every culler pays for them each frame, and each frame is
// measured as it comes. Measured: with frames spread over a q3 map's tour
// (1280x720) every frame was a cut, the start's round never advanced and
// its first candidate ran 46 of 100 frames (chc, 1.47x vfc there).
// OpenSceneGraph's bench warms up with 8 frames spread over the walk (7
// jumps): those stay unmeasured.
constexpr int kSlideshow = 8;

struct Candidate {
  std::string spec;
  std::unique_ptr<Culler> culler;
  bool device = false;     // culls on the device (hiz): needs Backend::device_culling()
  bool frustum = false;    // draws the whole frustum (vfc): its cost is estimated from others' frames
  bool cpu_occluders = false;  // occludes with the scene's vertices only (soc): needs meshes that have them
  std::uint64_t last_frame = 0;  // auto's frame it last ran (0: never)
};

class AutoCuller final : public Culler {
 public:
  AutoCuller(const SceneIndex& index, std::vector<Candidate> candidates, const AutoConfig& config)
      : scene_(index.scene), content_of_(index), candidates_(std::move(candidates)),
        schedule_(config, candidates_.size()) {}

  FrameResult cull(const View& view, Backend& backend) override {
    if (!started_) start(backend);
    if (awaiting_feedback_) finished(FrameMeasure{});  // the owner did not call frame_finished
    content_ = content_of_(view, false);
    const bool cut = camera_cut(view);
    cuts_in_a_row_ = cut ? cuts_in_a_row_ + 1 : 0;
    if (cut)
      after_cut_ = cuts_in_a_row_ > kSlideshow ? 0 : kCutFrames;
    else
      after_cut_ = std::max(after_cut_, 1) - 1;
    // vfc's estimate needs the frustum's exact content; it is measured now
    // and then, its share of the rough one kept.
    exact_now_ = frame_ % kExactEvery == 0;
    if (exact_now_) exact_share_ = content_of_(view, true) / content_;
    const std::size_t run = schedule_.next();
    if (run != last_ && last_ < candidates_.size()) hand_over(last_, run, backend);
    candidates_[run].last_frame = ++frame_;
    const bool tried = schedule_.starts_try(), switched = schedule_.just_switched();
    // The prediction: the candidate's last measured cost per unit of content (0 before its first).
    const double predicted = after_cut_ > 0 ? 0.0 : schedule_.cost(run) * content_;
    const auto t0 = std::chrono::steady_clock::now();
    const FrameResult result = candidates_[run].culler->render_frame(view, backend);
    own_ms_ = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    last_ = run;
    awaiting_feedback_ = true;
    tried_ = tried;
    switched_ = switched;
    predicted_ms_ = predicted;
    return result;
  }

  // The candidate's counters, and auto's: which candidate ran (1 + its
  // index in choices()), whether the frame started a try or a switch, and
  // the cost it predicted for it before running it (0: none yet, or a frame
  // after a camera cut), ms.
  void visit_counters(const CounterVisitor& visit) const override {
    if (last_ >= candidates_.size()) return;  // no frame rendered yet
    candidates_[last_].culler->visit_counters(visit);
    visit("auto_choice", double(last_ + 1));
    visit("auto_tries", tried_ ? 1.0 : 0.0);
    visit("auto_switches", switched_ ? 1.0 : 0.0);
    visit("auto_predicted_ms", predicted_ms_);
  }

  void frame_finished(const FrameMeasure& measured) override {
    if (last_ >= candidates_.size()) return;  // no frame rendered yet
    candidates_[last_].culler->frame_finished(measured);
    if (awaiting_feedback_) finished(measured);
  }

  [[nodiscard]] std::vector<std::string> choices() const override {
    std::vector<std::string> specs;
    for (const Candidate& c : candidates_) specs.push_back(c.spec);
    return specs;
  }

  void release(Backend& backend) override {
    for (Candidate& c : candidates_) c.culler->release(backend);
  }
  [[nodiscard]] std::size_t queries_held() const override {
    std::size_t n = 0;
    for (const Candidate& c : candidates_) n += c.culler->queries_held();
    return n;
  }

 private:
  // The first frame: candidates that cannot run on this backend never will,
  // nor can a CPU occlusion buffer cull in a scene whose meshes have no
  // vertices on the CPU (it would be vfc with a buffer's cost).
  void start(Backend& backend) {
    started_ = true;
    const Aabb world = scene_.bounds();
    scene_diagonal_ = world.empty() ? 0.0f : glm::length(world.extent());
    const auto meshes = scene_.meshes();
    const bool vertices =
        std::any_of(meshes.begin(), meshes.end(), [](const Mesh& m) { return !m.positions.empty(); });
    std::size_t left = candidates_.size();
    for (std::size_t c = 0; c < candidates_.size(); ++c)
      if (((candidates_[c].device && !backend.device_culling()) || (candidates_[c].cpu_occluders && !vertices)) &&
          left > 1) {
        schedule_.disable(c);
        --left;
      } else if (candidates_[c].device) {
        schedule_.starts_up(c);
      }
    // A candidate that cannot be resumed keeps no visibility across frames
    // (soc, vfc): its first frame is no cold one.
    if (!dynamic_cast<Resumable*>(candidates_[schedule_.next()].culler.get())) schedule_.no_cold_frame();
  }

  // The frame's cost reaches the schedule; with the owner's measure (frame
  // time, and its parts), vfc's cost is estimated too: it would draw the
  // frustum at the cost per unit drawn of this frame (the frame's time less
  // the culler's CPU, over what it drew). The estimate errs high: fixed
  // costs of the frame count as drawing, and so do the objects the culler
  // hid, which would fail the depth test, and the culler's query waits (the
  // device drawing what it was given, which vfc's frame pays too, and any
  // stall: taken out, they left llvmpipe's drawing at 1280x720 unpriced and
  // vfc took over at a tenth of its cost; VfcsEstimatePricesQueryWaitsAsDrawing).
  // It spares a try where vfc would lose by far (a dense city), and switches
  // to vfc where even so it is cheaper than the current by the margin (open
  // ground, where the culler hides little and its own CPU is what it adds).
  void finished(const FrameMeasure& measured) {
    awaiting_feedback_ = false;
    const double drawn = double(measured.triangles) + kTrianglesPerDraw * double(measured.draw_calls);
    // (Not from hiz's frames: what the device drew is read back after the frame, if at all.)
    if (measured.frame_ms > 0.0 && drawn > 0.0 && !candidates_[last_].frustum && !candidates_[last_].device) {
      // The median of the last kPriceFrames frames' price: one frame's spike does not skip vfc's try.
      prices_[priced_++ % kPriceFrames] = std::max(0.0, measured.frame_ms - measured.cpu_ms) / drawn;
      std::array<double, kPriceFrames> sorted = prices_;
      const std::size_t n = std::min<std::size_t>(priced_, kPriceFrames);
      std::nth_element(sorted.begin(), sorted.begin() + n / 2, sorted.begin() + n);
      for (std::size_t c = 0; c < candidates_.size(); ++c)
        if (candidates_[c].frustum) schedule_.estimate(c, sorted[n / 2] * exact_share_, exact_now_);
    }
    if (after_cut_ > 0)
      schedule_.unmeasured();
    else {
      const double ms = measured.frame_ms > 0.0 ? measured.frame_ms : own_ms_;
      schedule_.finished(ms / content_, ms);
    }
  }

  // `to` runs after `from` ran last frame: hands it the visibility `from`
  // found, when `to` has been away long or never ran, `from` culled by
  // occlusion and `to` can take it (the policy at the top of this file).
  void hand_over(std::size_t from, std::size_t to, Backend& backend) {
    if (candidates_[from].frustum) return;  // vfc drew the frustum: no news
    const std::uint64_t last = candidates_[to].last_frame;
    if (last != 0 && frame_ - last <= kFreshFrames) return;  // its own state is fresher
    auto* resumable = dynamic_cast<Resumable*>(candidates_[to].culler.get());
    if (!resumable) return;
    std::span<const ObjectId> drawn = candidates_[from].culler->drawn_objects();
    if (drawn.empty()) {  // hiz: its visible set is on the device
      handed_.clear();
      if (auto* giver = dynamic_cast<Resumable*>(candidates_[from].culler.get())) giver->last_visible(backend, handed_);
      drawn = handed_;
    }
    if (drawn.empty()) return;
    resumable->resume_from(drawn);
  }

  // Whether the view jumped since the last frame (see kCutDegrees).
  bool camera_cut(const View& view) {
    const glm::vec3 forward = -glm::vec3(view.view[0][2], view.view[1][2], view.view[2][2]);
    const bool cut = seen_view_ && (glm::dot(forward, last_forward_) < std::cos(glm::radians(kCutDegrees)) ||
                                    glm::distance(view.eye, last_eye_) > kCutShare * scene_diagonal_);
    seen_view_ = true;
    last_forward_ = forward;
    last_eye_ = view.eye;
    return cut;
  }

  const Scene& scene_;
  FrustumContent content_of_;
  float scene_diagonal_ = 0.0f;
  bool seen_view_ = false;
  glm::vec3 last_forward_{0.0f}, last_eye_{0.0f};
  int after_cut_ = 0;  // frames left that are not measured: the cut's and kCutFrames - 1 after it
  int cuts_in_a_row_ = 0;  // consecutive frames that were cuts, this one included
  double content_ = 1.0;      // this frame's, roughly
  double exact_share_ = 1.0;  // exact content / rough content, when last measured
  bool exact_now_ = false;    // ... in this frame
  std::vector<Candidate> candidates_;
  std::vector<ObjectId> handed_;  // a visible set read back for a hand-over (from hiz)
  AutoSchedule schedule_;
  std::size_t last_ = std::size_t(-1);  // the candidate run in the last frame
  std::uint64_t frame_ = 0;             // frames run, counting from 1
  double own_ms_ = 0.0;
  bool tried_ = false, switched_ = false;  // the last frame started a try, a switch (counters)
  double predicted_ms_ = 0.0;  // the cost predicted for the last frame, ms (counters)
  std::array<double, kPriceFrames> prices_{};  // the last frames' cost per unit drawn (vfc's estimate)
  std::size_t priced_ = 0;
  bool awaiting_feedback_ = false;
  bool started_ = false;
};

}  // namespace

Registration auto_registration() {
  using C = AutoConfig;
  static const ConfigTable<C> table =
      ConfigTable<C>()
          .text("candidates", &C::candidates,
                "cullers to choose among, joined by +, tried in this order (by default those that were cheapest "
                "somewhere in the default suite; hiz only on a backend with device culling; add nohc with a "
                "hardware profile)")
          .integer("trial", &C::trial, 1, 1000, "frames a try of a candidate runs at most (its cost: their mean)")
          .integer("period", &C::period, 1, 1000000,
                   "frames before a loser's next try (doubled after each further loss, up to 16x; a loss by more "
                   "than cut counts as three)")
          .real("margin", &C::margin, 0.0, 0.9,
                "a challenger must be this much cheaper to take over (frame times of one culler vary by a few "
                "percent between frames)")
          .real("cut", &C::cut, 1.0, 100.0,
                "a try costing more than this times the current culler's lost by far (its next try in 4x period "
                "frames at least)")
          .real("skip", &C::skip, 1.0, 100.0,
                "vfc is not tried while its estimated cost is above this times the current culler's")
          .real("budget", &C::budget, 0.0, 1.0,
                "tries after the start's round cost at most this share of any second's frame time above the "
                "current culler's (0: no tries after the start's round)");
  return registered(
      {"auto", "adaptive: runs the cheapest of its candidates (every conservative culler) for this view, learnt "
               "from the measured frame times, with hysteresis"},
      table, [](const SceneIndex& index, const C& c, const Options& o, const CullerContext& context) {
        std::vector<std::string> names;
        for (std::string_view rest = c.candidates; !rest.empty();) {
          const auto plus = rest.find('+');
          names.emplace_back(rest.substr(0, plus));
          rest = plus == std::string_view::npos ? std::string_view{} : rest.substr(plus + 1);
        }
        if (names.empty()) throw InputError("option auto.candidates: no candidate given (e.g. chcpp+vfc+nohc)");
        std::vector<Candidate> candidates;
        for (const std::string& name : names) {
          const AlgorithmInfo& info = find_algorithm(parse_algorithm_spec(name, o).name);
          if (info.name == "auto" || info.lab_only || !info.conservative)
            throw InputError(detail::format("option auto.candidates: '{}' cannot be a candidate (auto runs conservative "
                                         "cullers other than itself)",
                                         name));
          candidates.push_back(
              {name, make_culler(name, index, o, context), info.device, info.name == "vfc", info.cpu_occluders});
        }
        return std::make_unique<AutoCuller>(index, std::move(candidates), c);
      });
}

}  // namespace occull::detail
