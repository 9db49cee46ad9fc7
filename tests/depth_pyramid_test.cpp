// The depth pyramid's conservative box test (occull/depth_pyramid.hpp) on
// hand-made depth images: each rule of the header, and the same case with
// the rule switched off, which must fail (hide a box that shows).
#include "occull/depth_pyramid.hpp"

#include <glm/gtc/constants.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

using namespace occull;
using occull::detail::PyramidRules;

namespace {

constexpr ClipSpace kZeroToOne{DepthRange::zero_to_one, false};
constexpr ClipSpace kReversed{DepthRange::zero_to_one, true};

// An orthographic view whose window x and y are world x and y (pixel i is
// [i, i+1)) and whose depth is -z, for a width×height image.
glm::mat4 pixel_view(int width, int height) { return glm::orthoRH_ZO(0.0f, float(width), 0.0f, float(height), 0.0f, 1.0f); }
// The same with reversed-Z: depth 1 + z (z = 0 nearest, depth 1).
glm::mat4 pixel_view_reversed(int width, int height) {
  glm::mat4 p = pixel_view(width, height);
  p[2][2] = -p[2][2];
  p[3][2] = 1.0f - p[3][2];
  return p;
}

// A box over pixels [x0, x1] × [y0, y1] (a little inside their edges), at
// depths [near, far] of pixel_view.
Aabb over_pixels(float x0, float x1, float y0, float y1, float near, float far) {
  return {{x0 + 0.2f, y0 + 0.2f, -far}, {x1 + 0.8f, y1 + 0.8f, -near}};
}

std::vector<float> wall(int width, int height, float depth) {
  return std::vector<float>(std::size_t(width) * std::size_t(height), depth);
}

// A box over a gap in a wall: visible with the rules, hidden without `broken`.
void expect_only_the_rule_sees_the_gap(const std::vector<float>& image, int width, int height, const Aabb& box,
                                       const PyramidRules& broken, const ClipSpace& clip = kZeroToOne) {
  const glm::mat4 vp = clip.reversed_z ? pixel_view_reversed(width, height) : pixel_view(width, height);
  EXPECT_FALSE(DepthPyramid(image, width, height, clip.reversed_z).occluded(box, vp, clip));
  EXPECT_TRUE(DepthPyramid(image, width, height, clip.reversed_z, broken).occluded(box, vp, clip))
      << "the broken rule should have hidden the box";
}

}  // namespace

TEST(DepthPyramid, LevelIsTheCeilingOfLog2OfTheExtent) {
  const int expected[] = {0, 0, 1, 2, 2, 3, 3, 3, 3, 4};
  for (int extent = 1; extent <= 9; ++extent) EXPECT_EQ(pyramid_level_for(extent), expected[extent]) << extent;
}

TEST(DepthPyramid, FarthestDepthPerTexel) {
  std::vector<float> image = wall(8, 8, 0.5f);
  image[5 * 8 + 5] = 1.0f;  // one texel of background behind the wall
  PyramidRules broken;
  broken.farthest_reduction = false;
  expect_only_the_rule_sees_the_gap(image, 8, 8, over_pixels(4, 5, 4, 5, 0.7f, 0.8f), broken);
}

TEST(DepthPyramid, OddEdgesKeepTheirLastTexel) {
  std::vector<float> image = wall(5, 1, 0.5f);
  image[4] = 1.0f;  // the odd edge's last texel is a gap
  PyramidRules broken;
  broken.round_sizes_up = false;
  expect_only_the_rule_sees_the_gap(image, 5, 1, over_pixels(0, 4, 0, 0, 0.7f, 0.8f), broken);
  EXPECT_EQ(DepthPyramid(image, 5, 1, false).levels(), 4);  // 5, 3, 2, 1
}

TEST(DepthPyramid, LevelIsTheCeilingOfLog2) {
  // Pixels 3..8 (6 wide): 2 texels of level 3, but 3 of level 2.
  std::vector<float> image = wall(16, 1, 0.5f);
  image[8] = 1.0f;
  PyramidRules broken;
  broken.ceil_level = false;
  expect_only_the_rule_sees_the_gap(image, 16, 1, over_pixels(3, 8, 0, 0, 0.7f, 0.8f), broken);
}

TEST(DepthPyramid, LevelOneTooFineMissesAGap) {
  std::vector<float> image = wall(16, 1, 0.5f);
  image[8] = 1.0f;
  PyramidRules broken;
  broken.level_bias = -1;
  expect_only_the_rule_sees_the_gap(image, 16, 1, over_pixels(3, 8, 0, 0, 0.7f, 0.8f), broken);
}

TEST(DepthPyramid, MoreTexelsAtAFinerLevelTestTighter) {
  // Pixels 3..8 in front of a wall that ends at pixel 12: two texels of
  // level 3 reach the gap beyond it, three of level 2 do not.
  // (Rule 10 off: its octants, narrower, would hide the box at any count.)
  std::vector<float> image = wall(16, 1, 0.5f);
  for (int x = 12; x < 16; ++x) image[std::size_t(x)] = 1.0f;
  PyramidRules whole_boxes;
  whole_boxes.octants_tested = 0;
  const DepthPyramid pyramid(image, 16, 1, false, whole_boxes);
  const Aabb box = over_pixels(3, 8, 0, 0, 0.7f, 0.8f);
  EXPECT_FALSE(pyramid.occluded(box, pixel_view(16, 1), kZeroToOne, 2));
  EXPECT_TRUE(pyramid.occluded(box, pixel_view(16, 1), kZeroToOne, 4));
  EXPECT_TRUE(pyramid.occluded(box, pixel_view(16, 1), kZeroToOne, 8));
}

TEST(DepthPyramid, DepthAtTheNearestCorner) {
  // A box from in front of the wall to behind it: its front shows.
  PyramidRules broken;
  broken.nearest_corner = false;
  expect_only_the_rule_sees_the_gap(wall(4, 4, 0.5f), 4, 4, over_pixels(1, 2, 1, 2, 0.3f, 0.9f), broken);
}

TEST(DepthPyramid, DepthTiesAreVisible) {
  const std::vector<float> image = wall(4, 4, 0.5f);
  PyramidRules broken;
  broken.depth_margin = false;
  expect_only_the_rule_sees_the_gap(image, 4, 4, over_pixels(1, 2, 1, 2, 0.5f, 0.6f), broken);
  // ... and a box just behind the wall is still hidden.
  EXPECT_TRUE(DepthPyramid(image, 4, 4, false).occluded(over_pixels(1, 2, 1, 2, 0.501f, 0.6f), pixel_view(4, 4),
                                                         kZeroToOne));
}

TEST(DepthPyramid, ReversedZComparesTheOtherWay) {
  const std::vector<float> image = wall(4, 4, 0.5f);  // reversed: the wall at z = -0.5
  PyramidRules broken;
  broken.reversed_aware = false;
  // In front of the wall: z in [-0.3, -0.2], stored depths 0.7..0.8.
  expect_only_the_rule_sees_the_gap(image, 4, 4, over_pixels(1, 2, 1, 2, 0.2f, 0.3f), broken, kReversed);
  // Behind it: hidden.
  EXPECT_TRUE(DepthPyramid(image, 4, 4, true).occluded(over_pixels(1, 2, 1, 2, 0.8f, 0.9f), pixel_view_reversed(4, 4),
                                                        kReversed));
}

TEST(DepthPyramid, BoxesReachingTheEyeAreVisible) {
  // A perspective view at a wall 2 units away filling the image; a box from
  // behind the eye to 3 units away (its middle is in front of the wall).
  const int w = 16, h = 16;
  const glm::mat4 proj = glm::perspectiveRH_ZO(1.0f, 1.0f, 0.1f, 100.0f);
  const glm::vec4 at_wall = proj * glm::vec4(0, 0, -2, 1);
  const std::vector<float> image = wall(w, h, at_wall.z / at_wall.w);
  const Aabb reaching{{-0.3f, -0.3f, -3.0f}, {0.3f, 0.3f, 1.0f}};
  const ClipSpace clip{DepthRange::zero_to_one, false};
  EXPECT_FALSE(DepthPyramid(image, w, h, false).occluded(reaching, proj, clip));
  PyramidRules broken;
  broken.reaching_eye_visible = false;
  EXPECT_TRUE(DepthPyramid(image, w, h, false, broken).occluded(reaching, proj, clip))
      << "dropping the corners behind the eye should have hidden it";
  // A box wholly behind the wall is hidden.
  EXPECT_TRUE(DepthPyramid(image, w, h, false).occluded({{-0.3f, -0.3f, -5.0f}, {0.3f, 0.3f, -3.0f}}, proj, clip));
}

TEST(DepthPyramid, OnlyPixelCentresInTheRectangleCount) {
  // A wall with a gap at pixel 5; a box reaching into pixel 5 short of its
  // centre (5.5) makes no fragment there when the view is single-sampled.
  std::vector<float> image = wall(8, 1, 0.5f);
  image[5] = 1.0f;
  const DepthPyramid pyramid(image, 8, 1, false);
  const glm::mat4 vp = pixel_view(8, 1);
  const Aabb short_of_the_centre{{2.2f, 0.2f, -0.8f}, {5.4f, 0.8f, -0.7f}};
  EXPECT_TRUE(pyramid.occluded(short_of_the_centre, vp, kZeroToOne, 16, true));
  EXPECT_FALSE(pyramid.occluded(short_of_the_centre, vp, kZeroToOne, 16, false)) << "whole pixels: pixel 5 is touched";
  const Aabb over_the_centre{{2.2f, 0.2f, -0.8f}, {5.6f, 0.8f, -0.7f}};
  EXPECT_FALSE(pyramid.occluded(over_the_centre, vp, kZeroToOne, 16, true));
  // A box between two centres can make no fragment at all.
  EXPECT_TRUE(pyramid.occluded({{5.6f, 0.2f, -0.2f}, {6.4f, 0.8f, -0.1f}}, vp, kZeroToOne, 16, true));
}

TEST(DepthPyramid, CentresAreAtHalfPixels) {
  // A box over the gap's centre only: visible, unless centres are taken at
  // whole coordinates (5 and 6 lie outside it).
  std::vector<float> image = wall(8, 1, 0.5f);
  image[5] = 1.0f;
  const Aabb over_the_gap{{5.3f, 0.2f, -0.8f}, {5.7f, 0.8f, -0.7f}};
  const glm::mat4 vp = pixel_view(8, 1);
  EXPECT_FALSE(DepthPyramid(image, 8, 1, false).occluded(over_the_gap, vp, kZeroToOne, 16, true));
  PyramidRules broken;
  broken.centres_at_half = false;
  EXPECT_TRUE(DepthPyramid(image, 8, 1, false, broken).occluded(over_the_gap, vp, kZeroToOne, 16, true))
      << "centres at whole coordinates should have hidden it";
}

TEST(DepthPyramid, OctantsHideADeepBoxAtASlant) {
  // Looking down -z (90 degrees, 64x64): a box from 2 to 10 units away, off
  // to the right, spans columns 35..56, its far half (6..10 away) columns
  // 35..40. In front of it: columns 36 and beyond at 1.9 units, column 35 at
  // 5.9 (the box's points there are 8 or more away). Every point of the box
  // is hidden, but its nearest depth (2 units) is in front of column 35's.
  const int w = 64, h = 64;
  const glm::mat4 proj = glm::perspectiveRH_ZO(glm::half_pi<float>(), 1.0f, 0.1f, 100.0f);
  const auto depth_at = [&](float distance) {
    const glm::vec4 c = proj * glm::vec4(0, 0, -distance, 1);
    return c.z / c.w;
  };
  std::vector<float> image = wall(w, h, 1.0f);
  for (int y = 0; y < h; ++y)
    for (int x = 35; x < w; ++x) image[std::size_t(y * w + x)] = depth_at(x == 35 ? 5.9f : 1.9f);
  const Aabb deep{{1.0f, -0.25f, -10.0f}, {1.5f, 0.25f, -2.0f}};
  EXPECT_TRUE(DepthPyramid(image, w, h, false).occluded(deep, proj, kZeroToOne, 16));
  PyramidRules whole_boxes;
  whole_boxes.octants_tested = 0;
  EXPECT_FALSE(DepthPyramid(image, w, h, false, whole_boxes).occluded(deep, proj, kZeroToOne, 16))
      << "the whole box's nearest depth is in front of column 35";
}

TEST(DepthPyramid, EveryOctantIsTested) {
  // A box over pixels 0..3 at depths 0.4..0.8 before a wall at 0.3, but for
  // pixel (3, 3) at 0.5: only its near upper-right octant (the last) shows.
  std::vector<float> image = wall(4, 4, 0.3f);
  image[3 * 4 + 3] = 0.5f;
  const Aabb box = over_pixels(0, 3, 0, 3, 0.4f, 0.8f);
  EXPECT_FALSE(DepthPyramid(image, 4, 4, false).occluded(box, pixel_view(4, 4), kZeroToOne, 16));
  PyramidRules broken;
  broken.octants_tested = 7;
  EXPECT_TRUE(DepthPyramid(image, 4, 4, false, broken).occluded(box, pixel_view(4, 4), kZeroToOne, 16))
      << "skipping the last octant should have hidden it";
}

// Whatever the image, box and texels read: the pyramid hides a box only if
// every pixel its rectangle touches is nearer than its nearest corner (a
// brute force over level 0); with pixel centres, every pixel whose centre
// it holds.
TEST(DepthPyramid, HidesOnlyWhatEveryTouchedPixelHides) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  int hidden = 0;
  for (int trial = 0; trial < 400; ++trial) {
    const int w = 1 + int(rng() % 37), h = 1 + int(rng() % 23);
    std::vector<float> image(std::size_t(w) * std::size_t(h));
    const float base = 0.2f + 0.5f * unit(rng);
    for (float& d : image) d = unit(rng) < 0.03f ? 1.0f : base + 0.05f * unit(rng);
    const DepthPyramid pyramid(image, w, h, false);
    const glm::mat4 vp = pixel_view(w, h);
    for (int k = 0; k < 20; ++k) {
      const float x0 = unit(rng) * float(w), y0 = unit(rng) * float(h);
      const float near = unit(rng);
      const Aabb box{{x0, y0, -(near + 0.1f)}, {x0 + unit(rng) * float(w) / 2, y0 + unit(rng) * float(h) / 2, -near}};
      const int texels = 2 << (k % 4);  // 2, 4, 8, 16
      const bool centres = trial % 2 == 1;
      if (!pyramid.occluded(box, vp, kZeroToOne, texels, centres)) continue;
      ++hidden;
      const auto first = [&](float v) { return std::max(0, int(centres ? std::ceil(v - 0.5f) : std::floor(v))); };
      const auto last = [&](float v, int size) {
        return std::min(size - 1, int(centres ? std::floor(v - 0.5f) : std::floor(v)));
      };
      for (int y = first(box.min.y); y <= last(box.max.y, h); ++y)
        for (int x = first(box.min.x); x <= last(box.max.x, w); ++x)
          ASSERT_LT(image[std::size_t(y) * std::size_t(w) + std::size_t(x)], near)
              << "trial " << trial << ": pixel " << x << "," << y << " shows the box";
    }
  }
  EXPECT_GT(hidden, 100);  // the property was exercised
}
