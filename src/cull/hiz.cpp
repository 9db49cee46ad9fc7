// `hiz`: GPU-driven two-phase depth-pyramid occlusion culling (the scheme of
// zeux's niagara, nvpro's gl_occlusion_culling "temporal" mode, and
// Aaltonen and Haar, SIGGRAPH 2015), run by the device through the
// Backend's optional DeviceCulling capability (occull/device_culling.hpp).
//
// Each frame: (1) the device draws the objects in the frustum that it found
// visible last frame; (2) it builds a depth pyramid from that depth; (3) it
// tests every object in the frustum against the pyramid, records the
// outcome for the next frame, and draws those visible and not drawn in (1).
// Nothing waits a frame: an object uncovered this frame is drawn in this
// frame, so the culler is conservative exactly when the pyramid test is
// (occull/depth_pyramid.hpp: its rules, and the tests that break each).
//
// The CPU does no per-object work: three calls a frame. The culler holds one
// Visibility on the device, created on its first frame and handed back by
// release(). The objects it drew are on the device: drawn_objects() is
// empty for it; instruments read them back (RecordingBackend does, after the
// timed frame), and auto reads its visibility back when it hands over to
// another culler (last_visible).
#include "cullers.hpp"

#include "occull/device_culling.hpp"
#include "occull/error.hpp"

#include <optional>

namespace occull::detail {
namespace {

class HizCuller final : public Culler, public Resumable {
 public:
  explicit HizCuller(const HizConfig& config) : config_(config) {}

  FrameResult cull(const View&, Backend& backend) override {
    DeviceCulling& device = device_of(backend);
    if (!visibility_) visibility_ = device.create_visibility();
    if (resume_) device.set_visible(*visibility_, handed_over_);
    resume_ = false;
    device.draw_previously_visible(*visibility_);
    device.build_depth_pyramid();
    device.draw_newly_visible(*visibility_, config_.texels);
    return {};
  }

  // Phase 1 of the next frame draws `drawn` (auto's hand-over).
  void resume_from(std::span<const ObjectId> drawn) override {
    handed_over_.assign(drawn.begin(), drawn.end());
    resume_ = true;
  }

  // What phase 2 of its last frame found visible, read from the device.
  void last_visible(Backend& backend, std::vector<ObjectId>& out) override {
    if (visibility_) device_of(backend).read_visible(*visibility_, out);
  }

  void release(Backend& backend) override {
    if (!visibility_) return;
    device_of(backend).destroy_visibility(*visibility_);
    visibility_.reset();  // a later frame starts again from nothing visible
  }

 private:
  static DeviceCulling& device_of(Backend& backend) {
    DeviceCulling* device = backend.device_culling();
    if (!device)
      throw UsageError(
          "hiz culls on the device and this backend has no device culling (Backend::device_culling() is null): use "
          "occull's GL renderer, or implement DeviceCulling in the engine's backend (occull/device_culling.hpp)");
    return *device;
  }

  HizConfig config_;
  std::optional<DeviceCulling::Visibility> visibility_;
  std::vector<ObjectId> handed_over_;
  bool resume_ = false;
};

}  // namespace

Registration hiz_registration() {
  static const ConfigTable<HizConfig> table = ConfigTable<HizConfig>().choice(
      "texels", &HizConfig::texels, {{"2", 2}, {"4", 4}, {"8", 8}, {"16", 16}},
      "texels per axis each pyramid test reads at most: a box is tested at the level where its screen rectangle "
      "spans that many (more reads at a finer level: a tighter test)");
  return registered({"hiz",
                     "GPU-driven two-phase depth-pyramid culling: the device draws last frame's visible, builds a "
                     "depth pyramid, tests every object against it and draws the newly visible (needs a backend "
                     "with device culling)",
                     true, {}, false, SceneKind::bvh, false, true},
                    table, [](const SceneIndex&, const HizConfig& config, const Options&, const CullerContext&) {
                      return std::make_unique<HizCuller>(config);
                    });
}

}  // namespace occull::detail
