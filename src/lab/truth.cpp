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
#include <optional>

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

namespace {

// The rays of a view's pixel centres, from the near plane to the depth a
// depth image holds there, and where they enter an object's box: the
// arithmetic both the depth-error check and the box bound rely on.
class PixelRays {
 public:
  PixelRays(const View& view, int width, int height)
      : view_(view), width_(width), height_(height), to_world_(glm::inverse(glm::dmat4(view.view_proj))) {}

  // Where the ray of pixel (x, y) enters `box`, as a multiple of the
  // distance from the near plane to the pixel's depth `canonical` (0 near,
  // 1 far and nothing): 1 is the pixel's surface, below 1 nearer. The depth
  // is read at its farthest within 4 float units in the last place of a
  // window depth near 1 (interpolation and storage round it; read_depth's
  // 1 - d under reversed-Z rounds near 1 too). The box is grown by what a
  // correct rasteriser may put between a surface and its pixel: its
  // coordinates' float precision, and a 64th of a pixel at that depth
  // (vertices snap to 1/256 px; a face seen at a grazing angle moves far
  // along the ray when its outline moves a little). A pixel showing nothing
  // (at the far plane, or at infinity) puts its surface at infinity: the
  // entry is 0 when the ray meets the box at all. None when it misses the
  // box.
  [[nodiscard]] std::optional<double> entry(int x, int y, float canonical_depth, const Aabb& b) const {
    const double canonical = double(canonical_depth) + std::ldexp(1.0, -22);
    const bool nothing = canonical >= 1.0;
    // A pixel showing nothing is cast to the window depth halfway, its
    // surface at infinity.
    const double stored = stored_depth(nothing ? 0.5 : canonical);
    if (!nothing && view_.clip.reversed_z && stored <= 0.0) return 0.0;  // at infinity too
    const double ndc_z = view_.clip.depth == DepthRange::zero_to_one ? stored : 2.0 * stored - 1.0;
    const double nx = (x + 0.5) / width_ * 2.0 - 1.0, ny = (y + 0.5) / height_ * 2.0 - 1.0;
    const glm::dvec3 o = unproject(nx, ny, view_.clip.near_depth());  // the ray on the near plane
    const glm::dvec3 at = unproject(nx, ny, ndc_z);
    const glm::dvec3 d = at - o;  // ... to the pixel's depth: t = 1
    const double pixel = std::max(glm::distance(unproject(nx + 2.0 / width_, ny, ndc_z), at),
                                  glm::distance(unproject(nx, ny + 2.0 / height_, ndc_z), at));
    const double slack =
        std::ldexp(double(std::max({magnitude(b.min), magnitude(b.max), magnitude(view_.eye)})), -16) +
        pixel / 64.0;
    double enter = 0.0, leave = std::numeric_limits<double>::infinity();
    for (int a = 0; a < 3; ++a) {
      const double lo = double(b.min[a]) - slack, hi = double(b.max[a]) + slack;
      if (d[a] == 0.0) {
        if (o[a] < lo || o[a] > hi) return std::nullopt;
        continue;
      }
      const double t0 = (lo - o[a]) / d[a], t1 = (hi - o[a]) / d[a];
      enter = std::max(enter, std::min(t0, t1));
      leave = std::min(leave, std::max(t0, t1));
    }
    if (enter > leave) return std::nullopt;
    return nothing ? 0.0 : enter;
  }

  // Whether the pixel's surface lies nearer than where its ray enters the
  // box, by more than kDepthErrorTolerance of that distance; false when the
  // ray misses the box.
  [[nodiscard]] bool surface_before(int x, int y, float canonical_depth, const Aabb& b) const {
    const std::optional<double> e = entry(x, y, canonical_depth, b);
    return e && *e * (1.0 - kDepthErrorTolerance) > 1.0;
  }
  // Whether the ray meets the box no farther than the pixel's surface
  // (within kDepthErrorTolerance of the distance).
  [[nodiscard]] bool box_before(int x, int y, float canonical_depth, const Aabb& b) const {
    const std::optional<double> e = entry(x, y, canonical_depth, b);
    return e && !(*e * (1.0 - kDepthErrorTolerance) > 1.0);
  }

  // The pixels whose centres the box's outline may hold, a pixel wider on
  // every side (the ray test decides); every pixel when a corner lies
  // behind the eye or before the near plane. Empty (x0 > x1) when it lies
  // off the viewport.
  struct Rect {
    int x0, y0, x1, y1;
  };
  [[nodiscard]] Rect candidates(const Aabb& b) const {
    const Rect all{0, 0, width_ - 1, height_ - 1};
    const glm::dmat4 m(view_.view_proj);
    const double near_depth = double(view_.clip.near_depth());
    double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
    for (int k = 0; k < 8; ++k) {
      const glm::dvec4 c = m * glm::dvec4(k & 1 ? b.max.x : b.min.x, k & 2 ? b.max.y : b.min.y,
                                          k & 4 ? b.max.z : b.min.z, 1.0);
      const bool beyond_near = view_.clip.reversed_z ? c.z < c.w : c.z > near_depth * c.w;
      if (!(c.w > 0.0) || !beyond_near) return all;
      const double x = (c.x / c.w + 1.0) * 0.5 * width_, y = (c.y / c.w + 1.0) * 0.5 * height_;
      x0 = std::min(x0, x), x1 = std::max(x1, x), y0 = std::min(y0, y), y1 = std::max(y1, y);
    }
    // Clamped before the conversion: a corner far off the viewport lies
    // beyond int's range, where converting is undefined.
    const auto lo = [](double v, int size) { return int(std::clamp(std::floor(v - 0.5) - 1.0, 0.0, double(size))); };
    const auto hi = [](double v, int size) { return int(std::clamp(std::ceil(v) + 1.0, -1.0, double(size - 1))); };
    return {lo(x0, width_), lo(y0, height_), hi(x1, width_), hi(y1, height_)};
  }

 private:
  const View& view_;
  int width_, height_;
  glm::dmat4 to_world_;

  static double magnitude(const glm::vec3& v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z)}); }
  [[nodiscard]] double stored_depth(double canonical) const {
    return view_.clip.reversed_z ? 1.0 - canonical : canonical;
  }
  [[nodiscard]] glm::dvec3 unproject(double x, double y, double z) const {
    const glm::dvec4 p = to_world_ * glm::dvec4(x, y, z, 1.0);
    return glm::dvec3(p) / p.w;
  }
};

}  // namespace

std::vector<ObjectId> seen_only_through_depth_errors(const Scene& scene, const View& view,
                                                     std::span<const std::uint32_t> ids, std::span<const float> depth,
                                                     int width, int height) {
  const std::size_t n = scene.objects().size();
  std::vector<std::uint8_t> seen(n, 0), own_surface(n, 0);
  const PixelRays rays(view, width, height);
  for (int y = 0; y < height; ++y)
    for (int x = 0; x < width; ++x) {
      const std::size_t i = std::size_t(y) * std::size_t(width) + std::size_t(x);
      if (ids[i] == 0 || ids[i] > n) continue;
      const ObjectId id = ids[i] - 1;
      seen[id] = 1;
      if (own_surface[id]) continue;
      if (!rays.surface_before(x, y, depth[i], scene.object(id).bounds)) own_surface[id] = 1;
    }
  std::vector<ObjectId> only;
  for (ObjectId id = 0; id < n; ++id)
    if (seen[id] && !own_surface[id]) only.push_back(id);
  return only;
}

std::vector<ObjectId> boxes_reaching_depth(const Scene& scene, const View& view, std::span<const ObjectId> objects,
                                           std::span<const float> depth, int width, int height) {
  const PixelRays rays(view, width, height);
  std::vector<ObjectId> reach;
  for (ObjectId id : objects) {
    const Aabb& b = scene.object(id).bounds;
    const PixelRays::Rect r = rays.candidates(b);
    bool reaches = false;
    for (int y = r.y0; y <= r.y1 && !reaches; ++y)
      for (int x = r.x0; x <= r.x1 && !reaches; ++x)
        reaches = rays.box_before(x, y, depth[std::size_t(y) * std::size_t(width) + std::size_t(x)], b);
    if (reaches) reach.push_back(id);
  }
  std::sort(reach.begin(), reach.end());
  return reach;
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
  t.visible = device_->visible_pixels(view, in_frustum, &images);
  if (hooks_ && hooks_->truth_images) hooks_->truth_images(t.visible, images);
  // The full scene, for comparison: every opaque object left out of the
  // truth pass, drawn over its depth, must not pass a single sample.
  std::vector<std::uint8_t> drawn(objects.size(), 0);
  for (ObjectId id : in_frustum) drawn[id] = 1;
  for (ObjectId id = 0; id < objects.size(); ++id)
    if (!drawn[id] && scene.alive(id) && !scene.material(objects[id].material).translucent) outside.push_back(id);
  const std::uint64_t outside_samples = device_->samples_in_front(view, outside);

  device_->check("the ground truth");
  std::sort(in_frustum.begin(), in_frustum.end());
  detail::check_truth_in_frustum(where, t.visible, in_frustum);
  detail::check_truth_covers_full_render(where, images.ids, images.depth, outside_samples);
  detail::check_truth_not_empty(where, t.visible, images.ids, scene);
  t.probes = std::uint32_t(detail::check_truth_probes(where, scene, view, in_frustum, images.depth,
                                                       renderer_options_.cull_backfaces));
  t.coverage = detail::depth_coverage(images.depth);
  t.subpixel = detail::check_truth_holds_samples(where, t.visible, scene, view);
  t.depth_error_only = seen_only_through_depth_errors(scene, view, images.ids, images.depth, device_->width(),
                                                      device_->height());
  if (box_reach_) {
    t.box_reach = boxes_reaching_depth(scene, view, in_frustum, images.depth, device_->width(), device_->height());
    if (hooks_ && hooks_->box_reach) hooks_->box_reach(t.box_reach);
    detail::check_box_reach_holds_truth(where, t.visible, t.depth_error_only, t.box_reach);
  }
  return t;
}

std::vector<ObjectId> Session::verify_frame(std::string_view name, const Culler& culler, const CameraPath& path,
                                            int k, const FrameTruth& t, FrameStats& s) {
  const detail::FrameLabel where{scene_spec_, path.name(), k};
  std::vector<float> depth = device_->read_depth();
  if (hooks_ && hooks_->frame_depth) hooks_->frame_depth(depth);
  const Coverage frame = detail::depth_coverage(depth);
  detail::check_frame_within_truth(where, std::string(name), t.coverage, frame);
  if (const auto* oracle = dynamic_cast<const detail::OracleCuller*>(&culler)) {
    if (oracle->boxes())
      detail::check_oracle_draws(where, t.box_reach, recorder_->objects());
    else
      detail::check_oracle_draws_truth(where, t.visible, recorder_->objects(), t.coverage.depth_hash,
                                       frame.depth_hash);
  }
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
