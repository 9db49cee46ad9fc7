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

/// A Backend that forwards every call to another and, while given a log,
/// logs the calls into it. Stats are the wrapped backend's. Queries issued
/// before the current log was given are forwarded but not logged.
///
/// Switch logs per frame with log_into(). Precondition: `inner` outlives
/// this object.
class LoggingBackend final : public Backend {
 public:
  explicit LoggingBackend(Backend& inner) : inner_(inner) {}

  /// Logs the calls from now on into `log` (null: none); `log` must stay
  /// valid until the next log_into().
  void log_into(FrameLog* log) {
    log_ = log;
    in_flight_.clear();
  }

  void render(std::span<const ObjectId> objects) override;
  QueryId issue_query(std::span<const Aabb> boxes) override;
  bool result_available(QueryId q) override { return inner_.result_available(q); }
  std::uint64_t result(QueryId q) override;
  [[nodiscard]] bool conditional_rendering() const override { return inner_.conditional_rendering(); }
  void render_conditional(std::span<const ObjectId> objects, QueryId q, ConditionalWait wait) override;
  void flush() override { inner_.flush(); }
  [[nodiscard]] DeviceCulling* device_culling() override { return inner_.device_culling(); }
  [[nodiscard]] ResultReads result_reads() const override { return inner_.result_reads(); }
  [[nodiscard]] BackendStats stats() const override { return inner_.stats(); }

 private:
  // The log's index of in-flight query q (-1: not logged).
  [[nodiscard]] std::int64_t logged(QueryId q) const;

  Backend& inner_;
  FrameLog* log_ = nullptr;
  struct InFlight {
    QueryId id;
    std::size_t index;  // in log_->queries
  };
  std::vector<InFlight> in_flight_;
};

}  // namespace occull
