#include "invariants.hpp"

#include "occull/error.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <cstring>

namespace occull::detail {

void invariant_violated(const FrameLabel& where, std::string_view invariant, const std::string& detail) {
  throw InvariantViolation(fmt::format(
      "invariant {} violated — scene {}, path {}, frame {}: {}. The instrument cannot be trusted: "
      "nothing was measured against a broken ground truth (please report this with the command)",
      invariant, where.scene, where.path, where.frame, detail));
}

Coverage depth_coverage(std::span<const float> depth) {
  Coverage c;
  c.bits.assign((depth.size() + 63) / 64, 0);
  std::uint64_t h = 0xcbf29ce484222325ull;  // FNV-1a over the 32-bit patterns
  for (std::size_t i = 0; i < depth.size(); ++i) {
    std::uint32_t v;
    std::memcpy(&v, &depth[i], sizeof v);
    h = (h ^ v) * 0x100000001b3ull;
    if (depth[i] < 1.0f) {
      c.bits[i / 64] |= std::uint64_t(1) << (i % 64);
      ++c.pixels;
    }
  }
  c.depth_hash = h;
  return c;
}

void check_truth_in_frustum(const FrameLabel& where, std::span<const gl::Renderer::ObjectPixels> visible,
                            std::span<const ObjectId> drawn) {
  for (const auto& v : visible)
    if (!std::binary_search(drawn.begin(), drawn.end(), v.id))
      invariant_violated(where, "truth-in-frustum",
                         fmt::format("object {} is in the truth ({} pixels) but was not drawn by the "
                                     "truth pass (not inside the frustum)",
                                     v.id, v.pixels));
}

std::uint32_t check_truth_holds_samples(const FrameLabel& where, std::span<const gl::Renderer::ObjectPixels> visible,
                                        const Scene& scene, const View& view, const SubpixelRules& rules) {
  for (const auto& v : visible)
    if (holds_no_sample(scene.object(v.id).bounds, view, rules))
      invariant_violated(where, "truth-holds-samples",
                         fmt::format("object {} is in the truth ({} pixels) but its box holds no pixel centre by "
                                     "the sub-pixel rule (holds_no_sample): the rule would cull a visible object",
                                     v.id, v.pixels));
  std::uint32_t count = 0;
  for (ObjectId id = 0; id < scene.objects().size(); ++id) {
    const Aabb& box = scene.object(id).bounds;
    if (scene.alive(id) && view.frustum.classify(box) != Containment::outside && holds_no_sample(box, view, rules))
      ++count;
  }
  return count;
}

void check_truth_covers_full_render(const FrameLabel& where, std::span<const std::uint32_t> ids,
                                    std::span<const float> depth, std::uint64_t outside_samples) {
  std::uint64_t id_only = 0, depth_only = 0;
  std::size_t first = ids.size();
  for (std::size_t i = 0; i < ids.size() && i < depth.size(); ++i) {
    const bool has_id = ids[i] != 0, has_depth = depth[i] < 1.0f;
    if (has_id == has_depth) continue;
    (has_id ? id_only : depth_only) += 1;
    first = std::min(first, i);
  }
  if (ids.size() != depth.size() || id_only + depth_only > 0)
    invariant_violated(where, "truth-covers-full-render",
                       fmt::format("the id image and the depth image of the truth pass disagree: {} "
                                   "pixels have an id but no depth, {} have depth but no id (first at "
                                   "pixel {}); images of {} and {} pixels",
                                   id_only, depth_only, first, ids.size(), depth.size()));
  if (outside_samples > 0)
    invariant_violated(where, "truth-covers-full-render",
                       fmt::format("objects classified outside the frustum cover {} samples in front of "
                                   "the truth pass: the truth misses what the full scene shows",
                                   outside_samples));
}

void check_truth_not_empty(const FrameLabel& where, std::span<const gl::Renderer::ObjectPixels> visible,
                           std::span<const std::uint32_t> ids, const Scene& scene) {
  std::vector<std::uint32_t> counts(scene.objects().size(), 0);
  std::uint64_t covered = 0;
  for (std::uint32_t v : ids) {
    if (v == 0) continue;
    ++covered;
    if (v - 1 >= counts.size())
      invariant_violated(where, "truth-not-empty", fmt::format("the id image holds {}, not an object id + 1", v));
    ++counts[v - 1];
  }
  if (covered > 0 && visible.empty())
    invariant_violated(where, "truth-not-empty",
                       fmt::format("the truth is empty while the truth pass covers {} pixels", covered));
  std::size_t listed_opaque = 0;
  for (const auto& v : visible) {
    if (v.id >= counts.size())
      invariant_violated(where, "truth-not-empty", fmt::format("object {} of the truth does not exist", v.id));
    if (scene.material(scene.object(v.id).material).translucent) continue;
    ++listed_opaque;
    if (counts[v.id] != v.pixels)
      invariant_violated(where, "truth-not-empty",
                         fmt::format("object {} is listed with {} pixels, the id image has {}", v.id, v.pixels,
                                     counts[v.id]));
  }
  const auto in_image = std::size_t(std::count_if(counts.begin(), counts.end(), [](std::uint32_t c) { return c > 0; }));
  if (in_image != listed_opaque)
    invariant_violated(where, "truth-not-empty",
                       fmt::format("the id image shows {} objects, the truth lists {} opaque ones", in_image,
                                   listed_opaque));
}

namespace {

double cross2(const glm::dvec2& a, const glm::dvec2& b) { return a.x * b.y - a.y * b.x; }

}  // namespace

std::size_t check_truth_probes(const FrameLabel& where, const Scene& scene, const View& view,
                               std::span<const ObjectId> drawn, std::span<const float> depth,
                               bool back_faces_culled, std::size_t max_probes) {
  // A triangle wholly between the near and far planes, front-facing, whose
  // centre pixel lies at least half a pixel inside all three edges, covers
  // that pixel in any correct rasterisation; the depth there can only be
  // its own or nearer. Computed on the CPU from the scene alone.
  const double w = view.width, h = view.height;
  constexpr double kInside = 0.5;      // pixels from every edge: far beyond any vertex snapping
  // Depth slack: the rasteriser evaluates the depth plane of snapped vertices
  // in float, so allow ~16 ulps near 1 plus the depth change over a tenth of
  // a pixel along the triangle's own depth gradient (steep triangles near
  // the eye change depth fast across a pixel).
  constexpr double kDepthSlack = 1e-6;
  constexpr double kSnapPixels = 0.1;
  constexpr double kFloatUlps = 4.0;  // of float rounding in the device's clip-space products
  const glm::dmat4 view_proj(view.view_proj);
  const bool zero_to_one = view.clip.depth == DepthRange::zero_to_one;
  const double depth_scale = zero_to_one ? 1.0 : 0.5;  // window depth per unit of normalised depth
  // Largest on screen first: their triangles are the likeliest to qualify.
  std::vector<std::pair<double, ObjectId>> candidates;
  for (ObjectId id : drawn) {
    const Object& o = scene.object(id);
    if (scene.material(o.material).translucent) continue;
    const double area = projected_area(o.bounds, view.view_proj, view.width, view.height);
    if (area >= 4.0) candidates.emplace_back(area, id);
  }
  const std::size_t tried = std::min(candidates.size(), 4 * max_probes);
  std::partial_sort(candidates.begin(), candidates.begin() + long(tried), candidates.end(),
                    [](const auto& a, const auto& b) { return a.first > b.first || (a.first == b.first && a.second < b.second); });
  std::size_t probed = 0;
  for (std::size_t i = 0; i < tried && probed < max_probes; ++i) {
    const ObjectId id = candidates[i].second;
    const Object& o = scene.object(id);
    const Mesh& m = scene.mesh(o.mesh);
    const glm::dmat4 transform(o.transform);
    const std::size_t triangles = m.triangle_count();
    const std::size_t tstride = std::max<std::size_t>(1, triangles / 64);
    for (std::size_t t = 0; t < triangles; t += tstride) {
      glm::dvec2 p[3];
      double z[3];
      double rounding = 0.0;  // bound on the device's float rounding of window depth, over the vertices
      bool usable = true;
      for (int k = 0; k < 3 && usable; ++k) {
        // In double here; the device works in float, whose rounding of the
        // clip-space dot products grows with the magnitude of world
        // coordinates (a tiled world's camera is kilometres from the
        // origin), not with the depth: ~2 ulps of each row's terms.
        const glm::dvec4 world = transform * glm::dvec4(m.positions[m.indices[3 * t + std::size_t(k)]], 1.0);
        const glm::dvec4 clip = view_proj * world;
        usable = clip.w > 0.0 && clip.z > (zero_to_one ? 0.0 : -clip.w) && clip.z < clip.w;
        p[k] = {(clip.x / clip.w * 0.5 + 0.5) * w, (clip.y / clip.w * 0.5 + 0.5) * h};
        // Canonical window depth, as read_depth() gives it: 0 nearest, 1 farthest.
        const double window = zero_to_one ? clip.z / clip.w : clip.z / clip.w * 0.5 + 0.5;
        z[k] = view.clip.reversed_z ? 1.0 - window : window;
        double terms = 0.0;
        for (int j = 0; j < 4; ++j) terms += (std::abs(view_proj[j][2]) + std::abs(view_proj[j][3])) * std::abs(world[j]);
        rounding = std::max(rounding, depth_scale * kFloatUlps * 0x1p-24 * terms / clip.w);
      }
      if (!usable) continue;
      const double area2 = cross2(p[1] - p[0], p[2] - p[0]);  // twice the signed area, CCW > 0
      if (back_faces_culled ? area2 < 8.0 : std::abs(area2) < 8.0) continue;
      const glm::dvec2 centre = (p[0] + p[1] + p[2]) / 3.0;
      const double px = std::floor(centre.x), py = std::floor(centre.y);
      if (px < 0 || py < 0 || px >= w || py >= h) continue;
      const glm::dvec2 c{px + 0.5, py + 0.5};
      const double sign = area2 > 0 ? 1.0 : -1.0;
      double lambda[3];
      bool inside = true;
      for (int k = 0; k < 3 && inside; ++k) {
        const glm::dvec2& a = p[(k + 1) % 3];
        const glm::dvec2& b = p[(k + 2) % 3];
        const double edge = cross2(b - a, c - a);  // opposite vertex k
        inside = sign * edge / glm::length(b - a) >= kInside;
        lambda[k] = edge / area2;
      }
      if (!inside) continue;
      const double z_tri = lambda[0] * z[0] + lambda[1] * z[1] + lambda[2] * z[2];
      const double dz_dx = ((z[1] - z[0]) * (p[2].y - p[0].y) - (z[2] - z[0]) * (p[1].y - p[0].y)) / area2;
      const double dz_dy = ((z[2] - z[0]) * (p[1].x - p[0].x) - (z[1] - z[0]) * (p[2].x - p[0].x)) / area2;
      const double slack = kDepthSlack + rounding + kSnapPixels * (std::abs(dz_dx) + std::abs(dz_dy));
      if (z_tri + slack > 1.0 - kDepthSlack) continue;  // too close to the far plane to tell from nothing
      const float z_buf = depth[std::size_t(py) * std::size_t(view.width) + std::size_t(px)];
      if (double(z_buf) > z_tri + slack)
        invariant_violated(
            where, "truth-probe",
            fmt::format("triangle {} of object {} covers pixel ({}, {}) at window depth {:.7f}, but the truth "
                        "pass has {} there",
                        t, id, px, py, z_tri,
                        z_buf >= 1.0f ? std::string("nothing") : fmt::format("depth {:.7f}", z_buf)));
      ++probed;
      break;
    }
  }
  return probed;
}

void check_frame_within_truth(const FrameLabel& where, const std::string& algorithm,
                              const Coverage& truth, const Coverage& frame) {
  std::uint64_t outside = 0;
  std::size_t first = 0;
  for (std::size_t i = 0; i < frame.bits.size(); ++i) {
    const std::uint64_t extra = frame.bits[i] & ~(i < truth.bits.size() ? truth.bits[i] : 0);
    if (extra && outside == 0) first = i * 64 + std::size_t(__builtin_ctzll(extra));
    outside += std::uint64_t(__builtin_popcountll(extra));
  }
  if (outside > 0 || frame.bits.size() != truth.bits.size())
    invariant_violated(where, "frame-within-truth",
                       fmt::format("{} covers {} pixels the ground truth leaves empty (first: pixel {}; truth "
                                   "covers {} pixels, the frame {}): an algorithm draws a subset of the "
                                   "scene, so the truth is missing what the scene shows",
                                   algorithm, outside, first, truth.pixels, frame.pixels));
}

void check_oracle_draws(const FrameLabel& where, std::span<const ObjectId> expected, std::span<const ObjectId> rendered) {
  std::vector<ObjectId> drawn(rendered.begin(), rendered.end());
  std::sort(drawn.begin(), drawn.end());
  drawn.erase(std::unique(drawn.begin(), drawn.end()), drawn.end());
  if (std::equal(drawn.begin(), drawn.end(), expected.begin(), expected.end())) return;
  std::vector<ObjectId> missing, extra;
  std::set_difference(expected.begin(), expected.end(), drawn.begin(), drawn.end(), std::back_inserter(missing));
  std::set_difference(drawn.begin(), drawn.end(), expected.begin(), expected.end(), std::back_inserter(extra));
  invariant_violated(where, "oracle-draws-truth",
                     fmt::format("the oracle drew {} objects for a set of {}: {} missing (first {}), {} "
                                 "extra (first {})",
                                 drawn.size(), expected.size(), missing.size(),
                                 missing.empty() ? std::string("-") : std::to_string(missing[0]), extra.size(),
                                 extra.empty() ? std::string("-") : std::to_string(extra[0])));
}

void check_oracle_draws_truth(const FrameLabel& where, std::span<const gl::Renderer::ObjectPixels> visible,
                              std::span<const ObjectId> rendered, std::uint64_t truth_depth_hash,
                              std::uint64_t frame_depth_hash) {
  std::vector<ObjectId> truth;
  for (const auto& v : visible) truth.push_back(v.id);
  check_oracle_draws(where, truth, rendered);
  if (truth_depth_hash != frame_depth_hash)
    invariant_violated(where, "oracle-draws-truth",
                       "the oracle drew the truth's objects but its depth image differs from the truth pass's");
}

void check_box_reach_holds_truth(const FrameLabel& where, std::span<const gl::Renderer::ObjectPixels> visible,
                                 std::span<const ObjectId> depth_error_only, std::span<const ObjectId> box_reach) {
  std::size_t outside = 0;
  ObjectId first = 0;
  for (const auto& v : visible)
    if (!std::binary_search(box_reach.begin(), box_reach.end(), v.id) &&
        !std::binary_search(depth_error_only.begin(), depth_error_only.end(), v.id))
      if (outside++ == 0) first = v.id;
  if (outside > 0)
    invariant_violated(where, "box-reach-holds-truth",
                       fmt::format("{} visible objects (first {}) have boxes that reach in front of the truth's depth "
                                   "at no pixel centre",
                                   outside, first));
}

}  // namespace occull::detail
