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

}  // namespace occull::detail
