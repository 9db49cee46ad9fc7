// occull — a Backend decorator that records what a frame drew and queried,
// for the instrument: verification, the oracle's check and the cost
// model's prediction read it; nothing else pays for it.
#pragma once

#include "occull/backend.hpp"
#include "occull/device_culling.hpp"
#include "occull/scene.hpp"

#include <cstdint>
#include <functional>
#include <span>
#include <vector>

namespace occull {

/// Forwards every call to another Backend and records, from start_frame()
/// to finish_frame(), the objects drawn and the boxes of each query.
///
/// Objects drawn: those of render(), in call order; of render_conditional(),
/// the translucent ones at once (a backend draws those in any case) and the
/// opaque ones once their query's result is known to be non-zero — when it
/// passes through result(), or at finish_frame() for a query still in
/// flight then. So put it directly over the device's backend, below a
/// StallGuard (whose stand-in answers are not the device's): the results it
/// sees are the ones conditional rendering used.
///
/// Device culling (DeviceCulling, when the wrapped backend has it) passes
/// through it too; the objects the device drew are read back at
/// finish_frame() (DeviceCulling::read_drawn, after the timed frame) and
/// recorded then.
///
/// Stats are the wrapped backend's, with the recorder's own time added to
/// backend_ms: recording is backend work, not the culler's; and with the
/// device's draws (draw_calls, objects_rendered and triangles, one draw per
/// object) and pass times (pyramid_ms, device_cull_ms) once read back.
/// Precondition: `inner` and `scene` outlive this object.
class RecordingBackend final : public Backend, private DeviceCulling {
 public:
  RecordingBackend(Backend& inner, const Scene& scene) : inner_(inner), scene_(scene) {}

  /// Forgets the previous frame's record.
  void start_frame();
  /// Ends the frame's record: each conditional draw whose query is still in
  /// flight is settled with `in_flight_result(q)`, the device's result of
  /// that query read without ending its flight (gl::Renderer::unread_result).
  void finish_frame(const std::function<std::uint64_t(QueryId)>& in_flight_result);

  /// Objects drawn in the frame (an object drawn twice appears twice).
  [[nodiscard]] std::span<const ObjectId> objects() const noexcept { return objects_; }
  /// Boxes of the frame's queries, in issue order, and how many each query had.
  [[nodiscard]] std::span<const Aabb> query_boxes() const noexcept { return boxes_; }
  [[nodiscard]] std::span<const std::uint32_t> query_sizes() const noexcept { return sizes_; }

  void render(std::span<const ObjectId> objects) override;
  QueryId issue_query(std::span<const Aabb> boxes) override;
  bool result_available(QueryId q) override { return inner_.result_available(q); }
  std::uint64_t result(QueryId q) override;
  [[nodiscard]] bool conditional_rendering() const override { return inner_.conditional_rendering(); }
  void render_conditional(std::span<const ObjectId> objects, QueryId q, ConditionalWait wait) override;
  void flush() override { inner_.flush(); }
  [[nodiscard]] BackendStats stats() const override;
  [[nodiscard]] ResultReads result_reads() const override { return inner_.result_reads(); }
  [[nodiscard]] DeviceCulling* device_culling() override {
    return inner_.device_culling() ? static_cast<DeviceCulling*>(this) : nullptr;
  }

 private:
  // DeviceCulling, forwarded to the inner backend's; the frame's phases are noted.
  [[nodiscard]] Visibility create_visibility() override { return inner_.device_culling()->create_visibility(); }
  void destroy_visibility(Visibility v) override { inner_.device_culling()->destroy_visibility(v); }
  void draw_previously_visible(Visibility v) override;
  void build_depth_pyramid() override;
  void draw_newly_visible(Visibility v, int texels) override;
  DeviceCullingTimes read_drawn(std::vector<ObjectId>& out) override { return inner_.device_culling()->read_drawn(out); }
  void read_visible(Visibility v, std::vector<ObjectId>& out) override { inner_.device_culling()->read_visible(v, out); }
  void set_visible(Visibility v, std::span<const ObjectId> visible) override {
    inner_.device_culling()->set_visible(v, visible);
  }

  // Appends the pending draws on query q to objects_ if `samples` > 0.
  void settle(QueryId q, std::uint64_t samples);

  Backend& inner_;
  const Scene& scene_;
  std::vector<ObjectId> objects_;
  std::vector<Aabb> boxes_;
  std::vector<std::uint32_t> sizes_;
  struct Pending {
    QueryId query;
    std::size_t begin, count;  // in pending_objects_
  };
  std::vector<Pending> pending_;
  std::vector<ObjectId> pending_objects_;
  double own_ms_ = 0.0;  // time spent recording, added to backend_ms
  bool device_used_ = false;  // a device-culling call this frame: its draws are read back at finish_frame
  BackendStats device_;       // the device's draws and pass times read back so far
};

}  // namespace occull
