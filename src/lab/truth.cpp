// Ground truth and verification: the truth pass of a frame with its
// invariants, and each culler frame checked against it.
#include "occull/lab.hpp"

#include "fault_hooks.hpp"
#include "invariants.hpp"
#include "oracle.hpp"
#include "watchdog.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

namespace occull {

std::vector<ObjectId> check_frame(std::span<const gl::Renderer::ObjectPixels> truth,
                                  std::span<const ObjectId> rendered, std::size_t object_count,
                                  FrameStats& stats, std::span<const ObjectId> depth_error_only) {
  std::vector<std::uint8_t> drawn(object_count, 0);
  for (ObjectId id : rendered) drawn[id] = 1;
  std::vector<ObjectId> missed;
  stats.truth_objects = std::uint32_t(truth.size());
  stats.missed_objects = 0;
  stats.wrong_pixels = 0;
  stats.depth_error_objects = 0;
  std::size_t rendered_and_visible = 0;
  for (const auto& t : truth) {
    if (drawn[t.id]) {
      ++rendered_and_visible;
    } else if (std::binary_search(depth_error_only.begin(), depth_error_only.end(), t.id)) {
      ++stats.depth_error_objects;
    } else {
      missed.push_back(t.id);
      stats.wrong_pixels += t.pixels;
    }
  }
  stats.missed_objects = std::uint32_t(missed.size());
  const auto distinct = std::size_t(std::count(drawn.begin(), drawn.end(), std::uint8_t(1)));
  stats.extra_objects = std::uint32_t(distinct - rendered_and_visible);
  return missed;
}

std::vector<ObjectId> seen_only_through_depth_errors(const Scene& scene, const View& view,
                                                     std::span<const std::uint32_t> ids, std::span<const float> depth,
                                                     int width, int height) {
  const std::size_t n = scene.objects().size();
  std::vector<std::uint8_t> seen(n, 0), own_surface(n, 0);
  const glm::dmat4 to_world = glm::inverse(glm::dmat4(view.view_proj));
  const auto unproject = [&](double x, double y, double z) {
    const glm::dvec4 p = to_world * glm::dvec4(x, y, z, 1.0);
    return glm::dvec3(p) / p.w;
  };
  // A depth value is read at its farthest within 4 float units in the last
  // place of a window depth near 1 (interpolation and storage round it;
  // read_depth's 1 - d under reversed-Z rounds near 1 too).
  const double reading = std::ldexp(1.0, -22);
  const auto magnitude = [](const glm::vec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); };
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(width) + std::size_t(x);
      if (ids[i] == 0 || ids[i] > n) continue;
      const ObjectId id = ids[i] - 1;
      seen[id] = 1;
      if (own_surface[id]) continue;
      // Canonical depth (0 near, 1 far) to the stored window depth, then to clip space.
      const double canonical = double(depth[i]) + reading;
      const double stored = view.clip.reversed_z ? 1.0 - canonical : canonical;
      const double ndc_z = view.clip.depth == DepthRange::zero_to_one ? stored : 2.0 * stored - 1.0;
      if (canonical >= 1.0 || (view.clip.reversed_z && stored <= 0.0)) {
        own_surface[id] = 1;  // at the far plane, or at infinity: nothing lies beyond
        continue;
      }
      const double nx = (x + 0.5) / width * 2.0 - 1.0, ny = (y + 0.5) / height * 2.0 - 1.0;
      const glm::dvec3 o = unproject(nx, ny, view.clip.near_depth());  // the ray on the near plane
      const glm::dvec3 at = unproject(nx, ny, ndc_z);
      const glm::dvec3 d = at - o;  // ... to the pixel's depth: t = 1
      // The box grown by what a correct rasteriser may put between a surface
      // and its pixel: its coordinates' float precision, and a 64th of a
      // pixel at that depth (vertices snap to 1/256 px; a face seen at a
      // grazing angle moves far along the ray when its outline moves a little).
      const double pixel = std::max(glm::distance(unproject(nx + 2.0 / width, ny, ndc_z), at),
                                    glm::distance(unproject(nx, ny + 2.0 / height, ndc_z), at));
      const Aabb& b = scene.object(id).bounds;
      const double slack =
          std::ldexp(double(std::max({magnitude(b.min), magnitude(b.max), magnitude(view.eye)})), -16) +
          pixel / 64.0;
      double enter = 0.0, leave = std::numeric_limits<double>::infinity();
      for (int a = 0; a < 3; ++a) {
        const double lo = double(b.min[a]) - slack, hi = double(b.max[a]) + slack;
        if (d[a] == 0.0) {
          if (o[a] < lo || o[a] > hi) leave = -1.0;
          continue;
        }
        const double t0 = (lo - o[a]) / d[a], t1 = (hi - o[a]) / d[a];
        enter = std::max(enter, std::min(t0, t1));
        leave = std::min(leave, std::max(t0, t1));
      }
      const bool nearer_than_box = enter <= leave && enter * (1.0 - kDepthErrorTolerance) > 1.0;
      if (!nearer_than_box) own_surface[id] = 1;
    }
  std::vector<ObjectId> only;
  for (ObjectId id = 0; id < n; ++id)
    if (seen[id] && !own_surface[id]) only.push_back(id);
  return only;
}

std::vector<FrameTruth> Session::ground_truth(const CameraPath& path, int frames,
                                              const ProgressFn& progress) {
  std::vector<FrameTruth> truth;
  truth.reserve(std::size_t(frames));
  for (int k = 0; k < frames; ++k) {
    truth.push_back(truth_at(path, k, frames));
    if (progress) progress("ground truth", k, frames, false);
  }
  return truth;
}

FrameTruth Session::truth_at(const CameraPath& path, int k, int frames) {
  const View view = view_at(path, k, frames);  // the floating origin first: the scene's motions follow it
  advance_scene(frame_time(path, k, frames));
  const detail::FrameLabel where{scene_spec_, path.name(), k};
  if (bundle_.world) {
    bundle_.world->follow(bundle_.scene, view.eye);
    // The truth sees only the placed cells: the window must hold the frustum.
    if (!bundle_.world->covers(view))
      detail::invariant_violated(where, "window-covers-frustum",
                                 fmt::format("the frustum reaches past the {} x {} cells placed around the eye",
                                             2 * bundle_.world->radius() + 1, 2 * bundle_.world->radius() + 1));
  }
  return truth_of(view, where);
}

FrameTruth Session::truth_of(const View& view) { return truth_of(view, {scene_spec_, "(free camera)", 0}); }

FrameTruth Session::truth_of(const View& view, const detail::FrameLabel& where) {
  const Scene& scene = bundle_.scene;
  const auto objects = scene.objects();
  const auto step = watchdog_->step(fmt::format("ground-truth frame {} of path {}", where.frame, where.path));
  std::vector<ObjectId> in_frustum, outside;
  for (ObjectId id = 0; id < objects.size(); ++id)
    if (view.frustum.classify(objects[id].bounds) != Containment::outside) in_frustum.push_back(id);
  if (hooks_ && hooks_->truth_objects) hooks_->truth_objects(in_frustum);

  FrameTruth t;
  gl::Renderer::PassImages images;
  t.visible = renderer_->visible_pixels(view, in_frustum, &images);
  if (hooks_ && hooks_->truth_images) hooks_->truth_images(t.visible, images);
  // The full scene, for comparison: every opaque object left out of the
  // truth pass, drawn over its depth, must not pass a single sample.
  std::vector<std::uint8_t> drawn(objects.size(), 0);
  for (ObjectId id : in_frustum) drawn[id] = 1;
  for (ObjectId id = 0; id < objects.size(); ++id)
    if (!drawn[id] && scene.alive(id) && !scene.material(objects[id].material).translucent) outside.push_back(id);
  const std::uint64_t outside_samples = renderer_->samples_in_front(view, outside);

  context_->check("the ground truth");
  std::sort(in_frustum.begin(), in_frustum.end());
  detail::check_truth_in_frustum(where, t.visible, in_frustum);
  detail::check_truth_covers_full_render(where, images.ids, images.depth, outside_samples);
  detail::check_truth_not_empty(where, t.visible, images.ids, scene);
  t.probes = std::uint32_t(detail::check_truth_probes(where, scene, view, in_frustum, images.depth,
                                                       renderer_options_.cull_backfaces));
  t.coverage = detail::depth_coverage(images.depth);
  t.subpixel = detail::check_truth_holds_samples(where, t.visible, scene, view);
  t.depth_error_only = seen_only_through_depth_errors(scene, view, images.ids, images.depth, renderer_->width(),
                                                      renderer_->height());
  return t;
}

std::vector<ObjectId> Session::verify_frame(std::string_view name, const Culler& culler, const CameraPath& path,
                                            int k, const FrameTruth& t, FrameStats& s) {
  const detail::FrameLabel where{scene_spec_, path.name(), k};
  std::vector<float> depth = renderer_->read_depth();
  if (hooks_ && hooks_->frame_depth) hooks_->frame_depth(depth);
  const Coverage frame = detail::depth_coverage(depth);
  detail::check_frame_within_truth(where, std::string(name), t.coverage, frame);
  if (dynamic_cast<const detail::OracleCuller*>(&culler))
    detail::check_oracle_draws_truth(where, t.visible, recorder_->objects(), t.coverage.depth_hash,
                                     frame.depth_hash);
  s.subpixel_objects = t.subpixel;
  return check_frame(t.visible, recorder_->objects(), bundle_.scene.objects().size(), s, t.depth_error_only);
}

void MissRuns::add(const std::vector<ObjectId>& missed) {
  for (ObjectId id : previous_)
    if (!std::binary_search(missed.begin(), missed.end(), id)) run_[id] = 0;
  for (ObjectId id : missed) longest_ = std::max(longest_, ++run_[id]);
  previous_ = missed;
}

}  // namespace occull
