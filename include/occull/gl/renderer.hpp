// occull — the OpenGL 4.5 reference renderer: occull's Backend over real
// GPU (or llvmpipe) draws and hardware occlusion queries.
#pragma once

#include "occull/backend.hpp"
#include "occull/device_culling.hpp"
#include "occull/scene.hpp"
#include "occull/view.hpp"

#include <cstdint>
#include <memory>
#include <string>
#include <vector>

namespace occull::gl {

/// Which occlusion query target the renderer uses (one pool per target).
enum class QueryMode : std::uint8_t {
  samples_passed,                   ///< GL_SAMPLES_PASSED: exact sample counts
  any_samples_passed,               ///< GL_ANY_SAMPLES_PASSED: 0 or 1
  any_samples_passed_conservative,  ///< GL_ANY_SAMPLES_PASSED_CONSERVATIVE: 0 or 1, may overestimate
};

/// How query boxes stay conservative beyond the rasteriser's sub-pixel
/// vertex snapping. A box of zero thickness (a decal, a flat panel) has
/// exactly its object's outline, and snapping can put a pixel centre inside
/// the object's triangles but outside the box's face: the query then counts
/// 0 samples for a visible object.
enum class QueryRaster : std::uint8_t {
  /// Widen each box's outline on screen by RendererOptions::query_margin_px:
  /// a band along every silhouette edge, at that edge's depth — sideways,
  /// not toward the eye, so a box lying on a surface is not lifted above it
  /// (its depth moves only by the slope term of query_margin_px). Works on
  /// every driver (the default).
  margin,
  /// GL_NV_conservative_raster or GL_INTEL_conservative_rasterization: every
  /// pixel a box face touches. Falls back to `margin` without either.
  hardware,
  /// The boxes as the rasteriser draws them: not conservative at sub-pixel
  /// precision (to measure what the margin costs).
  exact,
};

/// How render() submits its objects.
enum class DrawMode : std::uint8_t {
  single,    ///< one draw per object, its matrix and id as uniforms (as scene-graph engines do)
  multi,     ///< one glMultiDrawElementsIndirect per material run (commands written by the CPU)
  /// One glMultiDrawElementsIndirect per render() call over every material:
  /// the draw path of device culling (its program, per-object instanced
  /// attributes, one command per object), with the commands written by the
  /// CPU. `vfc --draw indirect` beside `hiz` separates the cost of
  /// submission from the cost of culling.
  indirect,
};

struct RendererOptions {
  int width = 1280;   ///< render-target size in pixels, 1..limits::viewport_side (else Renderer throws InputError)
  int height = 720;
  QueryMode query_mode = QueryMode::samples_passed;
  bool write_ids = true;       ///< also write object ids (id + 1) into the R32UI target
  /// Cull back faces of scene geometry. Query boxes are drawn with their
  /// back faces culled whatever this says (two-sided only for a query with a
  /// box around the eye, see Renderer).
  bool cull_backfaces = true;
  /// How render() submits objects (same pixels whichever).
  DrawMode draw = DrawMode::single;
  /// Device culling draws with glMultiDrawElementsIndirectCount over the
  /// commands the device compacted, where the driver has it; off: always
  /// the fallback (one command per object, glMultiDrawElementsIndirect),
  /// to measure or test it.
  bool device_draw_count = true;
  glm::vec3 background{0.62f, 0.74f, 0.86f};
  QueryRaster query_raster = QueryRaster::margin;
  /// The sub-pixel error query boxes absorb, in pixels. With `margin`, each
  /// box's outline is widened (and its silhouette edges lengthened) on screen
  /// by this much; with `margin` and `hardware`, its depth is pulled toward
  /// the eye by this many pixels' worth of its own depth slope (a polygon
  /// offset factor), so a face coplanar with its object (a decal) passes
  /// where the object does. See README, "Conservative query geometry", for
  /// the measurements behind the default.
  float query_margin_px = 0.125f;
};

/// What `requested` amounts to on the current context: `hardware` becomes
/// `margin` without a conservative-raster extension. Precondition: a
/// gl::Context is current.
[[nodiscard]] QueryRaster effective_query_raster(QueryRaster requested);
/// One line saying how query boxes are kept conservative with `options` on
/// the current context (occull info). Precondition: a gl::Context is current.
[[nodiscard]] std::string describe_query_raster(const RendererOptions& options);

/// The reference renderer. Draws a Scene into an offscreen framebuffer with
/// a colour (RGBA8), a depth (32-bit float) and an object-id (R32UI)
/// attachment. Usage per frame: begin_frame(), any Backend calls (usually a
/// Culler::render_frame), end_frame().
///
/// Rendering: one draw per object from static vertex/index buffers, object
/// transforms in a storage buffer (dynamic objects re-uploaded by
/// begin_frame), each render() call sorted by material (stable, so a
/// front-to-back order within a material survives). Translucent objects are
/// deferred to end_frame() and drawn back to front with blending, without
/// writing depth or ids: they never occlude.
///
/// Queries: one shared unit cube drawn instanced, one instance per box, with
/// colour and depth writes off, depth test LEQUAL, a constant polygon offset
/// of 2 depth units towards the eye (no slope term: it would pull edge-on
/// faces through walls), depth clamping (a box crossing the near plane is
/// not clipped away) and back faces culled — except for a query with a box
/// around the eye (grown by the near-plane radius), which is drawn two-sided
/// because the eye sees only its back faces. So a query never reports fewer
/// samples than its boxes' visible surface has.
///
/// GL state: the renderer owns no context state between frames. Every
/// begin_frame() establishes all the state its passes rely on (framebuffer,
/// viewport, storage-buffer bindings, depth/cull/blend/scissor state, ...),
/// each switch between rendering and querying sets that pass's program,
/// vertex array and masks, and result()/read_ids()/read_rgba() bind what
/// they read through. So other GL code may use the same context between
/// frames — another Renderer (NOHC's calibration makes one), or an
/// engine's own passes — and even delete its objects without effect here.
/// Between begin_frame() and end_frame() no other GL code may run in the
/// context.
///
/// Preconditions: a gl::Context is current on the calling thread for the
/// renderer's whole life; `scene` outlives the renderer and keeps its
/// meshes. Objects may move (set_transform, place_object), be
/// removed and have their ids reused; objects added past the count the scene
/// had when the renderer was made, and meshes added after it, are refused
/// (UsageError at the next frame: make a new renderer). Query calls
/// check that the query is in flight (issued by this renderer, not yet read)
/// and throw UsageError otherwise.
class Renderer final : public Backend, public DeviceCulling {
 public:
  Renderer(const Scene& scene, const RendererOptions& options);
  ~Renderer() override;
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Clears the targets, sets the camera and uploads dynamic transforms.
  void begin_frame(const View& view);
  /// Draws the deferred translucent objects, then waits for the GPU
  /// (glFinish). Returns the GPU time of the frame in milliseconds from a
  /// timer query (0 when the device has no timer).
  double end_frame();

  // Backend
  void render(std::span<const ObjectId> objects) override;
  QueryId issue_query(std::span<const Aabb> boxes) override;
  bool result_available(QueryId q) override;
  std::uint64_t result(QueryId q) override;
  void flush() override;
  [[nodiscard]] bool conditional_rendering() const override { return true; }
  void render_conditional(std::span<const ObjectId> objects, QueryId q, ConditionalWait wait) override;
  [[nodiscard]] BackendStats stats() const override { return stats_; }
  [[nodiscard]] DeviceCulling* device_culling() override { return this; }

  // DeviceCulling (occull/device_culling.hpp): compute shaders over a
  // record per object (world box, draw command, material), a depth pyramid
  // (R32F, built from the depth target by one dispatch per level, the rules
  // of occull/depth_pyramid.hpp), and glMultiDrawElementsIndirectCount over
  // commands the device compacts, where the driver has it
  // (GL_ARB_indirect_parameters or GL 4.6); otherwise
  // glMultiDrawElementsIndirect over one command per object, those not drawn
  // with no instance. Made on first use (shaders compile then). Device
  // draws count in stats() as render_flushes (one per indirect draw); the
  // objects they drew are read back by read_drawn().
  [[nodiscard]] Visibility create_visibility() override;
  void destroy_visibility(Visibility v) override;
  void draw_previously_visible(Visibility v) override;
  void build_depth_pyramid() override;
  void draw_newly_visible(Visibility v, int texels) override;
  DeviceCullingTimes read_drawn(std::vector<ObjectId>& out) override;
  void set_visible(Visibility v, std::span<const ObjectId> visible) override;
  void read_visible(Visibility v, std::vector<ObjectId>& out) override;
  /// Whether device draws are compacted (drawn with a count the device
  /// wrote) rather than one command per object. Precondition: a
  /// DeviceCulling call was made.
  [[nodiscard]] bool device_draws_compacted() const;
  /// For tests: level `level` (>= 1) of the last build_depth_pyramid(),
  /// row-major, bottom row first, as stored (device depth). Waits for the device.
  [[nodiscard]] std::vector<float> read_depth_pyramid(int level) const;
  /// The device's depth target as stored (with reversed-Z, larger is
  /// nearer), unlike read_depth(): level 0 of the pyramid.
  [[nodiscard]] std::vector<float> read_stored_depth() const;

  /// The result of query `q` without ending its flight: the culler that
  /// issued it still reads it with result(). Waits for the device if the
  /// result is not there; not counted in stats(). For an instrument after
  /// end_frame() (RecordingBackend::finish_frame: what a conditional draw
  /// drew). Precondition: `q` is in flight (UsageError otherwise).
  [[nodiscard]] std::uint64_t unread_result(QueryId q);

  /// One object's visible area in a visible_pixels() pass.
  struct ObjectPixels {
    ObjectId id;
    std::uint32_t pixels;  ///< opaque: id-buffer pixels; translucent: samples passing the depth test
    friend bool operator==(const ObjectPixels&, const ObjectPixels&) = default;
  };
  /// The images a measuring pass read back (row-major, bottom row first).
  struct PassImages {
    std::vector<std::uint32_t> ids;  ///< 0 background, else object id + 1
    std::vector<float> depth;        ///< canonical window depth in [0, 1] (read_depth()); 1 where nothing opaque was drawn
  };

  /// Untimed measuring pass (ground truth): draws `objects` for `view` into
  /// the depth and id targets and returns, sorted by id, every object with
  /// at least one visible pixel. Opaque objects count the pixels they own in
  /// the id buffer; translucent ones (which never occlude) are tested with
  /// one occlusion query over their own triangles after all opaque ones.
  /// With `images`, also hands back the id and depth images it drew.
  /// Overwrites the frame's targets; does not count in stats(). Call it
  /// outside begin_frame()/end_frame().
  [[nodiscard]] std::vector<ObjectPixels> visible_pixels(const View& view,
                                                         std::span<const ObjectId> objects,
                                                         PassImages* images = nullptr);

  /// Untimed: draws `objects` for `view` against the depth buffer as the
  /// last pass left it (e.g. visible_pixels()), writing nothing, and returns
  /// how many samples pass its depth test (GL_LESS, as the scene pass): 0
  /// when none of them would change that pass's image. Does not count in
  /// stats(). Call it outside begin_frame()/end_frame().
  [[nodiscard]] std::uint64_t samples_in_front(const View& view, std::span<const ObjectId> objects);

  /// The depth target after end_frame(): width*height window depths in
  /// [0, 1], bottom row first, canonical whatever the last pass's view's
  /// clip conventions: 0 nearest, 1 farthest and where no opaque object was
  /// drawn (with reversed-Z, where the device stores d, this returns 1 - d).
  [[nodiscard]] std::vector<float> read_depth() const;

  /// Writing object ids can be switched off (timed runs that do not verify).
  void set_write_ids(bool on);
  /// The object-id target after end_frame(): width*height values, bottom
  /// row first; 0 is background, otherwise object id + 1.
  [[nodiscard]] std::vector<std::uint32_t> read_ids() const;
  /// The colour target after end_frame(): width*height RGBA8 pixels, top row first.
  [[nodiscard]] std::vector<std::uint8_t> read_rgba() const;
  /// Queries in flight (issued and not yet read by result()).
  [[nodiscard]] std::size_t queries_in_flight() const noexcept;

  /// The GL objects the renderer holds (occull soak watches them grow).
  struct Resources {
    std::size_t queries = 0;       ///< occlusion query objects created (the pool: in use and free)
    std::size_t queries_free = 0;  ///< ... of them free for the next issue_query()
    std::size_t buffers = 0;       ///< buffer objects (device culling's and its visibilities included)
    std::int64_t buffer_bytes = 0; ///< their sizes as GL reports them (GL_BUFFER_SIZE), bytes
  };
  /// Precondition: the renderer's context is current; not between
  /// begin_frame() and end_frame() (it binds nothing, but reads GL state).
  [[nodiscard]] Resources resources() const;

  [[nodiscard]] int width() const noexcept;
  [[nodiscard]] int height() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  BackendStats stats_;
};

}  // namespace occull::gl
