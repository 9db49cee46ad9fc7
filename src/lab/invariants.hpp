// Internal: the run-time invariants of the instrument (occull bench
// --verify on). Every verified frame is checked; a violation throws
// InvariantViolation naming the invariant, scene, path and frame, because
// a measurement against a broken ground truth is worse than none.
//
//   truth-holds-samples       no visible object of the truth holds no pixel
//                             centre by the sub-pixel rule (holds_no_sample).
//   truth-in-frustum          every visible object of the truth is one the
//                             truth pass drew: an object inside the frustum
//   truth-covers-full-render  the truth pass's id image covers exactly the
//                             pixels its depth image covers, and no object
//                             outside the frustum, drawn over it, passes a
//                             single sample: the id pass shows what the full
//                             scene would
//   truth-not-empty           the visible list is exactly the ids of the id
//                             image (so a covered frame has a non-empty truth)
//   truth-probe               an independent CPU check: for sampled
//                             front-facing triangles of objects in the
//                             frustum, the pixel under the triangle's centre
//                             is covered at least as near as the triangle
//   frame-within-truth        every pixel an algorithm's frame covers is
//                             covered in the truth (it draws a subset)
//   oracle-draws-truth        the oracle renders exactly the truth's objects
//                             and reproduces its depth image bit for bit
//                             (oracle:set=boxes: exactly the box reach)
//   box-reach-holds-truth     every object of the truth (but those seen only
//                             through depth errors) has a box that reaches
//                             in front of the truth's depth (when the
//                             session computes the box reach)
#pragma once

#include "occull/gl/renderer.hpp"
#include "occull/lab.hpp"

#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace occull::detail {

/// Where a check runs, for the message.
struct FrameLabel {
  std::string scene;
  std::string path;
  int frame = 0;
};

/// Throws InvariantViolation: "invariant <name> violated — scene S, path P, frame K: detail".
[[noreturn]] void invariant_violated(const FrameLabel& where, std::string_view invariant,
                                     const std::string& detail);

/// Opaque coverage of a depth image: a bit per pixel where depth < 1, the
/// number of such pixels, and a hash of every depth value.
[[nodiscard]] Coverage depth_coverage(std::span<const float> depth);

/// truth-in-frustum. `drawn`: the ids the truth pass drew, ascending.
void check_truth_in_frustum(const FrameLabel& where, std::span<const gl::Renderer::ObjectPixels> visible,
                            std::span<const ObjectId> drawn);

/// truth-holds-samples: no object of the truth may hold no sample by the
/// sub-pixel rule (holds_no_sample with `rules`; a test breaks them).
/// Returns how many objects of the frustum hold none.
std::uint32_t check_truth_holds_samples(const FrameLabel& where, std::span<const gl::Renderer::ObjectPixels> visible,
                                        const Scene& scene, const View& view, const SubpixelRules& rules = {});

/// truth-covers-full-render. `outside_samples`: samples of the objects
/// outside the frustum that passed the depth test over the truth pass.
void check_truth_covers_full_render(const FrameLabel& where, std::span<const std::uint32_t> ids,
                                    std::span<const float> depth, std::uint64_t outside_samples);

/// truth-not-empty. `scene` tells opaque from translucent objects (the
/// latter own no id pixels).
void check_truth_not_empty(const FrameLabel& where, std::span<const gl::Renderer::ObjectPixels> visible,
                           std::span<const std::uint32_t> ids, const Scene& scene);

/// truth-probe over up to `max_probes` objects of `drawn` (translucent ones
/// skipped). Returns how many triangles were probed (0 when none
/// qualified: all too small, clipped or edge-on).
std::size_t check_truth_probes(const FrameLabel& where, const Scene& scene, const View& view,
                               std::span<const ObjectId> drawn, std::span<const float> depth,
                               bool back_faces_culled, std::size_t max_probes = 16);

/// frame-within-truth.
void check_frame_within_truth(const FrameLabel& where, const std::string& algorithm,
                              const Coverage& truth, const Coverage& frame);

/// oracle-draws-truth for a set of objects: the oracle handed the backend
/// (`rendered`) exactly `expected` (ascending).
void check_oracle_draws(const FrameLabel& where, std::span<const ObjectId> expected, std::span<const ObjectId> rendered);
/// box-reach-holds-truth. `depth_error_only` and `box_reach` ascending.
void check_box_reach_holds_truth(const FrameLabel& where, std::span<const gl::Renderer::ObjectPixels> visible,
                                 std::span<const ObjectId> depth_error_only, std::span<const ObjectId> box_reach);

/// oracle-draws-truth. `rendered`: the objects the oracle handed the backend.
void check_oracle_draws_truth(const FrameLabel& where, std::span<const gl::Renderer::ObjectPixels> visible,
                              std::span<const ObjectId> rendered, std::uint64_t truth_depth_hash,
                              std::uint64_t frame_depth_hash);

}  // namespace occull::detail
