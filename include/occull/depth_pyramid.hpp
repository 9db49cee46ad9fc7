// occull — the depth pyramid and its conservative box test, on the CPU: the
// reference the device's shaders (gl::Renderer's DeviceCulling, `hiz`)
// implement line for line, and what the unit tests break on purpose.
//
// A box is found occluded only when every pixel it could cover already holds
// something nearer than the box's nearest point. The rules that make it so,
// each with the test in tests/depth_pyramid_test.cpp that fails without it
// (detail::PyramidRules switches each off):
//
//  1. Farthest depth per texel. Each texel of level k+1 holds the farthest
//     of the (up to) 2×2 texels of level k it covers: max of the depth, or
//     min with reversed-Z. A nearest-depth reduction would let one near
//     texel hide a gap beside it.                 (FarthestDepthPerTexel)
//  2. Sizes halve rounding up. Level k+1 is ceil(w/2) × ceil(h/2), its last
//     texel of an odd edge covering the one texel left over. Halving
//     rounding down (or starting from the previous power of two) drops that
//     texel: a gap on an odd edge disappears.     (OddEdgesKeepTheirLastTexel)
//  3. The box's screen rectangle is every pixel it touches: the box's 8
//     corners projected, the rectangle widened by 1/64 pixel for rounding
//     and sub-pixel vertex snapping, then floored to whole texels (a pixel
//     is touched when the rectangle overlaps any part of it).
//  4. The level is the coarsest one at which that rectangle, w × h texels
//     at level 0, spans at most 2×2 texels: L = ceil(log2(max(w, h))), since
//     w <= 2^L texels lie in at most two blocks of 2^L. All (up to four)
//     texels at L are read. floor(log2) instead, or one level finer
//     (a level "bias" of -1), leaves up to 3 blocks to 2 reads. A test
//     reading up to T × T texels (T = 4, 8 or 16) goes log2(T/2) levels finer,
//     where w <= (T/2)·2^L texels lie in at most T blocks, and reads them all.
//                                  (LevelIsTheCeilingOfLog2, LevelOneTooFineMissesAGap)
//  5. Depth at the box's nearest point: the nearest of its 8 corners (depth
//     is monotonic in the distance along the view axis, which is linear over
//     the box, so a corner is nearest). A box's centre depth would hide its
//     front poking through an occluder.           (DepthAtTheNearestCorner)
//  6. Boxes crossing the near plane or behind the eye are visible: a corner
//     with w <= 0 or in front of the near plane makes no meaningful screen
//     rectangle. Dropping such corners (as some peers do) keeps only the far
//     end of a box that reaches up to the eye.    (BoxesReachingTheEyeAreVisible)
//  7. Ties are visible, and a margin of depth rounding: occluded only when
//     the nearest depth is farther than the texel's by more than
//     4e-6 × |depth| + 4e-7 (interpolated fragment depth rounds by a few
//     ulps of the largest depth of its triangle).  (DepthTiesAreVisible)
//  8. Reversed-Z: "farther" is smaller depth. Comparing as if it were
//     standard depth turns every rule around.    (ReversedZComparesTheOtherWay)
//  9. Pixel centres, for a single-sampled view whose size is level 0's (the
//     caller says so: `pixel_centres`): a rasterizer makes a fragment only
//     at a pixel whose centre (x + 1/2, y + 1/2) a primitive covers, so the
//     rectangle of rule 3 is the pixels whose centre its widened rectangle
//     holds (none: hidden, nothing can be drawn). Taking centres at whole
//     coordinates shifts the rectangle half a pixel off the box.
//                  (OnlyPixelCentresInTheRectangleCount, CentresAreAtHalfPixels)
// 10. Octants: a box rules 3-9 cannot hide is cut at its centre into its 8
//     octants, each tested by rules 3-9 on its own, and is hidden when every
//     octant is (their union is the box). Each octant's rectangle is smaller
//     and its nearest depth its own, so a deep box seen at a slant (along a
//     road, up a slope) is no longer tested at its nearest depth everywhere.
//     Skipping an octant hides what shows through it alone.
//                          (OctantsHideADeepBoxAtASlant, EveryOctantIsTested)
// Outside those rules a box is visible: an empty box, or a rectangle that
// falls entirely off the image, is reported hidden only because nothing of it
// can be drawn (the frustum test in front of the pyramid normally culls it).
#pragma once

#include "occull/geometry.hpp"

#include <glm/mat4x4.hpp>

#include <span>
#include <vector>

namespace occull {

namespace detail {
/// The rules of the header, each switchable to show what breaks without it
/// (tests only; the defaults are the conservative test).
struct PyramidRules {
  bool farthest_reduction = true;  ///< rule 1; false: nearest depth per texel
  bool round_sizes_up = true;      ///< rule 2; false: sizes halve rounding down
  bool ceil_level = true;          ///< rule 4; false: floor(log2)
  int level_bias = 0;              ///< rule 4; -1: one level too fine
  bool nearest_corner = true;      ///< rule 5; false: depth at the box's centre
  bool reaching_eye_visible = true;///< rule 6; false: corners behind the eye or near plane dropped
  bool reversed_aware = true;      ///< rule 8; false: reversed-Z depth compared as standard
  bool depth_margin = true;        ///< rule 7; false: occluded when the box's depth is not nearer (ties hidden)
  bool centres_at_half = true;     ///< rule 9; false: pixel centres taken at whole coordinates
  int octants_tested = 8;          ///< rule 10; 7: the last octant skipped; 0: no octants
};
}  // namespace detail

/// The margin of rule 7: a texel of depth `far` (in the key order, see
/// DepthPyramid) hides a box only if the box's nearest key exceeds far +
/// depth_tolerance(far).
[[nodiscard]] float depth_tolerance(float far_key) noexcept;

/// A box's 8 corners projected onto a width × height image (the depth
/// pyramid's level 0, an occlusion buffer): what both box tests start from.
struct BoxFootprint {
  bool reaches_eye = false;  ///< a corner behind the eye or in front of the near plane
  int projected = 0;         ///< corners beyond the near plane, which the rest describes
  float min_x = 0, min_y = 0, max_x = 0, max_y = 0;  ///< their rectangle, in image units
  float min_depth = 0, max_depth = 0;                ///< their window depths
};
/// Projects `box` through `view_proj` with clip conventions `clip`.
[[nodiscard]] BoxFootprint project_box(const Aabb& box, const glm::mat4& view_proj, const ClipSpace& clip, int width,
                                       int height) noexcept;
/// The window depth of world point `p` (no check of w).
[[nodiscard]] float window_depth(const glm::vec3& p, const glm::mat4& view_proj, const ClipSpace& clip) noexcept;

/// The coarsest level at which a rectangle of `extent` texels at level 0
/// (the larger of its width and height, >= 1) spans at most 2×2 texels:
/// ceil(log2(extent)).
[[nodiscard]] int pyramid_level_for(int extent) noexcept;

/// A depth pyramid over a window-depth image, and the box test.
class DepthPyramid {
 public:
  /// `depth`: width*height window depths as the device stores them (with
  /// reversed-Z, larger is nearer), row-major, bottom row first (level 0).
  /// Throws UsageError unless width, height >= 1 and depth.size() ==
  /// width*height.
  DepthPyramid(std::span<const float> depth, int width, int height, bool reversed_z)
      : DepthPyramid(depth, width, height, reversed_z, detail::PyramidRules{}) {}
  /// Tests only: a pyramid with some rule of the header switched off.
  DepthPyramid(std::span<const float> depth, int width, int height, bool reversed_z,
               const detail::PyramidRules& rules);

  /// Levels, from 0 (the image) to the one of 1×1 texel.
  [[nodiscard]] int levels() const noexcept { return int(levels_.size()); }
  [[nodiscard]] int width(int level) const { return levels_.at(std::size_t(level)).width; }
  [[nodiscard]] int height(int level) const { return levels_.at(std::size_t(level)).height; }
  /// Texel (x, y) of a level, as stored (device depth).
  [[nodiscard]] float at(int level, int x, int y) const;
  /// A level's texels, row-major, bottom row first.
  [[nodiscard]] std::span<const float> level(int k) const { return levels_.at(std::size_t(k)).texels; }

  /// Whether `box` (world space) is hidden behind the depth of the image as
  /// seen through `view_proj` with clip conventions `clip` (its reversed_z
  /// must be the pyramid's). False means "may be visible". The test reads
  /// at most `texels` × `texels` texels (2, 4, 8 or 16), at the level where the
  /// box's rectangle spans that many: log2(texels / 2) levels finer than
  /// rule 4's, a tighter test for more reads. `pixel_centres`: the view is
  /// single-sampled and of level 0's size, so only pixel centres can receive
  /// fragments (rule 9); false for MSAA or another size. A box the whole-box
  /// test cannot hide is tested octant by octant (rule 10): up to 9 tests.
  [[nodiscard]] bool occluded(const Aabb& box, const glm::mat4& view_proj, const ClipSpace& clip,
                              int texels = 2, bool pixel_centres = false) const;

 private:
  struct Level {
    int width = 0, height = 0;
    std::vector<float> texels;
  };
  // Larger is farther: depth, or -depth with reversed-Z (unless broken).
  [[nodiscard]] float key(float depth) const noexcept { return reversed_ && rules_.reversed_aware ? -depth : depth; }
  // Rules 3-9 for one box (a whole box, or an octant of one).
  [[nodiscard]] bool whole_box_occluded(const Aabb& box, const glm::mat4& view_proj, const ClipSpace& clip,
                                        int texels, bool pixel_centres) const;
  std::vector<Level> levels_;
  bool reversed_ = false;
  detail::PyramidRules rules_;
};

}  // namespace occull
