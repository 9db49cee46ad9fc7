// The Backend of an OcclusionCullingGroup over osg::State.
//
// The query pass's state set, and why each entry is there:
// - colour and depth writes off: query boxes are tested, never seen;
// - depth test GL_LEQUAL, polygon offset toward the eye (-1, -2), and each
//   box a hair larger than asked (kMargin): a box face lying on a drawn
//   surface must pass, so an object flush with a wall is not culled by it;
// - face culling off: the eye may be inside a box (its back faces then pass);
// - depth clamp on: the part of a box in front of the near plane is clamped
//   to it instead of clipped away, so a box crossing the near plane passes;
// - lighting and texturing off, fixed-function: nothing the colour needs.
// Every attribute and mode is OVERRIDE | PROTECTED, so state sets above the
// group cannot turn a test into something else.
#include "osg_backend.hpp"

#include "occull/error.hpp"

#include <osg/ColorMask>
#include <osg/CullFace>
#include <osg/Depth>
#include <osg/PolygonOffset>
#include <osg/Program>

#include <fmt/format.h>

#include <algorithm>
#include <chrono>

namespace osgOccull::detail {
using namespace occull;
namespace {

using Clock = std::chrono::steady_clock;

// Adds the wall time of a Backend call to BackendStats::backend_ms.
class Timed {
 public:
  explicit Timed(BackendStats& stats) : stats_(stats), start_(Clock::now()) {}
  ~Timed() { stats_.backend_ms += std::chrono::duration<double, std::milli>(Clock::now() - start_).count(); }
  Timed(const Timed&) = delete;
  Timed& operator=(const Timed&) = delete;

 private:
  BackendStats& stats_;
  Clock::time_point start_;
};

// Rasterisers snap vertices to sub-pixels: boxes grow by this share of their
// size, plus the same in scene units.
constexpr double kMargin = 0.002;

::osg::ref_ptr<::osg::StateSet> make_query_state() {
  constexpr auto kMode = ::osg::StateAttribute::ON | ::osg::StateAttribute::OVERRIDE | ::osg::StateAttribute::PROTECTED;
  constexpr auto kOff = ::osg::StateAttribute::OFF | ::osg::StateAttribute::OVERRIDE | ::osg::StateAttribute::PROTECTED;
  ::osg::ref_ptr<::osg::StateSet> s = new ::osg::StateSet;
  s->setAttributeAndModes(new ::osg::ColorMask(false, false, false, false), kMode);
  s->setAttributeAndModes(new ::osg::Depth(::osg::Depth::LEQUAL, 0.0, 1.0, false), kMode);
  s->setAttributeAndModes(new ::osg::PolygonOffset(-1.0f, -2.0f), kMode);
  s->setMode(GL_CULL_FACE, kOff);
  s->setMode(GL_DEPTH_CLAMP, kMode);
  s->setMode(GL_LIGHTING, kOff);
  s->setMode(GL_BLEND, kOff);
  s->setTextureMode(0, GL_TEXTURE_2D, kOff);
  s->setAttributeAndModes(new ::osg::Program, kMode);  // an empty program: fixed function
  return s;
}

::osg::ref_ptr<::osg::Geometry> make_unit_cube() {
  static constexpr int kCorner[12][3] = {{0, 1, 3}, {0, 3, 2}, {4, 6, 7}, {4, 7, 5}, {0, 4, 5}, {0, 5, 1},
                                         {2, 3, 7}, {2, 7, 6}, {0, 2, 6}, {0, 6, 4}, {1, 5, 7}, {1, 7, 3}};
  ::osg::ref_ptr<::osg::Vec3Array> v = new ::osg::Vec3Array;
  for (const auto& tri : kCorner)
    for (int c : tri) v->push_back(::osg::Vec3(float(c & 1), float((c >> 1) & 1), float((c >> 2) & 1)));
  ::osg::ref_ptr<::osg::Geometry> g = new ::osg::Geometry;
  g->setVertexArray(v);
  g->addPrimitiveSet(new ::osg::DrawArrays(GL_TRIANGLES, 0, GLsizei(v->size())));
  g->setUseDisplayList(false);
  g->setUseVertexBufferObjects(true);
  return g;
}

}  // namespace

OsgBackend::OsgBackend(unsigned context_id)
    : context_id_(context_id), query_state_(make_query_state()), cube_(make_unit_cube()) {}

void OsgBackend::begin_frame(::osg::RenderInfo& info, const ::osg::Matrix& view, std::span<const Instance> instances,
                             const Scene& scene) {
  info_ = &info;
  gl_ = info.getState()->get<::osg::GLExtensions>();
  view_ = view;
  instances_ = instances;
  scene_ = &scene;
  mode_ = Mode::none;
  translucent_.clear();
}

void OsgBackend::enter(Mode mode) {
  if (mode_ == mode) return;
  if (mode_ != Mode::none) ++stats_.state_changes;
  mode_ = mode;
  if (mode == Mode::query) info_->getState()->apply(query_state_.get());
}

void OsgBackend::draw_object(ObjectId id) {
  const Instance& o = instances_[id];
  ::osg::State& state = *info_->getState();
  if (o.state)
    state.apply(o.state.get());
  else
    state.apply();
  state.applyModelViewMatrix(o.to_group * view_);
  o.drawable->draw(*info_);
  ++stats_.draw_calls;
  ++stats_.objects_rendered;
  stats_.triangles += scene_->object(id).triangles;
}

void OsgBackend::render(std::span<const ObjectId> objects) {
  Timed timed(stats_);
  enter(Mode::draw);
  ++stats_.render_flushes;
  batch_.clear();
  for (ObjectId id : objects) {
    if (id >= instances_.size() || !instances_[id].drawable)
      throw UsageError(fmt::format("OcclusionCullingGroup: the culler drew object {}, which is not there", id));
    (instances_[id].translucent ? translucent_ : batch_).push_back(id);
  }
  // A render queue's order: by state set, so state changes only between groups.
  std::sort(batch_.begin(), batch_.end(),
            [&](ObjectId a, ObjectId b) { return instances_[a].state.get() < instances_[b].state.get(); });
  const ::osg::StateSet* last = nullptr;
  for (std::size_t i = 0; i < batch_.size(); ++i) {
    const ::osg::StateSet* s = instances_[batch_[i]].state.get();
    if (i == 0 || s != last) ++stats_.material_changes;
    last = s;
    draw_object(batch_[i]);
  }
}

void OsgBackend::end_frame() {
  Timed timed(stats_);
  if (!translucent_.empty()) {
    enter(Mode::draw);
    // Back to front: farthest centre (in eye space, -z) first.
    std::sort(translucent_.begin(), translucent_.end());
    translucent_.erase(std::unique(translucent_.begin(), translucent_.end()), translucent_.end());
    auto depth = [&](ObjectId id) {
      const glm::vec3 c = scene_->object(id).bounds.center();
      return -(::osg::Vec3d(c.x, c.y, c.z) * view_).z();
    };
    std::sort(translucent_.begin(), translucent_.end(), [&](ObjectId a, ObjectId b) { return depth(a) > depth(b); });
    for (ObjectId id : translucent_) draw_object(id);
    translucent_.clear();
  }
  info_->getState()->apply();  // leave OSG's state as the stack above the group says
  mode_ = Mode::none;
}

QueryId OsgBackend::issue_query(std::span<const Aabb> boxes) {
  Timed timed(stats_);
  enter(Mode::query);
  QueryId q;
  if (free_.empty()) {
    GLuint name = 0;
    gl_->glGenQueries(1, &name);
    names_.push_back(name);
    live_.push_back(false);
    q = QueryId(names_.size() - 1);
  } else {
    q = free_.back();
    free_.pop_back();
  }
  live_[q] = true;
  ::osg::State& state = *info_->getState();
  gl_->glBeginQuery(GL_SAMPLES_PASSED, names_[q]);
  for (const Aabb& b : boxes) {
    const ::osg::Vec3d lo(b.min.x, b.min.y, b.min.z), hi(b.max.x, b.max.y, b.max.z);
    const ::osg::Vec3d grow = (hi - lo) * kMargin + ::osg::Vec3d(kMargin, kMargin, kMargin);
    const ::osg::Vec3d size = hi - lo + grow * 2.0;
    state.applyModelViewMatrix(::osg::Matrix::scale(size) * ::osg::Matrix::translate(lo - grow) * view_);
    cube_->draw(*info_);
  }
  gl_->glEndQuery(GL_SAMPLES_PASSED);
  submitted_ = false;
  ++stats_.queries;
  stats_.query_boxes += boxes.size();
  return q;
}

void OsgBackend::check(QueryId q) const {
  if (q >= live_.size() || !live_[q])
    throw UsageError(fmt::format("OcclusionCullingGroup: query {} is not in flight", q));
}

bool OsgBackend::poll(QueryId q) {
  check(q);
  if (!submitted_) {  // the driver submits the queries issued so far to answer
    ++stats_.flushes;
    submitted_ = true;
  }
  GLuint available = GL_FALSE;
  gl_->glGetQueryObjectuiv(names_[q], GL_QUERY_RESULT_AVAILABLE, &available);
  return available == GL_TRUE;
}

bool OsgBackend::result_available(QueryId q) {
  Timed timed(stats_);
  return poll(q);
}

std::uint64_t OsgBackend::result(QueryId q) {
  Timed timed(stats_);
  GLuint64 samples = 0;
  if (poll(q)) {
    gl_->glGetQueryObjectui64v(names_[q], GL_QUERY_RESULT, &samples);
  } else {
    ++stats_.blocking_waits;
    const auto t0 = Clock::now();
    gl_->glGetQueryObjectui64v(names_[q], GL_QUERY_RESULT, &samples);
    stats_.wait_ms += std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
  }
  live_[q] = false;
  free_.push_back(q);
  return samples;
}

void OsgBackend::flush() {
  Timed timed(stats_);
  glFlush();
  ++stats_.flushes;
  submitted_ = true;
}

std::size_t OsgBackend::queries_in_flight() const noexcept {
  return std::size_t(std::count(live_.begin(), live_.end(), true));
}

void OsgBackend::delete_queries() {
  if (!names_.empty() && gl_ != nullptr) gl_->glDeleteQueries(GLsizei(names_.size()), names_.data());
  names_.clear();
  live_.clear();
  free_.clear();
}

}  // namespace osgOccull::detail
