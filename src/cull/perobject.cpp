// `perobject`: per-object asynchronous occlusion queries, after the engine
// notes' "Simple Pseudo-code".
//
// Objects in the frustum are taken nearest first. Occluders (occluder class
// `always`, opaque) are drawn first as a pre-pass. Every other object is an
// occludee with three pieces of state: frames since its last test, whether a
// query is running, and how long it has been waiting. A visible occludee is
// re-tested every `interval` frames (MAX_FRAMES_WO_OCCLUSION_TESTING) and
// drawn in between; an occluded one is re-tested every frame. A running
// query is read only when its result is available — often a frame later, so
// the answer is about an older frame: this culler may pop, and the verifier
// measures how much. While a query is pending the occludee is drawn or not
// (`render_pending`, as the notes leave it open). Occludees closer to the
// eye than the near-plane radius are drawn without a test.
#include "cullers.hpp"
#include "traversal.hpp"

#include <algorithm>

namespace occull::detail {
namespace {

class PerObjectCuller final : public Culler {
 public:
  PerObjectCuller(const SceneIndex& index, const PerObjectConfig& c)
      : index_(index),
        interval_(c.interval),
        render_pending_(c.render_pending),
        prepass_(c.prepass),
        threshold_(c.threshold),
        state_(index.scene.objects().size()) {
    for (State& s : state_) s.frames_without_test = interval_;
  }

  void visit_counters(const CounterVisitor& visit) const override { counters_.visit(visit); }

  FrameResult cull(const View& view, Backend& backend) override {
    FrameResult result;
    counters_ = {};
    ++frame_;
    if (state_.size() < index_.scene.objects().size()) {  // objects added: unknown, so tested
      State fresh;
      fresh.frames_without_test = interval_;
      state_.resize(index_.scene.objects().size(), fresh);
    }
    in_frustum_.clear();
    collect_in_frustum_front_to_back(index_, view, in_frustum_, result.nodes_visited);
    const float radius = near_plane_radius(view);

    // Pre-pass: the occluders, nearest first.
    std::vector<ObjectId> occluders;
    occludees_.clear();
    for (ObjectId id : in_frustum_) {
      state_[id].seen = frame_;
      (is_occluder(id) ? occluders : occludees_).push_back(id);
    }
    if (!occluders.empty()) backend.render(occluders);

    const auto draw = [&](ObjectId id) { backend.render(std::span<const ObjectId>(&id, 1)); };
    for (ObjectId id : occludees_) {
      State& s = state_[id];
      const Aabb& box = index_.scene.object(id).bounds;
      if (!s.started && near_eye(box, view, radius)) {  // too near to test: visible
        draw(id);
        continue;
      }
      if (s.frames_without_test >= interval_) {
        if (!s.started) {
          s.query = backend.issue_query(std::span<const Aabb>(&box, 1));
          s.started = true;
          ++counters_.query_batches;
        }
      } else {
        ++s.frames_without_test;
        draw(id);
      }
      if (s.started) {
        if (!backend.result_available(s.query)) {
          if (render_pending_) draw(id);
        } else {
          s.started = false;
          if (backend.result(s.query) > threshold_) {
            draw(id);
            s.frames_without_test = 0;
          } else {
            s.frames_without_test = interval_;  // occluded now: test again next frame
          }
        }
      }
    }
    // Queries of objects that left the frustum: collect them when done.
    for (ObjectId id = 0; id < state_.size(); ++id) {
      State& s = state_[id];
      if (s.started && s.seen != frame_ && backend.result_available(s.query)) {
        (void)backend.result(s.query);
        s.started = false;
        s.frames_without_test = interval_;
      }
    }
    return result;
  }

  // A running query is read now; its answer counts as it would have when
  // read in a later frame.
  void release(Backend& backend) override {
    for (State& s : state_) {
      if (!s.started) continue;
      s.started = false;
      s.frames_without_test = backend.result(s.query) > threshold_ ? 0 : interval_;
    }
  }
  [[nodiscard]] std::size_t queries_held() const override {
    return std::size_t(std::count_if(state_.begin(), state_.end(), [](const State& s) { return s.started; }));
  }

 private:
  QueryCounters counters_;  // of the last frame
  struct State {
    std::uint32_t frames_without_test = 0;
    bool started = false;
    QueryId query = 0;
    std::uint32_t seen = 0;  // last frame in the frustum
  };

  bool is_occluder(ObjectId id) const {
    const Object& o = index_.scene.object(id);
    return prepass_ && o.occluder == OccluderClass::always &&
           !index_.scene.material(o.material).translucent;
  }

  SceneIndex index_;
  std::uint32_t interval_;
  bool render_pending_;
  bool prepass_;
  std::uint64_t threshold_;
  std::vector<State> state_;
  std::uint32_t frame_ = 0;
  std::vector<ObjectId> in_frustum_, occludees_;
};

}  // namespace

Registration perobject_registration() {
  static const ConfigTable<PerObjectConfig> table =
      ConfigTable<PerObjectConfig>()
          .integer("interval", &PerObjectConfig::interval, 1, 1000,
                   "MAX_FRAMES_WO_OCCLUSION_TESTING: frames a visible object goes untested")
          .flag("render_pending", &PerObjectConfig::render_pending, "draw an object while its query is pending")
          .flag("prepass", &PerObjectConfig::prepass, "draw occluders (class always) first and never test them")
          .integer("threshold", &PerObjectConfig::threshold, 0, 1 << 24,
                   "an object is visible when more samples (pixels) pass")
          .approximate_unless_default();
  return registered({"perobject",
                     "per-object async queries after an occluder pre-pass; visible objects re-tested every N frames "
                     "(the engine notes)",
                     false},
                    table, [](const SceneIndex& index, const PerObjectConfig& c, const Options&, const CullerContext&) {
                      return std::make_unique<PerObjectCuller>(index, c);
                    });
}

}  // namespace occull::detail
