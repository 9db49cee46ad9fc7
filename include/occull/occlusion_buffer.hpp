// occull — a strictly conservative CPU occlusion buffer: a low-resolution
// depth buffer into which occluder triangles are rasterized and against which
// boxes are tested, on the CPU, with no GL and no round trip (the `soc`
// culler; the first test before a query of `chc`, `chcpp` and `nohc` with
// cpu_test=on, occull/cpu_test_backend.hpp).
//
// A box is found hidden only when every pixel of the viewport it could cover
// is covered by an occluder triangle that is drawn in the same frame and lies
// nearer than the box's nearest point. Well-known CPU buffers are not
// conservative (a triangle covers a buffer texel when it covers the texel's
// centre, so at a resolution below the screen's an object seen through a
// sub-texel gap is hidden); this one keeps the promise by these rules. Each
// has the test in tests/occlusion_buffer_test.cpp that fails without it
// (detail::OcclusionRules switches it off):
//
//  1. Occluders are clipped at the near plane in clip space (the GPU draws
//     nothing in front of it), and at a guard band far outside the viewport
//     so that every coordinate fits the fixed-point edge functions (rule 3);
//     clipping is done in double precision. Clipping only at a plane just in
//     front of the eye would let the part between it and the near plane,
//     which is never drawn, hide what lies behind it.
//                                        (AnOccluderInFrontOfTheNearPlaneHidesNothing)
//  2. Only front faces occlude (counter-clockwise in window coordinates, as
//     occull's meshes wind them): a renderer culling back faces does not
//     draw the others. Degenerate triangles are skipped.
//                                        (ABackFacingOccluderHidesNothing)
//  3. Coverage is inner-conservative, per convex polygon (a triangle, or a
//     quad merged from two coplanar ones: OccluderMesh). Vertices are
//     snapped to 1/256 texel and edge functions are evaluated exactly in
//     64-bit integers. A texel is covered only if the whole texel, grown by
//     1/64 texel on every side, lies strictly inside every edge (the edge
//     function at the texel's corner farthest outside each edge is > 0:
//     ties are not covered). The growth covers both rasterizers' vertex
//     snapping (ours 1/512 texel, the GPU's 1/512 pixel, a pixel being no
//     larger than a texel) and float projection; no test shows it failing
//     (the GPU's snapping is not modelled on the CPU). Covering a texel when its centre is
//     inside (the GPU's point-sampling rule, MOC's) hides objects seen
//     through gaps narrower than a texel. A texel covered by two triangles
//     together but by neither alone is not covered: occlusion lost at seams,
//     never a miss.            (AGapNarrowerThanATexelKeepsWhatIsBehindItVisible,
//                               AnOccluderCoveringHalfATexelCoversNothing)
//  4. Each covered texel takes the occluder's farthest depth over it: the
//     triangle's depth plane (window depth is affine in window coordinates)
//     at the grown texel's farthest corner, no farther than the polygon's
//     farthest vertex, plus a bias of 2^-20 of its depths for float
//     evaluation and of how far its corners lie off that plane. A texel
//     keeps the nearest of its occluders' values (every one of them bounds
//     what can be seen there). Depth at the
//     texel's centre lets a box poke through a slanted occluder.
//                                        (ASlantedOccluderHidesOnlyWhatIsBehindItsFarthestPoint)
//  5. A box is tested over every texel its screen rectangle touches: its 8
//     corners projected, the rectangle grown by 1/64 texel, floored to whole
//     texels. Texels whose centre lies in the rectangle are not enough.
//                                        (ABoxReachingIntoAnUncoveredTexelIsVisible)
//  6. A box is tested at its nearest depth: the nearest of its 8 corners.
//                                        (ADeepBoxIsTestedAtItsNearestCorner)
//  7. A box crossing the near plane or reaching behind the eye is visible.
//                                        (ABoxReachingTheEyeIsVisible)
//  8. Ties are visible, with the depth margin of the depth pyramid's rule 7
//     (depth_tolerance in occull/depth_pyramid.hpp): hidden only when the
//     box's nearest depth is farther than the texel's by more than it.
//                                        (DepthTiesAreVisible)
//  9. Reversed-Z: depths are compared as keys, larger farther (the window
//     depth, negated with reversed-Z).  (ReversedZHidesWhatIsBehindOnly)
// 10. Sample coverage, only for a view that says how it is sampled (cleared
//     with clear(view)): when the view is single-sampled (View::samples ==
//     1: a fragment is made only at a pixel's centre) and its size is the
//     buffer's times a whole k on both axes, each texel holds k × k pixel
//     centres, and no fragment can be made anywhere else. Rules 3–5 then
//     apply to the square those centres span (the texel shrunk by half a
//     pixel on every side: a point when k = 1) instead of the whole texel:
//     covered when that square, grown by 1/64 texel, lies strictly inside
//     every edge; its depth the farthest over it; a box tested over the
//     texels whose square its grown rectangle reaches. A gap between two
//     occluders that holds no pixel centre shows nothing (as on the GPU),
//     so the seams of a mesh split into small polygons no longer lose a
//     texel's width of occlusion each — they lose 1/64 px. Any other view
//     (MSAA, another size, samples == 0) keeps whole texels.
//                                        (SampleCoverageOnlyForTheViewsOwnSampleGrid,
//                                         AGapHoldingAPixelCentreKeepsWhatIsBehindItVisible,
//                                         ABoxReachingAnUncoveredPixelCentreIsVisible)
// 11. Fused pairs: rule 3 leaves the texels along an edge shared by two
//     polygons to neither (a square within the growth of the edge is
//     wholly inside neither), though the GPU draws each pixel centre there
//     with one of them: a terrain or a split wall keeps a seam of lost
//     occlusion at every edge. For each edge of a mesh shared by two
//     polygons (OccluderMesh::neighbours: matched by position, each
//     direction of the edge used once; anything else is not fused), the
//     band of squares lying wholly on neither side of it is covered where a
//     square lies, grown, strictly inside every other edge of both: on
//     either side of the edge wherever the GPU's snapping puts it, it lies
//     in one of the two. Only when both are drawn unclipped (in front of the
//     near plane, and within twice the viewport's extent, which assumes the
//     GPU's guard band reaches that far) and surely front-facing (each
//     triangle the GPU draws of them counter-clockwise however snapping
//     moves its corners by a fixed-point step; detail::surely_front_facing,
//     tested on its own: the GPU's snapping is not modelled on the CPU).
//     Its depth is the farther of the two: one polygon's bound (rule 4)
//     plus the other's bias, plus the difference of their slopes over the
//     square's reach from the edge, plus what both planes miss the shared
//     corners by, grown along the edge as far as the band reaches past
//     them; no farther than the farther polygon's farthest vertex. An
//     optimisation on top of the rules (set_fused_pairs(false) leaves it
//     out: covering less is always conservative, and each polygon alone
//     costs less).
//                                        (APixelCentreOnASharedEdgeIsCoveredByThePair,
//                                         TheBandEndsAtBothPolygonsOtherEdges,
//                                         TheBandTakesTheFartherOfBothPolygonsDepths)
// The buffer is hierarchical: each tile of 8×8 texels keeps its farthest
// key (refreshed when a test reads a tile written since), and a box whose
// nearest depth is behind a tile's farthest needs no texel of that tile
// (tested equal to the texel-only answer: TilesAnswerAsTexelsDo).
//
// What a caller must guarantee: an occluder rasterized in a frame is drawn
// in that frame, opaque, writing depth with a less(-or-equal) test, and with
// the same matrices. Objects with a box crossing the near plane are
// visible, so an occluder through the eye hides nothing behind itself that
// a GPU would show.
//
// The inner loops (each texel row's depth writes, each tile's and box row's
// farthest key) are vectorised with Highway (libhwy-dev) with run-time
// dispatch between the instruction sets the CPU has; SimdPath::scalar runs
// the plain C++ reference, equal bit for bit (SimdMatchesScalar).
#pragma once

#include "occull/geometry.hpp"
#include "occull/view.hpp"

#include <glm/mat4x4.hpp>

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

namespace occull {

namespace detail {
class WorkerPool;
/// The rules of the header, each switchable to show what breaks without it
/// (tests only; the defaults are the conservative buffer).
struct OcclusionRules {
  bool clip_near = true;            ///< rule 1; false: clipped at w = 1e-5 only
  bool front_faces_only = true;     ///< rule 2; false: back faces rasterized too
  bool inner_coverage = true;       ///< rule 3; false: a texel is covered when its centre is inside
  bool farthest_depth = true;       ///< rule 4; false: the depth at the texel's centre
  bool outer_rectangle = true;      ///< rule 5; false: only texels whose centre is in the box's rectangle
  bool nearest_corner = true;       ///< rule 6; false: the box's centre depth
  bool reaching_eye_visible = true; ///< rule 7; false: corners behind the eye or near plane dropped
  bool depth_margin = true;         ///< rule 8; false: hidden when the box's depth is not nearer (ties hidden)
  bool tiles = true;                ///< false: no tile shortcut, every texel read (the answers must not change)
  bool sample_grid = true;          ///< rule 10; false: every view taken as single-sampled at width / buffer width
  bool fusion_other_edges = true;   ///< rule 11; false: the band not bounded by either polygon's other edges
  bool fusion_depth = true;         ///< rule 11; false: the band takes A's depth bound alone
};
}  // namespace detail

/// Which code runs the inner loops.
enum class SimdPath : std::uint8_t {
  best,    ///< the widest instruction set this CPU has (Highway's run-time dispatch)
  scalar,  ///< the plain C++ reference
};

/// Name of the instruction set SimdPath::best runs on this CPU ("AVX2", "SSE4", ...).
[[nodiscard]] std::string simd_target_name();

/// An occluder mesh made ready for the buffer: its triangles, each pair that
/// shares an edge, lies in one plane and makes a convex quad merged into that
/// quad (so that the diagonal of a wall's quad is no seam of uncovered
/// texels, rule 3), largest inscribed circle first, so that a caller
/// rasterizes only the polygons that can cover a texel whole from where the
/// camera is (a polygon covering a texel holds a circle of half a texel).
/// Built once per mesh.
struct OccluderMesh {
  static constexpr std::uint32_t no_corner = 0xffffffffu;  ///< a triangle's fourth corner
  /// 4 per polygon, counter-clockwise; no_corner last for a triangle. A
  /// corner is the first of the positions with its bits (welded): polygons
  /// at one point share it even where the mesh repeats the point.
  std::vector<std::uint32_t> corners;
  std::vector<float> inradius;         ///< per polygon, an upper bound (2 area / perimeter), object units, descending
  /// Per polygon, object space: the plane (unit normal of its counter-clockwise
  /// side, and offset: n·p = offset on it) and a sphere around its corners.
  struct Bounds {
    glm::vec3 normal;
    float offset;
    glm::vec3 centre;
    float radius;
    float area;  ///< object units squared
  };
  std::vector<Bounds> bounds;
  /// 4 per polygon: the polygon across its edge from corner k to corner k + 1
  /// (mod its corners), the edge's ends matched by position, when the mesh
  /// uses that edge once in each direction (a manifold edge between two
  /// polygons wound alike); no_corner otherwise (an open border, a T-junction,
  /// an edge of three polygons, a polygon left out by `detail`), and for a
  /// triangle's fourth. Rule 11 fuses the pairs.
  std::vector<std::uint32_t> neighbours;
  /// Whether its polygons share corners (at least 2 corners a vertex, as a
  /// terrain's or a box's do, welded, not a scatter of separate triangles'): then each
  /// vertex is transformed and projected once a call, not once a corner.
  bool shared_corners = false;
  [[nodiscard]] std::size_t polygons() const noexcept { return inradius.size(); }
  /// How many leading polygons have an inradius of at least `radius`.
  [[nodiscard]] std::size_t count_at_least(float radius) const noexcept;
};
/// Builds an OccluderMesh from a triangle mesh (3 indices per triangle;
/// degenerate triangles left out). Edges are matched by vertex position, so
/// meshes that do not share vertices merge too. `detail` > 0 leaves out the
/// polygons whose inscribed circle is smaller than 1/detail of the largest
/// (a building's window sills beside its walls: they cost the rasterizer
/// and rarely cover a texel the walls do not); 0 keeps them all. Leaving a
/// polygon out hides nothing. Precondition: indices < positions.size().
[[nodiscard]] OccluderMesh make_occluder_mesh(std::span<const glm::vec3> positions,
                                              std::span<const std::uint32_t> indices, double detail = 0.0);

/// A width × height occlusion buffer over a viewport, and its box test.
/// Not thread-safe; one per culler (and per view size). It may rasterize
/// on threads of its own (set_threads).
class OcclusionBuffer {
 public:
  static constexpr int tile_size = 8;  ///< texels per tile side
  static constexpr int max_threads = 64;

  /// Throws UsageError unless 1 <= width, height <= 8192.
  OcclusionBuffer(int width, int height, SimdPath simd = SimdPath::best)
      : OcclusionBuffer(width, height, simd, detail::OcclusionRules{}) {}
  /// Tests only: a buffer with some rule of the header switched off.
  OcclusionBuffer(int width, int height, SimdPath simd, const detail::OcclusionRules& rules);
  OcclusionBuffer(OcclusionBuffer&&) noexcept;
  OcclusionBuffer& operator=(OcclusionBuffer&&) noexcept;
  ~OcclusionBuffer();

  [[nodiscard]] int width() const noexcept { return width_; }
  [[nodiscard]] int height() const noexcept { return height_; }
  [[nodiscard]] SimdPath simd() const noexcept { return simd_; }

  /// Starts a frame: every texel empty (farthest), depths compared with the
  /// conventions `clip` from now on, texels covered whole (rules 3–5: the
  /// buffer knows nothing of how the image is sampled).
  void clear(const ClipSpace& clip);
  /// Starts a frame for `view`: as clear(view.clip), and with sample
  /// coverage (rule 10) when the view is single-sampled and its size is a
  /// whole multiple of the buffer's on both axes.
  void clear(const View& view);
  /// Pixel centres per texel side sampled this frame (rule 10); 0: texels
  /// are covered whole.
  [[nodiscard]] int pixels_per_texel() const noexcept { return pixels_; }

  /// Rule 11, fused pairs, on (the default) or off: off, each polygon
  /// covers alone, which hides less and costs less (where a mesh's polygons
  /// are smaller than a texel's centres' square, pairs rarely hold one).
  void set_fused_pairs(bool on) noexcept { fused_pairs_ = on; }
  [[nodiscard]] bool fused_pairs() const noexcept { return fused_pairs_; }

  /// Rasterizes on `threads` threads: the caller's and threads - 1 that the
  /// buffer starts and owns (1, the default: the caller's alone). A mesh
  /// call with enough polygons (parallel_polygons) is shared among them in
  /// small runs, each thread rasterizing into a copy of the buffer of its
  /// own, and the copies are merged into the buffer, each texel keeping the
  /// nearest key, before the call returns. Every texel keeps the nearest of
  /// the same keys in any order: the buffer is the same bit for bit
  /// whatever the threads (ThreadsRasterizeAsOneDoes). Throws UsageError
  /// unless 1 <= threads <= max_threads.
  void set_threads(int threads);
  [[nodiscard]] int threads() const noexcept { return int(lanes_.size()); }
  /// A mesh call rasterizing fewer polygons runs on the caller's thread alone.
  static constexpr std::size_t parallel_polygons = 96;

  /// Rasterizes the triangles `indices` (3 per triangle) of `positions`,
  /// transformed by `object_to_clip` (view_proj * object transform), into
  /// the buffer. Returns the triangles rasterized (front-facing, not clipped
  /// away entirely, not degenerate). Throws UsageError for an index past
  /// positions.size().
  std::uint32_t rasterize(std::span<const glm::vec3> positions, std::span<const std::uint32_t> indices,
                          const glm::dmat4& object_to_clip);
  /// Rasterizes the first `count` polygons of `mesh` (made from `positions`).
  /// Returns the polygons rasterized. Throws UsageError for count >
  /// mesh.polygons().
  std::uint32_t rasterize(std::span<const glm::vec3> positions, const OccluderMesh& mesh, std::size_t count,
                          const glm::dmat4& object_to_clip);
  /// Rasterizes the polygons of an object's `mesh` that can cover a texel
  /// seen through `view` (its transform `object_to_world`, world box
  /// `bounds`): polygons_worth_rasterizing(), less those that face away from
  /// the eye or lie too far from it for their size (tested one by one in
  /// object space: leaving a polygon out hides nothing). Returns the
  /// polygons rasterized.
  std::uint32_t rasterize(std::span<const glm::vec3> positions, const OccluderMesh& mesh, const View& view,
                          const glm::mat4& object_to_world, const Aabb& bounds);

  /// An occluder for the batch rasterize: what the one-object rasterize takes.
  struct OccluderDraw {
    std::span<const glm::vec3> positions;
    const OccluderMesh* mesh;  ///< made from positions; not null
    glm::mat4 object_to_world;
    Aabb bounds;               ///< world space
    std::uint32_t source = 0;  ///< the tag its texels keep (track_sources), as set_source sets for a single call
  };
  /// Rasterizes each of `draws` as rasterize(positions, *mesh, view,
  /// object_to_world, bounds) does, the draws shared among the buffer's
  /// threads (set_threads): the buffer ends as after those calls one by
  /// one, bit for bit. Returns the polygons rasterized.
  std::uint32_t rasterize(std::span<const OccluderDraw> draws, const View& view);

  /// How many of `mesh`'s leading polygons can cover a texel whole on this
  /// buffer, for an object with transform `object_to_world` and world box
  /// `bounds` seen through `view`: those whose inscribed circle, magnified
  /// as much as the lens can at the box's distance, reaches half a texel.
  /// The others never cover one (rule 3): leaving them out hides nothing.
  [[nodiscard]] std::size_t polygons_worth_rasterizing(const OccluderMesh& mesh, const View& view,
                                                       const glm::mat4& object_to_world, const Aabb& bounds) const;

  /// Whether `box` (world space) is hidden behind what was rasterized, seen
  /// through `view_proj` (the same view). False means "may be visible".
  /// An empty box, or one whose rectangle lies off the buffer, is visible
  /// (the caller's frustum test decides those). Not const: refreshes the
  /// farthest key of tiles written since they were last read. With
  /// track_sources and `sources`, a box found hidden appends to `sources`
  /// the tags of the texels it was compared against, each run of equal tags
  /// once (a tag may still appear more than once; no_source left out): each
  /// of them hid part of it. Nothing is appended for a box decided without
  /// texels, or found visible.
  [[nodiscard]] bool occluded(const Aabb& box, const glm::mat4& view_proj,
                              std::vector<std::uint32_t>* sources = nullptr);

  /// The texels' keys (window depth, negated with reversed-Z; +infinity
  /// where nothing is rasterized), row-major, bottom row first.
  [[nodiscard]] std::span<const float> keys() const noexcept { return keys_; }
  /// Texel (x, y)'s key.
  [[nodiscard]] float key_at(int x, int y) const { return keys_.at(std::size_t(y) * std::size_t(width_) + std::size_t(x)); }

  /// Sources: which occluder wrote each texel's key, for a caller that
  /// learns which occluders hide anything (soc's `rest`; occluded() hands
  /// them out). Off by default
  /// (no cost); on, every texel also keeps the tag of the polygon its key
  /// came from, the smallest tag among those that wrote that same nearest
  /// key: like the keys, the same in any order and on any threads. The keys
  /// are the same bit for bit on or off. Switching it on empties the tags
  /// (no_source) until the next clear.
  void track_sources(bool on);
  [[nodiscard]] bool tracks_sources() const noexcept { return !sources_.empty(); }
  static constexpr std::uint32_t no_source = 0xffffffffu;  ///< the tag of a texel nothing was rasterized into
  /// The tag the texels written by the single-call rasterize functions keep
  /// from now on (the batch call takes each draw's OccluderDraw::source).
  void set_source(std::uint32_t tag) noexcept { source_ = tag; }
  /// Texel (x, y)'s tag (no_source without track_sources).
  [[nodiscard]] std::uint32_t source_at(int x, int y) const {
    return sources_.empty() ? no_source : sources_.at(std::size_t(y) * std::size_t(width_) + std::size_t(x));
  }
  /// Texels with something rasterized.
  [[nodiscard]] std::size_t covered_texels() const noexcept;

 private:
  /// A vertex in clip space, where it lies against the clip planes, and
  /// (where it lies inside the near plane and the guard band) its texel
  /// coordinates, depth key and snapped coordinates: what every polygon at
  /// that corner needs of it.
  struct ClipVertex {
    glm::dvec4 clip;
    glm::dvec3 window;     // texel x, y and the depth key; set when inside
    std::int64_t x, y;     // window x, y snapped to 1/256 texel; set when inside
    unsigned outside;      // bits: beyond x = w, x = -w, y = w, y = -w
    bool crossing_near;    // behind the near plane, or w <= 0
    bool inside;           // inside the near plane and the guard band
  };
  [[nodiscard]] ClipVertex classify(const glm::dvec4& clip) const;
  /// What one thread writes while rasterizing: the texels' keys and the
  /// tiles' written flags (the buffer's own for lane 0, a copy's for the
  /// others), each vertex of the mesh being rasterized transformed and
  /// projected once however many polygons share it (valid where its stamp
  /// is `stamp`), and the polygons rasterized.
  struct Lane {
    float* keys = nullptr;
    std::uint8_t* dirty = nullptr;
    std::uint32_t* sources = nullptr;     // null without track_sources
    std::uint32_t source = 0;             // the tag of what is rasterized now
    std::vector<float> own_keys;          // lanes past 0
    std::vector<std::uint8_t> own_dirty;  // lanes past 0
    std::vector<std::uint32_t> own_sources;  // lanes past 0, with track_sources
    std::vector<ClipVertex> vertices;
    std::vector<std::uint32_t> vertex_stamp;
    std::uint32_t stamp = 0;
    std::uint32_t count = 0;
    std::vector<std::uint32_t> chosen;  // a call's polygons to rasterize (scratch)
  };
  /// Fills `chosen` with the polygons of `mesh` that the view-based
  /// rasterize rasterizes, in order; returns how many.
  std::size_t choose_polygons(std::vector<std::uint32_t>& chosen, const OccluderMesh& mesh, const View& view,
                              const glm::mat4& object_to_world, const Aabb& bounds) const;
  /// Rasterizes polygons list[0, count) of `mesh` (list null: 0..count-1),
  /// on every lane when there are enough of them. Returns how many were rasterized.
  std::uint32_t raster_polygons(std::span<const glm::vec3> positions, const OccluderMesh& mesh,
                                const std::uint32_t* list, std::size_t count, const glm::dmat4& object_to_clip);
  /// Points the first `lanes` lanes at their keys (lane 0 at the buffer's), none rasterized yet.
  void start_lanes(std::size_t lanes);
  /// Merges lanes 1..lanes-1 into the buffer; returns the polygons all rasterized.
  std::uint32_t finish_lanes(std::size_t lanes);
  /// Merges lane's keys into the buffer's (the nearest kept), and empties them.
  void merge(Lane& lane);
  /// Sets v's window, x and y if not yet. Precondition: !v.crossing_near.
  [[nodiscard]] glm::dvec3 project(const glm::dvec4& clip) const;
  /// Starts a call rasterizing polygons of `vertices` positions on `lane`:
  /// no vertex transformed yet.
  static void begin_vertices(Lane& lane, std::size_t vertices);
  struct Edge;
  struct DepthPlane;
  /// Points v[0, corners) at polygon p's corners, transformed and classified
  /// (shared through the vertex cache, or in `local`).
  void mesh_corners(Lane& lane, std::span<const glm::vec3> positions, const OccluderMesh& mesh, std::size_t p,
                    const glm::dmat4& object_to_clip, ClipVertex* local, ClipVertex** v) const;
  /// Rasterizes polygon p, and the bands along its shared edges (rule 11).
  void raster_mesh_polygon(Lane& lane, std::span<const glm::vec3> positions, const OccluderMesh& mesh, std::size_t p,
                           const glm::dmat4& object_to_clip) const;
  struct TexelRect {
    int x_lo, x_hi, y_lo, y_hi;
  };
  void fuse_edge(Lane& lane, std::span<const glm::vec3> positions, const OccluderMesh& mesh, ClipVertex* const* v,
                 int n, int k, std::uint32_t q, const TexelRect& r, const Edge* band,
                 const glm::dmat4& object_to_clip) const;
  bool drawn_whole(ClipVertex* const* c, int count) const;
  static bool might_cover(const Edge* edges, int count, const TexelRect& r);
  static Edge not_wholly_inside(const Edge& e);
  bool raster_clipped(Lane& lane, ClipVertex* const* v, int n) const;
  void raster_polygon(Lane& lane, const glm::dvec3* v, int n) const;
  void raster_snapped(Lane& lane, const glm::dvec3* v, const std::int64_t* X, const std::int64_t* Y, int n) const;
  static constexpr int kMaxEdges = 9;    ///< of a region: a polygon clipped at 5 planes, or a fused pair's band (rule 11)
  static constexpr int kFewTexels = 16;  ///< a region of at most this many texels is tested texel by texel
  static constexpr int kShortSpan = 8;   ///< a row span shorter than this is filled inline, not through SIMD dispatch
  [[nodiscard]] Edge make_edge(const std::int64_t* X, const std::int64_t* Y, int i, int j) const;
  int polygon_edges(const std::int64_t* X, const std::int64_t* Y, int n, Edge* edges) const;
  bool depth_plane(const glm::dvec3* v, int n, DepthPlane& out) const;
  template <class PlaneOf>  // PlaneOf: () -> const DepthPlane* (null: no plane)
  void fill_region(Lane& lane, const Edge* edges, int edge_count, const TexelRect& r, PlaneOf&& plane_of) const;
  float tile_farthest(int tx, int ty);
  /// Half the side of what a texel must have inside a polygon to be covered
  /// (the texel, or with rule 10 its pixel centres' square), in texels.
  [[nodiscard]] double covered_half_side() const noexcept;

  int width_, height_;
  int tiles_x_, tiles_y_;
  double guard_;  // the guard band's reach in clip space, as a multiple of w (guard_band)
  SimdPath simd_;
  detail::OcclusionRules rules_;
  ClipSpace clip_;
  int pixels_ = 0;            // rule 10: pixel centres per texel side, 0: whole texels
  bool fused_pairs_ = true;   // rule 11
  std::int64_t inset_ = 0;    // rule 10: fixed-point steps from a texel's side to its centres' square
  std::vector<float> keys_;
  std::vector<std::uint32_t> sources_;  // per texel with track_sources, else empty
  std::uint32_t source_ = 0;            // set_source
  std::vector<float> tile_far_;
  std::vector<std::uint8_t> tile_dirty_;
  std::vector<Lane> lanes_;                 // one a thread; lanes_[0] the caller's
  std::unique_ptr<detail::WorkerPool> pool_;  // threads for lanes_[1...]; null with one lane
};

}  // namespace occull
