// Internal: which objects occlude in a CPU occlusion buffer, and rasterizing
// them — shared by `soc` and the CPU first test (CpuTestBackend).
#pragma once

#include "occull/configs.hpp"
#include "occull/occlusion_buffer.hpp"
#include "occull/scene.hpp"
#include "occull/stats.hpp"

#include <optional>
#include <vector>

namespace occull::detail {

/// Occluders: opaque objects of class `always`, and of class `sometimes`
/// while the frame's budget of their triangles lasts, whose mesh has
/// vertices on the CPU (a mesh registered by MeshInfo only never occludes)
/// and that span at least `min_texels`. Their meshes are made OccluderMeshes
/// once (at construction for the objects then, later ones when first met).
class Occluders {
 public:
  Occluders(const Scene& scene, const OccluderChoice& choice);
  /// Starts a frame on `buffer` (already cleared) seen through `view`.
  void begin_frame(const View& view, const OcclusionBuffer& buffer);
  /// Rasterizes object `id` if it is an occluder; adds the time and
  /// polygons to stats.raster_ms and stats.occluder_triangles. The caller
  /// guarantees the object is drawn in this frame.
  void rasterize_if_occluder(OcclusionBuffer& buffer, ObjectId id, const View& view, FrameStats& stats);

 private:
  const OccluderMesh& occluder_of(MeshId mesh);

  const Scene& scene_;
  OccluderChoice choice_;
  std::vector<std::optional<OccluderMesh>> meshes_;  // per mesh, made when first needed
  double texel_scale_ = 1.0;
  std::uint64_t sometimes_left_ = 0;
};

}  // namespace occull::detail
