// occull — views and camera paths.
#pragma once

#include "occull/geometry.hpp"

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace occull {

/// One camera's view for one frame. Build it with make_view() (from an
/// engine's matrices, or from a pose and a lens) so the derived members
/// (eye, view_proj, frustum, near, far, near_radius, eye_projection) agree
/// with the others.
struct View {
  glm::vec3 eye{0.0f};       ///< camera position, world space (the view matrix's origin)
  glm::mat4 view{1.0f};      ///< world to eye space
  glm::mat4 proj{1.0f};      ///< eye to clip space, with the conventions `clip`
  glm::mat4 view_proj{1.0f}; ///< proj * view
  ClipSpace clip;            ///< depth range and reversed-Z of `proj`
  Frustum frustum;           ///< planes of view_proj (none at an infinite far plane)
  int width = 1;             ///< viewport width, pixels (> 0)
  int height = 1;            ///< viewport height, pixels (> 0)
  bool orthographic = false; ///< proj is affine (w = 1): sizes do not shrink with distance
  /// Distance of the near plane from the eye along the view direction, scene
  /// units: > 0 for a perspective view; any value below `far` for an
  /// orthographic one (its near plane may lie behind the camera).
  float near = 0.1f;
  /// Distance of the far plane, scene units (> near); +infinity for an
  /// infinite perspective projection.
  float far = 1000.0f;
  /// Distance from the eye to the farthest corner of the near-plane
  /// rectangle, scene units: a box farther than this from the eye cannot be
  /// cut by the near plane.
  float near_radius = 0.0f;
  /// How the image is sampled: 1, one sample at the centre of each of the
  /// width × height pixels (a single-sampled target of exactly that size,
  /// the default); 0, anything else or unknown (MSAA, sample shading, a
  /// render size other than width × height). Only with 1 may cullers skip a
  /// box that holds no pixel centre (holds_no_sample): drawn, it would make
  /// no fragment.
  int samples = 1;
  /// eye_relative_projection(*this), kept so that per-box tests
  /// (holds_no_sample) need not multiply it again: derived by make_view.
  glm::dmat4 eye_projection{0.0};
};

/// The projection times the view's rotation, in double: what positions
/// relative to the eye (world - eye) are projected by. The renderer projects
/// this way (small numbers near the camera whatever the coordinates' size),
/// and so does holds_no_sample.
[[nodiscard]] glm::dmat4 eye_relative_projection(const View& view) noexcept;

/// Exact sub-pixel culling: whether whatever lies in `box` (world space)
/// makes no fragment in `view`, because the rectangle its 8 corners project
/// to holds no pixel centre of the viewport. Lossless, unlike a size
/// threshold: a box smaller than a pixel that straddles a centre is kept.
/// Conservative by these rules (each with its test in tests/view_test.cpp,
/// SubpixelRules switching it off):
///  1. Only for view.samples == 1 (one sample at each pixel's centre).
///  2. The box is grown by 2^-20 of its coordinates' magnitude first: the
///     device transforms vertices in float, which can put a vertex a few
///     units in the last place outside the box it was bounded by.
///  3. Corners are projected relative to the eye in double, as the
///     renderer projects (occull/gl: world - eye, then projection times the
///     view's rotation); the rectangle is widened by 1/64 pixel on every side
///     for the device's vertex snapping (1/256 pixel on llvmpipe and current
///     GPUs) and its float projection.
///  4. A box with a corner behind the eye or in front of the near plane is
///     kept (its rectangle means nothing).
///  5. A centre on the rectangle's edge is inside (ties keep the box).
/// Returns false ("may make a fragment") for an empty box too.
struct SubpixelRules {
  bool grow_for_rounding = true;  ///< rule 2
  bool snapping_margin = true;    ///< rule 3's widening
  bool pixel_centres = true;      ///< false: a size threshold instead (the rectangle narrower than a pixel), as engines' small-feature culling does
};
[[nodiscard]] bool holds_no_sample(const Aabb& box, const View& view, const SubpixelRules& rules = {}) noexcept;

/// How make_view() builds a lens's projection.
enum class DepthMode : std::uint8_t {
  standard,  ///< OpenGL's: depth in [-1, 1] from near to far
  reversed,  ///< reversed-Z: depth in [0, 1] from near (1) to an infinite far plane (0); Lens::far unused
};

/// Lens of a perspective camera.
struct Lens {
  float fov_y_degrees = 60.0f;  ///< vertical field of view, in (0, 180)
  float near = 0.1f;            ///< scene units, > 0
  float far = 2000.0f;          ///< scene units, > near
  DepthMode depth = DepthMode::standard;
};

/// A reversed-Z perspective projection with an infinite far plane, for
/// ClipSpace{DepthRange::zero_to_one, true}: depth = near / distance (1 at the
/// near plane, 0 at infinity). fov_y in radians, aspect = width / height,
/// near in scene units; all > 0.
[[nodiscard]] glm::mat4 perspective_reversed_infinite(float fov_y, float aspect, float near) noexcept;

/// "standard" or "reversed" (the --depth option). Throws InputError listing both.
[[nodiscard]] DepthMode parse_depth_mode(std::string_view name);

/// A camera pose. Yaw turns about +Y (0 looks down -Z, positive turns left
/// towards -X); pitch looks up when positive. Both in radians.
struct CameraPose {
  glm::vec3 position{0.0f};
  float yaw = 0.0f;
  float pitch = 0.0f;
};

/// View::near_radius: a box farther than this from the eye cannot be cut
/// by the near plane. Scene units.
[[nodiscard]] inline float near_plane_radius(const View& view) noexcept { return view.near_radius; }

/// The view of an engine's camera: `view` maps world to eye space, `proj`
/// eye to clip space with the conventions `clip` (OpenGL's [-1, 1] depth by
/// default; [0, 1] for Vulkan, Direct3D and glClipControl; reversed-Z),
/// rendered on a width x height viewport. Perspective projections may be
/// asymmetric (VR eyes, TAA jitter) and have an infinite far plane;
/// orthographic ones (w = 1) are accepted too. Everything derived from the
/// lens (frustum, near and far distances, the near-plane radius) comes from
/// the matrices.
/// Throws InputError, naming the value, for a matrix entry that is not
/// finite, a view matrix that cannot be inverted, a singular projection, one
/// that is neither perspective (w from eye-space z alone) nor orthographic
/// (w constant), a perspective near plane not in front of the eye, depth
/// that does not run from near to far, or a side outside [1,
/// limits::viewport_side].
[[nodiscard]] View make_view(const glm::mat4& view, const glm::mat4& proj, int width, int height,
                             const ClipSpace& clip = {});

/// The view of `pose` through `lens` on a width x height viewport: a
/// symmetric perspective projection with OpenGL's clip conventions, or, for
/// DepthMode::reversed, reversed-Z in [0, 1] with an infinite far plane.
/// Throws InputError, naming the value, for a pose that is not finite, a
/// |pitch| not below pi/2, a field of view outside (0, 180) degrees, a lens
/// without 0 < near < far < infinity (a near plane of 0 leaves the depth
/// buffer no precision), or a side outside [1, limits::viewport_side].
[[nodiscard]] View make_view(const CameraPose& pose, const Lens& lens, int width, int height);

/// Where the frames of a run lie on a camera path.
struct FrameSampling {
  /// Frames per second of path time: frame k is at start_s + k / fps, as a
  /// real-time walk would render them. 0: the frames are spread evenly over
  /// the whole path instead (far apart on a long path: less coherent).
  double fps = 0.0;
  double start_s = 0.0;  ///< path time of frame 0 when fps > 0, seconds after the first key (>= 0)
};

/// A keyframed camera path. Poses are interpolated linearly between keys
/// (yaw along the shorter arc); a key marked `cut` is jumped to without
/// interpolation (a sudden change of viewpoint).
class CameraPath {
 public:
  struct Key {
    double time = 0.0;  ///< seconds, strictly increasing along the path
    CameraPose pose;
    bool cut = false;   ///< arrive here by a jump rather than by moving
  };

  CameraPath() = default;
  /// Throws UsageError without keys. Precondition: times strictly
  /// increasing.
  CameraPath(std::string name, std::string description, std::vector<Key> keys);

  [[nodiscard]] const std::string& name() const noexcept { return name_; }
  [[nodiscard]] const std::string& description() const noexcept { return description_; }
  [[nodiscard]] const std::vector<Key>& keys() const noexcept { return keys_; }
  /// Seconds from the first key to the last.
  [[nodiscard]] double duration() const noexcept;
  /// Pose at `time_s` (clamped to the path's time range).
  [[nodiscard]] CameraPose sample(double time_s) const;
  /// Time of frame `k` of `frames` (frames >= 1): spread evenly over the
  /// path, or at `sampling.fps` from `sampling.start_s` (not clamped; see
  /// frames_that_fit).
  [[nodiscard]] double frame_time(int k, int frames, const FrameSampling& sampling = {}) const noexcept;
  /// How many frames of `sampling` lie within the path: every one for
  /// spread sampling (INT_MAX), 0 when start_s is past the end.
  [[nodiscard]] int frames_that_fit(const FrameSampling& sampling) const noexcept;

 private:
  std::string name_;
  std::string description_;
  std::vector<Key> keys_;
};

/// Reads a recorded camera path: a text file with one pose per line,
/// "time x y z yaw pitch" (seconds, scene units, degrees; yaw turns about
/// +Y, 0 looks down -Z; pitch looks up when positive), optionally followed
/// by the word "cut" to jump to that pose. Blank lines and lines starting
/// with '#' are skipped. The path is named "file:" + the file name.
/// Throws InputError naming the file and line of anything malformed.
[[nodiscard]] CameraPath read_path_file(const std::string& file);

/// Writes a path in the format read_path_file reads. Throws InputError when
/// the file cannot be written.
void write_path_file(const CameraPath& path, const std::string& file);

}  // namespace occull
