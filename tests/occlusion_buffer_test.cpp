// The CPU occlusion buffer's rules (occull/occlusion_buffer.hpp): each test
// shows a rule keeping a visible box visible, and the same scene with that
// rule switched off (OcclusionRules) hiding it — a test that cannot fail
// proves nothing.
#include "occull/occlusion_buffer.hpp"

#include "core/fixed_point.hpp"
#include "occull/depth_pyramid.hpp"
#include "occull/error.hpp"
#include "occull/view.hpp"

#include <gtest/gtest.h>

#include <bit>
#include <cmath>
#include <map>
#include <random>
#include <set>

using namespace occull;
using occull::detail::OcclusionRules;

namespace {

// A camera at the origin looking down -Z, 60° vertical, viewport 160×90; the
// buffer is 16×9 texels, so one texel is 10×10 pixels.
constexpr int kW = 16, kH = 9;
constexpr float kTanHalf = 0.57735027f;  // tan(30°)
constexpr float kAspect = 160.0f / 90.0f;

View camera(DepthMode depth = DepthMode::standard, float near = 0.1f) {
  return make_view(CameraPose{}, Lens{60.0f, near, 100.0f, depth}, 160, 90);
}

// The world point at texel coordinates (tx, ty) of the buffer and distance d in front of the eye.
glm::vec3 at(float tx, float ty, float d) {
  const float nx = tx / float(kW) * 2.0f - 1.0f, ny = ty / float(kH) * 2.0f - 1.0f;
  return {nx * d * kTanHalf * kAspect, ny * d * kTanHalf, -d};
}

struct Polys {
  std::vector<glm::vec3> positions;
  std::vector<std::uint32_t> indices;
  // A rectangle over texels [x0, x1] × [y0, y1] at distances d0 (its left
  // edge) and d1 (its right edge), facing the eye (or away: `back`), as two triangles.
  void rect(float x0, float x1, float y0, float y1, float d0, float d1, bool back = false) {
    const auto base = std::uint32_t(positions.size());
    // One by one: GCC 12 warns (-Wstringop-overflow, falsely) at an inlined insert of a list here.
    for (const glm::vec3& p : {at(x0, y0, d0), at(x1, y0, d1), at(x1, y1, d1), at(x0, y1, d0)}) positions.push_back(p);
    if (back)
      indices.insert(indices.end(), {base, base + 2, base + 1, base, base + 3, base + 2});
    else
      indices.insert(indices.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
  }
  void rect(float x0, float x1, float y0, float y1, float d) { rect(x0, x1, y0, y1, d, d); }
};

// A thin box seen over texels [x0, x1] × [y0, y1] from distance d to d + depth.
Aabb box(float x0, float x1, float y0, float y1, float d, float depth = 0.01f) {
  Aabb b;
  for (float dist : {d, d + depth}) {
    // At the far distance the same screen rectangle is wider in the world;
    // the box is the near one's rectangle pushed back (a slab).
    b.extend(at(x0, y0, d) * (dist / d));
    b.extend(at(x1, y1, d) * (dist / d));
  }
  return b;
}

struct Fixture {
  View view;
  OcclusionBuffer buffer;
  explicit Fixture(const OcclusionRules& rules = {}, DepthMode depth = DepthMode::standard,
                   SimdPath simd = SimdPath::best)
      : view(camera(depth)), buffer(kW, kH, simd, rules) {
    buffer.clear(view.clip);
  }
  // Rasterizes the polygons as soc does: coplanar pairs merged into quads.
  std::uint32_t draw(const Polys& p) {
    const OccluderMesh mesh = make_occluder_mesh(p.positions, p.indices);
    return buffer.rasterize(p.positions, mesh, mesh.polygons(), glm::dmat4(view.view_proj));
  }
  bool hidden(const Aabb& b) { return buffer.occluded(b, view.view_proj); }
};

Polys full_screen(float d) {
  Polys p;
  p.rect(-2.0f, 18.0f, -2.0f, 11.0f, d);
  return p;
}

// A bumpy terrain of 24 × 24 vertices 5 m apart, 2 m below the eye, from 5 m
// behind it to 110 m ahead, no two triangles coplanar.
Polys bumpy_terrain(std::mt19937& rng) {
  std::uniform_real_distribution<float> bump(-1.0f, 1.0f);
  constexpr int kSide = 24;
  Polys t;
  for (int z = 0; z < kSide; ++z)
    for (int x = 0; x < kSide; ++x)
      t.positions.emplace_back(-60.0f + 5.0f * float(x), -2.0f + 0.6f * bump(rng), 5.0f - 5.0f * float(z));
  for (int z = 0; z + 1 < kSide; ++z)
    for (int x = 0; x + 1 < kSide; ++x) {
      const auto v = std::uint32_t(z * kSide + x);
      // Counter-clockwise seen from above (+y): the terrain faces the sky.
      t.indices.insert(t.indices.end(), {v, v + 1, v + kSide, v + 1, v + kSide + 1, v + kSide});
    }
  return t;
}

}  // namespace

TEST(OcclusionBuffer, ABoxBehindAFullScreenQuadIsHiddenAndOneInFrontIsNot) {
  Fixture f;
  EXPECT_EQ(f.draw(full_screen(5.0f)), 1u);
  EXPECT_EQ(f.buffer.covered_texels(), std::size_t(kW * kH));
  EXPECT_TRUE(f.hidden(box(3.2f, 4.7f, 2.2f, 3.6f, 10.0f)));
  EXPECT_FALSE(f.hidden(box(3.2f, 4.7f, 2.2f, 3.6f, 3.0f)));
}

TEST(OcclusionBuffer, NothingRasterizedHidesNothing) {
  Fixture f;
  EXPECT_FALSE(f.hidden(box(3.2f, 4.7f, 2.2f, 3.6f, 10.0f)));
}

// Rule 3: a gap of 0.3 texel beside the texel's centre, which the left quad covers.
TEST(OcclusionBuffer, AGapNarrowerThanATexelKeepsWhatIsBehindItVisible) {
  Polys p;
  p.rect(-2.0f, 5.6f, -2.0f, 11.0f, 5.0f);
  p.rect(5.9f, 18.0f, -2.0f, 11.0f, 5.0f);
  const Aabb behind_gap = box(5.65f, 5.85f, 3.2f, 3.8f, 10.0f);
  Fixture f;
  f.draw(p);
  EXPECT_FALSE(f.hidden(behind_gap));
  Fixture broken({.inner_coverage = false});
  broken.draw(p);
  EXPECT_TRUE(broken.hidden(behind_gap)) << "point-sampled coverage should hide it (the rule's reason)";
}

TEST(OcclusionBuffer, AnOccluderCoveringHalfATexelCoversNothing) {
  Fixture f;
  Polys half;
  half.rect(3.0f, 3.5f, -2.0f, 11.0f, 5.0f);
  f.draw(half);
  EXPECT_EQ(f.buffer.covered_texels(), 0u);
  Polys one_column;  // texel column 3 with room to spare
  one_column.rect(2.5f, 4.5f, -2.0f, 11.0f, 5.0f);
  f.draw(one_column);
  EXPECT_EQ(f.buffer.covered_texels(), std::size_t(kH));
  for (int y = 0; y < kH; ++y) EXPECT_NE(f.buffer.key_at(3, y), std::numeric_limits<float>::infinity());
}

// Rule 4: a wall receding to the right; a box in texel column 7, nearer
// than the wall at the column's right edge but farther than at its centre.
TEST(OcclusionBuffer, ASlantedOccluderHidesOnlyWhatIsBehindItsFarthestPoint) {
  Polys p;
  p.rect(-2.0f, 18.0f, -2.0f, 11.0f, 2.0f, 20.0f);
  // The wall's distance along the ray through texel x (y = any): the wall
  // is the segment from at(-2, ., 2) to at(18, ., 20) in x-z.
  const auto wall_distance = [](float tx) {
    const glm::vec3 a = at(-2.0f, 0.0f, 2.0f), b = at(18.0f, 0.0f, 20.0f);
    const glm::vec3 ray = at(tx, 0.0f, 1.0f);  // z = -1
    // Solve a + s (b - a) = t ray in x and z.
    const float det = (b.x - a.x) * (-ray.z) - (b.z - a.z) * (-ray.x);
    const float t = ((b.x - a.x) * (-a.z) - (b.z - a.z) * (-a.x)) / det;
    return t;  // distance along -z
  };
  const float centre = wall_distance(7.5f), edge = wall_distance(8.0f);
  ASSERT_LT(centre + 0.05f, edge);
  const Aabb between = box(7.3f, 7.7f, 3.3f, 3.7f, 0.5f * (centre + edge), 0.01f);
  Fixture f;
  f.draw(p);
  EXPECT_FALSE(f.hidden(between));
  EXPECT_TRUE(f.hidden(box(7.3f, 7.7f, 3.3f, 3.7f, edge + 0.5f)));
  Fixture broken({.farthest_depth = false});
  broken.draw(p);
  EXPECT_TRUE(broken.hidden(between)) << "the depth at the texel's centre should hide it";
}

// Rule 5: an occluder over texel columns 0..7; a box reaching 0.3 texel into column 8.
TEST(OcclusionBuffer, ABoxReachingIntoAnUncoveredTexelIsVisible) {
  Polys p;
  p.rect(-2.0f, 8.5f, -2.0f, 11.0f, 5.0f);
  const Aabb reaching = box(6.2f, 8.3f, 3.2f, 3.8f, 10.0f);
  Fixture f;
  f.draw(p);
  EXPECT_TRUE(f.hidden(box(6.2f, 7.9f, 3.2f, 3.8f, 10.0f)));
  EXPECT_FALSE(f.hidden(reaching));
  Fixture broken({.outer_rectangle = false});
  broken.draw(p);
  EXPECT_TRUE(broken.hidden(reaching)) << "texels by their centres should miss column 8";
}

// Rule 6: a box from in front of the occluder to far behind it.
TEST(OcclusionBuffer, ADeepBoxIsTestedAtItsNearestCorner) {
  const Aabb deep = box(6.0f, 7.0f, 3.0f, 4.0f, 4.0f, 16.0f);
  Fixture f;
  f.draw(full_screen(5.0f));
  EXPECT_FALSE(f.hidden(deep));
  Fixture broken({.nearest_corner = false});
  broken.draw(full_screen(5.0f));
  EXPECT_TRUE(broken.hidden(deep)) << "the centre's depth should hide it";
}

// Rule 7: a box from behind the eye to behind the occluder.
TEST(OcclusionBuffer, ABoxReachingTheEyeIsVisible) {
  Aabb around_eye;
  around_eye.extend(glm::vec3(-0.5f, -0.5f, 1.0f));
  around_eye.extend(glm::vec3(0.5f, 0.5f, -20.0f));
  Fixture f;
  f.draw(full_screen(5.0f));
  EXPECT_FALSE(f.hidden(around_eye));
  Fixture broken({.reaching_eye_visible = false});
  broken.draw(full_screen(5.0f));
  EXPECT_TRUE(broken.hidden(around_eye)) << "its far corners alone should be hidden";
}

// Rule 8: a box whose nearest key lies behind the texel's by less than the margin.
TEST(OcclusionBuffer, DepthTiesAreVisible) {
  Fixture f;
  f.draw(full_screen(5.0f));
  const float texel = f.buffer.key_at(6, 3);
  // The box's nearest key, as occluded() computes it, for a box starting at distance d.
  const auto key_of = [&](float d) {
    const glm::vec4 c = f.view.view_proj * glm::vec4(at(6.5f, 3.5f, d), 1.0f);
    return c.z / c.w * 0.5f + 0.5f;
  };
  float lo = 5.0f, hi = 5.5f;  // bisect for a key just behind the texel's, within the margin
  for (int i = 0; i < 60; ++i) {
    const float mid = 0.5f * (lo + hi);
    (key_of(mid) > texel + 0.5f * depth_tolerance(texel) ? hi : lo) = mid;
  }
  const float d = hi;
  ASSERT_GT(key_of(d), texel);
  const Aabb tie = box(6.3f, 6.7f, 3.3f, 3.7f, d, 0.5f);
  EXPECT_FALSE(f.hidden(tie));
  Fixture broken({.depth_margin = false});
  broken.draw(full_screen(5.0f));
  EXPECT_TRUE(broken.hidden(tie)) << "with no margin, a key not nearer should be hidden";
}

TEST(OcclusionBuffer, ReversedZHidesWhatIsBehindOnly) {
  Fixture f({}, DepthMode::reversed);
  f.draw(full_screen(5.0f));
  EXPECT_LT(f.buffer.key_at(4, 4), 0.0f);  // negated reversed depth
  EXPECT_TRUE(f.hidden(box(3.2f, 4.7f, 2.2f, 3.6f, 10.0f)));
  EXPECT_FALSE(f.hidden(box(3.2f, 4.7f, 2.2f, 3.6f, 3.0f)));
}

// Rule 10: with the view's own sample grid the buffer covers what holds a
// texel's pixel centres. `pixels` pixel centres per texel side (the view is
// kW × pixels by kH × pixels); `samples` as View::samples.
struct Sampled {
  View view;
  OcclusionBuffer buffer;
  explicit Sampled(int pixels, const OcclusionRules& rules = {}, int samples = 1, int extra_width = 0)
      : view(make_view(CameraPose{}, Lens{60.0f, 0.1f, 100.0f}, kW * pixels + extra_width, kH * pixels)),
        buffer(kW, kH, SimdPath::best, rules) {
    view.samples = samples;
    buffer.clear(view);
  }
  void draw(const Polys& p) {
    const OccluderMesh mesh = make_occluder_mesh(p.positions, p.indices);
    (void)buffer.rasterize(p.positions, mesh, mesh.polygons(), glm::dmat4(view.view_proj));
  }
  bool hidden(const Aabb& b) { return buffer.occluded(b, view.view_proj); }
};

// Two occluders meeting at a seam between texel 5's centre (5.5) and texel
// 6's (6.5), 0.02 texel apart: with one pixel per texel no fragment can come
// through, and a box behind texel 5 is hidden; with whole texels neither
// occluder covers texel 5 (a seam of lost occlusion, rule 3).
Polys seam() {
  Polys p;
  p.rect(-2.0f, 5.6f, -2.0f, 11.0f, 5.0f);
  p.rect(5.62f, 18.0f, -2.0f, 11.0f, 5.0f);
  return p;
}

TEST(OcclusionBufferSamples, ASeamHoldingNoPixelCentreHidesWhatIsBehindIt) {
  const Aabb behind = box(5.3f, 5.9f, 3.2f, 3.8f, 10.0f);
  Sampled sampled(1);
  ASSERT_EQ(sampled.buffer.pixels_per_texel(), 1);
  sampled.draw(seam());
  EXPECT_EQ(sampled.buffer.covered_texels(), std::size_t(kW * kH));
  EXPECT_TRUE(sampled.hidden(behind));
  Fixture whole;  // cleared with clip conventions only: whole texels
  EXPECT_EQ(whole.buffer.pixels_per_texel(), 0);
  whole.draw(seam());
  EXPECT_FALSE(whole.hidden(behind));
}

TEST(OcclusionBufferSamples, SampleCoverageOnlyForTheViewsOwnSampleGrid) {
  const Aabb behind = box(5.3f, 5.9f, 3.2f, 3.8f, 10.0f);
  // MSAA (or unknown sampling): the seam holds samples off the pixel centres.
  Sampled msaa(1, {}, 0);
  EXPECT_EQ(msaa.buffer.pixels_per_texel(), 0);
  msaa.draw(seam());
  EXPECT_FALSE(msaa.hidden(behind));
  // A view one pixel wider: its pixel centres do not fall on the texels'.
  Sampled wider(1, {}, 1, 1);
  EXPECT_EQ(wider.buffer.pixels_per_texel(), 0);
  wider.draw(seam());
  EXPECT_FALSE(wider.hidden(behind));
  Sampled broken(1, {.sample_grid = false}, 0);
  broken.draw(seam());
  EXPECT_TRUE(broken.hidden(behind)) << "taken as single-sampled, the MSAA view's seam should hide it";
}

TEST(OcclusionBufferSamples, AGapHoldingAPixelCentreKeepsWhatIsBehindItVisible) {
  Polys gap;  // texel 5's centre, 5.5, lies in the gap
  gap.rect(-2.0f, 5.45f, -2.0f, 11.0f, 5.0f);
  gap.rect(5.55f, 18.0f, -2.0f, 11.0f, 5.0f);
  Sampled f(1);
  f.draw(gap);
  EXPECT_EQ(f.buffer.covered_texels(), std::size_t((kW - 1) * kH));
  EXPECT_FALSE(f.hidden(box(5.3f, 5.7f, 3.2f, 3.8f, 10.0f)));
  EXPECT_TRUE(f.hidden(box(6.3f, 6.7f, 3.2f, 3.8f, 10.0f)));
}

// Ten pixels per texel: an occluder over texel 3's pixel centres (3.05 to
// 3.95) but not the whole texel (3.02 to 3.98) covers it; a box reaching the first pixel
// centre of texel 4 (4.05) by less than its margin of 1/64 texel is visible.
TEST(OcclusionBufferSamples, ATexelIsCoveredWhenItsPixelCentresAreAndABoxReachingAnUncoveredOneIsVisible) {
  Polys column;
  column.rect(3.02f, 3.98f, -2.0f, 11.0f, 5.0f);
  Sampled f(10);
  ASSERT_EQ(f.buffer.pixels_per_texel(), 10);
  f.draw(column);
  EXPECT_EQ(f.buffer.covered_texels(), std::size_t(kH));
  EXPECT_TRUE(f.hidden(box(3.2f, 4.02f, 3.2f, 3.8f, 10.0f)));
  const Aabb reaching = box(3.2f, 4.045f, 3.2f, 3.8f, 10.0f);
  EXPECT_FALSE(f.hidden(reaching));
  Sampled broken(10, {.outer_rectangle = false});
  broken.draw(column);
  EXPECT_TRUE(broken.hidden(reaching)) << "texels by their centres should leave texel 4 untested";
  Fixture whole;
  whole.draw(column);
  EXPECT_EQ(whole.buffer.covered_texels(), 0u);
}

// Rule 1: an occluder between the eye and the near plane (0.1) is never drawn.
TEST(OcclusionBuffer, AnOccluderInFrontOfTheNearPlaneHidesNothing) {
  const Aabb behind = box(3.2f, 4.7f, 2.2f, 3.6f, 10.0f);
  Fixture f;
  EXPECT_EQ(f.draw(full_screen(0.05f)), 0u);
  EXPECT_FALSE(f.hidden(behind));
  Fixture broken({.clip_near = false});
  broken.draw(full_screen(0.05f));
  EXPECT_TRUE(broken.hidden(behind)) << "clipped only at w = 1e-5, it should hide the box";
}

TEST(OcclusionBuffer, AnOccluderCrossingTheNearPlaneCoversOnlyWhatLiesBeyondIt) {
  // A floor from behind the eye to far ahead, below the eye: it covers the
  // lower rows (beyond the near plane) and nothing above the horizon.
  Fixture f;
  std::vector<glm::vec3> pos = {{-50, -1, 5}, {50, -1, 5}, {50, -1, -50}, {-50, -1, -50}};
  std::vector<std::uint32_t> idx = {0, 1, 2, 0, 2, 3};
  EXPECT_EQ(f.buffer.rasterize(pos, idx, glm::dmat4(f.view.view_proj)), 2u);
  EXPECT_GT(f.buffer.covered_texels(), 0u);
  for (int x = 0; x < kW; ++x) EXPECT_EQ(f.buffer.key_at(x, kH - 1), std::numeric_limits<float>::infinity());
  EXPECT_TRUE(f.hidden(Aabb{{-0.5f, -3.0f, -20.0f}, {0.5f, -2.0f, -19.0f}}));  // under the floor
}

// Rule 2: the same quad wound the other way.
TEST(OcclusionBuffer, ABackFacingOccluderHidesNothing) {
  Polys back;
  back.rect(-2.0f, 18.0f, -2.0f, 11.0f, 5.0f, 5.0f, true);
  const Aabb behind = box(3.2f, 4.7f, 2.2f, 3.6f, 10.0f);
  Fixture f;
  EXPECT_EQ(f.draw(back), 0u);
  EXPECT_FALSE(f.hidden(behind));
  Fixture broken({.front_faces_only = false});
  broken.draw(back);
  EXPECT_TRUE(broken.hidden(behind));
}

TEST(OcclusionBuffer, AQuadAsTwoTrianglesLeavesItsDiagonalUncoveredButMergedCoversIt) {
  Polys p;
  p.rect(2.5f, 12.5f, 1.5f, 7.5f, 5.0f);  // texels 3..11 × 2..6 whole
  Fixture triangles;
  triangles.buffer.rasterize(p.positions, p.indices, glm::dmat4(triangles.view.view_proj));
  const OccluderMesh mesh = make_occluder_mesh(p.positions, p.indices);
  ASSERT_EQ(mesh.polygons(), 1u);
  EXPECT_NE(mesh.corners[3], OccluderMesh::no_corner);
  Fixture merged;
  EXPECT_EQ(merged.buffer.rasterize(p.positions, mesh, 1, glm::dmat4(merged.view.view_proj)), 1u);
  EXPECT_EQ(merged.buffer.covered_texels(), std::size_t(9 * 5));
  EXPECT_LT(triangles.buffer.covered_texels(), merged.buffer.covered_texels());
}

TEST(OcclusionBuffer, OccluderMeshMergesCoplanarConvexPairsAndSortsLargestFirst) {
  Polys p;
  p.rect(0.0f, 1.0f, 0.0f, 1.0f, 5.0f);   // a small quad
  p.rect(4.0f, 12.0f, 0.0f, 8.0f, 5.0f);  // a large one
  p.positions.insert(p.positions.end(), {at(0, 0, 7), at(3, 0, 7), at(0, 3, 7)});
  p.indices.insert(p.indices.end(), {8, 9, 10});  // a lone triangle
  const OccluderMesh mesh = make_occluder_mesh(p.positions, p.indices);
  ASSERT_EQ(mesh.polygons(), 3u);
  EXPECT_GE(mesh.inradius[0], mesh.inradius[1]);
  EXPECT_GE(mesh.inradius[1], mesh.inradius[2]);
  EXPECT_EQ(mesh.count_at_least(mesh.inradius[1]), 2u);
  EXPECT_EQ(mesh.count_at_least(0.0f), 3u);
  EXPECT_EQ(mesh.count_at_least(mesh.inradius[0] * 2.0f), 0u);
  int quads = 0;
  for (std::size_t k = 0; k < mesh.polygons(); ++k) quads += mesh.corners[4 * k + 3] != OccluderMesh::no_corner;
  EXPECT_EQ(quads, 2);
}

// Rule 11's pairs: polygons across an edge used once in each direction (by
// position: the two halves of the fold below share no vertex), and no
// other: not an edge of three polygons, not two polygons wound against
// each other, not an open border, not a quad's merged diagonal.
TEST(OcclusionBuffer, OccluderMeshPairsPolygonsAcrossManifoldEdgesOnly) {
  const auto pairs = [](const std::vector<glm::vec3>& positions, const std::vector<std::uint32_t>& indices) {
    const OccluderMesh mesh = make_occluder_mesh(positions, indices);
    std::vector<std::pair<std::uint32_t, std::uint32_t>> out;
    for (std::size_t p = 0; p < mesh.polygons(); ++p)
      for (int k = 0; k < 4; ++k)
        if (const std::uint32_t q = mesh.neighbours[4 * p + std::size_t(k)]; q != OccluderMesh::no_corner)
          out.emplace_back(std::uint32_t(p), q);
    return out;
  };
  const glm::vec3 e0 = at(5, 0, 5), e1 = at(5, 8, 5), left = at(1, 4, 5), right = at(9, 4, 7), third = at(7, 2, 9);
  // A fold: two triangles, each its own vertices, across e0-e1.
  const auto fold = pairs({e0, e1, left, e1, e0, right}, {0, 1, 2, 3, 4, 5});
  ASSERT_EQ(fold.size(), 2u);
  EXPECT_EQ(fold[0].first, fold[1].second);
  EXPECT_EQ(fold[0].second, fold[1].first);
  EXPECT_TRUE(pairs({e0, e1, left, e1, e0, right, e1, e0, third}, {0, 1, 2, 3, 4, 5, 6, 7, 8}).empty())
      << "three polygons on one edge";
  EXPECT_TRUE(pairs({e0, e1, left, e0, e1, right}, {0, 1, 2, 3, 4, 5}).empty()) << "wound against each other";
  Polys quad;  // coplanar halves: merged, their diagonal no edge
  quad.rect(0.0f, 4.0f, 0.0f, 4.0f, 5.0f);
  EXPECT_TRUE(pairs(quad.positions, quad.indices).empty());
}

// A point the mesh repeats (a fold of two triangles, each its own vertices,
// as a flat-shaded mesh has) is one corner: the first of its positions, so
// that the polygons at it share its transform.
TEST(OcclusionBuffer, OccluderMeshCornersAtOnePointAreItsFirstVertex) {
  const glm::vec3 e0 = at(5, 0, 5), e1 = at(5, 8, 5), left = at(1, 4, 5), right = at(9, 4, 7);
  const std::vector<glm::vec3> positions{e0, e1, left, e1, e0, right};
  const OccluderMesh mesh = make_occluder_mesh(positions, std::vector<std::uint32_t>{0, 1, 2, 3, 4, 5});
  ASSERT_EQ(mesh.polygons(), 2u);
  std::vector<std::uint32_t> used;
  for (const std::uint32_t c : mesh.corners)
    if (c != OccluderMesh::no_corner) used.push_back(c);
  std::sort(used.begin(), used.end());
  EXPECT_EQ(used, (std::vector<std::uint32_t>{0, 0, 1, 1, 2, 5}));
}

// The tiles' farthest depths only shortcut the texels' answer.
TEST(OcclusionBuffer, TilesAnswerAsTexelsDo) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-4.0f, 40.0f), dist(1.0f, 40.0f);
  const View view = make_view(CameraPose{}, Lens{60.0f, 0.1f, 100.0f}, 640, 360);
  int hidden = 0, tested = 0;
  for (int round = 0; round < 20; ++round) {
    OcclusionBuffer tiles(64, 36), texels(64, 36, SimdPath::best, {.tiles = false});
    tiles.clear(view.clip);
    texels.clear(view.clip);
    std::vector<glm::vec3> pos;
    std::vector<std::uint32_t> idx;
    for (int k = 0; k < 20; ++k) {  // random walls facing the eye
      const float x = u(rng) - 20.0f, y = 0.5f * u(rng) - 10.0f, d = dist(rng), w = 0.3f * u(rng) + 1.0f;
      const auto base = std::uint32_t(pos.size());
      pos.insert(pos.end(), {{x, y, -d}, {x + w, y, -d}, {x + w, y + w, -d}, {x, y + w, -d}});
      idx.insert(idx.end(), {base, base + 1, base + 2, base, base + 2, base + 3});
    }
    const OccluderMesh mesh = make_occluder_mesh(pos, idx);
    tiles.rasterize(pos, mesh, mesh.polygons(), glm::dmat4(view.view_proj));
    texels.rasterize(pos, mesh, mesh.polygons(), glm::dmat4(view.view_proj));
    for (int k = 0; k < 200; ++k) {
      const glm::vec3 c(u(rng) - 20.0f, 0.5f * u(rng) - 10.0f, -dist(rng) - 2.0f);
      const Aabb b{c, c + glm::vec3(0.2f * u(rng) + 0.1f, 0.1f * u(rng) + 0.1f, 1.0f)};
      const bool a = tiles.occluded(b, view.view_proj);
      ASSERT_EQ(a, texels.occluded(b, view.view_proj)) << "round " << round << " box " << k;
      hidden += a;
      ++tested;
    }
  }
  EXPECT_GT(hidden, tested / 20);  // both answers came up
  EXPECT_LT(hidden, tested);
}

// The vectorised loops equal the scalar reference bit for bit, and so do
// the answers, over random occluders, sizes and boxes.
TEST(OcclusionBuffer, SimdMatchesScalar) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-4.0f, 20.0f), dist(1.0f, 40.0f);
  int covered_rounds = 0, hidden_answers = 0;
  for (int round = 0; round < 40; ++round) {
    const int w = 1 + int(rng() % 97), h = 1 + int(rng() % 61);
    const View view = camera(round % 2 ? DepthMode::reversed : DepthMode::standard);
    OcclusionBuffer best(w, h, SimdPath::best), scalar(w, h, SimdPath::scalar);
    best.clear(view.clip);
    scalar.clear(view.clip);
    Polys p;
    for (int k = 0; k < 30; ++k) {
      const float x0 = u(rng), y0 = u(rng) * 0.6f, d0 = dist(rng);
      p.rect(x0, x0 + std::abs(u(rng)) * 0.5f + 0.2f, y0, y0 + std::abs(u(rng)) * 0.4f + 0.2f, d0, d0 + u(rng) * 0.2f);
    }
    const std::uint32_t a = best.rasterize(p.positions, p.indices, glm::dmat4(view.view_proj));
    const std::uint32_t b = scalar.rasterize(p.positions, p.indices, glm::dmat4(view.view_proj));
    ASSERT_EQ(a, b);
    covered_rounds += best.covered_texels() > 0;
    for (std::size_t i = 0; i < best.keys().size(); ++i)
      ASSERT_EQ(std::bit_cast<std::uint32_t>(best.keys()[i]), std::bit_cast<std::uint32_t>(scalar.keys()[i]))
          << "round " << round << " texel " << i;
    for (int k = 0; k < 50; ++k) {
      const float x0 = u(rng), y0 = u(rng) * 0.6f;
      const Aabb b = box(x0, x0 + std::abs(u(rng)) * 0.3f, y0, y0 + 1.0f, dist(rng), 1.0f);
      const bool hidden = best.occluded(b, view.view_proj);
      ASSERT_EQ(hidden, scalar.occluded(b, view.view_proj));
      hidden_answers += hidden;
    }
  }
  EXPECT_GE(covered_rounds, 30);  // the comparison compared something
  EXPECT_GE(hidden_answers, 50);  // both answers came up
  EXPECT_FALSE(simd_target_name().empty());
}

// A mesh's polygons share their corners' transform and projection (each
// vertex of a call done once): the keys are those of rasterizing its
// triangles one by one, bit for bit, and a second call with another matrix
// transforms afresh. A bumpy terrain reaching behind the eye (clipped at the
// near plane), no two triangles coplanar (no quads), at whole texels and at
// pixel centres.
TEST(OcclusionBuffer, SharedVerticesRasterizeAsSeparateTriangles) {
  std::mt19937 rng(5);
  const Polys terrain = bumpy_terrain(rng);
  const std::vector<glm::vec3>& pos = terrain.positions;
  const std::vector<std::uint32_t>& idx = terrain.indices;
  const OccluderMesh mesh = make_occluder_mesh(pos, idx);
  ASSERT_EQ(mesh.polygons(), idx.size() / 3);  // no quad merged
  ASSERT_TRUE(mesh.shared_corners);
  const View view = camera();
  const glm::dmat4 moved = glm::dmat4(view.view_proj) * glm::dmat4(glm::mat4{1.0f, 0.0f, 0.0f, 0.0f,  //
                                                                             0.0f, 1.0f, 0.0f, 0.0f,  //
                                                                             0.0f, 0.0f, 1.0f, 0.0f,  //
                                                                             3.0f, -1.5f, -4.0f, 1.0f});
  for (const int size : {1, 10}) {  // texels of 10 × 10 pixels, covered whole; one pixel each, at its centre
    // Rule 11 off: the mesh's pairs fused would cover more than its triangles one by one.
    OcclusionBuffer shared(160 / size, 90 / size), one_by_one(160 / size, 90 / size);
    shared.set_fused_pairs(false);
    for (OcclusionBuffer* b : {&shared, &one_by_one}) size == 1 ? b->clear(view) : b->clear(view.clip);
    std::uint32_t polygons = 0, triangles = 0;
    for (const glm::dmat4& m : {glm::dmat4(view.view_proj), moved}) {
      polygons += shared.rasterize(pos, mesh, mesh.polygons(), m);
      triangles += one_by_one.rasterize(pos, idx, m);
    }
    EXPECT_EQ(polygons, triangles);
    EXPECT_GT(shared.covered_texels(), shared.keys().size() / 16) << size;  // the comparison compares something
    for (std::size_t i = 0; i < shared.keys().size(); ++i)
      ASSERT_EQ(std::bit_cast<std::uint32_t>(shared.keys()[i]), std::bit_cast<std::uint32_t>(one_by_one.keys()[i]))
          << "buffer " << shared.width() << "x" << shared.height() << " texel " << i;
  }
}

// Rasterizing on threads (set_threads) leaves the buffer as one thread does,
// bit for bit: a bumpy terrain of 1,058 triangles (a call of enough polygons
// to be shared among the threads) and 60 small slanted boxes, as one call each
// and as one batch, at pixel centres and at whole texels; the polygon counts
// agree too. Broken on purpose (the copies' keys not merged), it fails.
TEST(OcclusionBuffer, ThreadsRasterizeAsOneDoes) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> bump(-1.0f, 1.0f), u(0.0f, 1.0f);
  const Polys ground = bumpy_terrain(rng);
  const std::vector<glm::vec3>& terrain = ground.positions;
  const std::vector<std::uint32_t>& terrain_idx = ground.indices;
  const OccluderMesh terrain_mesh = make_occluder_mesh(terrain, terrain_idx);
  Polys boxes;  // a slanted quad each, drawn as its own object
  for (int k = 0; k < 60; ++k) {
    const float x0 = u(rng) * 15.0f, y0 = u(rng) * 8.0f, d = 2.0f + 30.0f * u(rng);
    boxes.rect(x0, x0 + 0.5f + 3.0f * u(rng), y0, y0 + 0.5f + 2.0f * u(rng), d, d + 2.0f * bump(rng));
  }
  std::vector<OccluderMesh> quads;
  for (std::size_t k = 0; k < boxes.indices.size(); k += 6)
    quads.push_back(make_occluder_mesh(boxes.positions, std::span(boxes.indices).subspan(k, 6)));
  const View view = camera();
  std::vector<OcclusionBuffer::OccluderDraw> draws;
  const auto bounds_of = [](std::span<const glm::vec3> p) {
    Aabb b;
    for (const glm::vec3& v : p) b.extend(v);
    return b;
  };
  draws.push_back({terrain, &terrain_mesh, glm::mat4(1.0f), bounds_of(terrain)});
  for (const OccluderMesh& q : quads) draws.push_back({boxes.positions, &q, glm::mat4(1.0f), bounds_of(boxes.positions)});
  for (const int size : {1, 10}) {
    OcclusionBuffer one(160 / size, 90 / size);
    const auto start = [&](OcclusionBuffer& b) { size == 1 ? b.clear(view) : b.clear(view.clip); };
    start(one);
    std::uint32_t expected = 0;
    for (const OcclusionBuffer::OccluderDraw& d : draws)
      expected += one.rasterize(d.positions, *d.mesh, view, d.object_to_world, d.bounds);
    ASSERT_GT(one.covered_texels(), one.keys().size() / 4) << size;  // the comparison compares something
    for (const int threads : {2, 3}) {
      OcclusionBuffer called(160 / size, 90 / size), batched(160 / size, 90 / size);
      called.set_threads(threads);
      batched.set_threads(threads);
      EXPECT_EQ(batched.threads(), threads);
      start(called);
      start(batched);
      std::uint32_t polygons = 0;
      for (const OcclusionBuffer::OccluderDraw& d : draws)
        polygons += called.rasterize(d.positions, *d.mesh, view, d.object_to_world, d.bounds);
      EXPECT_EQ(polygons, expected);
      EXPECT_EQ(batched.rasterize(draws, view), expected);
      for (std::size_t i = 0; i < one.keys().size(); ++i) {
        ASSERT_EQ(std::bit_cast<std::uint32_t>(called.keys()[i]), std::bit_cast<std::uint32_t>(one.keys()[i]))
            << threads << " threads, one call a draw, buffer " << one.width() << " texel " << i;
        ASSERT_EQ(std::bit_cast<std::uint32_t>(batched.keys()[i]), std::bit_cast<std::uint32_t>(one.keys()[i]))
            << threads << " threads, one batch, buffer " << one.width() << " texel " << i;
      }
      // The box test answers from the merged keys as from one thread's.
      int hidden = 0;
      for (int k = 0; k < 200; ++k) {
        const float x0 = u(rng) * 15.0f, y0 = u(rng) * 8.0f;
        const Aabb b = box(x0, x0 + 0.3f, y0, y0 + 0.3f, 3.0f + 50.0f * u(rng), 1.0f);
        const bool expected_hidden = one.occluded(b, view.view_proj);
        hidden += expected_hidden;
        ASSERT_EQ(batched.occluded(b, view.view_proj), expected_hidden) << threads << " threads, box " << k;
        ASSERT_EQ(called.occluded(b, view.view_proj), expected_hidden) << threads << " threads, box " << k;
      }
      EXPECT_GT(hidden, 10);
    }
  }
  OcclusionBuffer b(4, 4);
  EXPECT_THROW(b.set_threads(0), UsageError);
  EXPECT_THROW(b.set_threads(OcclusionBuffer::max_threads + 1), UsageError);
}

// track_sources: each texel names the occluder whose key it holds, the
// smallest tag of those that wrote that key, whatever the order of the draws,
// the threads and the inner loops; the keys are those of a buffer that tracks
// nothing. A hidden box names the tags it was compared against.
TEST(OcclusionBuffer, SourcesNameTheNearestOccluderWhateverTheOrderAndThreads) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> bump(-1.0f, 1.0f), u(0.0f, 1.0f);
  const Polys ground = bumpy_terrain(rng);
  const OccluderMesh terrain_mesh = make_occluder_mesh(ground.positions, ground.indices);
  Polys quads;
  for (int k = 0; k < 40; ++k) {
    const float x0 = u(rng) * 15.0f, y0 = u(rng) * 8.0f, d = 2.0f + 30.0f * u(rng);
    quads.rect(x0, x0 + 0.5f + 3.0f * u(rng), y0, y0 + 0.5f + 2.0f * u(rng), d, d + 2.0f * bump(rng));
  }
  for (int k = 0; k < 2; ++k) quads.rect(4.0f, 9.0f, 2.0f, 5.0f, 1.5f);  // the same quad twice: equal keys
  std::vector<OccluderMesh> meshes;
  for (std::size_t k = 0; k < quads.indices.size(); k += 6)
    meshes.push_back(make_occluder_mesh(quads.positions, std::span(quads.indices).subspan(k, 6)));
  const View view = camera();
  const auto bounds_of = [](std::span<const glm::vec3> p) {
    Aabb b;
    for (const glm::vec3& v : p) b.extend(v);
    return b;
  };
  std::vector<OcclusionBuffer::OccluderDraw> draws;
  draws.push_back({ground.positions, &terrain_mesh, glm::mat4(1.0f), bounds_of(ground.positions), 90});
  for (std::size_t k = 0; k < meshes.size(); ++k)  // tags not in draw order; the twin quads 7 and 3
    draws.push_back({quads.positions, &meshes[k], glm::mat4(1.0f), bounds_of(quads.positions),
                     k + 2 == meshes.size() ? 7u : k + 1 == meshes.size() ? 3u : std::uint32_t(200 - k)});
  const auto run = [&](SimdPath simd, int threads, bool batch, bool reversed, bool track) {
    OcclusionBuffer b(160, 90, simd);
    b.set_threads(threads);
    b.track_sources(track);
    b.clear(view);
    std::vector<OcclusionBuffer::OccluderDraw> order = draws;
    if (reversed) std::reverse(order.begin(), order.end());
    if (batch) {
      (void)b.rasterize(order, view);
    } else {
      for (const OcclusionBuffer::OccluderDraw& d : order) {
        b.set_source(d.source);
        (void)b.rasterize(d.positions, *d.mesh, view, d.object_to_world, d.bounds);
      }
    }
    return b;
  };
  const OcclusionBuffer plain = run(SimdPath::best, 1, false, false, false);
  const OcclusionBuffer first = run(SimdPath::best, 1, false, false, true);
  EXPECT_FALSE(plain.tracks_sources());
  EXPECT_EQ(plain.source_at(80, 45), OcclusionBuffer::no_source);
  ASSERT_GT(first.covered_texels(), first.keys().size() / 4);
  // Each tag names a draw that, alone, writes that very key there.
  std::map<std::uint32_t, OcclusionBuffer> alone;
  std::set<std::uint32_t> seen;
  for (int y = 0; y < first.height(); ++y)
    for (int x = 0; x < first.width(); ++x) {
      const float key = first.key_at(x, y);
      ASSERT_EQ(std::bit_cast<std::uint32_t>(key), std::bit_cast<std::uint32_t>(plain.key_at(x, y)));
      const std::uint32_t tag = first.source_at(x, y);
      if (std::isinf(key)) {
        ASSERT_EQ(tag, OcclusionBuffer::no_source) << x << "," << y;
        continue;
      }
      ASSERT_NE(tag, OcclusionBuffer::no_source) << x << "," << y;
      seen.insert(tag);
      auto it = alone.find(tag);
      if (it == alone.end()) {
        const auto d = std::find_if(draws.begin(), draws.end(), [&](const auto& d) { return d.source == tag; });
        ASSERT_NE(d, draws.end()) << tag;
        OcclusionBuffer b(160, 90);
        b.clear(view);
        (void)b.rasterize(d->positions, *d->mesh, view, d->object_to_world, d->bounds);
        it = alone.emplace(tag, std::move(b)).first;
      }
      ASSERT_EQ(std::bit_cast<std::uint32_t>(it->second.key_at(x, y)), std::bit_cast<std::uint32_t>(key))
          << "tag " << tag << " at " << x << "," << y;
    }
  EXPECT_TRUE(seen.count(90)) << "the terrain holds some texels";
  EXPECT_TRUE(seen.count(3)) << "the twin quads' texels name the smaller tag";
  EXPECT_FALSE(seen.count(7)) << "the twin quads' texels name the smaller tag";
  EXPECT_GT(seen.size(), 10u);
  // Any order, threads, batch or call, and the scalar loops: the same tags.
  for (const SimdPath simd : {SimdPath::best, SimdPath::scalar})
    for (const int threads : {1, 3})
      for (const bool batch : {false, true})
        for (const bool reversed : {false, true}) {
          const OcclusionBuffer b = run(simd, threads, batch, reversed, true);
          for (std::size_t i = 0; i < first.keys().size(); ++i) {
            const int x = int(i % 160), y = int(i / 160);
            ASSERT_EQ(std::bit_cast<std::uint32_t>(b.key_at(x, y)), std::bit_cast<std::uint32_t>(first.key_at(x, y)));
            ASSERT_EQ(b.source_at(x, y), first.source_at(x, y))
                << (simd == SimdPath::scalar ? "scalar" : "simd") << ", " << threads << " threads, "
                << (batch ? "batch" : "calls") << (reversed ? ", reversed" : "") << ", texel " << x << "," << y;
          }
        }
  // A box behind the twin quads only: they alone hid it.
  OcclusionBuffer b = run(SimdPath::best, 1, false, false, true);
  const Aabb hidden = box(5.0f, 8.0f, 3.0f, 4.0f, 1.6f, 0.1f);
  std::vector<std::uint32_t> tags;
  ASSERT_TRUE(b.occluded(hidden, view.view_proj, &tags));
  EXPECT_EQ(tags, std::vector<std::uint32_t>{3});
  tags.clear();
  OcclusionBuffer untracked = run(SimdPath::best, 1, false, false, false);
  ASSERT_TRUE(untracked.occluded(hidden, view.view_proj, &tags));
  EXPECT_TRUE(tags.empty()) << "no tags without track_sources";
}

// The rasterizer's integer bounds divide without a 64-bit division where the
// operands fit a double: the same floor as the plain division, for every
// sign, at exact multiples, one step off them, and around 2^52 where it
// hands over to the division.
TEST(FixedPoint, FloorDivWithoutIntegerDivisionEqualsFloorDiv) {
  std::mt19937_64 rng(11);
  std::vector<std::pair<std::int64_t, std::int64_t>> cases;
  const std::int64_t big = std::int64_t(1) << 52;
  for (const std::int64_t b : {std::int64_t(1), std::int64_t(3), std::int64_t(256), std::int64_t(65536 * 3),
                               big - 1, big, big + 1})
    for (const std::int64_t q : {std::int64_t(0), std::int64_t(1), std::int64_t(7), std::int64_t(1) << 30})
      for (const std::int64_t d : {-1, 0, 1})
        for (const std::int64_t sign : {-1, 1})
          if (q <= (std::int64_t(1) << 61) / b) cases.emplace_back(sign * (q * b + d), b);
  for (const std::int64_t a : {big - 1, big, big + 1, -big + 1, -big, -big - 1}) cases.emplace_back(a, 3);
  for (int i = 0; i < 200000; ++i) {
    const int bits_a = int(rng() % 60), bits_b = int(rng() % 56);
    const std::int64_t a = std::int64_t(rng() >> (64 - bits_a - 1)) * (rng() & 1 ? 1 : -1);
    const std::int64_t b = std::max<std::int64_t>(1, std::int64_t(rng() >> (64 - bits_b - 1)));
    cases.emplace_back(a, b);
  }
  int negative = 0;
  for (const auto& [a, b] : cases) {
    ASSERT_EQ(detail::floor_div_bounded(a, b), detail::floor_div(a, b)) << a << " / " << b;
    negative += a < 0 && a % b != 0;
  }
  EXPECT_GT(negative, 1000);  // the floor and the truncation differ in these
}

// next_up is std::nextafter toward +infinity for every kind of float.
TEST(FixedPoint, NextUpEqualsNextafter) {
  constexpr float inf = std::numeric_limits<float>::infinity();
  std::vector<float> values = {0.0f, -0.0f, 1.0f, -1.0f, inf, -inf, std::numeric_limits<float>::denorm_min(),
                               -std::numeric_limits<float>::denorm_min(), std::numeric_limits<float>::max(),
                               -std::numeric_limits<float>::max(), std::numeric_limits<float>::min(),
                               -std::numeric_limits<float>::min()};
  std::mt19937 rng(5);
  for (int i = 0; i < 100000; ++i) values.push_back(std::bit_cast<float>(std::uint32_t(rng())));
  for (const float x : values) {
    if (std::isnan(x)) {
      EXPECT_TRUE(std::isnan(detail::next_up(x)));
      continue;
    }
    ASSERT_EQ(std::bit_cast<std::uint32_t>(detail::next_up(x)), std::bit_cast<std::uint32_t>(std::nextafter(x, inf)))
        << x;
  }
}

namespace {
// Two triangles of one mesh, A on the left and B on the right, sharing the
// vertical edge x = `edge` from texel row `from` to `to` (texel coordinates
// of the buffer, one pixel a texel); A's third corner at `a`, B's at `b`,
// each at its own distance. Not in one plane: OccluderMesh keeps them apart.
struct Pair {
  float edge, from, to;
  glm::vec3 a, b;      // texel x, texel y, distance
  float edge_distance = 5.0f;
  Polys polys() const {
    Polys p;
    p.positions = {at(edge, from, edge_distance), at(edge, to, edge_distance), at(a.x, a.y, a.z), at(b.x, b.y, b.z)};
    p.indices = {0, 1, 2, 1, 0, 3};  // A: up the edge, then left; B: down it, then right
    return p;
  }
};
}  // namespace

// Rule 11: a pixel centre 0.005 texel from the edge two polygons share is
// covered by neither alone (rule 3's growth, 1/64 texel), but the GPU draws
// it with one of them: fused, the pair covers it.
TEST(OcclusionBufferFusion, APixelCentreOnASharedEdgeIsCoveredByThePair) {
  const Pair pair{5.505f, -2.0f, 11.0f, {-5.0f, 4.5f, 5.0f}, {20.0f, 4.5f, 6.0f}};
  const OccluderMesh mesh = make_occluder_mesh(pair.polys().positions, pair.polys().indices);
  ASSERT_EQ(mesh.polygons(), 2u);
  ASSERT_NE(mesh.neighbours[0] + mesh.neighbours[1] + mesh.neighbours[2], 3 * OccluderMesh::no_corner);
  const Aabb behind = box(5.45f, 5.55f, 3.3f, 3.7f, 10.0f);
  Sampled fused(1);
  fused.draw(pair.polys());
  EXPECT_TRUE(fused.hidden(behind));
  Sampled apart(1);
  apart.buffer.set_fused_pairs(false);
  apart.draw(pair.polys());
  EXPECT_FALSE(apart.hidden(behind)) << "texel column 5 lies on the seam";
  // The whole column (the edge runs from below the buffer to above it), and nothing else.
  EXPECT_EQ(fused.buffer.covered_texels(), apart.buffer.covered_texels() + std::size_t(kH));
}

// Rule 11: the band is bounded by both polygons' other edges, grown. Here
// B is a sliver narrowing to the edge's lower end (3.0): the centre (5.5,
// 3.5) lies 0.01 texel right of the edge, within the band, but outside B
// (and A): the GPU draws nothing there.
TEST(OcclusionBufferFusion, TheBandEndsAtBothPolygonsOtherEdges) {
  const Pair pair{5.49f, 3.0f, 11.0f, {-5.0f, 7.0f, 5.0f}, {5.59f, 11.0f, 6.0f}};
  const Aabb behind = box(5.45f, 5.55f, 3.3f, 3.7f, 10.0f);
  Sampled f(1);
  f.draw(pair.polys());
  EXPECT_FALSE(f.hidden(behind));
  EXPECT_TRUE(f.hidden(box(4.45f, 4.55f, 5.3f, 5.7f, 10.0f)));  // A covers its own texels
  Sampled broken(1, {.fusion_other_edges = false});
  broken.draw(pair.polys());
  EXPECT_TRUE(broken.hidden(behind)) << "the band along the whole edge should reach past B";
}

// Rule 11: a fragment of the band may be B's, at B's depth. B runs steeply
// away (from 5 to 50 over a texel), A faces the eye at 5; the centre (5.5,
// 4.5) lies 0.01 texel inside B, where B is farther than a box at 5.02: the
// box is visible there. A's plane alone would hide it.
TEST(OcclusionBufferFusion, TheBandTakesTheFartherOfBothPolygonsDepths) {
  const Pair pair{5.49f, -2.0f, 11.0f, {4.0f, 4.5f, 5.0f}, {6.5f, 4.5f, 50.0f}};
  const Aabb between = box(5.45f, 5.55f, 4.3f, 4.7f, 5.02f);
  Sampled f(1);
  f.draw(pair.polys());
  EXPECT_FALSE(f.hidden(between));
  EXPECT_TRUE(f.hidden(box(5.45f, 5.55f, 4.3f, 4.7f, 60.0f)));  // the band covers the centre
  Sampled broken(1, {.fusion_depth = false});
  broken.draw(pair.polys());
  EXPECT_TRUE(broken.hidden(between)) << "A's plane should put the band in front of the box";
}

// Rule 11: both polygons must surely be drawn: a triangle whose orientation
// any snapping by up to a step per corner (ours and the GPU's) could turn
// is not fused. Checked against every such move of the corners of random
// small triangles: accepted ones never turn, and some that are
// counter-clockwise as they stand are refused.
TEST(FixedPoint, ATriangleSurelyFrontFacingStaysSoUnderSnapping) {
  std::mt19937 rng(3);
  int accepted = 0, refused_ccw = 0;
  for (int round = 0; round < 4000; ++round) {
    std::int64_t X[3], Y[3];
    for (int i = 0; i < 3; ++i) X[i] = std::int64_t(rng() % 40), Y[i] = std::int64_t(rng() % 40);
    const std::int64_t area2 = (X[1] - X[0]) * (Y[2] - Y[0]) - (X[2] - X[0]) * (Y[1] - Y[0]);
    if (!detail::surely_front_facing(X, Y, 0, 1, 2)) {
      refused_ccw += area2 > 0;
      continue;
    }
    ++accepted;
    for (int move = 0; move < 729; ++move) {  // each of the 6 coordinates moved by -1, 0 or +1
      std::int64_t x[3], y[3];
      int code = move;
      for (int i = 0; i < 3; ++i) {
        x[i] = X[i] + code % 3 - 1, code /= 3;
        y[i] = Y[i] + code % 3 - 1, code /= 3;
      }
      ASSERT_GT((x[1] - x[0]) * (y[2] - y[0]) - (x[2] - x[0]) * (y[1] - y[0]), 0) << round << " " << move;
    }
  }
  EXPECT_GT(accepted, 100);
  EXPECT_GT(refused_ccw, 100);
}
