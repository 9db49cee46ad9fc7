// Internal: fault injection into the instrument, for tests only.
#pragma once

#include "occull/gl/renderer.hpp"
#include "occull/scene.hpp"

#include <functional>
#include <vector>

namespace occull::detail {

/// Each hook, when set, may corrupt one step of the instrument, so a test
/// can see the run-time invariant that guards that step stop the run (a
/// check never seen failing is not trusted). Set through
/// BenchConfig::hooks or Session::set_fault_hooks.
struct FaultHooks {
  /// The objects the truth pass is about to draw (those inside the frustum).
  std::function<void(std::vector<ObjectId>& drawn)> truth_objects;
  /// What the truth pass found and the images it read back.
  std::function<void(std::vector<gl::Renderer::ObjectPixels>& visible, gl::Renderer::PassImages& images)>
      truth_images;
  /// The box reach the truth computed (Session::set_box_reach).
  std::function<void(std::vector<ObjectId>& reach)> box_reach;
  /// The objects the oracle is told to render.
  std::function<void(std::vector<ObjectId>& visible)> oracle_objects;
  /// The depth image of a verified frame of an algorithm, as read back.
  std::function<void(std::vector<float>& depth)> frame_depth;
};

}  // namespace occull::detail
