// CHC / CHC++ behaviour with a Backend test double that answers queries
// from a known visibility.
#include "cull/chcpp.hpp"
#include "occull/culler.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <set>

using namespace occull;
using namespace occull::detail;

namespace {

// A row of `n` 2 m boxes along -Z in front of the camera, 4 m apart.
Scene row_scene(int n) {
  std::vector<Aabb> boxes;
  for (int i = 0; i < n; ++i)
    boxes.push_back({{-1, -1, -6.0f - 4.0f * float(i)}, {1, 1, -4.0f - 4.0f * float(i)}});
  return test::box_scene(boxes);
}

const View kView = test::unsampled(make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.1f, 500.0f}, 64, 64));

// Visible = overlaps one of the given boxes.
std::function<std::uint64_t(std::span<const Aabb>)> visible_if_overlapping(std::vector<Aabb>* visible) {
  return [visible](std::span<const Aabb> boxes) {
    std::uint64_t samples = 0;
    for (const Aabb& b : boxes)
      for (const Aabb& v : *visible)
        if (b.overlaps(v)) ++samples;
    return samples;
  };
}

}  // namespace

TEST(Multiquery, GroupSizeMaximisesBenefitOverCost) {
  // V(j) = j / (1 + (1 - prod_{i<=j} p_i) j), worked by hand.
  // 0.99 0.99 0.98 0.97 0.95 0.9 ...: V(4) = 4 / (1 + 0.06832 * 4) = 3.142,
  // V(5) = 5 / (1 + 0.114904 * 5) = 3.176, V(6) = 6 / (1 + 0.203414 * 6) = 2.702.
  EXPECT_EQ(best_multiquery_size(std::vector<double>{0.99, 0.99, 0.98, 0.97, 0.95, 0.9, 0.8, 0.6, 0.4, 0.3}), 5u);
  // 0.9 0.8 0.7 ...: V(1) = 0.909, V(2) = 2 / 1.56 = 1.282, V(3) = 3 / 2.488 = 1.206.
  EXPECT_EQ(best_multiquery_size(std::vector<double>{0.9, 0.8, 0.7, 0.6, 0.5, 0.4}), 2u);
  // 0.999 x 4: V(4) = 4 / 1.016 = 3.94, the largest.
  EXPECT_EQ(best_multiquery_size(std::vector<double>{0.999, 0.999, 0.999, 0.999}), 4u);
  // 0.3 0.3 0.29: every V(j) < 1 (V(1) = 0.588): each node alone.
  EXPECT_EQ(best_multiquery_size(std::vector<double>{0.3, 0.3, 0.29}), 1u);
  EXPECT_EQ(best_multiquery_size(std::vector<double>{0.9}), 1u);
  // Nodes certain to stay invisible go in one query.
  EXPECT_EQ(best_multiquery_size(std::vector<double>(30, 1.0)), 30u);
  // Likely ones first, the group stops where the unlikely ones begin.
  std::vector<double> mixed(5, 0.99);
  mixed.insert(mixed.end(), 20, 0.3);
  EXPECT_EQ(best_multiquery_size(mixed), 5u);
}

TEST(Chcpp, NodesThatStayInvisibleShareMultiqueriesAndAFailedOneIsSplit) {
  // 40 boxes in view, visible in a checkerboard pattern for 20 frames, so
  // the hidden leaves form the invisible boundary one by one (hidden ones
  // side by side would make a hidden subtree: one query for all of them);
  // their persistence grows and CHC++ tests them together. Then one odd box
  // appears: its multiquery comes back visible, the nodes are re-queried one
  // by one, and the object is drawn in that same frame.
  std::vector<Aabb> boxes;
  for (int i = 0; i < 40; ++i) {
    const float x = float(i % 8) * 3.0f - 12.0f, y = float(i / 8) * 3.0f - 7.0f;
    boxes.push_back({{x, y, -40}, {x + 1, y + 1, -39}});
  }
  const Scene scene = test::box_scene(boxes);
  BvhOptions bo;
  bo.max_leaf_objects = 1;
  const Bvh bvh = Bvh::build(scene, bo);
  Options o;
  o.set("chcpp.tight", "off");  // one box per node: boxes per query = nodes per query
  o.set("chcpp.virtual_leaf", "0");
  o.set("chcpp.pkeep_samples", "5");
  auto culler = make_culler("chcpp", {scene, bvh}, o);
  const auto hidden = [](ObjectId i) { return (i % 8 + i / 8) % 2 == 1; };
  std::vector<Aabb> visible;
  for (ObjectId i = 0; i < boxes.size(); ++i)
    if (!hidden(i)) visible.push_back(boxes[i]);
  test::ScriptedBackend backend;
  backend.visible_samples = visible_if_overlapping(&visible);
  const View view = test::unsampled(make_view({{0, 0, 0}, 0, 0}, {90.0f, 0.1f, 500.0f}, 64, 64));
  std::uint64_t multiqueries = 0;
  for (int f = 0; f < 20; ++f) {
    (void)culler->render_frame(view, backend);
    multiqueries += std::uint64_t(test::counter(*culler, "multiqueries"));
  }
  EXPECT_GT(multiqueries, 0u) << "persistently invisible nodes are grouped";
  std::size_t largest = 0;
  for (const auto& q : backend.queried) largest = std::max(largest, q.size());
  EXPECT_GE(largest, 10u) << "groups of many nodes";
  for (ObjectId id : backend.rendered) EXPECT_FALSE(hidden(id)) << "hidden object " << id << " drawn";

  ASSERT_TRUE(hidden(17));
  visible.push_back(boxes[17]);
  backend.rendered.clear();
  (void)culler->render_frame(view, backend);
  EXPECT_GE(test::counter(*culler, "failed_multiqueries"), 1.0);
  const std::set<ObjectId> drawn(backend.rendered.begin(), backend.rendered.end());
  EXPECT_TRUE(drawn.count(17)) << "drawn in the frame it appears";
  for (ObjectId id : drawn) EXPECT_TRUE(!hidden(id) || id == 17) << "hidden object " << id << " drawn";
}

TEST(Multiquery, NoGroupWhenIndividualQueriesAreExpectedToBeCheaper) {
  // V <= 1 means a group saves nothing over one query per node: query alone.
  EXPECT_EQ(best_multiquery_size(std::vector<double>{0.3, 0.3, 0.3, 0.3}), 1u);
  EXPECT_EQ(best_multiquery_size(std::vector<double>{0.01, 0.01, 0.01}), 1u);
}

TEST(VisibilityPersistence, AnalyticUntilEnoughSamples) {
  VisibilityPersistence p(10);
  EXPECT_DOUBLE_EQ(p.p_keep(0), 0.99 - 0.7);
  EXPECT_NEAR(p.p_keep(3), 0.99 - 0.7 * std::exp(-3.0), 1e-12);
  for (int k = 0; k < 9; ++k) p.record(2, true);
  EXPECT_NEAR(p.p_keep(2), 0.99 - 0.7 * std::exp(-2.0), 1e-12) << "9 samples are not enough";
  p.record(2, false);
  EXPECT_DOUBLE_EQ(p.p_keep(2), 0.9);
}

TEST(VisibilityPersistence, MeasuredValuesPropagateToHigherPersistence) {
  VisibilityPersistence p(4);
  for (int k = 0; k < 4; ++k) p.record(1, k != 0);  // 3 of 4 kept
  EXPECT_DOUBLE_EQ(p.p_keep(1), 0.75);
  EXPECT_DOUBLE_EQ(p.p_keep(5), 0.75);   // no data at 5: the value of 1 carries up
  EXPECT_DOUBLE_EQ(p.p_keep(40), 0.75);
  EXPECT_NEAR(p.p_keep(0), 0.29, 1e-12);  // nothing below: the formula
  for (int k = 0; k < 4; ++k) p.record(7, true);
  EXPECT_DOUBLE_EQ(p.p_keep(9), 1.0);
  EXPECT_DOUBLE_EQ(p.p_keep(6), 0.75);
  p.record(1000, true);  // clamped into the last bucket
  EXPECT_EQ(p.samples(VisibilityPersistence::kMaxPersistence), 1u);
}

TEST(Jitter, FirstRequeryDelaysCoverOneToNavMinusOne) {
  std::map<std::uint32_t, int> seen;
  for (std::uint64_t r = 0; r < 1000; ++r) ++seen[first_requery_delay(6, r * 2654435761u)];
  EXPECT_EQ(seen.begin()->first, 1u);
  EXPECT_EQ(seen.rbegin()->first, 5u);
  EXPECT_EQ(seen.size(), 5u);
  for (const auto& [delay, count] : seen) EXPECT_GT(count, 120) << delay;  // about 200 each
}

TEST(Jitter, NewlyVisibleLeavesAreNotReQueriedAllInOneFrame) {
  // 64 boxes side by side in view, all invisible in frame 1, all visible from
  // frame 2 on. With jitter, their re-queries spread over the next frames.
  std::vector<Aabb> boxes;
  for (int i = 0; i < 64; ++i) {
    const float x = -16.0f + float(i % 8) * 4.0f, y = -16.0f + float(i / 8) * 4.0f;
    boxes.push_back({{x, y, -60}, {x + 1, y + 1, -59}});
  }
  const Scene scene = test::box_scene(boxes);
  BvhOptions bo;
  bo.max_leaf_objects = 1;
  const Bvh bvh = Bvh::build(scene, bo);
  std::vector<Aabb> visible;
  for (const bool jitter : {true, false}) {
    Options o;
    o.set("chcpp.jitter", jitter ? "on" : "off");
    o.set("chcpp.multiquery", "off");
    o.set("chcpp.virtual_leaf", "0");
    auto culler = make_culler("chcpp", {scene, bvh}, o);
    visible.clear();
    test::ScriptedBackend backend;
    backend.visible_samples = visible_if_overlapping(&visible);
    const View view = test::unsampled(make_view({{0, 0, 0}, 0, 0}, {90.0f, 0.1f, 500.0f}, 64, 64));
    culler->render_frame(view, backend);  // frame 1: nothing visible
    visible = boxes;
    culler->render_frame(view, backend);  // frame 2: everything turns visible
    std::vector<std::size_t> leaf_queries;
    for (int f = 3; f <= 8; ++f) {
      backend.queried.clear();
      culler->render_frame(view, backend);
      leaf_queries.push_back(backend.queried.size());
    }
    const std::size_t peak = *std::max_element(leaf_queries.begin(), leaf_queries.end());
    if (jitter)
      EXPECT_LT(peak, 32u) << "re-queries should be spread over frames 3..7";
    else
      EXPECT_GE(peak, 64u) << "without jitter all 64 come back in the same frame";
  }
}

TEST(PullUp, MarksAncestorsUpToTheFirstVisibleOne) {
  const Scene scene = row_scene(16);
  BvhOptions bo;
  bo.max_leaf_objects = 1;
  const Bvh bvh = Bvh::build(scene, bo);
  std::vector<NodeState> state(bvh.size());
  NodeId leaf = 0;
  while (!bvh.node(leaf).is_leaf()) leaf = Bvh::left(leaf);
  pull_up_visibility(state, bvh, leaf);
  for (NodeId n = leaf; n != kNoNode; n = bvh.node(n).parent) EXPECT_TRUE(state[n].visible) << n;
  EXPECT_FALSE(state[bvh.right(Bvh::root())].visible);
  // Stops early: with the parent visible already, the root is left alone.
  std::vector<NodeState> fresh(bvh.size());
  fresh[bvh.node(leaf).parent].visible = true;
  pull_up_visibility(fresh, bvh, leaf);
  EXPECT_FALSE(fresh[Bvh::root()].visible);
}

TEST(EyeInside, NodeAroundTheCameraIsNotQueried) {
  // One big object around the eye: visible without a query in every culler.
  const Scene scene = test::box_scene({{{-50, -50, -50}, {50, 50, 50}}});
  const Bvh bvh = Bvh::build(scene);
  for (const char* name : {"stopwait", "chc", "chcpp"}) {
    auto culler = make_culler(name, {scene, bvh});
    test::ScriptedBackend backend;
    backend.visible_samples = [](std::span<const Aabb>) { return std::uint64_t(0); };
    for (int f = 0; f < 3; ++f) culler->render_frame(kView, backend);
    EXPECT_TRUE(backend.queried.empty()) << name;
    EXPECT_EQ(backend.rendered.size(), 3u) << name;
  }
}

TEST(Conservative, HierarchicalCullersRenderEveryVisibleObjectEveryFrame) {
  // Boxes scattered in view; the test double says which are visible, and
  // visibility changes every few frames. Every visible object must be
  // rendered in the frame it is visible.
  std::vector<Aabb> boxes;
  for (int i = 0; i < 60; ++i) {
    const float x = float((i * 37) % 21) - 10.0f, y = float((i * 11) % 13) - 6.0f;
    const float z = -8.0f - float((i * 7) % 40);
    boxes.push_back({{x, y, z}, {x + 0.8f, y + 0.8f, z + 0.8f}});
  }
  const Scene scene = test::box_scene(boxes);
  const Bvh bvh = Bvh::build(scene);
  for (const char* spec : {"stopwait", "chc", "chc:skip=3", "chcpp", "chcpp:multiquery=off",
                           "chcpp:vqueue=off", "chcpp:batch=1", "chcpp:tight=off", "chcpp:jitter=off",
                           "chcpp:virtual_leaf=40"}) {
    const AlgorithmSpec a = parse_algorithm_spec(spec);
    auto culler = make_culler(a.name, {scene, bvh}, a.options);
    std::vector<Aabb> visible;
    test::ScriptedBackend backend;
    backend.visible_samples = visible_if_overlapping(&visible);
    for (int f = 0; f < 30; ++f) {
      visible.clear();
      std::set<ObjectId> truth;
      for (ObjectId id = 0; id < boxes.size(); ++id)
        if ((id * 7 + ObjectId(f / 4)) % 5 < 2 && kView.frustum.classify(boxes[id]) != Containment::outside) {
          visible.push_back(boxes[id]);
          truth.insert(id);
        }
      backend.rendered.clear();
      culler->render_frame(kView, backend);
      const std::set<ObjectId> rendered(backend.rendered.begin(), backend.rendered.end());
      for (ObjectId id : truth) EXPECT_TRUE(rendered.count(id)) << spec << " frame " << f << " object " << id;
    }
  }
}

TEST(Chcpp, BatchingCutsStateChangesComparedWithChc) {
  // Needs a backend that counts state changes: count render<->query switches.
  class SwitchCounter final : public Backend {
   public:
    void render(std::span<const ObjectId>) override { mode(false); }
    QueryId issue_query(std::span<const Aabb>) override {
      mode(true);
      return 0;
    }
    bool result_available(QueryId) override { return true; }
    std::uint64_t result(QueryId) override { return 1; }
    BackendStats stats() const override { return s; }
    void mode(bool q) {
      if (q != querying) ++s.state_changes;
      querying = q;
    }
    BackendStats s;
    bool querying = false;
  };
  std::vector<Aabb> boxes;
  for (int i = 0; i < 200; ++i) {
    const float x = float(i % 20) * 2.0f - 20.0f, z = -10.0f - float(i / 20) * 3.0f;
    boxes.push_back({{x, -1, z}, {x + 1, 1, z + 1}});
  }
  const Scene scene = test::box_scene(boxes);
  const Bvh bvh = Bvh::build(scene);
  std::map<std::string, std::uint64_t> changes;
  for (const char* name : {"chc", "chcpp"}) {
    auto culler = make_culler(name, {scene, bvh});
    SwitchCounter backend;
    for (int f = 0; f < 10; ++f) culler->render_frame(kView, backend);
    changes[name] = backend.s.state_changes;
  }
  EXPECT_LT(changes["chcpp"] * 10, changes["chc"]);
}

TEST(EnteringGate, QueriesUntilEnteringNodesProveRarelyOccludedPerRegion) {
  EnteringGate gate(2, 0.1);
  EXPECT_TRUE(gate.query(0)) << "a new scene starts as plain CHC++";
  for (int i = 0; i < 100; ++i) gate.record(0, false);  // region 0: open ground
  for (int i = 0; i < 100; ++i) gate.record(1, i % 2 == 0);  // region 1: half occluded
  EXPECT_FALSE(gate.query(0));
  EXPECT_LT(gate.p_occluded(0), 0.1);
  EXPECT_TRUE(gate.query(1)) << "the other subtree keeps querying";
  EXPECT_NEAR(gate.p_occluded(1), 0.5, 0.15);
  for (int i = 0; i < 40; ++i) gate.record(0, true);  // walls come into view
  EXPECT_TRUE(gate.query(0)) << "recent outcomes weigh most";
  EnteringGate always(1, 0.0);
  for (int i = 0; i < 100; ++i) always.record(0, false);
  EXPECT_TRUE(always.query(0)) << "p_min 0: always query, as CHC++";
}

namespace {

// 48 boxes on a ring around the camera, which turns 0.15 rad a frame, so
// nodes keep entering the view. Returns the queries of frames 60..119 and
// checks every frame draws each box in the frustum that the backend calls visible.
std::uint64_t queries_while_turning(const char* enter_p_min, bool all_visible) {
  std::vector<Aabb> boxes;
  for (int i = 0; i < 48; ++i) {
    const float a = float(i) * 6.2831853f / 48.0f;
    const glm::vec3 c{20.0f * std::cos(a), 0.0f, 20.0f * std::sin(a)};
    boxes.push_back({c - glm::vec3(0.5f), c + glm::vec3(0.5f)});
  }
  const Scene scene = test::box_scene(boxes);
  const Bvh bvh = Bvh::build(scene);
  Options o;
  o.set("chcpp.virtual_leaf", "0");
  o.set("chcpp.enter_p_min", enter_p_min);
  auto culler = make_culler("chcpp", {scene, bvh}, o);
  test::ScriptedBackend backend;
  if (!all_visible) backend.visible_samples = [](std::span<const Aabb>) { return std::uint64_t(0); };
  std::uint64_t queries = 0;
  for (int f = 0; f < 120; ++f) {
    const View view = test::unsampled(make_view({{0, 0, 0}, 0.15f * float(f), 0}, {60.0f, 0.1f, 100.0f}, 64, 64));
    backend.rendered.clear();
    const std::uint64_t before = backend.stats().queries;
    (void)culler->render_frame(view, backend);
    if (f >= 60) queries += backend.stats().queries - before;
    if (!all_visible) continue;
    const std::set<ObjectId> drawn(backend.rendered.begin(), backend.rendered.end());
    for (ObjectId i = 0; i < boxes.size(); ++i)
      if (view.frustum.classify(boxes[i]) != Containment::outside) {
        EXPECT_TRUE(drawn.count(i)) << "visible box " << i << " not drawn in frame " << f;
      }
  }
  return queries;
}

}  // namespace

TEST(Chcpp, StopsQueryingNodesEnteringTheViewWhereNoneTurnsOutOccluded) {
  const std::uint64_t chcpp = queries_while_turning("0", true);
  const std::uint64_t gated = queries_while_turning("0.1", true);
  EXPECT_GT(chcpp, 60u);
  EXPECT_LT(gated * 2, chcpp) << "entering nodes are drawn without queries once none was occluded";
}

TEST(Chcpp, KeepsQueryingNodesEnteringTheViewWhereTheyTurnOutOccluded) {
  EXPECT_EQ(queries_while_turning("0.1", false), queries_while_turning("0", false));
}
