// occull — a first test on the CPU before hardware occlusion queries: a
// Backend decorator that answers a query itself when a strictly conservative
// CPU occlusion buffer (occull/occlusion_buffer.hpp) proves all its boxes
// hidden, and forwards it to the device otherwise.
//
// The buffer holds the occluders among the objects drawn so far in the
// frame (render(), not render_conditional(): the device may skip those), so
// "hidden" means what a query would find: hidden behind what is in the
// depth buffer. A query answered on the CPU costs no device work, no round
// trip and no flush; it reports 0 samples. Any query culler can run on it:
// `chc`, `chcpp` and `nohc` do with the option cpu_test=on.
#pragma once

#include "occull/backend.hpp"
#include "occull/occlusion_buffer.hpp"
#include "occull/scene.hpp"
#include "occull/frame_result.hpp"
#include "occull/view.hpp"

#include <memory>
#include <span>

namespace occull {

class CpuTestBackend final : public Backend {
 public:
  struct Options {
    int scale = 4;            ///< buffer = viewport / scale on each axis (>= 1)
    int budget = 20000;       ///< triangles of `sometimes` occluders rasterized per frame
    double min_texels = 2.0;  ///< occluders spanning fewer texels across are not rasterized
    double detail = 8.0;      ///< polygons below 1/detail of their mesh's largest inscribed circle left out (0: none)
    SimdPath simd = SimdPath::best;
    /// Threads rasterizing each batch drawn (OcclusionBuffer::set_threads), in
    /// [1, 64]; another makes begin_frame throw UsageError.
    int threads = 1;
  };

  /// Prepares the occluder meshes of `scene`'s objects. Precondition:
  /// `scene` outlives this object.
  explicit CpuTestBackend(const Scene& scene, const Options& options);
  explicit CpuTestBackend(const Scene& scene) : CpuTestBackend(scene, Options{}) {}
  ~CpuTestBackend() override;
  CpuTestBackend(const CpuTestBackend&) = delete;
  CpuTestBackend& operator=(const CpuTestBackend&) = delete;

  /// Starts a frame seen through `view`: forwards to `inner` from now on
  /// (it must outlive the frame), the buffer cleared. Queries still in
  /// flight from an earlier frame stay valid.
  void begin_frame(Backend& inner, const View& view);
  /// Ends the frame: forgets the view; the frame's counters stay readable.
  void end_frame();
  /// The buffer's counters of the current (or last) frame: "raster_ms",
  /// "test_ms" (CPU time rasterizing occluders and testing boxes, ms; the
  /// tests' time estimated from one test in 8),
  /// "occluder_triangles", "boxes_tested", "buffer_texels".
  void visit_counters(const CounterVisitor& visit) const;
  /// The buffer of the current (or last) frame; null before the first.
  [[nodiscard]] const OcclusionBuffer* buffer() const noexcept;
  /// Queries of this frame answered on the CPU.
  [[nodiscard]] std::uint64_t answered() const noexcept;

  void render(std::span<const ObjectId> objects) override;
  QueryId issue_query(std::span<const Aabb> boxes) override;
  bool result_available(QueryId q) override;
  std::uint64_t result(QueryId q) override;
  [[nodiscard]] bool conditional_rendering() const override;
  void render_conditional(std::span<const ObjectId> objects, QueryId q, ConditionalWait wait) override;
  void flush() override;
  [[nodiscard]] DeviceCulling* device_culling() override;
  [[nodiscard]] ResultReads result_reads() const override;
  [[nodiscard]] BackendStats stats() const override;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace occull
