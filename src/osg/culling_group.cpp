// OcclusionCullingGroup: see occull/osg/culling_group.hpp for what it does
// and the rules it keeps.
#include "occull/osg/culling_group.hpp"

#include "occull/bvh.hpp"
#include "occull/error.hpp"
#include "occull/view.hpp"
#include "gatherer.hpp"
#include "osg_backend.hpp"

#include <osg/Geode>
#include <osg/TriangleFunctor>
#include <osgUtil/CullVisitor>
#include <osgViewer/View>

#include <fmt/format.h>
#include <glm/gtc/type_ptr.hpp>

#include <chrono>
#include <map>
#include <optional>
#include <unordered_map>
#include <utility>

namespace osgOccull {
using namespace occull;
using detail::Gatherer;
using detail::TriangleCount;
using detail::is_translucent;
using detail::occluder_of;
namespace {

using Clock = std::chrono::steady_clock;

const char* threading_name(osgViewer::ViewerBase::ThreadingModel m) {
  switch (m) {
    case osgViewer::ViewerBase::SingleThreaded: return "SingleThreaded";
    case osgViewer::ViewerBase::CullDrawThreadPerContext: return "CullDrawThreadPerContext";
    case osgViewer::ViewerBase::DrawThreadPerContext: return "DrawThreadPerContext";
    case osgViewer::ViewerBase::CullThreadPerCameraDrawThreadPerContext:
      return "CullThreadPerCameraDrawThreadPerContext";
    case osgViewer::ViewerBase::AutomaticSelection: return "AutomaticSelection";
  }
  return "an unknown threading model";
}

glm::mat4 to_glm(const ::osg::Matrix& m) { return glm::make_mat4(::osg::Matrixf(m).ptr()); }

}  // namespace

void require_supported_threading(osgViewer::ViewerBase& viewer) {
  auto model = viewer.getThreadingModel();
  if (model == osgViewer::ViewerBase::AutomaticSelection) model = viewer.suggestBestThreadingModel();
  if (model == osgViewer::ViewerBase::SingleThreaded || model == osgViewer::ViewerBase::CullDrawThreadPerContext)
    return;
  throw UnsupportedThreading(fmt::format(
      "OcclusionCullingGroup: the viewer's threading model {} draws a frame while the next is updated and culled; "
      "the group supports SingleThreaded and CullDrawThreadPerContext (viewer.setThreadingModel(...))",
      threading_name(model)));
}

// The per-camera culler and backend.
struct CameraCuller {
  std::unique_ptr<Culler> culler;
  std::unique_ptr<detail::OsgBackend> backend;
  unsigned context_id = 0;
  CameraFrame frame;
};

struct OcclusionCullingGroup::State {
  Scene scene{"osg"};
  Bvh bvh = Bvh::build(std::span<const Aabb>{}, std::span<const std::uint32_t>{});
  bool built = false;
  MaterialId opaque = 0, translucent = 0;
  unsigned gathered_frame = ~0u;
  std::unordered_map<std::uint64_t, ObjectId> ids;            // instance path's key -> object
  std::unordered_map<const ::osg::Drawable*, MeshId> meshes;  // shared geometry: one mesh per drawable
  detail::MergedStates merged;                               // state-set list's key -> merged
  std::vector<std::uint64_t> state_keys;                      // per object: its list's key
  std::vector<std::uint64_t> seen;                            // per object: the last walk that met it
  std::uint64_t walk = 0;
  std::map<const ::osg::Camera*, CameraCuller> cameras;
  bool warned_view = false;
  double gather_ms = 0.0;  // the last gather's wall time
};

class OcclusionCullingGroup::Drawer : public ::osg::Drawable {
 public:
  explicit Drawer(OcclusionCullingGroup* group) : group_(group) {
    setUseDisplayList(false);
    setUseVertexBufferObjects(false);
    setCullingActive(false);  // the culler does the group's frustum culling
    setDataVariance(::osg::Object::DYNAMIC);
  }
  Drawer(const Drawer& d, const ::osg::CopyOp& op) : ::osg::Drawable(d, op), group_(d.group_) {}
  META_Object(occull, Drawer)
  void drawImplementation(::osg::RenderInfo& info) const override { group_->draw(info); }
  ::osg::BoundingBox computeBoundingBox() const override {
    const Aabb b = group_->state_->scene.bounds();
    if (b.empty()) return {};
    return {b.min.x, b.min.y, b.min.z, b.max.x, b.max.y, b.max.z};
  }

 private:
  Drawer() = default;
  OcclusionCullingGroup* group_ = nullptr;
};

OcclusionCullingGroup::OcclusionCullingGroup(std::string algorithm, Options options, CullerContext context)
    : context_(std::move(context)) {
  set_algorithm(std::move(algorithm), std::move(options));
  start();
}

// A copy culls the same subgraph with its own scene and cullers.
OcclusionCullingGroup::OcclusionCullingGroup(const OcclusionCullingGroup& g, const ::osg::CopyOp& op)
    : ::osg::Group(g, op), algorithm_(g.algorithm_), make_(g.make_), context_(g.context_) {
  start();
}

void OcclusionCullingGroup::start() {
  // OSG's frustum and small-feature culling would judge the whole group by
  // its bounding sphere (small-feature culling is not conservative); the
  // group's culler does both, conservatively.
  setCullingActive(false);
  state_ = std::make_shared<State>();
  state_->opaque = state_->scene.add_material({"opaque"});
  Material glass{"translucent"};
  glass.translucent = true;
  state_->translucent = state_->scene.add_material(glass);
  drawer_geode_ = new ::osg::Geode;
  drawer_geode_->addDrawable(new Drawer(this));
  drawer_geode_->setCullingActive(false);
}

OcclusionCullingGroup::~OcclusionCullingGroup() = default;

void OcclusionCullingGroup::set_algorithm(std::string algorithm, Options options) {
  (void)parse_algorithm_spec(algorithm, options);  // throws for an unknown name, listing the valid ones
  Maker make = [spec = algorithm, options = std::move(options)](const SceneIndex& index, const CullerContext& context) {
    return make_culler(spec, index, options, context);
  };
  set_maker(std::move(algorithm), std::move(make));
}

void OcclusionCullingGroup::set_maker(std::string algorithm, Maker make) {
  // Checked now, on an empty scene: an unknown option or a value out of range throws here.
  Scene empty;
  const Bvh bvh = Bvh::build(empty);
  (void)make({empty, bvh}, context_);
  const std::string name = algorithm.substr(0, algorithm.find(':'));
  if (find_algorithm(name).device)
    throw InputError(fmt::format("{} culls on the device, and the group's backend over osg::State has no device "
                                 "culling (DeviceCulling); use a culler that issues queries",
                                 name));
  std::lock_guard lock(mutex_);
  algorithm_ = std::move(algorithm);
  make_ = std::move(make);
}

const Scene& OcclusionCullingGroup::scene() const noexcept { return state_->scene; }

const CameraFrame* OcclusionCullingGroup::last_frame(const ::osg::Camera* camera) const {
  const auto it = state_->cameras.find(camera);
  return it == state_->cameras.end() ? nullptr : &it->second.frame;
}

void OcclusionCullingGroup::frame_finished(const ::osg::Camera* camera, const FrameMeasure& measured) {
  std::lock_guard lock(mutex_);
  const auto it = state_->cameras.find(camera);
  if (it != state_->cameras.end() && it->second.culler) it->second.culler->frame_finished(measured);
}

void OcclusionCullingGroup::traverse(::osg::NodeVisitor& nv) {
  if (nv.getVisitorType() != ::osg::NodeVisitor::CULL_VISITOR) {
    ::osg::Group::traverse(nv);
    return;
  }
  auto* cv = nv.asCullVisitor();
  if (::osg::Camera* camera = cv->getCurrentCamera(); camera != nullptr)
    if (auto* view = dynamic_cast<osgViewer::View*>(camera->getView()); view != nullptr)
      if (osgViewer::ViewerBase* viewer = view->getViewerBase(); viewer != nullptr)
        require_supported_threading(*viewer);
  gather(nv.getFrameStamp() != nullptr ? nv.getFrameStamp()->getFrameNumber() : 0u);
  drawer_geode_->accept(nv);
}

void OcclusionCullingGroup::gather(unsigned frame_number) {
  std::lock_guard lock(mutex_);
  State& s = *state_;
  if (s.built && s.gathered_frame == frame_number) return;  // another camera's cull gathered this frame
  s.gathered_frame = frame_number;
  const auto t0 = Clock::now();
  ++s.walk;
  auto found = [&](::osg::Drawable& drawable, const ::osg::NodePath& path, std::uint64_t path_key,
                   const ::osg::Matrix& to_group, std::span<const ::osg::StateSet* const> states,
                   std::uint64_t state_key) {
    // Known instance: the same path (a colliding key probes on).
    auto it = s.ids.find(path_key);
    while (it != s.ids.end() && instances_[it->second].path != path) it = s.ids.find(++path_key);
    if (it != s.ids.end()) {
      const ObjectId id = it->second;
      s.seen[id] = s.walk;
      Instance& inst = instances_[id];
      if (!(inst.to_group == to_group)) {
        s.scene.set_transform(id, to_glm(to_group));
        inst.to_group = to_group;
      }
      if (s.state_keys[id] != state_key) {
        s.state_keys[id] = state_key;
        inst.state = s.merged.get(states, state_key);
        // (a change of translucency keeps the object's class: it is re-added when it moves in the graph)
      }
      return;
    }
    auto [mesh_it, new_mesh] = s.meshes.try_emplace(&drawable, 0);
    if (new_mesh) {
      ::osg::TriangleFunctor<TriangleCount> count;
      drawable.accept(count);
      const ::osg::BoundingBox& b = drawable.getBoundingBox();
      MeshInfo info;
      if (b.valid()) info.bounds = Aabb{{b.xMin(), b.yMin(), b.zMin()}, {b.xMax(), b.yMax(), b.zMax()}};
      info.triangles = count.triangles;
      info.surface_area = count.area;
      mesh_it->second = s.scene.add_mesh(info);
    }
    ::osg::ref_ptr<::osg::StateSet> merged = s.merged.get(states, state_key);
    const bool translucent = is_translucent(merged.get());
    const ObjectId id = s.scene.add_object(mesh_it->second, translucent ? s.translucent : s.opaque,
                                           to_glm(to_group), occluder_of(path, translucent));
    s.ids.emplace(path_key, id);
    if (id >= instances_.size()) {
      instances_.resize(id + 1);
      s.seen.resize(id + 1, 0);
      s.state_keys.resize(id + 1, 0);
    }
    s.seen[id] = s.walk;
    s.state_keys[id] = state_key;
    instances_[id] = Instance{&drawable, path, to_group, merged, translucent};
  };
  Gatherer<decltype(found)> g(found);
  for (unsigned i = 0; i < getNumChildren(); ++i) getChild(i)->accept(g);
  for (auto it = s.ids.begin(); it != s.ids.end();) {  // what the walk did not meet is gone
    if (s.seen[it->second] == s.walk) {
      ++it;
      continue;
    }
    s.scene.remove_object(it->second);
    instances_[it->second] = Instance{};
    it = s.ids.erase(it);
  }
  if (!s.built) {
    s.bvh = Bvh::build(s.scene);
    s.built = true;
  } else {
    s.bvh.refit(s.scene);
  }
  s.scene.clear_moved();
  drawer_geode_->getDrawable(0)->dirtyBound();
  drawer_geode_->dirtyBound();
  s.gather_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

void OcclusionCullingGroup::draw(::osg::RenderInfo& info) {
  std::lock_guard lock(mutex_);
  State& s = *state_;
  ::osg::State& state = *info.getState();
  const ::osg::Camera* camera = info.getCurrentCamera();
  CameraCuller& c = s.cameras[camera];
  if (!c.culler) {
    c.culler = make_({s.scene, s.bvh}, context_);
    c.backend = std::make_unique<detail::OsgBackend>(state.getContextID());
    c.context_id = state.getContextID();
  }
  const ::osg::Matrix view_matrix = state.getModelViewMatrix();
  const ::osg::Viewport* vp = state.getCurrentViewport();
  if (vp == nullptr && camera != nullptr) vp = camera->getViewport();
  c.frame = {};
  c.frame.choices = c.culler->choices();
  c.frame.gather_ms = std::exchange(s.gather_ms, 0.0);  // the first camera drawn after a gather pays for it
  c.backend->begin_frame(info, view_matrix, instances_, s.scene);
  const BackendStats before = c.backend->stats();
  std::optional<View> view;
  try {
    view = make_view(to_glm(view_matrix), to_glm(state.getProjectionMatrix()), vp ? int(vp->width()) : 1,
                     vp ? int(vp->height()) : 1);
  } catch (const InputError& e) {
    // A projection the cullers cannot reason about: draw everything (always correct).
    if (!s.warned_view) OSG_WARN << "occull: OcclusionCullingGroup draws everything: " << e.what() << std::endl;
    s.warned_view = true;
  }
  if (view) {
    c.frame.culler = c.culler->render_frame(*view, *c.backend);
    c.frame.counters.clear();
    c.culler->visit_counters([&](std::string_view name, double value) { c.frame.counters.emplace_back(name, value); });
    const auto drawn = c.culler->drawn_objects();
    c.frame.drawn.assign(drawn.begin(), drawn.end());
  } else {
    const auto t0 = Clock::now();
    for (ObjectId id = 0; id < instances_.size(); ++id)
      if (instances_[id].drawable) c.frame.drawn.push_back(id);
    const BackendStats drawing = c.backend->stats();
    c.backend->render(c.frame.drawn);
    const double wall_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
    c.frame.culler = {.objects_drawn = c.frame.drawn.size(),
                      .cpu_ms = std::max(0.0, wall_ms - (c.backend->stats().backend_ms - drawing.backend_ms))};
    c.frame.counters.clear();
  }
  c.backend->end_frame();
  c.frame.backend = c.backend->stats() - before;
}

void OcclusionCullingGroup::releaseGLObjects(::osg::State* state) const {
  ::osg::Group::releaseGLObjects(state);
  auto* self = const_cast<OcclusionCullingGroup*>(this);
  std::lock_guard lock(self->mutex_);
  auto& cameras = state_->cameras;
  for (auto it = cameras.begin(); it != cameras.end();) {
    if (state != nullptr && it->second.context_id != state->getContextID()) {
      ++it;
      continue;
    }
    if (state != nullptr) {  // that context is current: read what the culler holds, free the query objects
      it->second.culler->release(*it->second.backend);
      it->second.backend->delete_queries();
    }
    it = cameras.erase(it);
  }
}

}  // namespace osgOccull
