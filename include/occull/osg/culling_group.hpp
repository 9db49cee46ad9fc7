// occull inside OpenSceneGraph (namespace osgOccull, as OSG's own osgUtil, osgShadow, ...): a group node whose subgraph an occull culler
// culls, in OSG's own viewer, drawn by OSG's own state machinery.
//
// Put the part of the scene graph worth occlusion culling under an
// OcclusionCullingGroup (as one would put it under osg::OcclusionQueryNode):
//
//   osg::ref_ptr<osgOccull::OcclusionCullingGroup> group =
//       new osgOccull::OcclusionCullingGroup("chcpp");
//   group->addChild(city);            // anything: transforms, geodes, LODs' chosen child, ...
//   root->addChild(group);
//   viewer.setSceneData(root);        // threading: SingleThreaded or CullDrawThreadPerContext (below)
//
// How it works. Each frame's first cull traversal that reaches the group
// walks its subgraph and keeps an occull Scene of what it finds: one object
// per drawable instance (a drawable under two transforms is two objects of
// one mesh: shared geometry stays shared), its box from the drawable's
// bounding box and the transforms above it (no vertex is copied), moved,
// added and removed as the graph changes; the hierarchy (Bvh) is refitted to
// it. OSG's cull traversal does not descend below the group: it files one
// drawable of the group's own instead, and in the draw traversal that
// drawable runs the culler of the camera being drawn (one culler per camera,
// made on its first frame) through a Backend over OSG's osg::State: objects
// are drawn by Drawable::draw with the state sets on their path applied,
// queries are boxes drawn with a state set of the group's (no colour or
// depth writes, depth clamp, both faces, offset toward the eye) inside GL
// occlusion queries on the camera's context. The view is the one the draw
// uses: the model-view matrix at the group and the projection OSG applied.
//
// What applies inside the group: occull's culling. OSG's own frustum and
// small-feature culling stop at the group's boundary (the group and its
// drawable are never culled by OSG; its culler does frustum culling
// conservatively); outside the group everything is as before.
// Translucent drawables (a state set with the transparent bin, or blending
// on) never occlude; they are drawn after the group's opaque ones, back to
// front. LOD and Switch nodes contribute the children active when the scene
// is gathered (the first cull of the frame; LODs: their nearest range).
//
// Threading. Supported: osgViewer's SingleThreaded and
// CullDrawThreadPerContext models (a frame's update, cull and draw never
// overlap the next frame's). DrawThreadPerContext and
// CullThreadPerCameraDrawThreadPerContext draw a frame while the next one is
// updated and culled: the group would read a graph being changed under it,
// and refuses them: its cull throws UnsupportedThreading (call
// require_supported_threading() before the first frame to hear it early).
//
// Queries are owned: releaseGLObjects(state) (OSG calls it when a context
// closes) hands back the queries of that context's cullers and deletes its
// query objects; a group destroyed with its contexts already gone drops them.
#pragma once

#include "occull/culler.hpp"
#include "occull/error.hpp"
#include "occull/backend.hpp"

#include <osg/Group>
#include <osg/NodeVisitor>
#include <osgViewer/ViewerBase>

#include <memory>
#include <functional>
#include <mutex>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

namespace osgOccull {

/// A threading model the group cannot run under (see the file comment).
class UnsupportedThreading : public occull::InputError {
 public:
  using occull::InputError::InputError;
};

/// A node the group cannot cull below: an osg::Camera or osg::Projection
/// (they draw their subgraph with a view of their own). The cull traversal
/// that meets one throws it, naming the node and its path.
class UnsupportedNode : public occull::InputError {
 public:
  using occull::InputError::InputError;
};

/// Throws UnsupportedThreading, naming the model and the supported ones,
/// when `viewer` runs (or, for AutomaticSelection, would choose) a threading
/// model other than SingleThreaded or CullDrawThreadPerContext.
void require_supported_threading(osgViewer::ViewerBase& viewer);

/// One drawable instance the group culls: an occull object.
struct Instance {
  ::osg::ref_ptr<::osg::Drawable> drawable;
  ::osg::NodePath path;                      ///< from below the group down to the drawable's geode (or the drawable)
  ::osg::Matrix to_group;                    ///< local to the group's coordinates
  ::osg::ref_ptr<::osg::StateSet> state;     ///< the state sets on the path, merged (null: none)
  bool translucent = false;
};

/// What one camera's culler did in its last frame.
struct CameraFrame {
  std::vector<occull::ObjectId> drawn;  ///< objects drawn (ascending; ids of instances())
  occull::FrameResult culler;           ///< what the culler returned (cpu_ms: its time outside backend calls, ms)
  /// Its algorithm's own counters (occull::Culler::visit_counters), by name.
  std::vector<std::pair<std::string_view, double>> counters;
  occull::BackendStats backend;         ///< what the backend counted in the frame (draws, queries, waits, ...)
  std::vector<std::string> choices;     ///< the culler's Culler::choices(): auto's candidates, in order (the counter "auto_choice" indexes them from 1)
  /// Time the group spent gathering the graph into its scene this frame
  /// (walk, changes, refit), ms; counted for the first camera drawn after it.
  double gather_ms = 0.0;
};

class OcclusionCullingGroup : public ::osg::Group {
 public:
  /// `algorithm`: an occull algorithm spec ("chcpp", "grid:cap=200", ...;
  /// `occull algos` lists them), made per camera with `options` and
  /// `context` (nohc needs a hardware profile there). The spec is checked
  /// here: throws occull::InputError for an unknown one, listing the valid names.
  explicit OcclusionCullingGroup(std::string algorithm = "chcpp", occull::Options options = {},
                                 occull::CullerContext context = {});
  /// Cullers made per camera from a typed config (occull/configs.hpp; a
  /// misspelt field does not compile): `OcclusionCullingGroup(
  /// occull::ChcppConfig{.batch = 20})`. Throws occull::InputError for a
  /// value outside its range, or a culler that needs device culling.
  template <class Config>
    requires requires { Config::algorithm; }
  explicit OcclusionCullingGroup(const Config& config, occull::CullerContext context = {})
      : context_(std::move(context)) {
    set_config(config);
    start();
  }
  OcclusionCullingGroup(const OcclusionCullingGroup&, const ::osg::CopyOp& = ::osg::CopyOp::SHALLOW_COPY);
  META_Node(occull, OcclusionCullingGroup)

  /// The algorithm of the cullers made from now on (cameras seen before keep
  /// theirs until releaseGLObjects). Throws occull::InputError as the constructor.
  void set_algorithm(std::string algorithm, occull::Options options = {});
  /// The typed config of the cullers made from now on, as set_algorithm().
  template <class Config>
    requires requires { Config::algorithm; }
  void set_config(const Config& config) {
    set_maker(std::string(Config::algorithm),
              [config](const occull::SceneIndex& index, const occull::CullerContext& context) {
                return occull::make_culler(config, index, context);
              });
  }
  /// The spec of set_algorithm(), or the algorithm of set_config().
  [[nodiscard]] const std::string& algorithm() const noexcept { return algorithm_; }

  void traverse(::osg::NodeVisitor& nv) override;
  void releaseGLObjects(::osg::State* state = nullptr) const override;

  /// The objects as gathered in the last frame (index = occull::ObjectId; an entry
  /// with a null drawable is a removed object's empty slot).
  [[nodiscard]] std::span<const Instance> instances() const noexcept { return instances_; }
  /// The occull scene of them (boxes, triangle counts, classes), in the
  /// group's coordinates.
  [[nodiscard]] const occull::Scene& scene() const noexcept;
  /// What `camera` drew in its last frame; null for a camera never drawn.
  [[nodiscard]] const CameraFrame* last_frame(const ::osg::Camera* camera) const;
  /// Optional feedback, as occull::Culler::frame_finished: once `camera`'s
  /// frame is complete (after viewer.frame(), with the GPU's work finished or
  /// timed), what the application measured of it — frame_ms at least, the
  /// whole frame's time in milliseconds. Adaptive cullers (`auto`) choose by
  /// it; without it they fall back to their own time inside the draw, which
  /// in OSG misses the draws the GPU runs after it (docs/osg.md). Ignored
  /// for a camera the group has not drawn. Thread-safe with the group's draw.
  void frame_finished(const ::osg::Camera* camera, const occull::FrameMeasure& measured);

 protected:
  ~OcclusionCullingGroup() override;

 private:
  struct State;       // the scene, hierarchy and per-camera cullers
  class Drawer;       // the drawable filed in the cull traversal; runs the culler in the draw
  friend class Drawer;
  // Makes a camera's culler over the group's scene.
  using Maker = std::function<std::unique_ptr<occull::Culler>(const occull::SceneIndex&, const occull::CullerContext&)>;
  std::string algorithm_;
  Maker make_;
  occull::CullerContext context_;
  std::vector<Instance> instances_;
  std::shared_ptr<State> state_;
  ::osg::ref_ptr<::osg::Geode> drawer_geode_;
  std::mutex mutex_;  // gathering and per-camera state: cull and draw threads of several contexts
  void start();  // an empty scene, no cullers yet, the group's drawable
  // Checks `make` on an empty scene (its name: `algorithm`) and keeps it for the cullers made from now on.
  void set_maker(std::string algorithm, Maker make);
  void gather(unsigned frame_number);
  void draw(::osg::RenderInfo& info);
};

}  // namespace osgOccull
