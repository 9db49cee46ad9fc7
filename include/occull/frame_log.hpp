// occull — what a culler asked of its backend in one frame, in order: the
// record the debug views (occull render --view, occull view) draw from.
#pragma once

#include "occull/backend.hpp"

#include <cstdint>
#include <optional>
#include <vector>

namespace occull {

/// One frame's Backend calls. Events are numbered in call order (one number
/// per render(), render_conditional(), issue_query() and result() call), so
/// a draw and a query answer can be ordered.
struct FrameLog {
  struct Draw {
    std::vector<ObjectId> objects;
    std::uint64_t event = 0;
    /// render_conditional(): the index in `queries` of the query it waited
    /// on; -1 for render().
    std::int64_t query = -1;
  };
  struct Query {
    std::vector<Aabb> boxes;
    std::uint64_t issued = 0;                 ///< its issue_query() event
    std::optional<std::uint64_t> samples;     ///< its result, when read this frame
    std::uint64_t answered = 0;               ///< the result() event (valid with samples)
  };
  std::vector<Draw> draws;
  std::vector<Query> queries;
  std::uint64_t events = 0;  ///< calls logged
};

/// A Backend that forwards every call to another and logs it into a
/// FrameLog: make one per frame, around the backend the culler renders
/// through. Stats are the wrapped backend's. Queries issued before it was
/// made (an earlier frame's) are forwarded but not logged.
/// Preconditions: `inner` and `log` outlive this object.
class LoggingBackend final : public Backend {
 public:
  LoggingBackend(Backend& inner, FrameLog& log) : inner_(inner), log_(log) {}

  void render(std::span<const ObjectId> objects) override;
  QueryId issue_query(std::span<const Aabb> boxes) override;
  bool result_available(QueryId q) override { return inner_.result_available(q); }
  std::uint64_t result(QueryId q) override;
  [[nodiscard]] bool conditional_rendering() const override { return inner_.conditional_rendering(); }
  void render_conditional(std::span<const ObjectId> objects, QueryId q, ConditionalWait wait) override;
  void flush() override { inner_.flush(); }
  [[nodiscard]] BackendStats stats() const override { return inner_.stats(); }

 private:
  // The log's index of in-flight query q (-1: issued before this backend).
  [[nodiscard]] std::int64_t logged(QueryId q) const;

  Backend& inner_;
  FrameLog& log_;
  struct InFlight {
    QueryId id;
    std::size_t index;  // in log_.queries
  };
  std::vector<InFlight> in_flight_;
};

}  // namespace occull
