// Logging a frame's Backend calls: see frame_log.hpp.
#include "occull/frame_log.hpp"

#include <algorithm>

namespace occull {

void LoggingBackend::render(std::span<const ObjectId> objects) {
  if (log_) log_->draws.push_back({{objects.begin(), objects.end()}, log_->events++, -1});
  inner_.render(objects);
}

QueryId LoggingBackend::issue_query(std::span<const Aabb> boxes) {
  const QueryId q = inner_.issue_query(boxes);
  if (!log_) return q;
  in_flight_.push_back({q, log_->queries.size()});
  log_->queries.push_back({{boxes.begin(), boxes.end()}, log_->events++, std::nullopt, 0});
  return q;
}

std::int64_t LoggingBackend::logged(QueryId q) const {
  const auto it = std::find_if(in_flight_.begin(), in_flight_.end(), [q](const InFlight& f) { return f.id == q; });
  return it == in_flight_.end() ? -1 : std::int64_t(it->index);
}

std::uint64_t LoggingBackend::result(QueryId q) {
  const std::uint64_t samples = inner_.result(q);
  if (const std::int64_t i = logged(q); i >= 0) {
    FrameLog::Query& query = log_->queries[std::size_t(i)];
    query.samples = samples;
    query.answered = log_->events++;
    std::erase_if(in_flight_, [q](const InFlight& f) { return f.id == q; });
  }
  return samples;
}

void LoggingBackend::render_conditional(std::span<const ObjectId> objects, QueryId q, ConditionalWait wait) {
  if (log_) log_->draws.push_back({{objects.begin(), objects.end()}, log_->events++, logged(q)});
  inner_.render_conditional(objects, q, wait);
}

}  // namespace occull
