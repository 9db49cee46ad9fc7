// The depth pyramid's reference implementation: see depth_pyramid.hpp for
// the rules. src/gl/renderer_device.cpp's shaders follow this file.
#include "occull/depth_pyramid.hpp"
#include "occull/error.hpp"
#include "core/format.hpp"

#include <glm/vec4.hpp>

#include <algorithm>
#include <bit>
#include <cassert>
#include <cmath>
#include <limits>

namespace occull {

float depth_tolerance(float far_key) noexcept { return 4e-6f * std::abs(far_key) + 4e-7f; }

BoxFootprint project_box(const Aabb& box, const glm::mat4& view_proj, const ClipSpace& clip, int width,
                         int height) noexcept {
  constexpr float inf = std::numeric_limits<float>::infinity();
  BoxFootprint f{false, 0, inf, inf, -inf, -inf, inf, -inf};
  for (int i = 0; i < 8; ++i) {
    const glm::vec4 c = view_proj * glm::vec4(box.corner(i), 1.0f);
    const float ndc_z = c.z / c.w;
    const bool before_near = clip.reversed_z ? ndc_z > 1.0f : ndc_z < clip.near_depth();
    if (c.w <= 0.0f || before_near) {
      f.reaches_eye = true;
      continue;
    }
    ++f.projected;
    const float depth = clip.depth == DepthRange::zero_to_one ? ndc_z : ndc_z * 0.5f + 0.5f;
    f.min_depth = std::min(f.min_depth, depth);
    f.max_depth = std::max(f.max_depth, depth);
    const float px = (c.x / c.w * 0.5f + 0.5f) * float(width);
    const float py = (c.y / c.w * 0.5f + 0.5f) * float(height);
    f.min_x = std::min(f.min_x, px);
    f.max_x = std::max(f.max_x, px);
    f.min_y = std::min(f.min_y, py);
    f.max_y = std::max(f.max_y, py);
  }
  return f;
}

float window_depth(const glm::vec3& p, const glm::mat4& view_proj, const ClipSpace& clip) noexcept {
  const glm::vec4 c = view_proj * glm::vec4(p, 1.0f);
  const float ndc_z = c.z / c.w;
  return clip.depth == DepthRange::zero_to_one ? ndc_z : ndc_z * 0.5f + 0.5f;
}

int pyramid_level_for(int extent) noexcept {
  if (extent <= 1) return 0;
  return std::bit_width(unsigned(extent - 1));  // ceil(log2(extent))
}

DepthPyramid::DepthPyramid(std::span<const float> depth, int width, int height, bool reversed_z,
                           const detail::PyramidRules& rules)
    : reversed_(reversed_z), rules_(rules) {
  if (width < 1 || height < 1 || depth.size() != std::size_t(width) * std::size_t(height))
    throw UsageError(detail::format("DepthPyramid: {} depth values for {}x{} texels", depth.size(), width, height));
  levels_.push_back({width, height, std::vector<float>(depth.begin(), depth.end())});
  while (levels_.back().width > 1 || levels_.back().height > 1) {
    const Level& src = levels_.back();
    const auto halve = [&](int n) { return std::max(1, rules_.round_sizes_up ? (n + 1) / 2 : n / 2); };
    Level dst{halve(src.width), halve(src.height), {}};
    dst.texels.resize(std::size_t(dst.width) * std::size_t(dst.height));
    for (int y = 0; y < dst.height; ++y)
      for (int x = 0; x < dst.width; ++x) {
        const int x0 = 2 * x, y0 = 2 * y;
        const int x1 = std::min(x0 + 1, src.width - 1), y1 = std::min(y0 + 1, src.height - 1);
        float v = src.texels[std::size_t(y0) * std::size_t(src.width) + std::size_t(x0)];
        for (const auto& [sx, sy] : {std::pair{x1, y0}, std::pair{x0, y1}, std::pair{x1, y1}}) {
          const float s = src.texels[std::size_t(sy) * std::size_t(src.width) + std::size_t(sx)];
          const bool farther = key(s) > key(v);
          if (farther == rules_.farthest_reduction) v = s;
        }
        dst.texels[std::size_t(y) * std::size_t(dst.width) + std::size_t(x)] = v;
      }
    levels_.push_back(std::move(dst));
  }
}

float DepthPyramid::at(int level, int x, int y) const {
  const Level& l = levels_.at(std::size_t(level));
  return l.texels.at(std::size_t(y) * std::size_t(l.width) + std::size_t(x));
}

bool DepthPyramid::occluded(const Aabb& box, const glm::mat4& view_proj, const ClipSpace& clip, int texels,
                            bool pixel_centres) const {
  if (texels != 2 && texels != 4 && texels != 8 && texels != 16)
    throw UsageError(detail::format("DepthPyramid::occluded: {} texels per axis (2, 4, 8 or 16)", texels));
  if (box.empty()) return true;  // nothing to draw
  if (whole_box_occluded(box, view_proj, clip, texels, pixel_centres)) return true;
  if (rules_.octants_tested == 0) return false;
  // Rule 10: the box is the union of its octants; hidden when each is.
  // (The order changes nothing but how soon a visible box is known: the
  // device's shader starts with the octant nearest the eye.)
  const glm::vec3 mid = box.center();
  for (int o = 0; o < rules_.octants_tested; ++o) {
    Aabb part;
    for (int axis = 0; axis < 3; ++axis) {
      const bool upper = (o >> axis & 1) != 0;
      part.min[axis] = upper ? mid[axis] : box.min[axis];
      part.max[axis] = upper ? box.max[axis] : mid[axis];
    }
    if (!whole_box_occluded(part, view_proj, clip, texels, pixel_centres)) return false;
  }
  return true;
}

bool DepthPyramid::whole_box_occluded(const Aabb& box, const glm::mat4& view_proj, const ClipSpace& clip, int texels,
                                      bool pixel_centres) const {
  const Level& base = levels_.front();
  const BoxFootprint f = project_box(box, view_proj, clip, base.width, base.height);
  if (f.reaches_eye && rules_.reaching_eye_visible) return false;  // rule 6
  if (f.projected == 0) return false;
  // Rule 5: the nearest corner (as a key, larger farther).
  float nearest = std::min(key(f.min_depth), key(f.max_depth));
  if (!rules_.nearest_corner) nearest = key(window_depth(box.center(), view_proj, clip));  // broken: the centre's
  const float min_x = f.min_x, max_x = f.max_x, min_y = f.min_y, max_y = f.max_y;
  // Rule 3: every pixel the rectangle touches, widened for rounding.
  constexpr float margin = 1.0f / 64.0f;
  // (Clamped as floats first: a corner just in front of the eye projects
  // far off the image, past what an int holds.)
  const auto pixel = [](float v, int size) { return int(std::clamp(std::floor(v), -1.0f, float(size))); };
  int x0 = pixel(min_x - margin, base.width), y0 = pixel(min_y - margin, base.height);
  int x1 = pixel(max_x + margin, base.width), y1 = pixel(max_y + margin, base.height);
  if (pixel_centres) {
    // Rule 9: only pixels whose centre (x + 1/2, y + 1/2) the widened
    // rectangle holds can receive a fragment.
    const float centre = rules_.centres_at_half ? 0.5f : 0.0f;
    const auto first = [&](float v, int size) { return int(std::clamp(std::ceil(v - centre), -1.0f, float(size))); };
    x0 = first(min_x - margin, base.width);
    y0 = first(min_y - margin, base.height);
    x1 = pixel(max_x + margin - centre, base.width);
    y1 = pixel(max_y + margin - centre, base.height);
  }
  x0 = std::max(0, x0);
  y0 = std::max(0, y0);
  x1 = std::min(base.width - 1, x1);
  y1 = std::min(base.height - 1, y1);
  if (x0 > x1 || y0 > y1) return true;  // off the image, or no pixel centre: nothing to draw
  // Rule 4: the level where the rectangle spans at most texels × texels.
  const int extent = std::max(x1 - x0 + 1, y1 - y0 + 1);
  int level = rules_.ceil_level ? pyramid_level_for(extent) : std::bit_width(unsigned(extent)) - 1;
  level -= std::bit_width(unsigned(texels)) - 2;  // log2(texels / 2) levels finer
  level = std::clamp(level + rules_.level_bias, 0, levels() - 1);
  const Level& l = levels_[std::size_t(level)];
  // The rectangle's texels at that level, at most `texels` from its first
  // along each axis (all of them at the right level).
  // (Within the level: sizes rounded down, rule 2 broken, leave fewer texels.)
  const int tx = std::min(x0 >> level, l.width - 1), ty = std::min(y0 >> level, l.height - 1);
  const int tx1 = std::min({x1 >> level, tx + texels - 1, l.width - 1});
  const int ty1 = std::min({y1 >> level, ty + texels - 1, l.height - 1});
  float farthest = -std::numeric_limits<float>::infinity();
  for (int y = ty; y <= ty1; ++y)
    for (int x = tx; x <= tx1; ++x)
      farthest = std::max(farthest, key(l.texels[std::size_t(y) * std::size_t(l.width) + std::size_t(x)]));
  // Rule 7: ties and depth rounding are visible.
  const float tolerance = rules_.depth_margin ? depth_tolerance(farthest) : 0.0f;
  return rules_.depth_margin ? nearest > farthest + tolerance : nearest >= farthest;
}

}  // namespace occull
