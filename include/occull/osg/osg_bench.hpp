// `occull osg`: occull's cullers inside OpenSceneGraph beside OSG's own
// osg::OcclusionQueryNode, in one OSG viewer, every frame checked against
// occull's ground truth.
#pragma once

#include "occull/bench.hpp"
#include "occull/gl/context.hpp"

#include <osgViewer/Viewer>

#include <cstdint>
#include <functional>
#include <memory>

#include <string>
#include <vector>

namespace osgOccull {

/// A headless osgViewer::Viewer: a compatibility-profile EGL context of its
/// own (Debian's OSG draws with the fixed-function pipeline) as the window's
/// graphics context, made current by OSG on the thread that draws (the
/// creating thread when SingleThreaded, OSG's draw thread otherwise), and a
/// width x height colour + depth FBO the viewer draws into. OSG computes no
/// near and far planes: the camera uses the view's projection as given.
class HeadlessViewer {
 public:
  /// Throws occull::GlUnavailable without a usable OpenGL 4.5 compatibility
  /// context, UnsupportedThreading (at the first set_scene) for a threading
  /// model OcclusionCullingGroup refuses.
  HeadlessViewer(int width, int height,
                 osgViewer::ViewerBase::ThreadingModel model = osgViewer::ViewerBase::SingleThreaded);
  ~HeadlessViewer();
  HeadlessViewer(const HeadlessViewer&) = delete;
  HeadlessViewer& operator=(const HeadlessViewer&) = delete;
  /// Shows `scene` (null: nothing). The scene shown before releases its GL
  /// objects on this context first (a culling group hands back its queries).
  void set_scene(::osg::Node* scene);
  /// One frame of `view` (its view and projection matrices) at `time_s`
  /// seconds: viewer.frame(), closed by glFinish. Returns its wall time, ms.
  double frame(const occull::View& view, double time_s);
  /// The last frame's colour, RGBA8, top row first (a PNG's order). Stops
  /// OSG's draw thread first (threaded models).
  [[nodiscard]] std::vector<std::uint8_t> read_rgba();
  [[nodiscard]] osgViewer::Viewer& viewer() noexcept { return *viewer_; }
  [[nodiscard]] ::osg::Camera& camera() noexcept { return *viewer_->getCamera(); }

 private:
  std::unique_ptr<occull::gl::Context> context_;
  int width_, height_;
  GLuint fbo_ = 0;
  GLuint renderbuffers_[2] = {0, 0};  // colour, depth
  ::osg::ref_ptr<osgViewer::Viewer> viewer_;
  ::osg::ref_ptr<::osg::GraphicsContext> window_;
  bool realized_ = false;
};

/// The rows `occull osg` runs when none are named: OSG without occlusion
/// culling, OcclusionQueryNode with its defaults and strict, occull's vfc,
/// chcpp, nohc and grid inside an OcclusionCullingGroup.
[[nodiscard]] const std::vector<std::string>& default_osg_rows();

/// What the OSG rows mean, one line each (`occull osg --help`, the docs).
[[nodiscard]] std::string describe_osg_rows();

struct OsgBenchConfig {
  std::string scene = "city";  ///< occull scene spec (exported to an OSG graph: export_scene)
  /// Instead of `scene`: a file OSG's plugins read (.osgt, .osgb, .ive,
  /// .obj, .3ds, .flt, ...), imported (import_graph) and flown on its
  /// `orbit` or `through` path, each row over its flattened graph (flatten).
  std::string file;
  std::string path;            ///< camera path; empty = the scene's first
  /// Rows: "osg" (OSG's frustum and small-feature culling only), "oqn"
  /// (an osg::OcclusionQueryNode over every object, OSG's defaults: 500
  /// pixels visibility threshold, a query every 5 frames), "oqn-strict"
  /// (threshold 0, a query every frame), or an occull algorithm spec run by
  /// an OcclusionCullingGroup over the whole scene. Empty: default_osg_rows().
  std::vector<std::string> rows;
  int frames = 100;            ///< timed frames per row and repeat, >= 1
  int warmup = 8;              ///< untimed frames first, >= 0
  int repeat = 1;              ///< runs of every row, interleaved, >= 1
  occull::FrameSampling sampling;
  int width = 1280, height = 720;
  bool verify = true;          ///< check every frame against occull's ground truth
  /// osgViewer's threading model: "single" (SingleThreaded) or "cull-draw"
  /// (CullDrawThreadPerContext); the others are refused (see culling_group.hpp).
  std::string threading = "single";
  occull::Options options;     ///< base options of the occull rows
  /// When set, called with each row's last timed frame of the first repeat:
  /// the row, width, height and RGBA8 pixels, top row first.
  std::function<void(const std::string& row, int width, int height, const std::vector<std::uint8_t>& rgba)>
      last_frame;
};

/// Runs every row over the same frames: per row and repeat a fresh
/// compatibility-profile context, a fresh export of the scene and a fresh
/// headless osgViewer::Viewer embedded in it (an FBO of width x height),
/// the camera's matrices set from the path's view each frame (near and far
/// not recomputed by OSG), each frame timed from viewer.frame() to glFinish.
/// What a row drew in a frame is what reached OSG's draw: for OSG's rows the
/// objects its cull traversal kept (a cull callback per object), for occull's
/// the objects the group's culler drew. Throws occull::InputError for an
/// unknown row, scene, path or threading model (listing the valid ones), a
/// file that is missing, that OSG cannot read, or that has no triangles.
[[nodiscard]] occull::BenchResult run_osg_bench(const OsgBenchConfig& config,
                                                const occull::ProgressFn& progress = {});

}  // namespace osgOccull
