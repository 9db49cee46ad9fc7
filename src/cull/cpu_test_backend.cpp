#include "occull/cpu_test_backend.hpp"

#include "occluders.hpp"
#include "occull/error.hpp"

#include <algorithm>
#include <optional>
#include <stdexcept>
#include <vector>

namespace occull {

struct CpuTestBackend::Impl {
  Impl(const Scene& s, const Options& o) : scene(s), options(o), occluders(s, {o.budget, o.min_texels, o.detail}) {}

  struct Slot {
    bool in_use = false;
    bool answered = false;  // hidden on the CPU: 0 samples, nothing on the device
    QueryId inner = 0;
  };

  Backend& inner_backend() {
    if (!inner) throw UsageError("CpuTestBackend: used before begin_frame()");
    return *inner;
  }
  QueryId add(Slot s) {
    s.in_use = true;
    if (!free.empty()) {
      const QueryId id = free.back();
      free.pop_back();
      slots[id] = s;
      return id;
    }
    slots.push_back(s);
    return QueryId(slots.size() - 1);
  }
  Slot& slot(QueryId q) {
    if (q >= slots.size() || !slots[q].in_use) throw UsageError("CpuTestBackend: a query not in flight");
    return slots[q];
  }

  const Scene& scene;
  Options options;
  detail::Occluders occluders;
  std::optional<OcclusionBuffer> buffer;
  const View* view = nullptr;
  Backend* inner = nullptr;
  detail::BufferCounters counters;
  std::uint64_t answered = 0;
  std::vector<Slot> slots;
  std::vector<OcclusionBuffer::OccluderDraw> draws;  // render()'s occluders (scratch)
  std::vector<QueryId> free;
  std::vector<ObjectId> translucent;
};

CpuTestBackend::CpuTestBackend(const Scene& scene, const Options& options)
    : impl_(std::make_unique<Impl>(scene, options)) {}
CpuTestBackend::~CpuTestBackend() = default;

void CpuTestBackend::begin_frame(Backend& inner, const View& view) {
  Impl& m = *impl_;
  m.inner = &inner;
  m.view = &view;
  const int scale = std::max(1, m.options.scale);
  const int w = std::max(1, view.width / scale), h = std::max(1, view.height / scale);
  if (!m.buffer || m.buffer->width() != w || m.buffer->height() != h) {
    m.buffer.emplace(w, h, m.options.simd);
    m.buffer->set_threads(m.options.threads);
  }
  m.buffer->clear(view);
  m.occluders.begin_frame(view, *m.buffer);
  m.counters = {};
  m.counters.buffer_texels = std::uint64_t(w) * std::uint64_t(h);
  m.answered = 0;
}

void CpuTestBackend::end_frame() { impl_->view = nullptr; }

void CpuTestBackend::visit_counters(const CounterVisitor& visit) const { impl_->counters.visit(visit); }

const OcclusionBuffer* CpuTestBackend::buffer() const noexcept {
  return impl_->buffer ? &*impl_->buffer : nullptr;
}

std::uint64_t CpuTestBackend::answered() const noexcept { return impl_->answered; }

void CpuTestBackend::render(std::span<const ObjectId> objects) {
  Impl& m = *impl_;
  m.inner_backend().render(objects);
  // Drawn: each occluder among them now hides what lies behind it, rasterized
  // as one batch (shared among the buffer's threads).
  m.draws.clear();
  for (ObjectId id : objects)
    if (auto draw = m.occluders.occluder_draw(id, m.scene.object(id).bounds, *m.view)) m.draws.push_back(*draw);
  if (!m.draws.empty()) m.occluders.rasterize(*m.buffer, m.draws, *m.view, m.counters);
}

QueryId CpuTestBackend::issue_query(std::span<const Aabb> boxes) {
  Impl& m = *impl_;
  Backend& inner = m.inner_backend();
  bool hidden = true;
  for (const Aabb& b : boxes)
    if (!test_box(*m.buffer, b, m.view->view_proj, m.counters)) {
      hidden = false;
      break;
    }
  if (hidden) {
    ++m.answered;
    return m.add({true, true, 0});
  }
  return m.add({true, false, inner.issue_query(boxes)});
}

bool CpuTestBackend::result_available(QueryId q) {
  Impl::Slot& s = impl_->slot(q);
  return s.answered || impl_->inner_backend().result_available(s.inner);
}

std::uint64_t CpuTestBackend::result(QueryId q) {
  Impl& m = *impl_;
  Impl::Slot& s = m.slot(q);
  const std::uint64_t samples = s.answered ? 0 : m.inner_backend().result(s.inner);
  s.in_use = false;
  m.free.push_back(q);
  return samples;
}

bool CpuTestBackend::conditional_rendering() const {
  return impl_->inner ? impl_->inner->conditional_rendering() : false;
}

void CpuTestBackend::render_conditional(std::span<const ObjectId> objects, QueryId q, ConditionalWait wait) {
  Impl& m = *impl_;
  Impl::Slot& s = m.slot(q);
  if (!s.answered) {
    m.inner_backend().render_conditional(objects, s.inner, wait);  // the device may skip them: no occluders
    return;
  }
  // Known hidden: the device would skip every draw but the translucent
  // objects', which are drawn unconditionally.
  m.translucent.clear();
  for (ObjectId id : objects)
    if (m.scene.material(m.scene.object(id).material).translucent) m.translucent.push_back(id);
  if (!m.translucent.empty()) m.inner_backend().render(m.translucent);
}

void CpuTestBackend::flush() { impl_->inner_backend().flush(); }
DeviceCulling* CpuTestBackend::device_culling() { return impl_->inner_backend().device_culling(); }
ResultReads CpuTestBackend::result_reads() const {
  return impl_->inner ? impl_->inner->result_reads() : ResultReads::in_frame;
}
BackendStats CpuTestBackend::stats() const {
  return impl_->inner ? impl_->inner->stats() : BackendStats{};
}

}  // namespace occull
