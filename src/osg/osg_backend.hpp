// occull::Backend over OpenSceneGraph's osg::State: what an
// OcclusionCullingGroup's culler draws and queries through, in OSG's draw
// traversal on the camera's graphics context.
#pragma once

#include "occull/backend.hpp"
#include "occull/osg/culling_group.hpp"

#include <osg/GLExtensions>
#include <osg/Geometry>
#include <osg/RenderInfo>
#include <osg/StateSet>

#include <span>
#include <vector>

namespace osgOccull::detail {

/// One context's backend. GL state belongs to whoever draws: every switch
/// between drawing and querying goes through osg::State::apply (never a raw
/// GL state call behind OSG's back), so OSG's view of the state stays true.
/// Only the query objects themselves are raw GL calls (through OSG's
/// GLExtensions of the context).
class OsgBackend final : public occull::Backend {
 public:
  explicit OsgBackend(unsigned context_id);
  OsgBackend(const OsgBackend&) = delete;
  OsgBackend& operator=(const OsgBackend&) = delete;

  /// Starts a frame: draws go through `info`'s state with `view` (the
  /// group's model-view matrix) on top of each instance's own transform.
  /// `instances` and `scene` must stay unchanged until end_frame().
  void begin_frame(::osg::RenderInfo& info, const ::osg::Matrix& view, std::span<const Instance> instances,
                   const occull::Scene& scene);
  /// Draws the translucent objects deferred by render(), back to front.
  void end_frame();
  /// Deletes the context's query objects (every query must have been read:
  /// Culler::release first). Precondition: the context is current.
  void delete_queries();
  /// Queries issued and not yet read.
  [[nodiscard]] std::size_t queries_in_flight() const noexcept;

  void render(std::span<const occull::ObjectId> objects) override;
  occull::QueryId issue_query(std::span<const occull::Aabb> boxes) override;
  bool result_available(occull::QueryId q) override;
  std::uint64_t result(occull::QueryId q) override;
  void flush() override;
  [[nodiscard]] occull::BackendStats stats() const override { return stats_; }

 private:
  enum class Mode { none, draw, query };
  unsigned context_id_;
  ::osg::GLExtensions* gl_ = nullptr;
  ::osg::RenderInfo* info_ = nullptr;
  ::osg::Matrix view_;
  std::span<const Instance> instances_;
  const occull::Scene* scene_ = nullptr;
  Mode mode_ = Mode::none;
  ::osg::ref_ptr<::osg::StateSet> query_state_;  // the query pass's state (see osg_backend.cpp)
  ::osg::ref_ptr<::osg::Geometry> cube_;         // the unit cube [0, 1]^3, 12 triangles
  std::vector<GLuint> names_;                    // query objects, by occull::QueryId
  std::vector<bool> live_;                       // issued and not yet read
  std::vector<occull::QueryId> free_;
  bool submitted_ = true;                        // no query issued since the last submission
  std::vector<occull::ObjectId> batch_;                  // render()'s objects, sorted by state set
  std::vector<occull::ObjectId> translucent_;            // deferred to end_frame()
  occull::BackendStats stats_;
  void enter(Mode mode);
  void draw_object(occull::ObjectId id);
  void check(occull::QueryId q) const;
  bool poll(occull::QueryId q);  // whether q's result is there, counting the submission a first poll makes
};

}  // namespace osgOccull::detail
