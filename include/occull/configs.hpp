// occull — each algorithm's configuration as a type the compiler checks.
//
//   auto culler = occull::make_culler(occull::ChcppConfig{.batch = 20}, {scene, bvh});
//
// A member initialiser is the option's default; a misspelt member does not
// compile. The string specs of the command line and of files
// ("chcpp:batch=20", `occull algos` lists them) fill the same structs through
// one table per algorithm, which also checks each value's range:
// make_culler() throws InputError for a value outside it, naming the option
// as the spec writes it ("option chcpp.batch: 0 is outside [1, 100000]").
// Every config names its algorithm (`algorithm`), as the registry does.
#pragma once

#include "occull/backend.hpp"
#include "occull/grid.hpp"

#include <cstdint>
#include <optional>
#include <string>
#include <string_view>

namespace occull {

/// What every hierarchical query culler (stopwait, chc, chcpp, nohc) shares.
struct QueryOptions {
  /// A node is visible when more samples (pixels) than this pass; in
  /// [0, 2^24]. Above 0 the culler may cull visible objects (approximate).
  std::uint64_t threshold = 0;
  /// Subtrees with at most this many triangles count as leaves (Bittner et
  /// al. 2009's virtual leaves); in [0, 2^30], 0: off.
  std::uint32_t virtual_leaf_triangles = 0;
  /// Ask a conservative CPU occlusion buffer of the occluders drawn so far
  /// before each query, and issue it only when the buffer cannot prove the
  /// boxes hidden (occull/cpu_test_backend.hpp).
  bool cpu_test = false;
  /// The CPU test's buffer = viewport / cpu_scale on each axis; in [1, 64].
  /// 1 at a single-sampled view covers pixel centres (the buffer's rule 10):
  /// more hidden, more CPU.
  int cpu_scale = 4;
  /// Threads rasterizing the CPU test's occluders, each batch drawn shared
  /// among them; in [1, 64]. The buffer is the same whatever the threads.
  int cpu_threads = 1;
};

/// The boxes a node's query draws.
struct QueryShape {
  /// Query with the descendants' boxes (Bittner et al. 2009, "tighter
  /// bounding volumes") instead of the node's own box.
  bool tight = false;
  int d_max = 3;       ///< tight boxes: levels below the node, in [0, 16]
  float s_max = 1.4f;  ///< tight boxes: most total surface area, relative to the node's, in [1, 100]
};

/// Render every object: the reference cost of no culling.
struct NoneConfig {
  static constexpr std::string_view algorithm = "none";
};

/// Hierarchical view-frustum culling over the BVH, front to back.
struct VfcConfig {
  static constexpr std::string_view algorithm = "vfc";
};

/// Hierarchical stop-and-wait: every node in the frustum queried front to
/// back, each waited for.
struct StopWaitConfig {
  static constexpr std::string_view algorithm = "stopwait";
  QueryOptions common;
};

/// Coherent hierarchical culling (Bittner & Wimmer 2004).
struct ChcConfig {
  static constexpr std::string_view algorithm = "chc";
  QueryOptions common;
  std::uint32_t skip = 0;         ///< n_av: a visible leaf is queried every n_av + 1 frames; in [0, 1000]
  std::uint32_t flush_every = 8;  ///< queries handed to the device together; in [1, 2^20]
  /// Option reads=earlier: read every result at the start of the next frame,
  /// never in the frame that issued it, as engines on explicit APIs do with
  /// frames in flight (Backend::result_reads, after_submit): no submission
  /// or wait mid-frame, but a node that turns visible is drawn a frame late.
  /// Not conservative. reads=frame (false, the default): CHC as published.
  bool reads_earlier = false;
};

/// CHC++ (Mattausch, Bittner & Wimmer 2008): batched queues, render queue,
/// multiqueries, jittered re-queries, tight bounding volumes.
struct ChcppConfig {
  static constexpr std::string_view algorithm = "chcpp";
  std::uint32_t batch = 50;       ///< b: previously invisible nodes per query batch; in [1, 100000]
  bool v_queue = true;            ///< defer visible-leaf queries to fill idle time
  bool multiquery = true;         ///< group previously invisible nodes into multiqueries by p_keep
  bool jitter = true;             ///< randomise the first re-query of a newly visible leaf (0 < r < n_av)
  std::uint32_t n_av = 6;         ///< frames between queries of a visible leaf; in [1, 1000]
  QueryShape shape{true, 3, 1.4f};
  QueryOptions common{0, 1500};   ///< threshold 0; virtual leaves up to 1500 triangles
  std::uint32_t leaf_objects = 0; ///< ... and at most this many objects; in [0, 2^30], 0: any number
  std::uint32_t pkeep_min_samples = 20;  ///< tests at persistence i before the measured p_keep(i) is used; in [1, 2^24]
  std::uint64_t seed = 1;                ///< of the jitter; in [0, 2^30]
  bool flush_batches = true;             ///< Backend::flush() after each query batch
  /// Also hand the render queue over (and flush) once it holds this many
  /// triangles; in [0, 2^30], 0: only before query batches.
  std::uint64_t render_batch_triangles = 20000;
  /// Query nodes entering the view only in BVH regions where at least this
  /// share of them was found occluded; in [0, 1], 0: always (plain CHC++).
  double enter_p_min = 0.1;
  /// A leaf found visible k times in a row waits n_av * 2^min(k-1, backoff)
  /// frames for its next query; in [0, 10], 0: always n_av.
  std::uint32_t backoff = 2;
  int gate_depth = 5;  ///< BVH depth of the regions that learn the entering share on their own; in [0, 30]
};

/// Near-optimal hierarchical culling (Guthe et al. 2006): occlusion
/// probabilities and a calibrated hardware cost model
/// (CullerContext says where the model comes from).
struct NohcConfig {
  static constexpr std::string_view algorithm = "nohc";
  QueryOptions common;
  /// A hardware profile file (read by CullerContext::hardware_profile); empty:
  /// the context's profile.
  std::string profile;
  double fragments_per_pixel = 2.0;  ///< overdraw assumed when estimating shaded fragments; in [0, 100]
  double visible_factor = 0.5;       ///< p_occl = factor * p_cov^2 for nodes visible last frame; in [0, 1]
  double levels = 0.0;               ///< levels the benefit is spread over; in [0, 1000], 0: log2(N_h + 1)
  int max_parallel = 0;              ///< N_q: queries in flight; in [0, 100000], 0: from the profile
  bool exact_area = true;            ///< c_bb from the exact projected box area (off: the paper's approximation)
  std::uint32_t flush_every = 8;     ///< queries handed to the device together; in [1, 2^20]
  bool learn = true;                 ///< correct p_occl by the measured outcomes of its queries
};

/// Which objects a CPU occlusion buffer rasterizes.
struct OccluderChoice {
  int budget = 20000;       ///< triangles of `sometimes` occluders per frame (`always` ones always); in [0, 2^30]
  double min_texels = 2.0;  ///< occluders whose bounding sphere spans fewer texels across are left out; in [0, 1e6]
  /// Polygons whose inscribed circle is below 1/detail of their mesh's
  /// largest are left out; in [0, 1e6], 0: none.
  double detail = 8.0;
  /// Frames an occluder goes on being rasterized while hiding nothing; in
  /// [0, 1e6], 0: off (every occluder every frame). Past that it rests:
  /// rasterized one frame in `rest` (staggered by object; one in 2, 4, then
  /// 8 × `rest` as it goes on hiding nothing), back for `rest` frames
  /// whenever a box found hidden reads a texel whose key it wrote
  /// (OcclusionBuffer::track_sources), and when it comes back into view
  /// (met as an occluder this frame, not the last). Any choice of occluders is
  /// conservative: a resting one is still drawn when visible, it only hides
  /// nothing on the CPU. Only `soc` learns this (4 there: SocConfig; the
  /// query cullers' CPU test leaves it 0).
  int rest = 0;
  /// With rest: occluders of fewer triangles never rest; in [0, 2^30]. They
  /// cost little to rasterize, and one resting when it could hide something
  /// costs the draws it would have saved until its next try.
  int rest_triangles = 64;
};

/// Software occlusion culling: a strictly conservative CPU occlusion buffer,
/// occluders (meshes with CPU vertices) rasterized front to back, no queries.
struct SocConfig {
  static constexpr std::string_view algorithm = "soc";
  /// Buffer = viewport / scale on each axis; in [0, 64]. 0: about
  /// `auto_width` texels across whatever the view (scale = view width /
  /// auto_width, at least 1: 1 at 320×180, 4 at 1280×720, 6 at 1920×1080).
  int scale = 0;
  static constexpr int auto_width = 320;
  int width = 0;   ///< explicit buffer width in texels; in [0, 8192], 0: from scale
  int height = 0;  ///< explicit buffer height in texels; in [0, 8192], 0: from scale
  /// Which objects occlude; soc's own default rests occluders that hide
  /// nothing (rest = 4: field/glide's CPU 5.9 -> 3.7 ms, docs/performance.md).
  OccluderChoice occluders{.rest = 4};
  bool simd = true;  ///< vectorised inner loops (off: the scalar reference, equal bit for bit)
  bool fuse = true;  ///< fused pairs (OcclusionBuffer rule 11): polygons sharing an edge cover the seam between them
  /// Threads rasterizing the prepass and an occluder of many polygons
  /// (OcclusionBuffer::set_threads); in [0, 64]. 0: two, one on a machine
  /// of one hardware thread.
  int threads = 0;
  bool prepass = true;  ///< last frame's occluders still in the frustum rasterized first, as one batch; those then visible drawn
};

/// GPU-driven two-phase depth-pyramid culling; needs a backend with device
/// culling (Backend::device_culling()).
struct HizConfig {
  static constexpr std::string_view algorithm = "hiz";
  int texels = 8;  ///< texels per axis each pyramid test reads at most: 2, 4, 8 or 16
};

/// Per-object asynchronous queries after an occluder pre-pass (the engine notes).
struct PerObjectConfig {
  static constexpr std::string_view algorithm = "perobject";
  std::uint32_t interval = 5;  ///< frames a visible object goes untested; in [1, 1000]
  bool render_pending = true;  ///< draw an object while its query is pending
  bool prepass = true;         ///< draw occluders (class always) first and never test them
  std::uint64_t threshold = 0; ///< an object is visible when more samples pass; in [0, 2^24]; above 0 approximate
};

/// How split-screen views share the grid's query cap (grid_views.hpp).
enum class SplitPolicy : std::uint8_t {
  reveal,  ///< by demand and by how often a view's re-queries reveal hidden cells
  even,    ///< cap / views each
};

/// Uniform-grid culling with a per-frame query cap (Seletsky 2013).
struct GridConfig {
  static constexpr std::string_view algorithm = "grid";
  /// Cell edge, scene units; in [0, 1e9], 0: twice the median object size,
  /// at most 256 cells along the scene.
  float cell = 0.0f;
  GridTraversal::Mode traversal = GridTraversal::Mode::frustum;
  int cap = 4000;          ///< queries per frame; in [1, 2^24]
  int vis_duration = 20;   ///< frames a visible answer holds; in [1, 2^16]
  int vis_growth = 4;      ///< ... longer by this per consecutive frame that hit the cap; in [0, 2^16]
  int invis_duration = 1;  ///< frames an occluded answer holds; in [1, 2^16]
  int invis_growth = 1;    ///< ... longer by this per consecutive frame that hit the cap; in [0, 2^16]
  int prepass = 75;        ///< `sometimes` occluders drawn in the pre-pass per frame; in [0, 2^24]
  bool unknown_visible = true;  ///< a cell the frustum did not meet last frame is drawn while queried (else it pops)
  bool tight = true;            ///< query the box of what a cell holds, not the whole cell
  int latency = 0;  ///< 0: a hidden cell's answer is waited for in the frame; 1: used next frame (pops); in [0, 1]
  /// A queried cell's pre-pass under conditional rendering on its query
  /// (nullopt: off).
  std::optional<ConditionalWait> conditional = ConditionalWait::wait;
  std::uint64_t threshold = 0;  ///< a cell is visible when more samples pass; in [0, 2^24]; above 0 approximate
  std::uint32_t seed = 1;       ///< of the answers' extra duration when capped; in [0, 2^30]
  SplitPolicy split = SplitPolicy::reveal;  ///< split screen only
  double split_floor = 1.0;  ///< split=reveal: share of an even split each view is sure of; in [0, 1]
};

/// Adaptive: runs the cheapest of its candidates for this view, learnt from
/// the measured frame times, with hysteresis. Its candidates are specs, so
/// each may carry its options here (`.candidates = "chcpp:batch=20+vfc"`);
/// a spec of auto reaches them through the base options
/// ("auto:candidates=chcpp+vfc" with "chcpp.batch=20").
struct AutoConfig {
  static constexpr std::string_view algorithm = "auto";
  /// Candidates, joined by +, tried in this order at the start (every one a
  /// conservative culler other than auto). soc first: its first frame is a
  /// settled one, and the query cullers after it start from its visible set.
  /// hiz is left out on a backend without device culling.
  std::string candidates = "soc+chc+chcpp+hiz+vfc";
  int trial = 2;           ///< frames a try runs (its cost: their mean, spikes left out); in [1, 1000]
  int period = 40;         ///< frames before a loser's next try; doubled after each further loss, up to 16x; in [1, 1e6]
  double margin = 0.08;    ///< a challenger must be this much cheaper to take over; in [0, 0.9]
  double cut = 1.3;        ///< a try costing above this times the current's lost by far; in [1, 100]
  double skip = 1.5;       ///< vfc is not tried while estimated above this times the current's cost; in [1, 100]
  double smoothing = 0.15; ///< weight of the newest frame in the running cost of the current culler
  /// Tries after the start's round cost at most this share of the frame
  /// time over any second of frames (what their frames cost above the
  /// current culler's predicted cost of them); in [0, 1]. 0: no tries after
  /// the start's round.
  double budget = 0.02;
};

/// Tiled worlds: every tile in the frustum drawn, no queries.
struct TileVfcConfig {
  static constexpr std::string_view algorithm = "tilevfc";
  int evict = 60;  ///< frames a tile instance may go unused before it is freed; in [1, 1e6]
};

/// Tiled worlds: every tile in the frustum culled by its own CHC++ context,
/// no tile queries.
struct PerTileConfig {
  static constexpr std::string_view algorithm = "pertile";
  int evict = 60;  ///< frames a tile instance may go unused before it is freed; in [1, 1e6]
};

/// Tiled worlds: visibility propagated tile to tile by queries of the common
/// box (Gomez et al. 2013), CHC++ inside each visible tile. Made from this
/// config, the tiles' CHC++ runs with its defaults; a spec's base options
/// ("chcpp.batch=20") reach it.
struct TilesConfig {
  static constexpr std::string_view algorithm = "tiles";
  std::string local = "chcpp";  ///< culling inside a visible tile: "chcpp" or "" (draw the whole tile)
  int evict = 60;               ///< frames a tile instance may go unused before it is freed; in [1, 1e6]
  int neighbors = 8;            ///< neighbours a visible tile queries: 4 (edges) or 8 (and corners)
  std::uint32_t requery = 1;    ///< a visible tile is queried again every N frames; in [1, 1000]
  /// Tile queries draw the common box (false: the tile's own box, not
  /// conservative; Gomez et al. 2013's Figure 7).
  bool common_box = true;
};

}  // namespace occull
