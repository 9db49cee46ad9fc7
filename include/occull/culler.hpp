// occull — the culler interface and the algorithm registry.
#pragma once

#include "occull/backend.hpp"
#include "occull/bvh.hpp"
#include "occull/configs.hpp"
#include "occull/cost_model.hpp"
#include "occull/scene.hpp"
#include "occull/frame_result.hpp"
#include "occull/tiles.hpp"
#include "occull/view.hpp"

#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace occull {

class OcclusionBuffer;
namespace detail {
class DrawRecorder;
}


/// What a culler reads: the scene and its hierarchy, shared read-only by
/// every culler instance. Both must outlive the cullers made from them; the
/// owner changes the scene (set_transform, add_object,
/// remove_object) and calls Bvh::refit between frames, and the cullers
/// follow: per-object state grows with the scene, per-node state is carried
/// over when the hierarchy is rebuilt (Bvh::generation).
struct SceneIndex {
  const Scene& scene;
  const Bvh& bvh;
  /// The tiled world whose window `scene` holds, or null: the tile
  /// algorithms (tilevfc, pertile, tiles) need one; `bvh` means nothing then.
  const TiledWorld* world = nullptr;
};

/// Algorithm options as "algorithm.key" -> "value" strings, e.g.
/// "chcpp.batch" -> "50". Each algorithm reads its own keys into its typed
/// config (one table per algorithm: key, member, range, default, help);
/// make_culler() rejects unknown keys of the algorithm it makes.
class Options {
 public:
  Options() = default;
  /// Adds "algo.key=value". Throws InputError when it is not of that form.
  void set(std::string_view assignment);
  void set(std::string key, std::string value) { values_[std::move(key)] = std::move(value); }
  [[nodiscard]] bool has(const std::string& key) const { return values_.count(key) != 0; }
  [[nodiscard]] const std::map<std::string, std::string>& values() const noexcept { return values_; }

  /// Typed reads; `fallback` when absent. Throw InputError naming the key
  /// when the value does not parse or lies outside [lo, hi].
  [[nodiscard]] int get_int(const std::string& key, int fallback, int lo, int hi) const;
  [[nodiscard]] double get_double(const std::string& key, double fallback, double lo,
                                  double hi) const;
  /// Accepts on/off, true/false, yes/no, 1/0.
  [[nodiscard]] bool get_bool(const std::string& key, bool fallback) const;

 private:
  std::map<std::string, std::string> values_;
};

/// A region a culler decides visibility for as a whole (a grid cell, a
/// tile instance), as the debug views show it (occull render --view cells).
struct CullRegion {
  Aabb box;      ///< world space
  bool visible;  ///< drawn in the frame (false: found occluded)
};

/// Culls and renders one view per call, keeping that view's visibility
/// state between calls (one instance per view: split screen, shadow views).
///
/// Query ownership. A culler may keep queries in flight from one frame to
/// the next (`grid`, `perobject`, `tiles` do: their answers arrive late); it
/// keeps no Backend between calls. Whoever owns the culler hands its queries
/// back with release() before the backend, or its device, goes away, and
/// before destroying a culler that holds any (queries_held() > 0): a culler
/// destroyed holding queries cannot read them, and they stay allocated in
/// the backend. Every backend given to one culler must reach the same device
/// (a decorator over it is fine), since a query is read through the backend
/// of a later call.
class Culler {
 public:
  Culler();
  virtual ~Culler();
  Culler(const Culler&) = delete;
  Culler& operator=(const Culler&) = delete;

  /// Renders the frame's visible objects through `backend` (the algorithm's
  /// cull()) and records what it drew (drawn_objects()). The caller has
  /// started the frame (cleared the targets) and closes it afterwards.
  /// Returns what every culler has (objects drawn, queries, nodes visited,
  /// its CPU time); its algorithm's own counters: visit_counters().
  FrameResult render_frame(const View& view, Backend& backend);

  /// The objects the last render_frame() drew — handed to the backend's
  /// render() or render_conditional() — each once, ascending: the visible
  /// set for shadow passes, reflections, LOD and streaming. Every object of
  /// the frustum it does not hold was found occluded (or, for a culler that
  /// is not conservative, culled); objects_not_drawn() lists those. Valid
  /// until the next render_frame(). Empty for a culler that draws on the
  /// device (`hiz`): the device holds what it drew (DeviceCulling::read_drawn).
  [[nodiscard]] std::span<const ObjectId> drawn_objects() const;

  /// The algorithm's own counters of the last render_frame(), each by name
  /// and value: the query cullers' "query_batches" (and CHC++'s
  /// "multiqueries", "failed_multiqueries"), the CPU occlusion buffer's
  /// "raster_ms", "boxes_tested", ..., grid's "capped", "over_cap", ...,
  /// auto's "auto_choice", ... (with its candidate's), the tiled-world
  /// cullers' "tiles_rendered", .... None before the first frame; none for
  /// cullers without counters of their own (`none`, `vfc`).
  virtual void visit_counters(const CounterVisitor& visit) const { (void)visit; }
  /// The counter `name` of the last render_frame() (visit_counters), or
  /// nullopt when this culler keeps none of that name.
  [[nodiscard]] std::optional<double> counter(std::string_view name) const;

  /// Optional feedback: the owner calls it once the frame rendered by the
  /// last render_frame() is complete, with what it measured (frame_ms at
  /// least: CPU and GPU time of the whole frame, milliseconds). Adaptive
  /// cullers (`auto`) learn from it; the others ignore it. Without it `auto`
  /// falls back to its own time inside render_frame().
  virtual void frame_finished(const FrameMeasure& measured) { (void)measured; }

  /// Optional, for the debug views: the regions the last render_frame()
  /// decided on — `grid`: the occupied cells its traversal met; the
  /// tiled-world cullers: the tile instances drawn (their tile's box) and,
  /// for `tiles`, the cells whose tile query came back hidden (the box
  /// queried). Empty for cullers without such regions. Valid until the
  /// next render_frame().
  [[nodiscard]] virtual std::span<const CullRegion> regions() const { return {}; }

  /// Optional, for the debug views: the CPU occlusion buffer the last
  /// render_frame() culled with (`soc`; `chc`, `chcpp`, `nohc` with
  /// cpu_test=on), or null. Valid until the next render_frame().
  [[nodiscard]] virtual const OcclusionBuffer* occlusion_buffer() const { return nullptr; }

  /// Optional, for the reports: the candidates an adaptive culler (`auto`)
  /// chooses among, in the order its counter "auto_choice" numbers them
  /// from 1 (the spec each was made from). Empty for the other cullers.
  [[nodiscard]] virtual std::vector<std::string> choices() const { return {}; }

  /// Hands back every query the culler holds, through `backend` (which must
  /// reach the device they were issued on): the answers it can use are read
  /// and kept as its next frame would keep them, so nothing it learned is
  /// lost; afterwards queries_held() is 0. The culler stays usable: a later
  /// render_frame() goes on from there. Call it at the end of a run, before
  /// the backend goes, and before destroying the culler.
  virtual void release(Backend& backend) { (void)backend; }

  /// Queries issued by this culler and not yet read (0 for cullers that read
  /// every query within the frame that issued it).
  [[nodiscard]] virtual std::size_t queries_held() const { return 0; }

 protected:
  /// The algorithm: renders the frame's visible objects through `backend`.
  /// Returns the nodes it visited (FrameResult::nodes_visited);
  /// render_frame() fills in the rest.
  virtual FrameResult cull(const View& view, Backend& backend) = 0;

 private:
  std::unique_ptr<detail::DrawRecorder> recorder_;  // the frame's backend, keeping the ids drawn
};

/// The objects of `scene` in `view`'s frustum that are not in `drawn`
/// (ascending, as Culler::drawn_objects() gives it): what a culler found
/// occluded in that frame. Removed objects are never listed.
[[nodiscard]] std::vector<ObjectId> objects_not_drawn(const Scene& scene, const View& view,
                                                      std::span<const ObjectId> drawn);

struct OptionInfo {
  std::string key;            ///< without the algorithm prefix
  std::string default_value;
  std::string values;         ///< what it takes: "[1, 100000]", "on|off", "frustum|box"; empty: any text
  std::string help;
  /// Any value but the default may cull visible objects (a sample
  /// threshold, tiles.box=tile): is_conservative() says no for such a run.
  bool approximate_unless_default = false;
};

/// What kind of scene an algorithm runs on.
enum class SceneKind : std::uint8_t {
  bvh,    ///< one scene with its BVH (every scene but a tiled world)
  tiled,  ///< a tiled world only (SceneIndex::world)
  any,    ///< either
};

struct AlgorithmInfo {
  std::string name;
  std::string summary;
  bool conservative = true;   ///< never culls a visible object (verified by the lab)
  std::vector<OptionInfo> options;
  /// Needs each frame's ground truth, so only the lab can run it
  /// (`oracle`); make_culler() refuses it.
  bool lab_only = false;
  SceneKind scenes = SceneKind::bvh;
  /// Its cullers of the views of one frame share state (`grid`: one grid
  /// and one query cap), so make_split_screen() makes them together.
  bool shares_views = false;
  /// Culls on the device (`hiz`): its backend must offer DeviceCulling
  /// (Backend::device_culling()), and render_frame() throws UsageError on
  /// one that does not.
  bool device = false;
  /// Occludes only with the triangles of meshes whose vertices the scene
  /// holds (`soc`): on a scene of meshes registered by MeshInfo alone (an
  /// engine keeps the vertices, as OpenSceneGraph's group does) it culls by
  /// the frustum only.
  bool cpu_occluders = false;
};

/// Every algorithm make_culler() knows, in presentation order.
[[nodiscard]] std::span<const AlgorithmInfo> algorithms();
/// Whether `info` runs on a tiled world (`tiled`) or on a scene with a BVH.
[[nodiscard]] bool runs_on(const AlgorithmInfo& info, bool tiled) noexcept;
/// What `occull bench` runs when no algorithm is named: every algorithm
/// that runs on the scene's kind, in presentation order; on a tiled world
/// also `tiles:local=none` (Gomez et al. 2013's "tile query alone").
[[nodiscard]] std::vector<std::string> default_algorithms(bool tiled);
/// The frustum-culling baseline the lab's "vs vfc" ratios divide by:
/// `vfc`, or `tilevfc` on a tiled world.
[[nodiscard]] std::string_view vfc_baseline(bool tiled) noexcept;
/// Comma-separated list of algorithm names (for error messages and help).
[[nodiscard]] std::string algorithm_names();
/// The named algorithm. Throws InputError listing the valid names.
[[nodiscard]] const AlgorithmInfo& find_algorithm(std::string_view name);

/// An algorithm with its own options: "name" or "name:key=value:key=value"
/// (e.g. "chcpp:multiquery=off:batch=20"), so one run can compare variants.
struct AlgorithmSpec {
  std::string name;  ///< the algorithm
  Options options;   ///< `base` with the spec's keys (as "name.key") set over it
};
/// Parses a spec. Throws InputError for an unknown algorithm or option, or
/// an item that is not key=value.
[[nodiscard]] AlgorithmSpec parse_algorithm_spec(std::string_view spec, const Options& base = {});

/// Whether a run of `spec` must never cull a visible object: its algorithm
/// is conservative and no option makes it approximate
/// (OptionInfo::approximate_unless_default) — `threshold` > 0 culls nodes
/// with up to that many visible pixels, and `tiles.box=tile` queries a
/// tile's own box instead of the common box, so such runs may pop.
/// The lab reports misses of a conservative run as failures and those
/// of any other run as popping.
[[nodiscard]] bool is_conservative(const AlgorithmSpec& spec);

/// Checks every key of `options`: its algorithm must exist and know the
/// option. Throws InputError listing the valid algorithms or options.
void check_options(const Options& options);

/// What an algorithm may need beyond its options, from the program that
/// makes it.
///
/// nohc's calibrated hardware cost model (occull/cost_model.hpp) comes from
/// `hardware_profile`: the file its option nohc.profile names, else the
/// device's. Without one, making nohc throws InputError, and auto's default
/// candidates leave nohc out.
struct CullerContext {
  /// Where a culler that models the hardware (`nohc`) gets its profile;
  /// called only when one is made, with the file its option names
  /// (nohc.profile=FILE), or "" for the device's own profile. Returns the
  /// profile, or nullopt where there is none (no such file; no profile of
  /// the device); throws InputError for a corrupt file. The culling core
  /// reads no files: occull::lab's load_profile (occull/profile_io.hpp)
  /// reads one; Session gives its device's profile, calibrating it on first
  /// use (seconds); with_profile() a profile in memory. Unset: make_culler()
  /// throws InputError for nohc.
  std::function<std::optional<HardwareProfile>(const std::string& file)> hardware_profile;
};

/// A context whose hardware profile is `profile` (e.g. one from
/// gl::calibrate); it reads no files (a nohc.profile=FILE option makes
/// make_culler() throw InputError).
[[nodiscard]] CullerContext with_profile(HardwareProfile profile);

/// Makes a culler from an algorithm spec: a name ("chcpp") or a name with
/// options ("chcpp:batch=20:tight=off", see parse_algorithm_spec), over
/// `options` ("algo.key" -> value) as its base. Throws InputError for an
/// unknown name (listing the valid ones), an unknown / invalid option of that
/// algorithm, a scene of a kind it does not run on (AlgorithmInfo::scenes;
/// the message lists those that do), or nohc without a profile.
[[nodiscard]] std::unique_ptr<Culler> make_culler(std::string_view spec, const SceneIndex& index,
                                                  const Options& options = {}, const CullerContext& context = {});

/// Makes a culler from its typed config (occull/configs.hpp), as
/// make_culler(spec) makes one from the options of a spec:
///
///   auto culler = make_culler(ChcppConfig{.batch = 20}, {scene, bvh});
///
/// Throws InputError for a value outside its option's range (named as the
/// option: "option chcpp.batch: 0 is outside [1, 100000]"), a scene of a
/// kind the algorithm does not run on, or nohc without a profile. auto's
/// candidates are specs that carry their options (AutoConfig::candidates);
/// tiles' local CHC++ runs with its defaults.
[[nodiscard]] std::unique_ptr<Culler> make_culler(const NoneConfig& config, const SceneIndex& index,
                                                  const CullerContext& context = {});
[[nodiscard]] std::unique_ptr<Culler> make_culler(const VfcConfig& config, const SceneIndex& index,
                                                  const CullerContext& context = {});
[[nodiscard]] std::unique_ptr<Culler> make_culler(const StopWaitConfig& config, const SceneIndex& index,
                                                  const CullerContext& context = {});
[[nodiscard]] std::unique_ptr<Culler> make_culler(const ChcConfig& config, const SceneIndex& index,
                                                  const CullerContext& context = {});
[[nodiscard]] std::unique_ptr<Culler> make_culler(const ChcppConfig& config, const SceneIndex& index,
                                                  const CullerContext& context = {});
[[nodiscard]] std::unique_ptr<Culler> make_culler(const NohcConfig& config, const SceneIndex& index,
                                                  const CullerContext& context = {});
[[nodiscard]] std::unique_ptr<Culler> make_culler(const SocConfig& config, const SceneIndex& index,
                                                  const CullerContext& context = {});
[[nodiscard]] std::unique_ptr<Culler> make_culler(const HizConfig& config, const SceneIndex& index,
                                                  const CullerContext& context = {});
[[nodiscard]] std::unique_ptr<Culler> make_culler(const PerObjectConfig& config, const SceneIndex& index,
                                                  const CullerContext& context = {});
[[nodiscard]] std::unique_ptr<Culler> make_culler(const GridConfig& config, const SceneIndex& index,
                                                  const CullerContext& context = {});
[[nodiscard]] std::unique_ptr<Culler> make_culler(const AutoConfig& config, const SceneIndex& index,
                                                  const CullerContext& context = {});
[[nodiscard]] std::unique_ptr<Culler> make_culler(const TileVfcConfig& config, const SceneIndex& index,
                                                  const CullerContext& context = {});
[[nodiscard]] std::unique_ptr<Culler> make_culler(const PerTileConfig& config, const SceneIndex& index,
                                                  const CullerContext& context = {});
[[nodiscard]] std::unique_ptr<Culler> make_culler(const TilesConfig& config, const SceneIndex& index,
                                                  const CullerContext& context = {});

/// The cullers of the views of one frame (split screen), one per view.
class SplitScreen {
 public:
  virtual ~SplitScreen() = default;
  [[nodiscard]] virtual int size() const noexcept = 0;
  /// The culler of view `k` (0-based); render each view's frame with it.
  [[nodiscard]] virtual Culler& view(int k) = 0;
  /// Call once per frame before the views render (cullers that share a
  /// budget split it here).
  virtual void begin_frame() {}
};

/// The cullers of `views` views (1 to 16) of one frame, for a spec as
/// make_culler() takes it: made together where the algorithm shares state
/// between views (AlgorithmInfo::shares_views), else one make_culler() per
/// view. Throws InputError as make_culler() does, and for a view count out
/// of range.
[[nodiscard]] std::unique_ptr<SplitScreen> make_split_screen(std::string_view spec, const SceneIndex& index,
                                                             int views, const Options& options = {},
                                                             const CullerContext& context = {});

namespace detail {
/// `views` cullers of `algorithm`, one make() each, for the typed
/// make_split_screen(). Throws InputError for a view count out of range.
std::unique_ptr<SplitScreen> independent_views(std::string_view algorithm, int views,
                                               const std::function<std::unique_ptr<Culler>()>& make);
}  // namespace detail

/// The cullers of `views` views (1 to 16) of one frame from a typed config,
/// as make_culler(config) makes one: `make_split_screen(ChcppConfig{.batch =
/// 20}, {scene, bvh}, 2)`. Throws InputError as make_culler() does, and for
/// a view count out of range.
template <class Config>
  requires requires { Config::algorithm; }
[[nodiscard]] std::unique_ptr<SplitScreen> make_split_screen(const Config& config, const SceneIndex& index, int views,
                                                             const CullerContext& context = {}) {
  return detail::independent_views(Config::algorithm, views,
                                   [&] { return make_culler(config, index, context); });
}
/// `grid`'s views share one grid and one query cap (occull/grid_views.hpp).
[[nodiscard]] std::unique_ptr<SplitScreen> make_split_screen(const GridConfig& config, const SceneIndex& index,
                                                             int views, const CullerContext& context = {});

}  // namespace occull
