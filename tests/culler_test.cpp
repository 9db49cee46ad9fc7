#include "cull/traversal.hpp"
#include "occull/cost_model.hpp"
#include "occull/culler.hpp"
#include "occull/error.hpp"
#include "occull/grid_views.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <random>
#include <set>

using namespace occull;

namespace {

Scene scattered(int n, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-100.0f, 100.0f);
  std::vector<Aabb> boxes;
  for (int i = 0; i < n; ++i) {
    const glm::vec3 p(pos(rng), pos(rng) * 0.2f, pos(rng));
    boxes.push_back({p, p + glm::vec3(2.0f)});
  }
  return test::box_scene(boxes);
}

}  // namespace

TEST(Registry, KnowsNoneAndVfc) {
  std::vector<std::string> names;
  for (const auto& a : algorithms()) names.push_back(a.name);
  EXPECT_NE(std::find(names.begin(), names.end(), "none"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "vfc"), names.end());
}

TEST(Registry, UnknownAlgorithmListsTheValidOnes) {
  const Scene scene = scattered(4, 1);
  const Bvh bvh = Bvh::build(scene);
  try {
    (void)make_culler("nope", {scene, bvh});
    FAIL() << "no error";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("none, vfc, stopwait, perobject, chc, chcpp, nohc, grid, hiz, soc, auto, tilevfc, pertile, tiles, oracle"), std::string::npos) << e.what();
  }
}

TEST(Options, RejectUnknownKeysAndBadValues) {
  Options o;
  EXPECT_THROW(o.set("nodot=3"), InputError);
  EXPECT_THROW(o.set("vfc.x"), InputError);
  o.set("vfc.bogus=1");
  EXPECT_THROW(check_options(o), InputError);
  Options other;
  other.set("notanalgo.key=1");
  EXPECT_THROW(check_options(other), InputError);
  Options typed;
  typed.set("a.n=12x");
  typed.set("a.b=maybe");
  typed.set("a.d=2.5");
  EXPECT_THROW((void)typed.get_int("a.n", 0, 0, 100), InputError);
  EXPECT_THROW((void)typed.get_bool("a.b", false), InputError);
  EXPECT_DOUBLE_EQ(typed.get_double("a.d", 0, 0, 10), 2.5);
  EXPECT_THROW((void)typed.get_double("a.d", 0, 0, 1), InputError);
  EXPECT_EQ(typed.get_int("a.absent", 7, 0, 10), 7);
}

TEST(None, RendersEveryObject) {
  const Scene scene = scattered(50, 2);
  const Bvh bvh = Bvh::build(scene);
  auto culler = make_culler("none", {scene, bvh});
  test::ScriptedBackend backend;
  const View view = make_view({{0, 0, 0}, 0, 0}, {}, 64, 64);
  culler->render_frame(view, backend);
  EXPECT_EQ(backend.rendered.size(), 50u);
  EXPECT_TRUE(backend.queried.empty());
}

TEST(Vfc, RendersExactlyTheObjectsNotOutsideTheFrustum) {
  const Scene scene = scattered(2000, 3);
  const Bvh bvh = Bvh::build(scene);
  auto culler = make_culler("vfc", {scene, bvh});
  for (float yaw : {0.0f, 1.0f, 2.5f, -2.0f}) {
    const View view = make_view({{3, 1, -4}, yaw, 0.1f}, {60.0f, 0.1f, 80.0f}, 160, 90);
    test::ScriptedBackend backend;
    const FrameResult stats = culler->render_frame(view, backend);
    std::vector<ObjectId> expected;
    for (ObjectId id = 0; id < scene.objects().size(); ++id)
      if (view.frustum.classify(scene.object(id).bounds) != Containment::outside) expected.push_back(id);
    std::vector<ObjectId> got = backend.rendered;
    std::sort(got.begin(), got.end());
    EXPECT_EQ(got, expected) << "yaw " << yaw;
    EXPECT_TRUE(backend.queried.empty());
    EXPECT_GT(stats.nodes_visited, 0u);
    EXPECT_LT(stats.nodes_visited, bvh.size()) << "subtrees outside the frustum are skipped";
  }
}

TEST(Culler, RenderFrameReturnsWhatItDrewQueriedAndVisited) {
  const Scene scene = scattered(2000, 3);
  const Bvh bvh = Bvh::build(scene);
  const View view = make_view({{3, 1, -4}, 1.0f, 0.1f}, {60.0f, 0.1f, 80.0f}, 160, 90);
  for (const char* algorithm : {"vfc", "stopwait", "chcpp", "soc", "grid"}) {
    auto culler = make_culler(algorithm, {scene, bvh});
    test::ScriptedBackend backend;
    backend.visible_samples = [](std::span<const Aabb> boxes) { return std::uint64_t(boxes.size() % 2); };
    for (int frame = 0; frame < 3; ++frame) {
      backend.rendered.clear();
      backend.queried.clear();
      const FrameResult result = culler->render_frame(view, backend);
      EXPECT_EQ(result.objects_drawn, backend.rendered.size()) << algorithm << ", frame " << frame;
      EXPECT_EQ(result.queries, backend.queried.size()) << algorithm << ", frame " << frame;
      EXPECT_GT(result.nodes_visited, 0u) << algorithm;
      EXPECT_GE(result.cpu_ms, 0.0) << algorithm;
    }
    culler->release(backend);
  }
}

TEST(Vfc, RendersFrontToBackByNode) {
  // A row of boxes along -Z: the nearest is rendered first.
  std::vector<Aabb> row;
  for (int i = 0; i < 32; ++i) row.push_back({{-1, -1, -5.0f - 4.0f * float(i)}, {1, 1, -3.0f - 4.0f * float(i)}});
  const Scene scene = test::box_scene(row);
  BvhOptions o;
  o.max_leaf_objects = 1;
  const Bvh bvh = Bvh::build(scene, o);
  auto culler = make_culler("vfc", {scene, bvh});
  test::ScriptedBackend backend;
  culler->render_frame(make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.1f, 500.0f}, 64, 64), backend);
  ASSERT_EQ(backend.rendered.size(), 32u);
  for (std::size_t i = 0; i < 32; ++i) EXPECT_EQ(backend.rendered[i], ObjectId(i));
}

TEST(Registry, AThresholdAboveZeroMakesARunApproximate) {
  EXPECT_TRUE(is_conservative(parse_algorithm_spec("chc")));
  EXPECT_TRUE(is_conservative(parse_algorithm_spec("chc:threshold=0")));
  EXPECT_FALSE(is_conservative(parse_algorithm_spec("chc:threshold=3")));
  EXPECT_TRUE(is_conservative(parse_algorithm_spec("vfc")));
  EXPECT_FALSE(is_conservative(parse_algorithm_spec("perobject")));
  Options base;
  base.set("chcpp.threshold=2");  // --opt chcpp.threshold=2 reaches every chcpp spec
  EXPECT_FALSE(is_conservative(parse_algorithm_spec("chcpp:batch=10", base)));
  EXPECT_TRUE(is_conservative(parse_algorithm_spec("nohc", base)));
}

TEST(MakeCuller, TakesSpecsWithOptionsAndAProfileInMemory) {
  const Scene scene = test::box_scene({{{-1, -1, -10}, {1, 1, -8}}});
  const Bvh bvh = Bvh::build(scene);
  EXPECT_NO_THROW((void)make_culler("chcpp:batch=20:tight=off", {scene, bvh}));
  EXPECT_THROW((void)make_culler("chcpp:nope=1", {scene, bvh}), InputError);
  EXPECT_THROW((void)make_culler("nohc", {scene, bvh}), InputError);  // no profile anywhere
  const HardwareProfile profile = test::hardware_profile();
  const CullerContext context = with_profile(profile);
  auto nohc = make_culler("nohc:learn=off", {scene, bvh}, {}, context);
  test::ScriptedBackend backend;
  const View view = make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.1f, 100.0f}, 64, 64);
  (void)nohc->render_frame(view, backend);
  EXPECT_EQ(nohc->drawn_objects().size(), 1u);
  auto with_nohc = make_culler("auto:candidates=vfc+nohc", {scene, bvh}, {}, context);
  EXPECT_NE(with_nohc, nullptr);
}

TEST(Registry, EveryDefaultShownIsAValueItsAlgorithmTakes) {
  for (const AlgorithmInfo& a : algorithms()) {
    if (a.lab_only) continue;
    const bool conservative = is_conservative(parse_algorithm_spec(a.name));
    for (const OptionInfo& o : a.options) {
      if (o.default_value.starts_with("(")) continue;  // a placeholder: "(calibrated)"
      const std::string spec = a.name + ":" + o.key + "=" + o.default_value;
      SCOPED_TRACE(spec);
      // is_conservative parses every option of the spec: it throws for a value the table refuses.
      EXPECT_EQ(is_conservative(parse_algorithm_spec(spec)), conservative);
    }
  }
}

TEST(Registry, ApproximationIsJudgedOnTheParsedValue) {
  EXPECT_TRUE(is_conservative(parse_algorithm_spec("chc:threshold=00")));
  EXPECT_TRUE(is_conservative(parse_algorithm_spec("tiles:box=common")));
  EXPECT_FALSE(is_conservative(parse_algorithm_spec("tiles:box=tile")));
  EXPECT_FALSE(is_conservative(parse_algorithm_spec("stopwait:threshold=1")));
}

TEST(MakeCuller, AValueOutOfRangeNamesTheKeyAndTheRange) {
  const Scene scene = test::box_scene({{{-1, -1, -10}, {1, 1, -8}}});
  const Bvh bvh = Bvh::build(scene);
  for (const auto& [spec, says] : std::vector<std::pair<std::string, std::string>>{
           {"chcpp:batch=0", "chcpp.batch: 0 is outside [1, 100000]"},
           {"grid:traversal=spiral", "grid.traversal: 'spiral' is not one of frustum, box"},
           {"chc:skip=x", "chc.skip: 'x' is not a whole number"},
           {"nohc:visible_factor=2", "nohc.visible_factor: 2 is outside [0, 1]"}}) {
    try {
      (void)make_culler(spec, {scene, bvh});
      ADD_FAILURE() << spec << ": no error";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find(says), std::string::npos) << e.what();
    }
  }
}

TEST(MakeCuller, AsksTheContextForNohcsProfileOnlyWhenACullerNeedsIt) {
  const Scene scene = test::box_scene({{{-1, -1, -10}, {1, 1, -8}}});
  const Bvh bvh = Bvh::build(scene);
  const HardwareProfile profile = test::hardware_profile();
  int asked = 0;
  CullerContext context;
  context.hardware_profile = [&](const std::string&) -> std::optional<HardwareProfile> {
    ++asked;
    return profile;
  };
  (void)make_culler("chcpp", {scene, bvh}, {}, context);
  (void)make_culler("auto:candidates=chcpp+vfc", {scene, bvh}, {}, context);
  EXPECT_EQ(asked, 0);
  (void)make_culler("nohc", {scene, bvh}, {}, context);
  EXPECT_EQ(asked, 1);
  (void)make_culler("auto", {scene, bvh}, {}, context);  // the default candidates leave nohc out
  EXPECT_EQ(asked, 1);
  (void)make_culler("auto:candidates=chc+nohc", {scene, bvh}, {}, context);  // ... and take it when named
  EXPECT_EQ(asked, 2);
}

TEST(MakeSplitScreen, AlgorithmsThatShareViewsMakeThemTogetherTheOthersOnePerView) {
  const Scene scene = scattered(40, 5);
  const Bvh bvh = Bvh::build(scene);
  auto grid = make_split_screen("grid:cap=100", {scene, bvh}, 3);
  EXPECT_EQ(grid->size(), 3);
  EXPECT_NE(dynamic_cast<GridViews*>(grid.get()), nullptr) << "grid's views share one grid and query cap";
  EXPECT_TRUE(find_algorithm("grid").shares_views);
  auto chcpp = make_split_screen("chcpp", {scene, bvh}, 2);
  EXPECT_EQ(chcpp->size(), 2);
  EXPECT_NE(&chcpp->view(0), &chcpp->view(1));
  EXPECT_THROW((void)make_split_screen("chcpp", {scene, bvh}, 0), InputError);
  EXPECT_THROW((void)make_split_screen("grid:nope=1", {scene, bvh}, 2), InputError);
  EXPECT_THROW((void)make_split_screen("oracle", {scene, bvh}, 2), InputError);  // lab only
}

TEST(Culler, HizOverABackendWithoutDeviceCullingIsTheCallersMistake) {
  const Scene scene = test::box_scene(test::scattered_boxes(5));
  const Bvh bvh = Bvh::build(scene);
  auto hiz = make_culler("hiz", {scene, bvh});  // made: the backend comes with the frame
  test::ScriptedBackend backend;  // no DeviceCulling
  const View view = test::unsampled(make_view({{0, 0, 0}, 0, 0}, {70.0f, 0.1f, 500.0f}, 64, 64));
  try {
    (void)hiz->render_frame(view, backend);
    FAIL() << "hiz culled over a backend without device culling";
  } catch (const UsageError& e) {
    EXPECT_NE(std::string(e.what()).find("no device culling"), std::string::npos) << e.what();
  }
}

// The front-to-back queue holds its last push outside the heap: over a
// whole descent (and pushes in any order) it pops exactly what an ordered
// set of (squared distance, node id) does.
TEST(DistanceQueue, PopsNearestFirstWithLowerIdsOnTies) {
  const Scene scene = scattered(300, 7);
  const Bvh bvh = Bvh::build(scene);
  const glm::vec3 eye(3.0f, 1.0f, -2.0f);
  detail::DistanceQueue queue;
  std::set<std::pair<float, NodeId>> reference;
  const auto push = [&](NodeId n) {
    queue.push(bvh, n, eye);
    reference.insert({distance_squared(eye, bvh.node(n).bounds), n});
  };
  push(Bvh::root());
  std::size_t popped = 0;
  while (!queue.empty()) {
    ASSERT_FALSE(reference.empty());
    const NodeId n = queue.pop();
    ASSERT_EQ(n, reference.begin()->second) << "pop " << popped;
    reference.erase(reference.begin());
    ++popped;
    if (!bvh.is_leaf(n)) {
      // Children in both orders, so that the held entry is both kept and displaced.
      if (n % 2 == 0) push(Bvh::left(n)), push(bvh.right(n));
      else push(bvh.right(n)), push(Bvh::left(n));
    }
  }
  EXPECT_TRUE(reference.empty());
  EXPECT_EQ(popped, bvh.size());
  // Pushes with no descent between them: far first, then nearer ones.
  for (NodeId n = NodeId(bvh.size()); n-- > 0;) push(n);
  for (std::size_t i = 0; i < bvh.size(); ++i) {
    ASSERT_EQ(queue.pop(), reference.begin()->second) << "pop " << i;
    reference.erase(reference.begin());
  }
  EXPECT_TRUE(queue.empty());
}

// The frustum cache's sub-pixel test left out on request: for an interior
// node only (it then culls less); a leaf is always tested in full.
TEST(FrustumCache, LeavesOutTheSubpixelTestForInteriorNodesOnly) {
  // Two specks far down the view: each, and their parent, hold no pixel centre.
  const Scene scene = test::box_scene({{{0.0f, 0.0f, -50.0f}, {0.001f, 0.001f, -49.999f}},
                                       {{0.003f, 0.0f, -50.0f}, {0.004f, 0.001f, -49.999f}}});
  const Bvh bvh = Bvh::build(scene);
  ASSERT_FALSE(bvh.is_leaf(Bvh::root()));
  const View view = make_view(CameraPose{}, Lens{60.0f, 0.1f, 100.0f}, 64, 64);
  ASSERT_TRUE(holds_no_sample(bvh.node(Bvh::root()).bounds, view));
  detail::FrustumCache cache;
  cache.begin(bvh, view);
  EXPECT_TRUE(cache.outside(bvh, Bvh::root()));
  cache.begin(bvh, view);
  EXPECT_FALSE(cache.outside(bvh, Bvh::root(), false));
  const NodeId leaf = Bvh::left(Bvh::root());
  ASSERT_TRUE(bvh.is_leaf(leaf));
  EXPECT_TRUE(cache.outside(bvh, leaf, false));
}

// A leaf's objects through the frustum cache: a one-object leaf the cache
// passed is appended untested, and every leaf yields exactly what testing
// its objects does — with one object a leaf and with several, for leaves
// inside, outside and across the frustum, and for removed objects (empty
// boxes in leaves the frustum's planes need not test: never appended).
TEST(FrustumCache, AppendsALeafsObjectsAsTestingThemDoes) {
  for (const int per_leaf : {1, 4}) {
    Scene scene = scattered(2000, 5);
    Bvh bvh = Bvh::build(scene, BvhOptions{.max_leaf_objects = per_leaf});
    // Removed objects: their leaves keep them, with an empty box, until a rebuild.
    for (ObjectId id = 0; id < scene.objects().size(); id += 7) scene.remove_object(id);
    bvh.refit(scene);
    const SceneIndex index{scene, bvh};
    detail::FrustumCache cache;
    std::size_t appended = 0, outside = 0, in_leaves = 0;  // objects
    for (const float yaw : {0.0f, 1.0f, 2.5f, 4.0f}) {
      const View view = make_view({{3, 1, -4}, yaw, 0.1f}, {60.0f, 0.1f, 80.0f}, 160, 90);
      cache.begin(bvh, view);
      for (NodeId n = 0; n < bvh.size(); ++n) {  // parents first: a child tests the planes its parent straddles
        const bool out = cache.outside(bvh, n);
        if (!bvh.is_leaf(n) || bvh.node(n).object_count == 0) continue;
        std::vector<ObjectId> got, expected;
        cache.append_objects(index, n, got);
        detail::append_objects_in_frustum(index, n, view, expected, cache.planes(n));
        ASSERT_EQ(got, expected) << "leaf " << n << ", " << per_leaf << " a leaf, yaw " << yaw;
        appended += got.size();
        if (bvh.node(n).bounds.empty()) continue;  // removed objects only
        in_leaves += bvh.node(n).object_count;
        if (out) outside += bvh.node(n).object_count;
      }
    }
    EXPECT_GT(appended, 100u) << per_leaf;
    EXPECT_GT(outside, 100u) << per_leaf;
    // One object a leaf: the leaf's test is its object's. Several: some
    // objects of a leaf that passed fail their own test (removed ones too).
    if (per_leaf == 1) EXPECT_EQ(appended + outside, in_leaves);
    else EXPECT_LT(appended + outside, in_leaves);
  }
}
