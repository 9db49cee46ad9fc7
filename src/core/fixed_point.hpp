// Internal: exact integer and float steps of the CPU occlusion buffer's
// rasterizer (occlusion_buffer.cpp), inline, and tested against the plain
// forms they replace (tests/occlusion_buffer_test.cpp).
#pragma once

#include <bit>
#include <cmath>
#include <cstdint>
#include <limits>

namespace occull::detail {

/// floor(a / b). Precondition: b > 0.
[[nodiscard]] inline std::int64_t floor_div(std::int64_t a, std::int64_t b) {
  const std::int64_t q = a / b;
  return (a % b != 0 && a < 0) ? q - 1 : q;
}

/// floor(a / b) as floor_div, without a 64-bit integer division where a and
/// b fit a double's mantissa (such a division takes tens of cycles on many
/// x86 cores): the quotient in double, truncated, lies within 2 of the
/// floor and is corrected exactly. Precondition: b > 0.
[[nodiscard]] inline std::int64_t floor_div_bounded(std::int64_t a, std::int64_t b) {
  constexpr std::int64_t kExact = std::int64_t(1) << 52;
  if (a <= -kExact || a >= kExact || b >= kExact) return floor_div(a, b);
  std::int64_t q = std::int64_t(double(a) / double(b));
  std::int64_t r = a - q * b;
  while (r < 0) --q, r += b;
  while (r >= b) ++q, r -= b;
  return q;
}

/// std::nextafter(x, +infinity), inline (the library's is a call, and the
/// rasterizer takes one a texel row).
[[nodiscard]] inline float next_up(float x) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  if (std::isnan(x) || x == kInf) return x;
  if (x == 0.0f) return std::numeric_limits<float>::denorm_min();
  const std::uint32_t bits = std::bit_cast<std::uint32_t>(x);
  return std::bit_cast<float>(x > 0.0f ? bits + 1 : bits - 1);
}

/// Rule 11 (occull/occlusion_buffer.hpp): whether the triangle of corners
/// i, j, k of X, Y (fixed point, 256 steps a texel) is counter-clockwise
/// however each corner moves by up to one step on each axis (ours and the
/// GPU's snapping together): twice its area exceeds what such moves can
/// change it by (2 (|ab|_1 + |ac|_1) + 8).
[[nodiscard]] inline bool surely_front_facing(const std::int64_t* X, const std::int64_t* Y, int i, int j, int k) {
  const std::int64_t ax = X[j] - X[i], ay = Y[j] - Y[i], bx = X[k] - X[i], by = Y[k] - Y[i];
  const std::int64_t area2 = ax * by - bx * ay;
  const auto abs = [](std::int64_t v) { return v < 0 ? -v : v; };
  return area2 > 4 * (abs(ax) + abs(ay) + abs(bx) + abs(by)) + 16;
}
/// Every triangle a GPU draws of polygon X, Y (n = 3 or 4 corners; a quad's
/// two share corners 0 and 2, the diagonal OccluderMesh merges along)
/// surely counter-clockwise.
[[nodiscard]] inline bool surely_front_facing(const std::int64_t* X, const std::int64_t* Y, int n) {
  return surely_front_facing(X, Y, 0, 1, 2) && (n == 3 || surely_front_facing(X, Y, 0, 2, 3));
}

}  // namespace occull::detail
