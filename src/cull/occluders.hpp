// Internal: which objects occlude in a CPU occlusion buffer, and rasterizing
// them — shared by `soc` and the CPU first test (CpuTestBackend).
#pragma once

#include "occull/configs.hpp"
#include "occull/occlusion_buffer.hpp"
#include "occull/scene.hpp"
#include "occull/frame_result.hpp"

#include <optional>
#include <vector>

namespace occull::detail {

/// The counters of a frame culled with a CPU occlusion buffer (`soc`, and
/// the query cullers' first test).
struct BufferCounters {
  double raster_ms = 0.0;                ///< CPU time rasterizing occluders
  double test_ms = 0.0;                  ///< CPU time testing boxes (estimated: test_box)
  std::uint64_t occluder_triangles = 0;  ///< triangles rasterized (after clipping, front faces)
  std::uint64_t boxes_tested = 0;        ///< node and object boxes tested
  std::uint64_t buffer_texels = 0;       ///< the buffer's width × height
  std::uint64_t occluders_resting = 0;   ///< occluders not rasterized for hiding nothing lately (soc's rest)

  void visit(const CounterVisitor& visit) const {
    visit("raster_ms", raster_ms);
    visit("test_ms", test_ms);
    visit("occluder_triangles", double(occluder_triangles));
    visit("boxes_tested", double(boxes_tested));
    visit("buffer_texels", double(buffer_texels));
    visit("occluders_resting", double(occluders_resting));
  }
};

/// Tests `box` against `buffer` (OcclusionBuffer::occluded, `sources` passed
/// on) and counts it in counters.boxes_tested. Only one test in kTestsPerTimedTest is timed, and its
/// time times kTestsPerTimedTest added to counters.test_ms: reading the clock
/// twice costs about as much as a quick box test (docs/performance.md, "The
/// walk's cost per box"), so test_ms is a sampled estimate.
bool test_box(OcclusionBuffer& buffer, const Aabb& box, const glm::mat4& view_proj, BufferCounters& counters,
              std::vector<std::uint32_t>* sources = nullptr);
inline constexpr std::uint64_t kTestsPerTimedTest = 8;

/// Occluders: opaque objects of class `always`, and of class `sometimes`
/// while the frame's budget of their triangles lasts, whose mesh has
/// vertices on the CPU (a mesh registered by MeshInfo only never occludes)
/// and that span at least `min_texels`. Their meshes are made OccluderMeshes
/// once (at construction for the objects then, later ones when first met).
class Occluders {
 public:
  Occluders(const Scene& scene, const OccluderChoice& choice);
  /// Whether occluders may rest (OccluderChoice::rest): rest is on and some
  /// occluder has rest_triangles or more. The buffer must then track
  /// sources (OcclusionBuffer::track_sources) before begin_frame; otherwise
  /// it need not (no cost).
  [[nodiscard]] bool learns();
  /// Starts a frame on `buffer` (already cleared) seen through `view`.
  /// Throws UsageError where learns() and the buffer does not track sources.
  void begin_frame(const View& view, const OcclusionBuffer& buffer);
  /// test_box; and where learns(), a box found hidden credits the
  /// occluders whose texels it was compared against: they hid something
  /// this frame and do not rest for `rest` frames.
  bool hidden(OcclusionBuffer& buffer, const Aabb& box, const glm::mat4& view_proj, BufferCounters& counters);
  /// Occluders resting this frame (OccluderChoice::rest), so far.
  [[nodiscard]] std::uint64_t resting() const noexcept { return resting_; }
  /// Rasterizes object `id` if it is an occluder; adds the time and
  /// polygons to counters.raster_ms and counters.occluder_triangles.
  /// Returns whether it was. The caller guarantees the object is drawn in
  /// this frame.
  bool rasterize_if_occluder(OcclusionBuffer& buffer, ObjectId id, const View& view, BufferCounters& counters) {
    return rasterize_if_occluder(buffer, id, scene_.object(id).bounds, view, counters);
  }
  /// The same, given the object's world box `bounds` (a one-object leaf's
  /// box, in cache where the object is not): the size test goes first and
  /// reads nothing else, so an object too small to occlude is passed over
  /// without reading it (a cache miss per object on the field: 14 % of
  /// soc's CPU there). Precondition: `bounds` is the object's box.
  bool rasterize_if_occluder(OcclusionBuffer& buffer, ObjectId id, const Aabb& bounds, const View& view,
                             BufferCounters& counters);
  /// Object `id`'s draw if it is an occluder (counted against the frame's
  /// budget as rasterizing it is), to rasterize in a batch.
  std::optional<OcclusionBuffer::OccluderDraw> occluder_draw(ObjectId id, const Aabb& bounds, const View& view);
  /// Rasterizes `draws` in one batch on the buffer's threads, counted as
  /// rasterize_if_occluder counts. The caller guarantees they are drawn in
  /// this frame.
  void rasterize(OcclusionBuffer& buffer, std::span<const OcclusionBuffer::OccluderDraw> draws, const View& view,
                 BufferCounters& counters);

 private:
  const OccluderMesh& occluder_of(MeshId mesh);
  /// Whether occluder `id` rests this frame (OccluderChoice::rest); its first
  /// frame as an occluder starts its `rest` frames.
  bool rests(ObjectId id);

  const Scene& scene_;
  OccluderChoice choice_;
  std::vector<std::optional<OccluderMesh>> meshes_;  // per mesh, made when first needed
  double texel_scale_ = 1.0;
  std::uint64_t sometimes_left_ = 0;
  std::uint32_t frame_ = 1;            // frames begun, plus 1, for rest (no object met in frame 1 - 1)
  std::vector<std::uint32_t> useful_;  // per object, with rest: the last frame it hid something, or came into view
  std::vector<std::uint32_t> met_;     // per object, with rest: the last frame it was met as an occluder (0: never)
  std::vector<std::uint32_t> tags_;    // a hidden box's sources (scratch)
  std::uint64_t resting_ = 0;          // this frame
  bool restable_ = false;              // learns(): some occluder of the objects checked may rest
  std::size_t restable_checked_ = 0;   // objects checked for restable_ so far
};

}  // namespace occull::detail
