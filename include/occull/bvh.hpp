// occull — bounding volume hierarchy over scene objects.
//
// Built once per scene (binned SAH), stored as a flat array in depth-first
// order: a node's left child directly follows it, and every node's subtree
// covers one contiguous range of Bvh::objects(). Dynamic objects live in a
// subtree of their own under the root, so refitting them after they move
// never loosens the static part. Cullers read it const and share it.
#pragma once

#include "occull/geometry.hpp"
#include "occull/scene.hpp"

#include <cstdint>
#include <span>
#include <vector>

namespace occull {

using NodeId = std::uint32_t;
inline constexpr NodeId kNoNode = 0xffffffffu;

struct BvhNode {
  Aabb bounds;                      ///< world space; union of the subtree's object bounds
  NodeId parent = kNoNode;          ///< kNoNode for the root
  NodeId right = kNoNode;           ///< right child; left child is this node's index + 1. kNoNode for leaves
  std::uint32_t first_object = 0;   ///< subtree objects: Bvh::objects()[first_object, +object_count)
  std::uint32_t object_count = 0;
  std::uint32_t triangles = 0;      ///< triangles of the subtree's objects
  std::uint16_t depth = 0;          ///< root is 0

  [[nodiscard]] bool is_leaf() const noexcept { return right == kNoNode; }
};

enum class SplitMethod : std::uint8_t { sah, median };

struct BvhOptions {
  /// Leaves hold at most this many objects (>= 1). The default builds one
  /// object per leaf — the "slightly deeper hierarchy" of Bittner et al. 2009, where
  /// cullers group small subtrees into virtual leaves as they see fit.
  int max_leaf_objects = 1;
  int sah_bins = 16;            ///< centroid bins per axis for the SAH sweep (>= 2)
  float traversal_cost = 1.0f;  ///< SAH cost of visiting a node, relative to one object
  SplitMethod split = SplitMethod::sah;
  bool separate_dynamic = true; ///< give dynamic objects their own subtree
};

class Bvh {
 public:
  /// Builds the hierarchy over every object of `scene` at its current
  /// bounds. An empty scene gives a single empty leaf.
  [[nodiscard]] static Bvh build(const Scene& scene, const BvhOptions& options = {});
  /// Builds over bare boxes: object i has box `bounds[i]` and `triangles[i]`
  /// triangles, and every object is static (a tile's local objects, built
  /// once and instanced). Throws UsageError unless both spans have the same
  /// size and options.max_leaf_objects >= 1.
  [[nodiscard]] static Bvh build(std::span<const Aabb> bounds, std::span<const std::uint32_t> triangles,
                                 const BvhOptions& options = {});
  /// A copy moved by `offset` (scene units) whose leaves name object
  /// `first_object + i` for object i of this one: the BVH of one instance
  /// of a tile whose objects occupy consecutive ids from `first_object`.
  [[nodiscard]] Bvh instance(const glm::vec3& offset, ObjectId first_object) const;

  /// Follows the scene after the frame's changes (an engine's
  /// set_transform of any object, add_object, remove_object), before the cullers
  /// run. Refits the dynamic subtree and the ancestors of every object the
  /// engine changed (Scene::for_each_changed_since), so no node's box is
  /// stale. Rebuilds the whole hierarchy (generation() changes) when objects
  /// were added past the count it was built over, or when refitting let its
  /// SAH cost grow past kRebuildFactor times its cost right after the last
  /// build. Precondition: same scene as build.
  void refit(const Scene& scene);

  /// SAH cost growth (sah_cost() over its value after the last build) past
  /// which refit() rebuilds.
  static constexpr double kRebuildFactor = 1.25;
  /// Changes whenever the nodes were rebuilt: node ids and the objects under
  /// them mean something else. Cullers that keep state per node compare it.
  [[nodiscard]] std::uint64_t generation() const noexcept { return generation_; }
  /// SAH cost (sah_cost(traversal cost of the build)) right after the last build.
  [[nodiscard]] double built_sah_cost() const noexcept { return built_sah_; }

  [[nodiscard]] std::span<const BvhNode> nodes() const noexcept { return nodes_; }
  [[nodiscard]] const BvhNode& node(NodeId n) const { return nodes_[n]; }
  [[nodiscard]] static constexpr NodeId root() noexcept { return 0; }
  [[nodiscard]] static constexpr NodeId left(NodeId n) noexcept { return n + 1; }
  [[nodiscard]] NodeId right(NodeId n) const { return nodes_[n].right; }
  [[nodiscard]] std::size_t size() const noexcept { return nodes_.size(); }
  /// Objects in leaf order; a node's objects are a contiguous range of it.
  [[nodiscard]] std::span<const ObjectId> objects() const noexcept { return objects_; }
  /// The objects of node n's subtree.
  [[nodiscard]] std::span<const ObjectId> objects(NodeId n) const {
    return std::span<const ObjectId>(objects_).subspan(nodes_[n].first_object,
                                                       nodes_[n].object_count);
  }

  /// True when traversal should stop at `n`: a real leaf, or a "virtual
  /// leaf" (Bittner et al. 2009): an interior node with at most `virtual_leaf_triangles`
  /// triangles. 0 disables virtual leaves. A traversal that stops at the
  /// first such node from the root sees exactly the topmost ones.
  [[nodiscard]] bool is_leaf(NodeId n, std::uint32_t virtual_leaf_triangles = 0) const {
    const BvhNode& node = nodes_[n];
    return node.is_leaf() || node.triangles <= virtual_leaf_triangles;
  }

  /// Tight bounding volume of node `n` (Bittner et al. 2009, "Tighter bounding
  /// volumes"): replaces the node's box by the boxes of its descendants,
  /// level by level down to `d_max` levels below `n` (objects of a real leaf
  /// count as the level below it), as long as the sum of their surface areas
  /// stays at most `s_max` times the node's. Appends the boxes to `out`
  /// (at least one for a node whose box is not empty: empty boxes, of objects
  /// without triangles, are left out). Preconditions: d_max >= 0, s_max >= 1.
  void gather_tight_boxes(NodeId n, int d_max, float s_max, const Scene& scene,
                          std::vector<Aabb>& out) const;

  /// SAH cost of the tree (traversal cost per interior node + 1 per object in
  /// a leaf, weighted by surface area relative to the root). Lower is better.
  [[nodiscard]] double sah_cost(float traversal_cost = 1.0f) const;
  /// Deepest node depth.
  [[nodiscard]] int max_depth() const noexcept;

 private:
  std::vector<BvhNode> nodes_;
  std::vector<ObjectId> objects_;
  NodeId dynamic_root_ = kNoNode;  // first node of the dynamic subtree, if separated
  BvhOptions options_;             // of the last build, for rebuilds
  std::vector<NodeId> leaf_of_;    // per object: the leaf holding it
  std::size_t built_objects_ = 0;  // Scene::objects().size() at the last build
  std::uint64_t seen_placement_ = 0;  // Scene::placement_revision() refit() has followed
  std::uint64_t generation_ = 0;
  double built_sah_ = 0.0;
  std::vector<std::uint8_t> marked_;  // refit()'s scratch: nodes to refit
  double weighted_area_ = 0.0;     // sum over nodes of area x SAH weight, kept by refit()
  void finish_build();             // leaf_of_, built_sah_ of a new tree
  void rebuild(const Scene& scene);  // a new build with options_, the next generation
  [[nodiscard]] double sah_of_weighted_area() const;  // sah_cost() from weighted_area_
};

}  // namespace occull
