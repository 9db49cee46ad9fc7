// The occlusion buffer's inner loops, vectorised with Highway and compiled
// once per instruction set Highway targets; the best one this CPU runs is
// chosen at run time. occlusion_buffer.cpp holds the scalar reference they
// equal bit for bit: the same float operations in the same order, min and
// max with the x86 rule for equal operands (the second is returned).
#undef HWY_TARGET_INCLUDE
#define HWY_TARGET_INCLUDE "src/core/occlusion_buffer_simd.cpp"
#include <hwy/foreach_target.h>  // IWYU pragma: keep

#include <hwy/highway.h>

#include "occlusion_buffer_simd.hpp"

HWY_BEFORE_NAMESPACE();
namespace occull::simd::HWY_NAMESPACE {
namespace hn = hwy::HWY_NAMESPACE;

// row[i] = min(row[i], min(base + step * i, cap)) for i in [0, count).
void FillSpan(float* HWY_RESTRICT row, int count, float base, float step, float cap) {
  const hn::ScalableTag<float> d;
  const int lanes = int(hn::Lanes(d));
  const auto vbase = hn::Set(d, base), vstep = hn::Set(d, step), vcap = hn::Set(d, cap);
  auto index = hn::Iota(d, 0.0f);
  const auto advance = hn::Set(d, float(lanes));
  int i = 0;
  for (; i + lanes <= count; i += lanes) {
    const auto depth = hn::Min(hn::Add(vbase, hn::Mul(vstep, index)), vcap);
    hn::StoreU(hn::Min(hn::LoadU(d, row + i), depth), d, row + i);
    index = hn::Add(index, advance);
  }
  for (; i < count; ++i) {  // the tail, as the reference does it
    const float v = base + step * float(i);
    const float depth = v < cap ? v : cap;
    row[i] = row[i] < depth ? row[i] : depth;
  }
}

// FillSpan keeping each texel's tag: where the new depth is nearer, `tag`;
// where it equals the key, the smaller of the two tags.
void FillSpanSourced(float* HWY_RESTRICT row, std::uint32_t* HWY_RESTRICT sources, int count, float base, float step,
                     float cap, std::uint32_t tag) {
  const hn::ScalableTag<float> d;
  const hn::RebindToUnsigned<decltype(d)> du;
  const int lanes = int(hn::Lanes(d));
  const auto vbase = hn::Set(d, base), vstep = hn::Set(d, step), vcap = hn::Set(d, cap);
  const auto vtag = hn::Set(du, tag);
  auto index = hn::Iota(d, 0.0f);
  const auto advance = hn::Set(d, float(lanes));
  int i = 0;
  for (; i + lanes <= count; i += lanes) {
    const auto depth = hn::Min(hn::Add(vbase, hn::Mul(vstep, index)), vcap);
    const auto old = hn::LoadU(d, row + i);
    const auto src = hn::LoadU(du, sources + i);
    const auto take = hn::Or(hn::RebindMask(du, hn::Lt(depth, old)),
                             hn::And(hn::RebindMask(du, hn::Eq(depth, old)), hn::Lt(vtag, src)));
    hn::StoreU(hn::Min(old, depth), d, row + i);
    hn::StoreU(hn::IfThenElse(take, vtag, src), du, sources + i);
    index = hn::Add(index, advance);
  }
  for (; i < count; ++i) {  // the tail, as the reference does it
    const float v = base + step * float(i);
    const float depth = v < cap ? v : cap;
    if (depth < row[i] || (depth == row[i] && tag < sources[i])) sources[i] = tag;
    row[i] = row[i] < depth ? row[i] : depth;
  }
}

// The largest of row[0, count); -infinity when count is 0.
float MaxSpan(const float* HWY_RESTRICT row, int count) {
  const hn::ScalableTag<float> d;
  const int lanes = int(hn::Lanes(d));
  float best = -std::numeric_limits<float>::infinity();
  int i = 0;
  if (count >= lanes) {
    auto acc = hn::LoadU(d, row);
    for (i = lanes; i + lanes <= count; i += lanes) acc = hn::Max(acc, hn::LoadU(d, row + i));
    best = hn::GetLane(hn::MaxOfLanes(d, acc));
  }
  for (; i < count; ++i) best = best > row[i] ? best : row[i];
  return best;
}

std::int64_t Target() { return HWY_TARGET; }

}  // namespace occull::simd::HWY_NAMESPACE
HWY_AFTER_NAMESPACE();

#if HWY_ONCE
namespace occull::simd {

HWY_EXPORT(FillSpan);
HWY_EXPORT(MaxSpan);
HWY_EXPORT(FillSpanSourced);
HWY_EXPORT(Target);

void fill_span(float* row, int count, float base, float step, float cap) {
  HWY_DYNAMIC_DISPATCH(FillSpan)(row, count, base, step, cap);
}
void fill_span_sourced(float* row, std::uint32_t* sources, int count, float base, float step, float cap,
                       std::uint32_t tag) {
  HWY_DYNAMIC_DISPATCH(FillSpanSourced)(row, sources, count, base, step, cap, tag);
}
float max_span(const float* row, int count) { return HWY_DYNAMIC_DISPATCH(MaxSpan)(row, count); }
std::string target_name() { return hwy::TargetName(HWY_DYNAMIC_DISPATCH(Target)()); }

}  // namespace occull::simd
#endif
