// What OcclusionCullingGroup and import_graph both need: the walk over a
// subgraph that finds every drawable instance, and how an instance is read.
#pragma once

#include "occull/osg/culling_group.hpp"
#include "occull/scene.hpp"

#include <osg/Camera>
#include <osg/Drawable>
#include <osg/NodeVisitor>
#include <osg/Projection>
#include <osg/StateSet>
#include <osg/Transform>

#include <fmt/format.h>

#include <cstdint>
#include <span>
#include <string>
#include <unordered_map>
#include <vector>

namespace osgOccull::detail {

// Triangles and their area, for a drawable's MeshInfo.
struct TriangleCount {
  std::uint32_t triangles = 0;
  double area = 0.0;
  void operator()(const ::osg::Vec3& a, const ::osg::Vec3& b, const ::osg::Vec3& c) {
    ++triangles;
    area += 0.5 * double(((b - a) ^ (c - a)).length());
  }
};

inline bool is_translucent(const ::osg::StateSet* s) {
  return s != nullptr && (s->getRenderingHint() == ::osg::StateSet::TRANSPARENT_BIN ||
                          (s->getMode(GL_BLEND) & ::osg::StateAttribute::ON) != 0);
}

// "occull.occluder" on a node of the path: always | sometimes | never.
inline occull::OccluderClass occluder_of(const ::osg::NodePath& path, bool translucent) {
  if (translucent) return occull::OccluderClass::never;
  for (auto it = path.rbegin(); it != path.rend(); ++it) {
    std::string value;
    if ((*it)->getUserValue("occull.occluder", value)) {
      if (value == "always") return occull::OccluderClass::always;
      if (value == "never") return occull::OccluderClass::never;
      return occull::OccluderClass::sometimes;
    }
  }
  return occull::OccluderClass::sometimes;
}

// The state sets of a path merged into one, one per distinct list (keyed by
// the list's running hash, as Gatherer gives it): what an instance is drawn
// with. Null for a path without state sets.
class MergedStates {
 public:
  ::osg::ref_ptr<::osg::StateSet> get(std::span<const ::osg::StateSet* const> states, std::uint64_t key) {
    if (states.empty()) return nullptr;
    auto [it, added] = merged_.try_emplace(key);
    if (added) {
      it->second = new ::osg::StateSet;
      for (const ::osg::StateSet* s : states) it->second->merge(*s);
    }
    return it->second;
  }

 private:
  std::unordered_map<std::uint64_t, ::osg::ref_ptr<::osg::StateSet>> merged_;
};

// Keys of node paths and of lists of state sets: a running hash, one entry
// per depth, so a drawable's keys cost nothing to compute and nothing is
// copied for a drawable that has not changed.
inline std::uint64_t mix(std::uint64_t key, const void* p) {
  std::uint64_t x = key ^ (std::uint64_t(reinterpret_cast<std::uintptr_t>(p)) + 0x9e3779b97f4a7c15ull + (key << 6));
  x ^= x >> 31;
  x *= 0xbf58476d1ce4e5b9ull;
  return x ^ (x >> 29);
}
constexpr std::uint64_t kSeed = 0x2545f4914f6cdd1dull;

// Walks a subgraph and calls `found(drawable, path, path_key, to_group,
// states, states_key)` for every drawable reached through active children:
// its node path, its transform to the walk's start and the state sets above
// it (and its own), each list with its key.
template <class Found>
class Gatherer : public ::osg::NodeVisitor {
 public:
  explicit Gatherer(Found found) : ::osg::NodeVisitor(TRAVERSE_ACTIVE_CHILDREN), found_(std::move(found)) {}
  void apply(::osg::Node& node) override {
    push(node);
    traverse(node);
    pop(node);
  }
  void apply(::osg::Transform& t) override {
    push(t);
    const ::osg::Matrix saved = matrix_;
    t.computeLocalToWorldMatrix(matrix_, this);
    traverse(t);
    matrix_ = saved;
    pop(t);
  }
  // A camera (render to texture, a HUD) or a projection draws its subgraph
  // with a view of its own, which a culler of this group's view cannot judge.
  void apply(::osg::Camera& c) override { refuse(c, "osg::Camera"); }
  void apply(::osg::Projection& p) override { refuse(p, "osg::Projection"); }
  void apply(::osg::Drawable& d) override {
    push(d);
    found_(d, getNodePath(), path_keys_.back(), matrix_, std::span<const ::osg::StateSet* const>(states_),
           state_keys_.back());
    pop(d);
  }

 private:
  Found found_;
  ::osg::Matrix matrix_;
  std::vector<std::uint64_t> path_keys_{kSeed};
  std::vector<const ::osg::StateSet*> states_;
  std::vector<std::uint64_t> state_keys_{kSeed};
  [[noreturn]] void refuse(::osg::Node& n, const char* kind) {
    std::string where;
    for (const ::osg::Node* p : getNodePath())
      where += fmt::format("{}{}", where.empty() ? "" : " > ", p->getName().empty() ? p->className() : p->getName());
    throw UnsupportedNode(fmt::format(
        "OcclusionCullingGroup: cannot cull below a {} ('{}', at {}): it draws its subgraph with a view of its own; "
        "put it outside the group",
        kind, n.getName(), where));
  }
  void push(::osg::Node& n) {
    path_keys_.push_back(mix(path_keys_.back(), &n));
    if (n.getStateSet() != nullptr) {
      states_.push_back(n.getStateSet());
      state_keys_.push_back(mix(state_keys_.back(), n.getStateSet()));
    }
  }
  void pop(::osg::Node& n) {
    path_keys_.pop_back();
    if (n.getStateSet() != nullptr) {
      states_.pop_back();
      state_keys_.pop_back();
    }
  }
};


}  // namespace osgOccull::detail
