#include "oracle.hpp"

#include <algorithm>

namespace occull::detail {

FrameResult OracleCuller::cull(const View& view, Backend& backend) {
  // Nearest first, as a front-to-back render queue would submit them; the
  // backend then sorts by material (stably).
  std::vector<std::pair<float, ObjectId>> order;
  order.reserve(visible_.size());
  for (ObjectId id : visible_) order.emplace_back(distance(view.eye, scene_.object(id).bounds), id);
  std::sort(order.begin(), order.end());
  std::vector<ObjectId> queue;
  queue.reserve(order.size());
  for (const auto& [d, id] : order) queue.push_back(id);
  if (!queue.empty()) backend.render(queue);
  return {};
}

}  // namespace occull::detail
