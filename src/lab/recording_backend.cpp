// Recording a frame's draws and query boxes: see recording_backend.hpp.
#include "occull/recording_backend.hpp"

#include <algorithm>
#include <chrono>

namespace occull {
namespace {

using Clock = std::chrono::steady_clock;

// Adds the wall time of the enclosing scope to `sink`, milliseconds.
struct Timed {
  double& sink;
  Clock::time_point t0 = Clock::now();
  ~Timed() { sink += std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }
};

}  // namespace

void RecordingBackend::start_frame() {
  device_used_ = false;
  objects_.clear();
  boxes_.clear();
  sizes_.clear();
  pending_.clear();
  pending_objects_.clear();
}

void RecordingBackend::finish_frame(const std::function<std::uint64_t(QueryId)>& in_flight_result) {
  while (!pending_.empty()) {
    const QueryId q = pending_.front().query;
    settle(q, in_flight_result(q));
  }
  pending_objects_.clear();
  if (device_used_) {
    device_used_ = false;
    const std::size_t begin = objects_.size();
    const DeviceCullingTimes times = inner_.device_culling()->read_drawn(objects_);
    for (std::size_t k = begin; k < objects_.size(); ++k) device_.triangles += scene_.object(objects_[k]).triangles;
    device_.draw_calls += objects_.size() - begin;
    device_.objects_rendered += objects_.size() - begin;
    device_.pyramid_ms += times.pyramid_ms;
    device_.device_cull_ms += times.cull_ms;
  }
}

void RecordingBackend::draw_previously_visible(Visibility v) {
  device_used_ = true;
  inner_.device_culling()->draw_previously_visible(v);
}

void RecordingBackend::build_depth_pyramid() {
  device_used_ = true;
  inner_.device_culling()->build_depth_pyramid();
}

void RecordingBackend::draw_newly_visible(Visibility v, int texels) {
  device_used_ = true;
  inner_.device_culling()->draw_newly_visible(v, texels);
}

void RecordingBackend::render(std::span<const ObjectId> objects) {
  {
    const Timed t{own_ms_};
    objects_.insert(objects_.end(), objects.begin(), objects.end());
  }
  inner_.render(objects);
}

QueryId RecordingBackend::issue_query(std::span<const Aabb> boxes) {
  {
    const Timed t{own_ms_};
    boxes_.insert(boxes_.end(), boxes.begin(), boxes.end());
    sizes_.push_back(std::uint32_t(boxes.size()));
  }
  return inner_.issue_query(boxes);
}

std::uint64_t RecordingBackend::result(QueryId q) {
  const std::uint64_t samples = inner_.result(q);
  if (!pending_.empty()) {
    const Timed t{own_ms_};
    settle(q, samples);
  }
  return samples;
}

void RecordingBackend::render_conditional(std::span<const ObjectId> objects, QueryId q, ConditionalWait wait) {
  {
    const Timed t{own_ms_};
    const std::size_t begin = pending_objects_.size();
    for (ObjectId id : objects)
      (scene_.material(scene_.object(id).material).translucent ? objects_ : pending_objects_).push_back(id);
    if (pending_objects_.size() > begin) pending_.push_back({q, begin, pending_objects_.size() - begin});
  }
  inner_.render_conditional(objects, q, wait);
}

void RecordingBackend::settle(QueryId q, std::uint64_t samples) {
  std::erase_if(pending_, [&](const Pending& p) {
    if (p.query != q) return false;
    if (samples > 0)
      objects_.insert(objects_.end(), pending_objects_.begin() + long(p.begin),
                      pending_objects_.begin() + long(p.begin + p.count));
    return true;
  });
}

BackendStats RecordingBackend::stats() const {
  BackendStats s = inner_.stats();
  s.backend_ms += own_ms_;
  s.draw_calls += device_.draw_calls;
  s.objects_rendered += device_.objects_rendered;
  s.triangles += device_.triangles;
  s.pyramid_ms += device_.pyramid_ms;
  s.device_cull_ms += device_.device_cull_ms;
  return s;
}

}  // namespace occull
