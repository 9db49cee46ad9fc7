// Internal: the occlusion buffer's vectorised inner loops
// (occlusion_buffer_simd.cpp, Highway with run-time dispatch).
#pragma once

#include <cstdint>
#include <string>

namespace occull::simd {

/// row[i] = min(row[i], min(base + step * i, cap)) for i in [0, count),
/// min returning its second operand on ties (x86's rule).
void fill_span(float* row, int count, float base, float step, float cap);
/// fill_span, and sources[i] (each texel's tag, OcclusionBuffer::track_sources)
/// set to `tag` where the new depth is nearer than row[i], to the smaller
/// of the two where it is equal.
void fill_span_sourced(float* row, std::uint32_t* sources, int count, float base, float step, float cap,
                       std::uint32_t tag);
/// The largest of row[0, count); -infinity when count is 0.
[[nodiscard]] float max_span(const float* row, int count);
/// The instruction set the dispatch chose ("AVX2", "SSE4", ...).
[[nodiscard]] std::string target_name();

}  // namespace occull::simd
