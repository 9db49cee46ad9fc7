// run_osg_bench: OSG's culling and occull's inside one OSG viewer.
#include "occull/osg/osg_bench.hpp"

#include "occull/counters.hpp"
#include "occull/error.hpp"
#include "occull/gl/context.hpp"
#include "occull/osg/culling_group.hpp"
#include "occull/osg/scene_graph.hpp"

#include <osg/OcclusionQueryNode>
#include <osg/Version>
#include <osgViewer/Viewer>

#include <fmt/format.h>
#include <glm/gtc/type_ptr.hpp>

#include <GL/gl.h>
#include <GL/glext.h>

#include <algorithm>
#include <chrono>
#include <memory>

namespace osgOccull {
using namespace occull;
namespace {

using Clock = std::chrono::steady_clock;

::osg::Matrix to_osg(const glm::mat4& m) { return ::osg::Matrix(glm::value_ptr(m)); }

bool is_osg_row(const std::string& row) { return row == "osg" || row == "oqn" || row == "oqn-strict"; }

// Records the objects OSG's cull traversal kept: a cull callback per object
// (it runs only for a node that passed frustum and small-feature culling and
// that an OcclusionQueryNode above it let through).
class KeptRecorder : public ::osg::NodeCallback {
 public:
  KeptRecorder(ObjectId id, std::vector<ObjectId>& kept) : id_(id), kept_(kept) {}
  void operator()(::osg::Node* node, ::osg::NodeVisitor* nv) override {
    kept_.push_back(id_);
    traverse(node, nv);
  }

 private:
  ObjectId id_;
  std::vector<ObjectId>& kept_;
};

// The device of one row: a compatibility context (Debian's OSG draws with
// the fixed-function pipeline) and the FBO the embedded viewer draws into.
struct Device {
  std::unique_ptr<gl::Context> context;
  GLuint fbo = 0, colour = 0, depth = 0;
  Device(int width, int height) : context(gl::Context::create({.debug = false, .compatibility = true})) {
    glGenFramebuffers(1, &fbo);
    glGenRenderbuffers(1, &colour);
    glGenRenderbuffers(1, &depth);
    glBindRenderbuffer(GL_RENDERBUFFER, colour);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
    glBindRenderbuffer(GL_RENDERBUFFER, depth);
    glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
    glBindFramebuffer(GL_FRAMEBUFFER, fbo);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, colour);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, depth);
    if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
      throw GlUnavailable("occull osg: the driver cannot make a colour + depth framebuffer");
  }
  ~Device() {
    context->make_current();
    glDeleteFramebuffers(1, &fbo);
    glDeleteRenderbuffers(1, &colour);
    glDeleteRenderbuffers(1, &depth);
  }
  Device(const Device&) = delete;
  Device& operator=(const Device&) = delete;
};

osgViewer::ViewerBase::ThreadingModel threading_model(const std::string& name) {
  if (name == "single") return osgViewer::ViewerBase::SingleThreaded;
  if (name == "cull-draw") return osgViewer::ViewerBase::CullDrawThreadPerContext;
  if (name == "draw") return osgViewer::ViewerBase::DrawThreadPerContext;
  if (name == "cull-per-camera") return osgViewer::ViewerBase::CullThreadPerCameraDrawThreadPerContext;
  throw InputError(fmt::format("--threading {}: valid: single, cull-draw (draw and cull-per-camera exist in OSG "
                               "but the culling group refuses them)", name));
}

// One row's graph over a fresh export of the scene.
struct RowGraph {
  ExportedScene exported;
  ::osg::ref_ptr<::osg::Group> root;
  ::osg::ref_ptr<OcclusionCullingGroup> group;  // occull rows
};

RowGraph make_row_graph(const std::string& row, const Scene& scene, const Options& options,
                        const CullerContext& context, std::vector<ObjectId>& kept) {
  RowGraph g;
  g.exported = export_scene(scene);
  for (ObjectId id = 0; id < g.exported.objects.size(); ++id)
    if (g.exported.objects[id]) g.exported.objects[id]->setCullCallback(new KeptRecorder(id, kept));
  g.root = new ::osg::Group;
  if (row == "osg") {
    g.root->addChild(g.exported.root);
  } else if (row == "oqn" || row == "oqn-strict") {
    // One OcclusionQueryNode over every object (as OSG's osgocclusionquery example places them over geodes).
    ::osg::ref_ptr<::osg::Group> wrapped = new ::osg::Group;
    for (const auto& object : g.exported.objects) {
      if (!object) continue;
      ::osg::ref_ptr<::osg::OcclusionQueryNode> q = new ::osg::OcclusionQueryNode;
      if (row == "oqn-strict") {
        q->setVisibilityThreshold(0);
        q->setQueryFrameCount(1);
      }
      q->addChild(object);
      wrapped->addChild(q);
    }
    g.root->addChild(wrapped);
  } else {
    g.group = new OcclusionCullingGroup(row, options, context);
    g.group->addChild(g.exported.root);
    g.root->addChild(g.group);
  }
  return g;
}

// The ids of the exported objects an occull row's group drew.
void drawn_by_group(const OcclusionCullingGroup& group, const ::osg::Camera* camera, std::vector<ObjectId>& out) {
  const CameraFrame* f = group.last_frame(camera);
  if (f == nullptr) return;
  for (ObjectId id : f->drawn) {
    const std::int64_t object = exported_object(group.instances()[id].path);
    if (object < 0) throw std::logic_error(fmt::format("occull osg: the group drew instance {}, not an exported object", id));
    out.push_back(ObjectId(object));
  }
}

}  // namespace

const std::vector<std::string>& default_osg_rows() {
  static const std::vector<std::string> rows{"osg", "oqn", "oqn-strict", "vfc", "chcpp", "nohc", "grid"};
  return rows;
}

std::string describe_osg_rows() {
  return "osg: OSG's own frustum and small-feature culling, no occlusion culling\n"
         "oqn: an osg::OcclusionQueryNode over every object, OSG's defaults (500 pixels visibility threshold, a "
         "query every 5 frames, answers a frame late)\n"
         "oqn-strict: the same, threshold 0 and a query every frame (as lossless as OcclusionQueryNode gets)\n"
         "any occull spec (vfc, chcpp, nohc, grid, chcpp:batch=20, ...): an osgOccull::OcclusionCullingGroup over "
         "the scene running it\n";
}

BenchResult run_osg_bench(const OsgBenchConfig& config, const ProgressFn& progress) {
  const std::vector<std::string>& rows = config.rows.empty() ? default_osg_rows() : config.rows;
  if (config.frames < 1) throw InputError(fmt::format("--frames {}: must be at least 1", config.frames));
  if (config.warmup < 0) throw InputError(fmt::format("--warmup {}: must not be negative", config.warmup));
  if (config.repeat < 1) throw InputError(fmt::format("--repeat {}: must be at least 1", config.repeat));
  const auto model = threading_model(config.threading);

  gl::RendererOptions ropts;
  ropts.width = config.width;
  ropts.height = config.height;
  Session session(config.scene, ropts);
  if (session.bundle().world) throw InputError(fmt::format("{}: a tiled world cannot be exported to OSG", config.scene));
  session.set_sampling(config.sampling);
  const CameraPath& path = session.path(config.path);
  if (const int fit = path.frames_that_fit(config.sampling); config.frames > fit)
    throw InputError(fmt::format("--frames {} runs past the end of path {}: {} frames fit", config.frames,
                                 path.name(), fit));
  const auto say = [&](const std::string& line) {
    if (progress) progress(line, 0, 0, false);
  };
  for (const std::string& row : rows)
    if (!is_osg_row(row)) (void)session.make(row, config.options, say);  // checks the spec, calibrates nohc once
  const CullerContext context = session.culler_context(say);

  BenchResult result;
  result.device = session.device();
  result.scene = config.scene;
  result.path = path.name();
  result.objects = session.scene().objects().size();
  result.triangles = session.scene().triangle_count();
  result.bvh_nodes = session.bvh().size();
  result.frames = config.frames;
  result.sampling = config.sampling;
  result.path_duration_s = path.duration();
  result.warmup = config.warmup;
  result.repeat = config.repeat;
  result.verified = config.verify;
  result.width = config.width;
  result.height = config.height;
  result.query_geometry = "OSG rows: OSG's query boxes; occull rows: boxes 0.2% larger, polygon offset toward the eye";
  result.conditions = fmt::format("inside OpenSceneGraph {} ({} threading), one osgViewer::Viewer per row",
                                  osgGetVersion(), config.threading);
  if (session.has_hardware_profile()) result.profile_path = session.hardware_profile_path();

  std::vector<FrameTruth> truth;
  if (config.verify) truth = session.ground_truth(path, config.frames, progress);
  for (const FrameTruth& t : truth) {
    result.truth_probes += t.probes;
    result.truth_pixels += t.coverage.pixels;
  }
  Scene& scene = session.scene();

  std::unique_ptr<Device> retired;  // kept idle until the next row's (see Session::reset_renderer)
  for (int rep = 0; rep < config.repeat; ++rep) {
    for (const std::string& row : rows) {
      const std::string label = config.repeat > 1 ? fmt::format("{} #{}", row, rep + 1) : row;
      auto device = std::make_unique<Device>(config.width, config.height);
      std::vector<ObjectId> kept;
      RowGraph graph = make_row_graph(row, scene, config.options, context, kept);
      ::osg::ref_ptr<osgViewer::Viewer> viewer = new osgViewer::Viewer;
      viewer->setUseConfigureAffinity(false);  // OSG would pin this thread to one core (REFERENCE.md)
      viewer->setThreadingModel(model);
      ::osg::ref_ptr<osgViewer::GraphicsWindowEmbedded> window =
          viewer->setUpViewerAsEmbeddedInWindow(0, 0, config.width, config.height);
      window->setDefaultFboId(device->fbo);
      ::osg::Camera* camera = viewer->getCamera();
      camera->setDrawBuffer(GL_COLOR_ATTACHMENT0);
      camera->setReadBuffer(GL_COLOR_ATTACHMENT0);
      camera->setComputeNearFarMode(::osg::CullSettings::DO_NOT_COMPUTE_NEAR_FAR);
      camera->setClearColor({0.55f, 0.65f, 0.8f, 1.0f});
      viewer->setSceneData(graph.root);
      if (graph.group) require_supported_threading(*viewer);
      viewer->realize();

      AlgorithmRun run;
      run.name = row;
      run.repeat = rep;
      run.conservative = !is_osg_row(row) && is_conservative(parse_algorithm_spec(row, config.options));
      MissRuns misses(scene.objects().size());
      const int total = config.warmup + config.frames;
      for (int step = 0; step < total; ++step) {
        const bool warm = step < config.warmup;
        // Warm-up frames spread over the path, then the timed frames.
        const int k = warm ? (config.warmup > 1 ? step * (config.frames - 1) / (config.warmup - 1) : 0)
                           : step - config.warmup;
        const double t = session.frame_time(path, k, config.frames);
        scene.update(t);
        update_exported(scene, graph.exported);
        const View view = session.view_at(path, k, config.frames);
        camera->setViewMatrix(to_osg(view.view));
        camera->setProjectionMatrix(to_osg(view.proj));
        kept.clear();
        const auto t0 = Clock::now();
        viewer->frame(t);
        glFinish();
        const double frame_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
        if (progress) progress(label, warm ? step : step - config.warmup, warm ? config.warmup : config.frames, warm);
        if (warm) continue;
        FrameStats stats;
        std::vector<ObjectId> drawn;
        if (graph.group) {
          drawn_by_group(*graph.group, camera, drawn);
          if (const CameraFrame* f = graph.group->last_frame(camera)) {
            stats = f->culler;
            copy_backend_counters(f->backend, stats);
          }
        } else {
          drawn = kept;
        }
        std::sort(drawn.begin(), drawn.end());
        drawn.erase(std::unique(drawn.begin(), drawn.end()), drawn.end());
        stats.frame_ms = frame_ms;
        stats.draw_calls = drawn.size();
        stats.objects_rendered = drawn.size();
        stats.triangles = 0;
        for (ObjectId id : drawn) stats.triangles += scene.object(id).triangles;
        if (config.verify) {
          const std::vector<ObjectId> missed =
              check_frame(truth[std::size_t(k)].visible, drawn, scene.objects().size(), stats);
          misses.add(missed);
          if (!missed.empty() && run.first_miss.empty())
            run.first_miss = fmt::format("frame {}: {}", k, session.describe_object(missed.front()));
        }
        run.frames.push_back(stats);
      }
      run.longest_miss_frames = misses.longest();
      // Queries handed back and GL objects freed while the row's context is current.
      device->context->make_current();
      if (graph.group) graph.group->releaseGLObjects(window->getState());
      graph.root->releaseGLObjects(window->getState());
      viewer = nullptr;
      window = nullptr;
      result.runs.push_back(std::move(run));
      retired = std::move(device);
    }
  }
  retired.reset();
  session.context().make_current();
  result.summaries = summarize_runs(result.runs);
  return result;
}

}  // namespace osgOccull
