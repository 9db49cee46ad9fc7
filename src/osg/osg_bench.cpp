// run_osg_bench: OSG's culling and occull's inside one OSG viewer.
#include "occull/osg/osg_bench.hpp"

#include "occull/counters.hpp"
#include "occull/error.hpp"
#include "occull/gl/context.hpp"
#include "occull/osg/culling_group.hpp"
#include "occull/osg/scene_graph.hpp"

#include <osg/OcclusionQueryNode>
#include <osg/Version>
#include <osgDB/ReadFile>
#include <osgViewer/Viewer>

#include <fmt/format.h>
#include <glm/gtc/type_ptr.hpp>

#include <GL/gl.h>
#include <GL/glext.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
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

RowGraph make_row_graph(const std::string& row, ExportedScene exported, const Options& options,
                        const CullerContext& context, std::vector<ObjectId>& kept) {
  RowGraph g;
  g.exported = std::move(exported);
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

namespace {

// An embedded window whose context is ours: OSG's draw thread (threaded
// models) makes it current there, and a "swap" finishes the frame (glFinish),
// so viewer.frame() returns with the frame done in every threading model.
class EglWindow : public osgViewer::GraphicsWindowEmbedded {
 public:
  EglWindow(gl::Context& context, int width, int height)
      : osgViewer::GraphicsWindowEmbedded(0, 0, width, height), context_(context) {}
  bool makeCurrentImplementation() override {
    context_.make_current();
    return true;
  }
  bool releaseContextImplementation() override {
    context_.release();
    return true;
  }
  void swapBuffersImplementation() override { glFinish(); }

 private:
  gl::Context& context_;
};

}  // namespace

HeadlessViewer::HeadlessViewer(int width, int height, osgViewer::ViewerBase::ThreadingModel model)
    : context_(gl::Context::create({.debug = false, .compatibility = true})), width_(width), height_(height) {
  glGenFramebuffers(1, &fbo_);
  glGenRenderbuffers(2, renderbuffers_);
  glBindRenderbuffer(GL_RENDERBUFFER, renderbuffers_[0]);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_RGBA8, width, height);
  glBindRenderbuffer(GL_RENDERBUFFER, renderbuffers_[1]);
  glRenderbufferStorage(GL_RENDERBUFFER, GL_DEPTH_COMPONENT24, width, height);
  glBindFramebuffer(GL_FRAMEBUFFER, fbo_);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, renderbuffers_[0]);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, renderbuffers_[1]);
  if (glCheckFramebufferStatus(GL_FRAMEBUFFER) != GL_FRAMEBUFFER_COMPLETE)
    throw GlUnavailable("the driver cannot make a colour + depth framebuffer for OpenSceneGraph");
  viewer_ = new osgViewer::Viewer;
  viewer_->setUseConfigureAffinity(false);  // OSG would pin this thread to one core (REFERENCE.md)
  viewer_->setThreadingModel(model);
  window_ = new EglWindow(*context_, width, height);
  window_->setDefaultFboId(fbo_);
  ::osg::Camera* camera = viewer_->getCamera();
  camera->setGraphicsContext(window_.get());
  camera->setViewport(new ::osg::Viewport(0, 0, width, height));
  camera->setDrawBuffer(GL_COLOR_ATTACHMENT0);
  camera->setReadBuffer(GL_COLOR_ATTACHMENT0);
  camera->setComputeNearFarMode(::osg::CullSettings::DO_NOT_COMPUTE_NEAR_FAR);
  camera->setClearColor({0.55f, 0.65f, 0.8f, 1.0f});
  // A sun fixed in the world (+Y up, as occull's scenes) and some sky: OSG's
  // default head light leaves every surface seen edge-on black.
  viewer_->setLightingMode(::osg::View::SKY_LIGHT);
  ::osg::Light* sun = viewer_->getLight();
  sun->setPosition({0.4f, 1.0f, 0.6f, 0.0f});
  sun->setAmbient({0.45f, 0.45f, 0.45f, 1.0f});
  sun->setDiffuse({0.7f, 0.7f, 0.7f, 1.0f});
}

HeadlessViewer::~HeadlessViewer() {
  set_scene(nullptr);
  viewer_ = nullptr;
  window_ = nullptr;
  context_->make_current();
  glDeleteFramebuffers(1, &fbo_);
  glDeleteRenderbuffers(2, renderbuffers_);
}

void HeadlessViewer::set_scene(::osg::Node* scene) {
  if (::osg::Node* old = viewer_->getSceneData(); old != nullptr && realized_) {
    viewer_->stopThreading();  // a draw thread holds the context: it lets go
    context_->make_current();
    old->releaseGLObjects(window_->getState());  // a culling group hands back its queries here
  }
  viewer_->setSceneData(scene);
  if (scene != nullptr && !realized_) {
    require_supported_threading(*viewer_);  // heard here rather than from a draw thread
    context_->release();                    // OSG makes it current where it draws
    viewer_->realize();
    realized_ = true;
  }
}

std::vector<std::uint8_t> HeadlessViewer::read_rgba() {
  viewer_->stopThreading();
  context_->make_current();
  std::vector<std::uint8_t> rgba(std::size_t(width_) * std::size_t(height_) * 4);
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
  glReadBuffer(GL_COLOR_ATTACHMENT0);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
  const std::size_t row = std::size_t(width_) * 4;
  for (int y = 0; y < height_ / 2; ++y)
    std::swap_ranges(rgba.begin() + std::ptrdiff_t(row * std::size_t(y)), rgba.begin() + std::ptrdiff_t(row * std::size_t(y + 1)),
                     rgba.begin() + std::ptrdiff_t(row * std::size_t(height_ - 1 - y)));
  return rgba;
}

double HeadlessViewer::frame(const View& view, double time_s) {
  viewer_->getCamera()->setViewMatrix(to_osg(view.view));
  viewer_->getCamera()->setProjectionMatrix(to_osg(view.proj));
  const auto t0 = Clock::now();
  viewer_->frame(time_s);  // closed by the window's swap: glFinish
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

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
  // A file: read by OSG, imported as an occull scene (its truth), each row over its flattened graph.
  ImportedGraph imported;
  if (!config.file.empty()) {
    std::error_code ec;
    if (!std::filesystem::is_regular_file(config.file, ec)) throw InputError(fmt::format("{}: no such file", config.file));
    const ::osg::ref_ptr<::osg::Node> loaded = osgDB::readNodeFile(config.file);
    if (!loaded)
      throw InputError(fmt::format("{}: OpenSceneGraph cannot read it (no plugin for its extension, or the file is "
                                   "damaged)",
                                   config.file));
    imported = import_graph(*loaded, config.file);
  }
  Session session = config.file.empty() ? Session(config.scene, ropts)
                                        : Session(config.file, std::move(imported.bundle), ropts);
  if (session.bundle().world) throw InputError(fmt::format("{}: a tiled world cannot be exported to OSG", config.scene));
  session.set_sampling(config.sampling);
  const CameraPath& path = session.path(config.path);
  if (const int fit = path.frames_that_fit(config.sampling); config.frames > fit)
    throw InputError(fmt::format("--frames {} runs past the end of path {}: {} frames fit", config.frames,
                                 path.name(), fit));
  // The OSG graph is made once from the scene as it stands: the session's
  // floating origin must not move during the walk (it re-places occull's objects only).
  for (int k = 0; k < config.frames; ++k)
    if (session.origin_for(path.sample(session.frame_time(path, k, config.frames))) != session.origin())
      throw InputError(fmt::format("{}: path {} crosses from one floating-origin cell of {:g} m to another (frame {}); "
                                   "OSG's graph does not follow a moved origin: run occull bench there",
                                   config.scene, path.name(), session.origin_grid(), k));
  const auto say = [&](const std::string& line) {
    if (progress) progress(line, 0, 0, false);
  };
  for (const std::string& row : rows) {
    if (is_osg_row(row)) continue;
    try {
      (void)session.make(row, config.options, say);  // checks the spec; calibrates nohc once
    } catch (const InputError& e) {
      throw InputError(fmt::format("row {}: not osg, oqn or oqn-strict, nor an occull algorithm: {}", row, e.what()));
    }
  }
  const CullerContext context = session.culler_context(say);

  BenchResult result;
  describe_run(session, path, config.frames, result);
  result.scene = config.file.empty() ? config.scene : config.file;
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

  std::unique_ptr<HeadlessViewer> retired;  // kept idle until the next row's (see Session::reset_renderer)
  for (int rep = 0; rep < config.repeat; ++rep) {
    for (const std::string& row : rows) {
      const std::string label = config.repeat > 1 ? fmt::format("{} #{}", row, rep + 1) : row;
      auto device = std::make_unique<HeadlessViewer>(config.width, config.height, model);
      std::vector<ObjectId> kept;
      RowGraph graph = make_row_graph(row, config.file.empty() ? export_scene(scene) : flatten(imported.instances),
                                      config.options, context, kept);
      device->set_scene(graph.root.get());
      const ::osg::Camera* camera = &device->camera();

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
        animate(scene, session.bundle().scripted, t);
        update_exported(scene, graph.exported);
        kept.clear();
        const double frame_ms = device->frame(session.view_at(path, k, config.frames), t);
        if (graph.group) {  // the frame's measured time reaches the camera's culler, as Session does for occull's rows
          FrameMeasure measured;
          if (const CameraFrame* f = graph.group->last_frame(camera)) {
            measured.cpu_ms = f->culler.cpu_ms;
            measured.draw_calls = f->drawn.size();
            for (ObjectId id : f->drawn) measured.triangles += scene.object(id).triangles;
          }
          measured.frame_ms = frame_ms;
          graph.group->frame_finished(camera, measured);
        }
        if (progress) progress(label, warm ? step : step - config.warmup, warm ? config.warmup : config.frames, warm);
        if (warm) continue;
        FrameStats stats;
        std::vector<ObjectId> drawn;
        if (graph.group) {
          drawn_by_group(*graph.group, camera, drawn);
          if (const CameraFrame* f = graph.group->last_frame(camera)) {
            stats.nodes_visited = f->culler.nodes_visited;
            for (const auto& [name, value] : f->counters) set_counter(stats, name, value);
            stats.cpu_ms = f->culler.cpu_ms + f->gather_ms;  // the group's own CPU time: its gathering and its culler
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
              check_frame(truth[std::size_t(k)].visible, drawn, scene.objects().size(), stats,
                          truth[std::size_t(k)].depth_error_only);
          misses.add(missed);
          if (!missed.empty() && run.first_miss.empty())
            run.first_miss = fmt::format("frame {}: {}", k, session.describe_object(missed.front()));
        }
        run.frames.push_back(stats);
      }
      run.longest_miss_frames = misses.longest();
      if (graph.group)  // auto's candidates: the report says what it ran
        if (const CameraFrame* f = graph.group->last_frame(camera)) run.choices = f->choices;
      if (config.last_frame && rep == 0) config.last_frame(row, config.width, config.height, device->read_rgba());
      device->set_scene(nullptr);  // the group hands back its queries, the graph its GL objects
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
