#include "occull/bvh.hpp"
#include "occull/motion.hpp"
#include "test_util.hpp"

#include <gtest/gtest.h>

#include <random>

using namespace occull;

namespace {

std::vector<Aabb> random_boxes(int n, unsigned seed, float spread = 100.0f) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> pos(-spread, spread), size(0.2f, 3.0f);
  std::vector<Aabb> boxes;
  for (int i = 0; i < n; ++i) {
    const glm::vec3 p(pos(rng), pos(rng) * 0.1f, pos(rng));
    boxes.push_back({p, p + glm::vec3(size(rng), size(rng), size(rng))});
  }
  return boxes;
}

void expect_valid(const Bvh& bvh, const Scene& scene) {
  std::vector<int> seen(scene.objects().size(), 0);
  for (NodeId n = 0; n < bvh.size(); ++n) {
    const BvhNode& node = bvh.node(n);
    Aabb objects;
    for (ObjectId id : bvh.objects(n)) objects.extend(scene.object(id).bounds);
    EXPECT_EQ(node.bounds, objects) << "node " << n << " bounds are not the union of its objects";
    if (node.is_leaf()) {
      for (ObjectId id : bvh.objects(n)) ++seen[id];
      continue;
    }
    const NodeId l = Bvh::left(n), r = bvh.right(n);
    EXPECT_EQ(bvh.node(l).parent, n);
    EXPECT_EQ(bvh.node(r).parent, n);
    EXPECT_TRUE(node.bounds.contains(bvh.node(l).bounds));
    EXPECT_TRUE(node.bounds.contains(bvh.node(r).bounds));
    EXPECT_EQ(node.object_count, bvh.node(l).object_count + bvh.node(r).object_count);
    EXPECT_EQ(node.triangles, bvh.node(l).triangles + bvh.node(r).triangles);
  }
  for (std::size_t id = 0; id < seen.size(); ++id) EXPECT_EQ(seen[id], 1) << "object " << id;
}

}  // namespace

TEST(Bvh, EveryObjectInExactlyOneLeafAndParentsContainChildren) {
  const Scene scene = test::box_scene(random_boxes(500, 1));
  const Bvh bvh = Bvh::build(scene);
  expect_valid(bvh, scene);
  EXPECT_EQ(bvh.node(Bvh::root()).object_count, 500u);
}

TEST(Bvh, LeavesRespectTheObjectLimit) {
  const Scene scene = test::box_scene(random_boxes(300, 2));
  for (int limit : {1, 2, 4, 8}) {
    BvhOptions o;
    o.max_leaf_objects = limit;
    const Bvh bvh = Bvh::build(scene, o);
    for (const BvhNode& n : bvh.nodes())
      if (n.is_leaf()) EXPECT_LE(n.object_count, std::uint32_t(limit));
  }
}

TEST(Bvh, IdenticalCentroidsStillSplitToTheLeafLimit) {
  const Scene scene = test::box_scene(std::vector<Aabb>(20, Aabb{{0, 0, 0}, {1, 1, 1}}));
  const Bvh bvh = Bvh::build(scene);
  expect_valid(bvh, scene);
  for (const BvhNode& n : bvh.nodes())
    if (n.is_leaf()) EXPECT_LE(n.object_count, 4u);
}

TEST(Bvh, EmptySceneGivesOneEmptyLeaf) {
  const Scene scene;
  const Bvh bvh = Bvh::build(scene);
  ASSERT_EQ(bvh.size(), 1u);
  EXPECT_TRUE(bvh.node(0).is_leaf());
  EXPECT_EQ(bvh.node(0).object_count, 0u);
}

TEST(Bvh, SahBeatsMedianSplitOnASkewedScene) {
  // A dense cluster of small boxes and a sparse spray of large ones far away.
  std::vector<Aabb> boxes = random_boxes(400, 3, 5.0f);
  std::mt19937 rng(4);
  std::uniform_real_distribution<float> far(200.0f, 1000.0f);
  for (int i = 0; i < 40; ++i) {
    const glm::vec3 p(far(rng), 0.0f, far(rng));
    boxes.push_back({p, p + glm::vec3(20.0f)});
  }
  const Scene scene = test::box_scene(boxes);
  BvhOptions median;
  median.split = SplitMethod::median;
  const double sah_cost = Bvh::build(scene).sah_cost();
  const double median_cost = Bvh::build(scene, median).sah_cost();
  EXPECT_LT(sah_cost, median_cost);
}

TEST(Bvh, RefitAfterMovesKeepsBoundsValidAndTight) {
  Scene scene("moving");
  const MaterialId mat = scene.add_material({});
  for (const Aabb& b : random_boxes(200, 5))
    scene.add_object(scene.add_mesh(test::box_mesh(b)), mat, glm::mat4(1), OccluderClass::always);
  const MeshId car = scene.add_mesh(test::box_mesh({{0, 0, 0}, {2, 1, 1}}));
  std::vector<ScriptedObject> cars;
  for (int i = 0; i < 30; ++i) {
    Motion m;
    m.waypoints = {{-80.0f + 5.0f * float(i), 0, -80}, {80, 0, -80}, {80, 0, 80}};
    m.speed = 7.0f + float(i);
    add_scripted_object(scene, cars, car, mat, m, OccluderClass::sometimes);
  }
  Bvh bvh = Bvh::build(scene);
  const std::vector<BvhNode> before(bvh.nodes().begin(), bvh.nodes().end());
  for (double t : {1.0, 5.0, 17.5}) {
    animate(scene, cars, t);
    bvh.refit(scene);
    expect_valid(bvh, scene);
  }
  // The static subtree is untouched by refits.
  std::size_t unchanged = 0;
  for (NodeId n = 1; n < bvh.size(); ++n)
    if (bvh.node(n).bounds == before[n].bounds) ++unchanged;
  EXPECT_GT(unchanged, bvh.size() / 2);
}

TEST(Bvh, DynamicObjectsGetASubtreeOfTheirOwn) {
  Scene scene("moving");
  const MaterialId mat = scene.add_material({});
  for (const Aabb& b : random_boxes(50, 6))
    scene.add_object(scene.add_mesh(test::box_mesh(b)), mat, glm::mat4(1), OccluderClass::always);
  for (int i = 0; i < 5; ++i)
    scene.add_dynamic_object(scene.add_mesh(test::box_mesh({{0, 0, 0}, {1, 1, 1}})), mat, glm::mat4(1.0f),
                             OccluderClass::never);
  const Bvh bvh = Bvh::build(scene);
  const NodeId dyn = bvh.right(Bvh::root());
  ASSERT_EQ(bvh.node(dyn).object_count, 5u);
  for (ObjectId id : bvh.objects(dyn)) EXPECT_TRUE(scene.object(id).dynamic());
}

TEST(Bvh, VirtualLeavesStopAtTheTopmostSmallNode) {
  const Scene scene = test::box_scene(random_boxes(64, 7));  // 12 triangles each
  const Bvh bvh = Bvh::build(scene);
  EXPECT_FALSE(bvh.is_leaf(Bvh::root(), 0));
  EXPECT_TRUE(bvh.is_leaf(Bvh::root(), 64 * 12));
  // Traversal that stops at virtual leaves covers every object exactly once.
  std::vector<NodeId> stack{Bvh::root()};
  std::size_t covered = 0, leaves = 0;
  while (!stack.empty()) {
    const NodeId n = stack.back();
    stack.pop_back();
    if (bvh.is_leaf(n, 48)) {
      if (!bvh.node(n).is_leaf()) EXPECT_LE(bvh.node(n).triangles, 48u);
      covered += bvh.node(n).object_count;
      ++leaves;
      continue;
    }
    stack.push_back(Bvh::left(n));
    stack.push_back(bvh.right(n));
  }
  EXPECT_EQ(covered, 64u);
  EXPECT_LT(leaves, 64u);
}

TEST(Bvh, TightBoxesCoverTheSubtreeWithinTheAreaLimit) {
  const Scene scene = test::box_scene(random_boxes(200, 8));
  const Bvh bvh = Bvh::build(scene);
  for (NodeId n = 0; n < bvh.size(); ++n) {
    std::vector<Aabb> boxes;
    bvh.gather_tight_boxes(n, 3, 1.4f, scene, boxes);
    ASSERT_FALSE(boxes.empty());
    EXPECT_LE(boxes.size(), 8u);  // at most 2^d_max nodes
    float area = 0.0f;
    for (const Aabb& b : boxes) area += b.surface_area();
    if (boxes.size() > 1) EXPECT_LE(area, 1.4f * bvh.node(n).bounds.surface_area() * 1.0001f);
    // Every object of the subtree lies inside one of the boxes.
    for (ObjectId id : bvh.objects(n)) {
      bool inside = false;
      for (const Aabb& b : boxes) inside = inside || b.contains(scene.object(id).bounds);
      EXPECT_TRUE(inside) << "node " << n << " object " << id;
    }
  }
}

TEST(Bvh, TightBoxesOfDepthZeroIsTheNodeBox) {
  const Scene scene = test::box_scene(random_boxes(20, 9));
  const Bvh bvh = Bvh::build(scene);
  std::vector<Aabb> boxes;
  bvh.gather_tight_boxes(Bvh::root(), 0, 1.4f, scene, boxes);
  ASSERT_EQ(boxes.size(), 1u);
  EXPECT_EQ(boxes[0], bvh.node(Bvh::root()).bounds);
}

TEST(Bvh, TightBoxesOfALeafAreItsObjects) {
  const Scene scene = test::box_scene({{{0, 0, 0}, {1, 1, 1}}, {{5, 0, 0}, {6, 1, 1}}});
  BvhOptions o;
  o.max_leaf_objects = 4;
  o.traversal_cost = 10.0f;  // splitting never pays: one leaf
  const Bvh bvh = Bvh::build(scene, o);
  ASSERT_TRUE(bvh.node(0).is_leaf());
  std::vector<Aabb> boxes;
  bvh.gather_tight_boxes(0, 3, 10.0f, scene, boxes);
  EXPECT_EQ(boxes.size(), 2u);
}

TEST(Bvh, RefitFollowsStaticObjectsTheEngineMoves) {
  // The static part used to be left alone: a static object moved by the
  // engine left its ancestors' boxes stale, and cullers missed it there.
  Scene scene = test::box_scene(random_boxes(200, 11));
  Bvh bvh = Bvh::build(scene);
  scene.set_transform(17, glm::translate(glm::mat4(1.0f), glm::vec3(40.0f, 5.0f, -30.0f)));
  scene.set_transform(120, glm::translate(glm::mat4(1.0f), glm::vec3(-3.0f, 0.0f, 2.0f)));
  bvh.refit(scene);
  expect_valid(bvh, scene);
}

TEST(Bvh, RemovedObjectsLeaveEmptyBoxesAndReusedIdsAreRefitted) {
  Scene scene = test::box_scene(random_boxes(100, 12));
  Bvh bvh = Bvh::build(scene);
  scene.remove_object(5);
  scene.remove_object(60);
  bvh.refit(scene);
  expect_valid(bvh, scene);
  EXPECT_EQ(bvh.generation(), 0u);  // no new leaves needed
  const ObjectId again = scene.add_object(scene.object(1).mesh, 0, glm::translate(glm::mat4(1.0f), {0, 50, 0}),
                                          OccluderClass::always);
  EXPECT_EQ(again, 60u);  // the most recently removed id
  bvh.refit(scene);
  expect_valid(bvh, scene);
  EXPECT_TRUE(bvh.node(Bvh::root()).bounds.contains(scene.object(60).bounds));
}

TEST(Bvh, ObjectsAddedPastItsCountRebuildIt) {
  Scene scene = test::box_scene(random_boxes(50, 13));
  Bvh bvh = Bvh::build(scene);
  const MeshId mesh = scene.object(0).mesh;
  scene.add_object(mesh, 0, glm::translate(glm::mat4(1.0f), {7, 0, 7}), OccluderClass::never);
  bvh.refit(scene);
  EXPECT_EQ(bvh.generation(), 1u);
  expect_valid(bvh, scene);
}

TEST(Bvh, QualityStaysWithinItsFactorOfAFreshBuildUnderMotion) {
  // 10% of 2000 objects jump around every frame for 300 frames.
  Scene scene = test::box_scene(random_boxes(2000, 14));
  std::vector<glm::vec3> home;
  for (const Object& o : scene.objects()) home.push_back(o.bounds.min);
  Bvh bvh = Bvh::build(scene);
  std::mt19937 rng(15);
  std::uniform_int_distribution<int> pick(0, 1999);
  std::uniform_real_distribution<float> step(-4.0f, 4.0f);
  std::vector<glm::vec3> offset(2000, glm::vec3(0.0f));
  for (int frame = 0; frame < 300; ++frame) {
    for (int k = 0; k < 200; ++k) {
      const int id = pick(rng);
      offset[std::size_t(id)] += glm::vec3(step(rng), 0.0f, step(rng));
      scene.set_transform(ObjectId(id), glm::translate(glm::mat4(1.0f), offset[std::size_t(id)]));
    }
    bvh.refit(scene);
    ASSERT_LE(bvh.sah_cost(), Bvh::kRebuildFactor * bvh.built_sah_cost() + 1e-9) << "frame " << frame;
  }
  expect_valid(bvh, scene);
  EXPECT_GT(bvh.generation(), 0u);  // it did rebuild
  const double fresh = Bvh::build(scene).sah_cost();
  EXPECT_LE(bvh.sah_cost(), 1.3 * fresh);
}
