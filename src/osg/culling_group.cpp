// OcclusionCullingGroup: see occull/osg/culling_group.hpp for what it does
// and the rules it keeps.
#include "occull/osg/culling_group.hpp"

#include "occull/bvh.hpp"
#include "occull/view.hpp"
#include "osg_backend.hpp"

#include <osg/BlendFunc>
#include <osg/Camera>
#include <osg/Geode>
#include <osg/Projection>
#include <osg/TriangleFunctor>
#include <osgUtil/CullVisitor>
#include <osgViewer/View>

#include <fmt/format.h>
#include <optional>
#include <glm/gtc/type_ptr.hpp>

#include <chrono>
#include <map>
#include <unordered_map>

namespace osgOccull {
using namespace occull;
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

// Triangles and their area, for a drawable's MeshInfo.
struct TriangleCount {
  std::uint32_t triangles = 0;
  double area = 0.0;
  void operator()(const ::osg::Vec3& a, const ::osg::Vec3& b, const ::osg::Vec3& c) {
    ++triangles;
    area += 0.5 * double(((b - a) ^ (c - a)).length());
  }
};

bool is_translucent(const ::osg::StateSet* s) {
  return s != nullptr && (s->getRenderingHint() == ::osg::StateSet::TRANSPARENT_BIN ||
                          (s->getMode(GL_BLEND) & ::osg::StateAttribute::ON) != 0);
}

// "occull.occluder" on a node of the path: always | sometimes | never.
OccluderClass occluder_of(const ::osg::NodePath& path, bool translucent) {
  if (translucent) return OccluderClass::never;
  for (auto it = path.rbegin(); it != path.rend(); ++it) {
    std::string value;
    if ((*it)->getUserValue("occull.occluder", value)) {
      if (value == "always") return OccluderClass::always;
      if (value == "never") return OccluderClass::never;
      return OccluderClass::sometimes;
    }
  }
  return OccluderClass::sometimes;
}

// Walks a subgraph: every drawable reached through active children, with
// its path, its transform to the walk's start and the state sets above it.
class Gatherer : public ::osg::NodeVisitor {
 public:
  struct Found {
    ::osg::Drawable* drawable;
    ::osg::NodePath path;
    ::osg::Matrix to_group;
    std::vector<const ::osg::StateSet*> states;
  };
  std::vector<Found> found;

  Gatherer() : ::osg::NodeVisitor(TRAVERSE_ACTIVE_CHILDREN) {}
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
    found.push_back({&d, getNodePath(), matrix_, states_});
    pop(d);
  }

 private:
  ::osg::Matrix matrix_;
  std::vector<const ::osg::StateSet*> states_;
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
    if (n.getStateSet() != nullptr) states_.push_back(n.getStateSet());
  }
  void pop(::osg::Node& n) {
    if (n.getStateSet() != nullptr) states_.pop_back();
  }
};

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
  std::map<::osg::NodePath, ObjectId> ids;                   // instance path -> object
  std::unordered_map<const ::osg::Drawable*, MeshId> meshes;  // shared geometry: one mesh per drawable
  std::map<std::vector<const ::osg::StateSet*>, ::osg::ref_ptr<::osg::StateSet>> merged;
  std::map<const ::osg::Camera*, CameraCuller> cameras;
  bool warned_view = false;
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
    : ::osg::Group(g, op), algorithm_(g.algorithm_), options_(g.options_), context_(g.context_) {
  start();
}

void OcclusionCullingGroup::start() {
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
  // Checked now, on an empty scene: an unknown name or option throws here.
  Scene empty;
  const Bvh bvh = Bvh::build(empty);
  (void)make_culler(algorithm, {empty, bvh}, options, context_);
  std::lock_guard lock(mutex_);
  algorithm_ = std::move(algorithm);
  options_ = std::move(options);
}

const Scene& OcclusionCullingGroup::scene() const noexcept { return state_->scene; }

const CameraFrame* OcclusionCullingGroup::last_frame(const ::osg::Camera* camera) const {
  const auto it = state_->cameras.find(camera);
  return it == state_->cameras.end() ? nullptr : &it->second.frame;
}

::osg::BoundingSphere OcclusionCullingGroup::computeBound() const { return ::osg::Group::computeBound(); }

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
  Gatherer g;
  for (unsigned i = 0; i < getNumChildren(); ++i) getChild(i)->accept(g);

  instances_.resize(s.scene.objects().size());
  std::vector<bool> seen(s.scene.objects().size(), false);
  for (Gatherer::Found& f : g.found) {
    // The merged state of the path (one StateSet per distinct list).
    ::osg::ref_ptr<::osg::StateSet> merged;
    if (!f.states.empty()) {
      auto [it, added] = s.merged.try_emplace(f.states);
      if (added) {
        it->second = new ::osg::StateSet;
        for (const ::osg::StateSet* ss : f.states) it->second->merge(*ss);
      }
      merged = it->second;
    }
    const glm::mat4 transform = to_glm(f.to_group);
    if (const auto it = s.ids.find(f.path); it != s.ids.end()) {
      const ObjectId id = it->second;
      seen[id] = true;
      Instance& inst = instances_[id];
      if (!(inst.to_group == f.to_group)) {
        s.scene.set_transform(id, transform);
        inst.to_group = f.to_group;
      }
      inst.state = merged;
      continue;
    }
    auto [mesh_it, new_mesh] = s.meshes.try_emplace(f.drawable, 0);
    if (new_mesh) {
      ::osg::TriangleFunctor<TriangleCount> count;
      f.drawable->accept(count);
      const ::osg::BoundingBox& b = f.drawable->getBoundingBox();
      MeshInfo info;
      if (b.valid()) info.bounds = Aabb{{b.xMin(), b.yMin(), b.zMin()}, {b.xMax(), b.yMax(), b.zMax()}};
      info.triangles = count.triangles;
      info.surface_area = count.area;
      mesh_it->second = s.scene.add_mesh(info);
    }
    const bool translucent = is_translucent(merged.get());
    const ObjectId id = s.scene.add_object(mesh_it->second, translucent ? s.translucent : s.opaque, transform,
                                           occluder_of(f.path, translucent));
    s.ids.emplace(f.path, id);
    if (id >= instances_.size()) {
      instances_.resize(id + 1);
      seen.resize(id + 1, false);
    }
    seen[id] = true;
    instances_[id] = Instance{f.drawable, f.path, f.to_group, merged, translucent};
  }
  for (auto it = s.ids.begin(); it != s.ids.end();) {
    if (seen[it->second]) {
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
}

void OcclusionCullingGroup::draw(::osg::RenderInfo& info) {
  std::lock_guard lock(mutex_);
  State& s = *state_;
  ::osg::State& state = *info.getState();
  const ::osg::Camera* camera = info.getCurrentCamera();
  CameraCuller& c = s.cameras[camera];
  if (!c.culler) {
    c.culler = make_culler(algorithm_, {s.scene, s.bvh}, options_, context_);
    c.backend = std::make_unique<detail::OsgBackend>(state.getContextID());
    c.context_id = state.getContextID();
  }
  const ::osg::Matrix view_matrix = state.getModelViewMatrix();
  const ::osg::Viewport* vp = state.getCurrentViewport();
  if (vp == nullptr && camera != nullptr) vp = camera->getViewport();
  c.frame = {};
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
  const auto t0 = Clock::now();
  if (view) {
    c.frame.culler = c.culler->render_frame(*view, *c.backend);
    const auto drawn = c.culler->drawn_objects();
    c.frame.drawn.assign(drawn.begin(), drawn.end());
  } else {
    for (ObjectId id = 0; id < instances_.size(); ++id)
      if (instances_[id].drawable) c.frame.drawn.push_back(id);
    c.backend->render(c.frame.drawn);
  }
  const double culler_wall_ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  c.backend->end_frame();
  c.frame.backend = c.backend->stats() - before;
  c.frame.culler.cpu_ms = std::max(0.0, culler_wall_ms - c.frame.backend.backend_ms);
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
