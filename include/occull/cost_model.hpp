// occull — the NOHC hardware cost model and occlusion probability model
// (Guthe, Balázs, Klein 2006).
//
// A HardwareProfile holds the characteristic times of Table 2, measured once
// per renderer by calibration (occull calibrate, gl::calibrate). The
// functions below turn them, with a node's screen coverage, into the
// rendering time t_r, the query time t_o and the occlusion probability the
// NOHC culler schedules its queries by. All times in milliseconds; screen
// fractions in [0, 1].
#pragma once

#include "occull/geometry.hpp"
#include "occull/view.hpp"

#include <cstdint>
#include <map>
#include <string>

namespace occull {

/// Characteristic times of one renderer (Guthe et al. 2006, Table 2), milliseconds.
struct HardwareProfile {
  std::string renderer;              ///< GL_RENDERER and GL_VERSION it was measured on
  int width = 0;                     ///< render-target size used for the measurement, pixels
  int height = 0;
  double draw_setup_ms = 0.0;        ///< T_r^s: per draw call
  double triangle_ms = 0.0;          ///< T_r^Δ: per triangle
  /// T_r^f: per shaded fragment, by material shading cost (Material::shading_cost).
  std::map<int, double> fragment_ms;
  double query_setup_ms = 0.0;       ///< T_o^s: per occlusion query (a box)
  double query_fragment_ms = 0.0;    ///< T_o^f: per fragment of a query box
  double query_latency_ms = 0.0;     ///< T_o^l: longest wait from issue to result
  double query_overhead_ms = 0.0;    ///< T_o^o: a query issued along with rendering, over rendering alone

  /// T_r^f for a shading cost: the measured class, or linear interpolation /
  /// extrapolation between the nearest measured ones. Throws UsageError for an
  /// empty fragment_ms.
  [[nodiscard]] double fragment_cost(int shading_cost) const;
  /// N_q = ceil(T_o^l / min(T_o^s, T_o^o + T_r^s)) + 1: queries that can be in
  /// flight before the first one must have finished.
  [[nodiscard]] int max_parallel_queries() const;
};

/// What the model needs to know of a node (or object) in one view.
struct NodeCost {
  std::uint32_t draws = 0;        ///< draw calls to render it (objects)
  std::uint64_t triangles = 0;
  double shading_cost = 0.0;      ///< mean material shading cost, weighted by triangles
  double c_bb = 0.0;              ///< screen fraction of its bounding box
  double r_cov = 1.0;             ///< R_cov: c(O) ≈ R_cov · c_bb
};

/// c_bb by the paper's approximation: ((1 / (d · sqrt(w/h) · 2 tan(θ/2)))^2 · A_bb / 6,
/// clamped to [0, 1]. d: distance eye–box (scene units, > 0; 0 gives 1),
/// A_bb: box surface area, θ: vertical field of view (radians).
[[nodiscard]] double bbox_screen_fraction(double box_area, double distance, int width, int height,
                                          double fov_y);
/// The same fraction for the projection of `view` (asymmetric, jittered,
/// orthographic): the screen spans 2d / proj[0][0] by 2d / proj[1][1] scene
/// units at distance d (2 / proj[0][0] by 2 / proj[1][1] at any distance
/// when orthographic). Equals the formula above for a symmetric perspective
/// view with θ = 2 atan(1 / proj[1][1]).
[[nodiscard]] double bbox_screen_fraction(double box_area, double distance, const View& view);

/// R_cov = 3/2 · A(O) / A_bb (sphere-like objects seen face-on boxes).
[[nodiscard]] double coverage_ratio(double object_area, double box_area);

/// Screen fraction the object itself covers: min(1, R_cov) · c_bb.
[[nodiscard]] double object_screen_fraction(const NodeCost& n);

/// Front-to-back accumulation: c_scr(O_{i+1}) = c_scr + (1 - c_scr) · c(O_i).
[[nodiscard]] double accumulate_coverage(double c_scr, double c_object);

/// p_cov = (sqrt(c_scr) - sqrt(c_bb))^2 when c_bb < c_scr, else 0.
[[nodiscard]] double coverage_probability(double c_scr, double c_bb);

/// What a node was in the previous frame, for p_occl.
enum class PreviousState : std::uint8_t { visible, outside, occluded };

/// p_occl: 1/2 p_cov^2 if previously visible, p_cov if previously outside the
/// frustum (or unknown), 1 if previously occluded.
[[nodiscard]] double occlusion_probability(PreviousState previous, double p_cov);

/// t_r = max(draws · T_r^s, triangles · T_r^Δ, f · T_r^f) with f = fragments_per_pixel · w · h · c(O).
[[nodiscard]] double render_time(const HardwareProfile& hw, const NodeCost& n, int width, int height,
                                 double fragments_per_pixel = 2.0);

/// t_o = T_o^s + w · h · c_bb · T_o^f (one query whose boxes cover c_bb).
[[nodiscard]] double query_time(const HardwareProfile& hw, double c_bb, int width, int height);

}  // namespace occull
