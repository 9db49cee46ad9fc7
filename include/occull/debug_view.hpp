// occull — the debug views: what a culler did in one frame, as a picture
// (occull render --view V, occull view). The papers' figures are such
// pictures: Guthe et al. 2006's Figure 1 (NOHC: queried boxes, successful
// and wasted), Bittner et al. 2009's Figures 8.4.2 (CHC++: state-change
// batches) and 8.4.6 (multiqueries), Seletsky 2013's Figure 4.2 (grid cells
// green or red).
//
// A Picture is a description in world space — objects in flat colours,
// boxes, lines, over the frame's own image or a plain background — made
// here without any graphics API; gl::Painter draws it.
#pragma once

#include "occull/culler.hpp"
#include "occull/frame_log.hpp"
#include "occull/occlusion_buffer.hpp"
#include "occull/scene.hpp"
#include "occull/view.hpp"

#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace occull {

enum class DebugView : std::uint8_t {
  color,         ///< the frame as rendered
  queries,       ///< query boxes by outcome: occluded, visible, wasted (NOHC Figure 1)
  multiqueries,  ///< one colour per query of several boxes (CHC++ Figure 8.4.6)
  batches,       ///< draws and queries coloured by state-change batch, in order (CHC++ Figure 8.4.2)
  overview,      ///< bird's-eye view: frustum; drawn, frustum-culled, occlusion-culled, missed objects
  cells,         ///< from above: grid cells met, drawn (green) over hidden (red), and the frustum (thesis Figure 4.2); `grid` only
  tiles,         ///< from above: tile instances drawn (green) over cells found hidden (red); tiled-world cullers only
};

struct DebugViewInfo {
  DebugView view;
  std::string_view name;
  std::string_view summary;
};
/// Every view, in presentation order.
[[nodiscard]] std::span<const DebugViewInfo> debug_views();
/// The named view. Throws InputError listing the valid names.
[[nodiscard]] DebugView parse_debug_view(std::string_view name);
[[nodiscard]] std::string_view debug_view_name(DebugView view);
/// Whether `algorithm` has what `view` shows: `cells` needs `grid`, `tiles`
/// a tiled-world algorithm; the other views fit every algorithm.
[[nodiscard]] bool view_fits(DebugView view, const AlgorithmInfo& algorithm);

/// Colours of the views (linear RGB in [0, 1]); the legend of every
/// picture names the ones it uses.
namespace palette {
inline constexpr glm::vec3 occluded{0.85f, 0.15f, 0.15f};       ///< query found nothing visible: culled (red)
inline constexpr glm::vec3 visible{0.15f, 0.75f, 0.20f};        ///< query found visible, and what it covers was drawn after its answer (green)
inline constexpr glm::vec3 wasted{0.10f, 0.10f, 0.10f};         ///< query found visible, its objects drawn anyway (black, as NOHC)
inline constexpr glm::vec3 unanswered{0.60f, 0.60f, 0.60f};     ///< result not read in the frame (grey)
inline constexpr glm::vec3 drawn{0.20f, 0.70f, 0.25f};          ///< overview: drawn (green)
inline constexpr glm::vec3 frustum_culled{0.80f, 0.80f, 0.80f}; ///< overview: outside the frustum (light grey)
inline constexpr glm::vec3 occlusion_culled{0.25f, 0.40f, 0.85f};  ///< overview: in the frustum, not drawn, not visible (blue)
inline constexpr glm::vec3 missed{1.00f, 0.00f, 0.00f};         ///< overview: visible in the truth, not drawn (red)
inline constexpr glm::vec3 frustum{0.90f, 0.00f, 0.90f};        ///< overview: the frustum's edges (magenta)
inline constexpr glm::vec3 background{1.0f, 1.0f, 1.0f};        ///< overview and batches: behind everything
/// Colour k of a sequence of distinguishable colours (batches, multiqueries).
[[nodiscard]] glm::vec3 sequence(std::size_t k);
}  // namespace palette

/// What a query was worth, judged from the frame's log.
enum class QueryOutcome : std::uint8_t {
  occluded,    ///< 0 samples: what it covers was culled
  visible,     ///< samples passed, and an object it covers was drawn after its answer (or conditionally on it)
  wasted,      ///< samples passed, and every object it covers that was drawn was drawn before its answer
  unanswered,  ///< not read in this frame
};
/// One outcome per query of `log`. An object is covered by a query when the
/// centre of its box lies in one of the query's boxes (every hierarchy
/// node, tight box and cell box holds the centres of its objects).
[[nodiscard]] std::vector<QueryOutcome> classify_queries(const Scene& scene, const FrameLog& log);

/// A CPU occlusion buffer as an RGBA image of width × height pixels, top
/// row first (as PNGs are written), each texel a block of pixels (nearest
/// texel): covered texels in grey, nearer brighter (keys scaled between the
/// nearest and farthest covered texel), empty ones dark blue.
/// Preconditions: width, height >= 1.
[[nodiscard]] std::vector<std::uint8_t> occlusion_buffer_rgba(const OcclusionBuffer& buffer, int width, int height);

/// A picture in world space, drawn in this order: the background (the
/// frame's image, or `clear`), `objects` in flat colours (depth-tested),
/// then `boxes` (opaque, their front faces only, over everything before: a
/// box around the eye is not drawn) layer by layer, each layer over the
/// ones before and depth-tested within itself, then `lines` over all.
struct Picture {
  glm::mat4 view_proj{1.0f};
  ClipSpace clip;  ///< conventions of view_proj (a frame's view may be reversed-Z)
  bool frame_background = true;  ///< the frame as rendered under everything
  glm::vec3 clear = palette::background;
  struct Paint {
    ObjectId id;
    glm::vec3 color;
  };
  struct Box {
    Aabb box;
    glm::vec3 color;
    std::uint8_t layer = 0;  ///< boxes come sorted by layer
  };
  struct Line {
    glm::vec3 a, b;
    glm::vec3 color;
  };
  struct Legend {
    std::string label;
    glm::vec3 color;
    std::size_t count;
  };
  std::vector<Paint> objects;
  std::vector<Box> boxes;
  std::vector<Line> lines;
  std::vector<Legend> legend;  ///< what the colours mean, and how many of each
};

/// What a picture is made from: the frame just run.
struct DebugFrame {
  const Scene& scene;
  const View& view;          ///< the frame's view
  const FrameLog& log;       ///< its backend calls (LoggingBackend)
  std::span<const CullRegion> regions;  ///< the culler's (Culler::regions)
  std::span<const ObjectId> drawn;      ///< objects the frame drew (RecordingBackend::objects, Session::recording)
  /// Objects with a visible pixel (ground truth), sorted; the overview
  /// marks those not drawn as missed. Empty: not known.
  std::span<const ObjectId> truth;
};

/// The picture of `view` for `frame`, for an image of `aspect` = width /
/// height (the overview fits the scene to it).
[[nodiscard]] Picture make_picture(DebugView view, const DebugFrame& frame, float aspect);

}  // namespace occull
