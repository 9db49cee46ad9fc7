#include "occull/bvh.hpp"
#include "occull/error.hpp"
#include "core/format.hpp"

#include <algorithm>
#include <functional>
#include <cassert>
#include <limits>

namespace occull {
namespace {

struct BuildItem {
  Aabb box;
  glm::vec3 centroid;
  ObjectId id;
  std::uint32_t triangles;
};

class Builder {
 public:
  Builder(std::vector<BuildItem>& items, const BvhOptions& options, std::vector<BvhNode>& nodes)
      : items_(items), options_(options), nodes_(nodes) {}

  NodeId build(std::size_t begin, std::size_t end, NodeId parent, int depth) {
    const NodeId id = NodeId(nodes_.size());
    nodes_.emplace_back();
    BvhNode node;
    node.parent = parent;
    node.depth = std::uint16_t(depth);
    node.first_object = std::uint32_t(begin);
    node.object_count = std::uint32_t(end - begin);
    Aabb centroids;
    for (std::size_t i = begin; i < end; ++i) {
      node.bounds.extend(items_[i].box);
      centroids.extend(items_[i].centroid);
      node.triangles += items_[i].triangles;
    }
    nodes_[id] = node;
    const std::size_t count = end - begin;
    if (count <= 1) return id;

    const std::size_t mid = split(begin, end, node.bounds, centroids);
    if (mid == begin || mid == end) return id;  // a leaf is best
    build(begin, mid, id, depth + 1);
    const NodeId right = build(mid, end, id, depth + 1);
    nodes_[id].right = right;
    return id;
  }

  // Builds two given ranges as the children of a new root (static | dynamic).
  NodeId build_pair(std::size_t split_at, std::size_t end, NodeId& second_root) {
    nodes_.emplace_back();
    BvhNode root;
    root.first_object = 0;
    root.object_count = std::uint32_t(end);
    build(0, split_at, 0, 1);
    second_root = build(split_at, end, 0, 1);
    root.right = second_root;
    root.bounds = nodes_[1].bounds;
    root.bounds.extend(nodes_[second_root].bounds);
    root.triangles = nodes_[1].triangles + nodes_[second_root].triangles;
    nodes_[0] = root;
    return 0;
  }

 private:
  // Returns the partition point; begin or end means "make a leaf".
  std::size_t split(std::size_t begin, std::size_t end, const Aabb& bounds,
                    const Aabb& centroids) {
    const std::size_t count = end - begin;
    const glm::vec3 ext = centroids.extent();
    if (options_.split == SplitMethod::median) {
      if (count <= std::size_t(options_.max_leaf_objects)) return begin;
      const int axis = ext.x >= ext.y && ext.x >= ext.z ? 0 : (ext.y >= ext.z ? 1 : 2);
      const std::size_t mid = begin + count / 2;
      std::nth_element(items_.begin() + long(begin), items_.begin() + long(mid),
                       items_.begin() + long(end), [axis](const BuildItem& a, const BuildItem& b) {
                         return a.centroid[axis] < b.centroid[axis];
                       });
      return mid;
    }

    // Binned SAH over all three axes.
    const int bins = std::max(2, options_.sah_bins);
    const float parent_area = std::max(bounds.surface_area(), 1e-12f);
    float best_cost = std::numeric_limits<float>::infinity();
    int best_axis = -1, best_bin = -1;
    std::vector<Aabb> bin_box(bins);
    std::vector<std::size_t> bin_count(bins);
    std::vector<float> right_area(bins);
    std::vector<std::size_t> right_count(bins);
    for (int axis = 0; axis < 3; ++axis) {
      if (ext[axis] <= 0.0f) continue;
      std::fill(bin_box.begin(), bin_box.end(), Aabb{});
      std::fill(bin_count.begin(), bin_count.end(), 0);
      const float scale = float(bins) / ext[axis];
      for (std::size_t i = begin; i < end; ++i) {
        const int b = bin_of(items_[i].centroid[axis], centroids.min[axis], scale, bins);
        bin_box[b].extend(items_[i].box);
        ++bin_count[b];
      }
      Aabb acc;
      std::size_t n = 0;
      for (int b = bins - 1; b > 0; --b) {
        acc.extend(bin_box[b]);
        n += bin_count[b];
        right_area[b] = acc.surface_area();
        right_count[b] = n;
      }
      acc = Aabb{};
      n = 0;
      for (int b = 0; b < bins - 1; ++b) {  // split between bin b and b + 1
        acc.extend(bin_box[b]);
        n += bin_count[b];
        if (n == 0 || right_count[b + 1] == 0) continue;
        const float cost = options_.traversal_cost +
                           (acc.surface_area() * float(n) +
                            right_area[b + 1] * float(right_count[b + 1])) / parent_area;
        if (cost < best_cost) {
          best_cost = cost;
          best_axis = axis;
          best_bin = b;
        }
      }
    }
    const bool fits_leaf = count <= std::size_t(options_.max_leaf_objects);
    if (best_axis < 0) {
      // All centroids coincide: no spatial split exists. Split by index when
      // the leaf would be too large.
      return fits_leaf ? begin : begin + count / 2;
    }
    if (fits_leaf && float(count) <= best_cost) return begin;
    const float scale = float(bins) / ext[best_axis];
    const float lo = centroids.min[best_axis];
    const auto mid = std::partition(items_.begin() + long(begin), items_.begin() + long(end),
                                    [&](const BuildItem& it) {
                                      return bin_of(it.centroid[best_axis], lo, scale, bins) <=
                                             best_bin;
                                    });
    return std::size_t(mid - items_.begin());
  }

  static int bin_of(float c, float lo, float scale, int bins) {
    return std::clamp(int((c - lo) * scale), 0, bins - 1);
  }

  std::vector<BuildItem>& items_;
  const BvhOptions& options_;
  std::vector<BvhNode>& nodes_;
};

}  // namespace

Bvh Bvh::build(const Scene& scene, const BvhOptions& options) {
  if (options.max_leaf_objects < 1)
    throw UsageError(detail::format("Bvh::build: max_leaf_objects {} (at least 1)", options.max_leaf_objects));
  Bvh bvh;
  const auto objects = scene.objects();
  std::vector<BuildItem> items;
  items.reserve(objects.size());
  for (ObjectId id = 0; id < objects.size(); ++id)
    items.push_back({objects[id].bounds, objects[id].bounds.center(), id, objects[id].triangles});
  // Static objects first, dynamic ones after: each gets a subtree of its own.
  const auto dyn_begin = std::stable_partition(
      items.begin(), items.end(), [&](const BuildItem& it) { return !objects[it.id].dynamic(); });
  const std::size_t split_at = std::size_t(dyn_begin - items.begin());

  bvh.nodes_.reserve(2 * items.size() + 1);
  Builder builder(items, options, bvh.nodes_);
  if (options.separate_dynamic && split_at > 0 && split_at < items.size()) {
    builder.build_pair(split_at, items.size(), bvh.dynamic_root_);
  } else {
    builder.build(0, items.size(), kNoNode, 0);
  }
  bvh.objects_.reserve(items.size());
  for (const auto& it : items) bvh.objects_.push_back(it.id);
  bvh.options_ = options;
  bvh.built_objects_ = objects.size();
  bvh.seen_placement_ = scene.placement_revision();
  bvh.finish_build();
  return bvh;
}

void Bvh::finish_build() {
  leaf_of_.assign(objects_.size(), kNoNode);
  for (NodeId n = 0; n < nodes_.size(); ++n)
    if (nodes_[n].is_leaf())
      for (ObjectId id : objects(n))
        if (id < leaf_of_.size()) leaf_of_[id] = n;
  built_sah_ = sah_cost(options_.traversal_cost);
  weighted_area_ = built_sah_ * (nodes_.empty() ? 0.0 : std::max(double(nodes_[0].bounds.surface_area()), 1e-12));
  marked_.assign(nodes_.size(), 0);
}

Bvh Bvh::build(std::span<const Aabb> bounds, std::span<const std::uint32_t> triangles,
               const BvhOptions& options) {
  if (options.max_leaf_objects < 1 || bounds.size() != triangles.size())
    throw UsageError(detail::format("Bvh::build: max_leaf_objects {} (at least 1), {} boxes and {} triangle counts "
                                    "(one per box)",
                                    options.max_leaf_objects, bounds.size(), triangles.size()));
  Bvh bvh;
  std::vector<BuildItem> items;
  items.reserve(bounds.size());
  for (ObjectId id = 0; id < bounds.size(); ++id)
    items.push_back({bounds[id], bounds[id].center(), id, triangles[id]});
  bvh.nodes_.reserve(2 * items.size() + 1);
  Builder builder(items, options, bvh.nodes_);
  builder.build(0, items.size(), kNoNode, 0);
  bvh.objects_.reserve(items.size());
  for (const auto& it : items) bvh.objects_.push_back(it.id);
  bvh.options_ = options;
  bvh.built_objects_ = bounds.size();
  bvh.finish_build();
  return bvh;
}

Bvh Bvh::instance(const glm::vec3& offset, ObjectId first_object) const {
  Bvh copy = *this;
  for (BvhNode& n : copy.nodes_) {
    if (n.bounds.empty()) continue;
    n.bounds.min += offset;
    n.bounds.max += offset;
  }
  for (ObjectId& id : copy.objects_) id += first_object;
  return copy;
}

void Bvh::refit(const Scene& scene) {
  if (scene.objects().size() != built_objects_) return rebuild(scene);  // objects added: new leaves
  const auto objects = scene.objects();
  // Refits node n from its objects or children, keeping weighted_area_ (the
  // SAH cost times the root's area) up to date as it goes.
  const auto refit_node = [&](NodeId n) {
    BvhNode& node = nodes_[n];
    const double weight = node.is_leaf() ? double(node.object_count) : double(options_.traversal_cost);
    weighted_area_ -= weight * double(node.bounds.surface_area());
    if (node.is_leaf()) {
      node.bounds = Aabb{};
      node.triangles = 0;
      for (ObjectId id : this->objects(n)) {
        node.bounds.extend(objects[id].bounds);
        node.triangles += objects[id].triangles;
      }
    } else {
      node.bounds = nodes_[left(n)].bounds;
      node.bounds.extend(nodes_[node.right].bounds);
      node.triangles = nodes_[left(n)].triangles + nodes_[node.right].triangles;
    }
    weighted_area_ += weight * double(node.bounds.surface_area());
  };
  // The dynamic subtree: its objects move every frame (Scene::update).
  // Children follow their parents in the array, so a reverse sweep sees
  // every child before its parent.
  const NodeId static_end = dynamic_root_ != kNoNode ? dynamic_root_ : NodeId(nodes_.size());
  bool root_stale = false;
  if (dynamic_root_ != kNoNode) {
    for (NodeId n = NodeId(nodes_.size()); n-- > dynamic_root_;) refit_node(n);
    root_stale = true;
  } else if (!scene.dynamic_objects().empty()) {  // one tree for all
    for (NodeId n = NodeId(nodes_.size()); n-- > 0;) refit_node(n);
  }
  // What the engine changed: each object's leaf and its ancestors, marked,
  // then refitted children first by a sweep down the marked range.
  NodeId lowest = static_end, highest = 0;
  seen_placement_ = scene.for_each_changed_since(seen_placement_, [&](ObjectId id) {
    for (NodeId n = leaf_of_[id]; n != kNoNode && !marked_[n]; n = nodes_[n].parent) {
      marked_[n] = 1;
      lowest = std::min(lowest, n);
      highest = std::max(highest, n);
    }
  });
  const bool changed = lowest <= highest;
  if (changed)
    for (NodeId n = highest + 1; n-- > lowest;) {
      if (!marked_[n]) continue;
      marked_[n] = 0;
      if (n < static_end) refit_node(n);  // the dynamic subtree was refitted above
    }
  if (root_stale) refit_node(root());
  // Boxes that moved far loosen the tree: rebuild when it got too costly.
  if (changed && sah_of_weighted_area() > kRebuildFactor * built_sah_) rebuild(scene);
}

void Bvh::rebuild(const Scene& scene) {
  const std::uint64_t generation = generation_;
  *this = build(scene, options_);
  generation_ = generation + 1;
}

double Bvh::sah_of_weighted_area() const {
  return nodes_.empty() ? 0.0 : weighted_area_ / std::max(double(nodes_[0].bounds.surface_area()), 1e-12);
}

void Bvh::gather_tight_boxes(NodeId n, int d_max, float s_max, const Scene& scene,
                             std::vector<Aabb>& out) const {
  // An entry is a node, or an object (below a real leaf); objects are final.
  struct Entry {
    bool is_object;
    std::uint32_t index;
    Aabb box;
  };
  const float limit = s_max * nodes_[n].bounds.surface_area();
  std::vector<Entry> current{{false, n, nodes_[n].bounds}};
  std::vector<Entry> next;
  for (int level = 0; level < d_max; ++level) {
    next.clear();
    bool expanded = false;
    float area = 0.0f;
    for (const Entry& e : current) {
      if (e.is_object) {
        next.push_back(e);
      } else if (!nodes_[e.index].is_leaf()) {
        for (NodeId c : {left(e.index), nodes_[e.index].right})
          next.push_back({false, c, nodes_[c].bounds});
        expanded = true;
      } else if (nodes_[e.index].object_count > 1) {
        for (ObjectId id : objects(e.index)) next.push_back({true, id, scene.object(id).bounds});
        expanded = true;
      } else {
        next.push_back(e);
      }
    }
    for (const Entry& e : next) area += e.box.surface_area();
    if (!expanded || area > limit) break;
    std::swap(current, next);
  }
  for (const Entry& e : current)
    if (!e.box.empty()) out.push_back(e.box);  // an object without triangles has nothing to query
}

double Bvh::sah_cost(float traversal_cost) const {
  if (nodes_.empty()) return 0.0;
  const double root_area = std::max(double(nodes_[0].bounds.surface_area()), 1e-12);
  double cost = 0.0;
  for (const BvhNode& node : nodes_) {
    const double rel = node.bounds.surface_area() / root_area;
    cost += rel * (node.is_leaf() ? double(node.object_count) : double(traversal_cost));
  }
  return cost;
}

int Bvh::max_depth() const noexcept {
  int d = 0;
  for (const BvhNode& node : nodes_) d = std::max(d, int(node.depth));
  return d;
}

}  // namespace occull
