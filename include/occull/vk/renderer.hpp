// occull — the Vulkan renderer: occull's Backend over a headless Vulkan
// device (vk::Context), drawing the same scenes and materials as the
// OpenGL reference renderer into offscreen images, with precise occlusion
// query pools and, where the device has VK_EXT_conditional_rendering,
// conditional draws.
#pragma once

#include "occull/backend.hpp"
#include "occull/scene.hpp"
#include "occull/view.hpp"
#include "occull/vk/context.hpp"

#include <cstdint>
#include <memory>
#include <vector>

namespace occull::vk {

struct RendererOptions {
  int width = 1280;   ///< image size in pixels, 1..limits::viewport_side (else Renderer throws InputError)
  int height = 720;
  bool write_ids = true;        ///< also write object ids (id + 1) into the R32_UINT image
  bool cull_backfaces = true;   ///< cull back faces of scene geometry (query boxes: see gl::Renderer)
  glm::vec3 background{0.62f, 0.74f, 0.86f};
  /// The sub-pixel error query boxes absorb, in pixels: each box's outline
  /// is widened by this much on screen and its depth pulled toward the eye
  /// by this many pixels of its own slope, as gl::QueryRaster::margin.
  float query_margin_px = 0.125f;
  /// Use VK_EXT_conditional_rendering for render_conditional() where the
  /// device has it; off (or without it), conditional draws draw everything.
  bool conditional_rendering = true;
};

/// The Vulkan renderer. The same pixels as gl::Renderer for the same
/// frames, up to the rasterisers' tie-breaking at pixel edges (the tests
/// count the difference): the same shading, the same colour (RGBA8), depth
/// (32-bit float) and object-id (R32_UINT) images, the same query boxes.
/// Images are stored bottom row first, as OpenGL's: the view's projection
/// (OpenGL clip conventions) is turned into Vulkan's by mapping depth
/// [-1, 1] to [0, 1], without flipping y, so front faces are the clockwise
/// ones in Vulkan's framebuffer coordinates.
///
/// Frames and the latency of reads. A frame is recorded into command
/// buffers and submitted at end_frame(). A query's answer exists only after
/// the commands that issued it were submitted and ran: result_available()
/// of a query not yet submitted submits the commands recorded so far (a
/// flush, counted in stats().flushes, as a GL driver flushes when polled)
/// and says whether the device is done with it; result() of one not yet
/// done submits likewise and waits (stats().blocking_waits, wait_ms). Each
/// submission ends the render pass, and the next commands begin another that
/// loads the images: in Vulkan that is the cost of reading a result in the
/// frame that issued it.
///
/// Usage per frame: begin_frame(), any Backend calls (usually a
/// Culler::render_frame), end_frame(). One thread. Preconditions: `context`
/// and `scene` outlive the renderer; objects may move (set_transform),
/// be removed and have their ids reused; objects added past the count the
/// scene had when the renderer was made, and meshes added after it, are
/// refused (UsageError at the next frame). Query calls check that the query
/// is in flight and throw UsageError otherwise.
class Renderer final : public Backend {
 public:
  Renderer(Context& context, const Scene& scene, const RendererOptions& options);
  ~Renderer() override;
  Renderer(const Renderer&) = delete;
  Renderer& operator=(const Renderer&) = delete;

  /// Starts recording a frame: clears the images, sets the camera and
  /// uploads moved objects' transforms.
  void begin_frame(const View& view);
  /// Draws the deferred translucent objects, submits the frame and waits for
  /// the device. Returns its GPU time in milliseconds from timestamps (0
  /// when the queue has none).
  double end_frame();

  // Backend
  void render(std::span<const ObjectId> objects) override;
  QueryId issue_query(std::span<const Aabb> boxes) override;
  bool result_available(QueryId q) override;
  std::uint64_t result(QueryId q) override;
  /// Submits the commands recorded so far without waiting.
  void flush() override;
  [[nodiscard]] bool conditional_rendering() const override;
  /// Through VK_EXT_conditional_rendering: the query's result is copied into
  /// a buffer the device reads (vkCmdCopyQueryPoolResults, outside the render
  /// pass: the commands so far are split there, not submitted). Vulkan has
  /// no "no wait": both ConditionalWait values draw once the result is known
  /// on the device, which orders the copy after the query.
  void render_conditional(std::span<const ObjectId> objects, QueryId q, ConditionalWait wait) override;
  [[nodiscard]] BackendStats stats() const override { return stats_; }
  /// after_submit: a mid-frame read of a query not yet submitted submits (see above).
  [[nodiscard]] ResultReads result_reads() const override { return ResultReads::after_submit; }

  /// The result of query `q` without ending its flight (an instrument after
  /// end_frame(): what a conditional draw drew). Waits; not counted.
  [[nodiscard]] std::uint64_t unread_result(QueryId q);

  /// One object's visible area in a visible_pixels() pass.
  struct ObjectPixels {
    ObjectId id;
    std::uint32_t pixels;  ///< opaque: id-image pixels; translucent: samples passing the depth test
    friend bool operator==(const ObjectPixels&, const ObjectPixels&) = default;
  };
  /// The images a measuring pass read back (bottom row first).
  struct PassImages {
    std::vector<std::uint32_t> ids;  ///< 0 background, else object id + 1
    std::vector<float> depth;        ///< canonical window depth (read_depth())
  };
  /// Untimed measuring pass (ground truth), as gl::Renderer::visible_pixels:
  /// every object of `objects` with a visible pixel for `view`, sorted by id;
  /// with `images`, also the id and depth images it drew. Overwrites the
  /// images; not counted in stats(). Outside begin/end_frame.
  [[nodiscard]] std::vector<ObjectPixels> visible_pixels(const View& view, std::span<const ObjectId> objects,
                                                         PassImages* images = nullptr);
  /// Untimed, as gl::Renderer::samples_in_front: draws `objects` against the
  /// depth image as the last pass left it, writing nothing, and returns the
  /// samples passing its depth test. Outside begin/end_frame.
  [[nodiscard]] std::uint64_t samples_in_front(const View& view, std::span<const ObjectId> objects);

  /// The object-id image after end_frame(): width*height values, bottom row
  /// first; 0 background, else object id + 1.
  [[nodiscard]] std::vector<std::uint32_t> read_ids();
  /// The depth image after end_frame(), canonical as gl::Renderer::read_depth
  /// (0 nearest, 1 farthest and nothing), bottom row first.
  [[nodiscard]] std::vector<float> read_depth();
  /// The colour image after end_frame(): RGBA8, top row first.
  [[nodiscard]] std::vector<std::uint8_t> read_rgba();

  /// What the renderer holds (occull soak watches it grow).
  struct Resources {
    std::size_t queries = 0;       ///< occlusion queries in its pools (in use and free)
    std::size_t queries_free = 0;  ///< ... of them free for the next issue_query()
    std::size_t buffers = 0;       ///< buffers it made
    std::int64_t buffer_bytes = 0; ///< their sizes, bytes
  };
  [[nodiscard]] Resources resources() const;

  void set_write_ids(bool on);
  [[nodiscard]] std::size_t queries_in_flight() const noexcept;
  [[nodiscard]] int width() const noexcept;
  [[nodiscard]] int height() const noexcept;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  BackendStats stats_;
};

}  // namespace occull::vk
