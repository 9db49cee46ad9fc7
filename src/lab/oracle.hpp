// Internal: the `oracle` — renders exactly the frame's ground-truth visible
// set, nearest first, with no queries: the cost of perfect culling with zero
// overhead, the lower bound every report compares against.
#pragma once

#include "occull/culler.hpp"

#include <vector>

namespace occull::detail {

class OracleCuller final : public Culler {
 public:
  explicit OracleCuller(const Scene& scene) : scene_(scene) {}

  /// The visible set of the next frame (from the untimed truth pass).
  void set_visible(std::vector<ObjectId> visible) { visible_ = std::move(visible); }

  FrameResult cull(const View& view, Backend& backend) override;

 private:
  const Scene& scene_;
  std::vector<ObjectId> visible_;
};

}  // namespace occull::detail
