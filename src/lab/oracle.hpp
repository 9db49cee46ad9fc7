// Internal: the `oracle` — renders exactly the frame's ground-truth visible
// set, nearest first, with no queries: the cost of perfect culling with zero
// overhead, the lower bound every report compares against. `oracle:set=boxes`
// renders the frame's box reach instead (boxes_reaching_depth): the bound
// of every culler that tests objects by their boxes.
#pragma once

#include "occull/culler.hpp"

#include <vector>

namespace occull::detail {

class OracleCuller final : public Culler {
 public:
  /// `boxes`: the session feeds it each frame's box reach
  /// (FrameTruth::box_reach, `oracle:set=boxes`) instead of the truth.
  OracleCuller(const Scene& scene, bool boxes) : scene_(scene), boxes_(boxes) {}

  [[nodiscard]] bool boxes() const noexcept { return boxes_; }

  /// The set of the next frame (from the untimed truth pass).
  void set_visible(std::vector<ObjectId> visible) { visible_ = std::move(visible); }

  FrameResult cull(const View& view, Backend& backend) override;

 private:
  const Scene& scene_;
  bool boxes_;
  std::vector<ObjectId> visible_;
};

}  // namespace occull::detail
