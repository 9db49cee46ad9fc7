// The debug views' pictures: see debug_view.hpp.
#include "occull/debug_view.hpp"

#include "occull/error.hpp"

#include <fmt/format.h>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <limits>
#include <array>
#include <cmath>

namespace occull {
namespace {

constexpr std::array<DebugViewInfo, 7> kViews{{
    {DebugView::color, "color", "the frame as rendered"},
    {DebugView::queries, "queries",
     "query boxes by outcome: occluded (red), visible (green), wasted: visible and drawn anyway (black)"},
    {DebugView::multiqueries, "multiqueries", "one colour per query of several boxes (a CHC++ multiquery or tight boxes)"},
    {DebugView::batches, "batches", "draws and query boxes coloured by state-change batch, in order"},
    {DebugView::overview, "overview",
     "from above: the frustum; drawn, frustum-culled, occlusion-culled and missed (red) objects"},
    {DebugView::cells, "cells", "from above: grid cells met, drawn (green) over hidden (red); algorithm grid"},
    {DebugView::tiles, "tiles",
     "from above: tile instances drawn (green) over cells found hidden (red); tiled-world algorithms"},
}};

// The query's boxes hold the centre of object `id`.
bool covers(const FrameLog::Query& q, const Aabb& enclosing, const glm::vec3& centre) {
  if (!enclosing.contains(centre)) return false;
  return std::any_of(q.boxes.begin(), q.boxes.end(), [&](const Aabb& b) { return b.contains(centre); });
}

// Every box's 12 edges as lines.
void box_edges(const Aabb& b, const glm::vec3& color, std::vector<Picture::Line>& out) {
  for (int i = 0; i < 8; ++i)
    for (int axis = 0; axis < 3; ++axis)
      if (!(i & (1 << axis))) out.push_back({b.corner(i), b.corner(i | (1 << axis)), color});
}

Picture over_frame(const DebugFrame& f) {
  Picture p;
  p.view_proj = f.view.view_proj;
  p.clip = f.view.clip;
  p.frame_background = true;
  return p;
}

Picture queries_picture(const DebugFrame& f) {
  Picture p = over_frame(f);
  const std::vector<QueryOutcome> outcome = classify_queries(f.scene, f.log);
  // Bottom layer first: what a query culled is drawn over the rest.
  static constexpr std::array<std::pair<QueryOutcome, std::string_view>, 4> kNames{{
      {QueryOutcome::wasted, "wasted (visible, drawn anyway)"},
      {QueryOutcome::unanswered, "not read this frame"},
      {QueryOutcome::visible, "visible"},
      {QueryOutcome::occluded, "occluded"},
  }};
  const auto color = [](QueryOutcome o) {
    switch (o) {
      case QueryOutcome::occluded: return palette::occluded;
      case QueryOutcome::visible: return palette::visible;
      case QueryOutcome::wasted: return palette::wasted;
      case QueryOutcome::unanswered: break;
    }
    return palette::unanswered;
  };
  std::uint8_t layer = 0;
  for (const auto& [o, name] : kNames) {
    std::size_t n = 0;
    for (std::size_t q = 0; q < outcome.size(); ++q) {
      if (outcome[q] != o) continue;
      ++n;
      for (const Aabb& b : f.log.queries[q].boxes) p.boxes.push_back({b, color(o), layer});
    }
    ++layer;
    p.legend.push_back({std::string(name), color(o), n});
  }
  return p;
}

Picture multiqueries_picture(const DebugFrame& f) {
  Picture p = over_frame(f);
  std::size_t groups = 0, single = 0;
  for (const FrameLog::Query& q : f.log.queries) {
    const glm::vec3 c = q.boxes.size() > 1 ? palette::sequence(groups++) : palette::unanswered;
    if (q.boxes.size() <= 1) ++single;
    for (const Aabb& b : q.boxes) p.boxes.push_back({b, c});
  }
  p.legend.push_back({"queries of several boxes (one colour each)", palette::sequence(0), groups});
  p.legend.push_back({"queries of one box", palette::unanswered, single});
  return p;
}

Picture batches_picture(const DebugFrame& f) {
  Picture p;
  p.view_proj = f.view.view_proj;
  p.clip = f.view.clip;
  p.frame_background = false;
  // Merge draws and queries by event number; a batch ends where the kind
  // changes. A frame starts in the render state (as the renderer counts
  // changes), so a first query batch is a change too.
  std::size_t d = 0, q = 0, batch = 0, render_batches = 0, query_batches = 0, changes = 0;
  int last = -1, state = 0;  // 0 render, 1 query
  while (d < f.log.draws.size() || q < f.log.queries.size()) {
    const bool draw = q >= f.log.queries.size() ||
                      (d < f.log.draws.size() && f.log.draws[d].event < f.log.queries[q].issued);
    const int kind = draw ? 0 : 1;
    if (kind != last) {
      if (last >= 0) ++batch;
      ++(draw ? render_batches : query_batches);
      last = kind;
    }
    if (kind != state) {
      ++changes;
      state = kind;
    }
    const glm::vec3 c = palette::sequence(batch);
    if (draw) {
      for (ObjectId id : f.log.draws[d++].objects) p.objects.push_back({id, c});
    } else {
      for (const Aabb& b : f.log.queries[q++].boxes) box_edges(b, c, p.lines);
    }
  }
  p.legend.push_back({"render batches (objects in the batch's colour)", palette::sequence(0), render_batches});
  p.legend.push_back({"query batches (box edges in the batch's colour)", palette::sequence(1), query_batches});
  p.legend.push_back({"state changes", palette::wasted, changes});
  return p;
}

// A camera looking straight down (-y) on `area`, fitted to `aspect`, north (-z) up.
glm::mat4 top_down(const Aabb& area, float aspect) {
  const glm::vec3 centre = area.center();
  const glm::vec3 size = area.max - area.min;
  // x to the right, -z up in the image (north up), with a 5 % margin.
  float half_w = 0.5f * std::max(size.x, 1e-3f) * 1.05f, half_h = 0.5f * std::max(size.z, 1e-3f) * 1.05f;
  if (half_w / half_h < aspect) half_w = half_h * aspect; else half_h = half_w / aspect;
  const float top = area.max.y + 1.0f, depth = std::max(size.y, 1e-3f) + 2.0f;
  const glm::mat4 look = glm::lookAt(glm::vec3(centre.x, top, centre.z), glm::vec3(centre.x, top - 1.0f, centre.z),
                                     glm::vec3(0.0f, 0.0f, -1.0f));
  return glm::ortho(-half_w, half_w, -half_h, half_h, 0.0f, depth) * look;
}

// The frustum's edges: its four side edges, and the near and far rectangles.
void frustum_lines(const View& view, std::vector<Picture::Line>& out) {
  const glm::mat4 inv = glm::inverse(view.view_proj);
  const auto corner = [&](float x, float y, float z) {
    const glm::vec4 w = inv * glm::vec4(x, y, z, 1.0f);
    return glm::vec3(w) / w.w;
  };
  std::array<glm::vec3, 4> near_c, far_c;
  for (int i = 0; i < 4; ++i) {
    const float x = (i == 1 || i == 2) ? 1.0f : -1.0f, y = i >= 2 ? 1.0f : -1.0f;
    near_c[std::size_t(i)] = corner(x, y, view.clip.near_depth());
    // An infinite far plane is drawn 2000 near-plane distances out.
    far_c[std::size_t(i)] = std::isfinite(view.far)
                                ? corner(x, y, view.clip.far_depth())
                                : view.eye + (near_c[std::size_t(i)] - view.eye) * 2000.0f;
  }
  for (std::size_t i = 0; i < 4; ++i) {
    out.push_back({near_c[i], far_c[i], palette::frustum});
    out.push_back({far_c[i], far_c[(i + 1) % 4], palette::frustum});
    out.push_back({near_c[i], near_c[(i + 1) % 4], palette::frustum});
  }
}

// From above, as the thesis' Figure 4.2: each region's footprint, drawn
// ones over hidden ones (a column with a drawn cell shows drawn), and the frustum.
Picture regions_picture(const DebugFrame& f, std::string_view what, float aspect) {
  Picture p;
  p.frame_background = false;
  Aabb area;
  area.extend(f.view.eye);
  for (const CullRegion& r : f.regions) area.extend(r.box);
  p.view_proj = top_down(area, aspect);
  std::size_t shown = 0, hidden = 0;
  for (const CullRegion& r : f.regions) {
    Aabb footprint = r.box;
    footprint.max.y = footprint.min.y = area.min.y;
    p.boxes.push_back({footprint, r.visible ? palette::visible : palette::occluded, std::uint8_t(r.visible ? 1 : 0)});
    ++(r.visible ? shown : hidden);
  }
  std::stable_sort(p.boxes.begin(), p.boxes.end(),
                   [](const Picture::Box& a, const Picture::Box& b) { return a.layer < b.layer; });
  frustum_lines(f.view, p.lines);
  p.legend.push_back({fmt::format("{} drawn", what), palette::visible, shown});
  p.legend.push_back({fmt::format("{} hidden", what), palette::occluded, hidden});
  return p;
}

// Looks straight down on the scene's box and the eye.
Picture overview_picture(const DebugFrame& f, float aspect) {
  Picture p;
  p.frame_background = false;
  Aabb area = f.scene.bounds();
  area.extend(f.view.eye);
  p.view_proj = top_down(area, aspect);

  std::vector<ObjectId> drawn(f.drawn.begin(), f.drawn.end());
  std::sort(drawn.begin(), drawn.end());
  const auto in = [](std::span<const ObjectId> sorted, ObjectId id) {
    return std::binary_search(sorted.begin(), sorted.end(), id);
  };
  std::size_t n_drawn = 0, n_frustum = 0, n_occlusion = 0, n_missed = 0;
  const auto objects = f.scene.objects();
  for (ObjectId id = 0; id < objects.size(); ++id) {
    if (objects[id].bounds.empty()) continue;
    glm::vec3 c;
    if (in(drawn, id)) {
      c = palette::drawn;
      ++n_drawn;
    } else if (in(f.truth, id)) {
      c = palette::missed;
      ++n_missed;
    } else if (f.view.frustum.classify(objects[id].bounds) == Containment::outside) {
      c = palette::frustum_culled;
      ++n_frustum;
    } else {
      c = palette::occlusion_culled;
      ++n_occlusion;
    }
    p.objects.push_back({id, c});
  }
  // Missed objects last, so nothing is drawn over them at equal depth.
  std::stable_partition(p.objects.begin(), p.objects.end(),
                        [](const Picture::Paint& o) { return o.color != palette::missed; });
  frustum_lines(f.view, p.lines);
  p.legend.push_back({"drawn", palette::drawn, n_drawn});
  p.legend.push_back({"outside the frustum", palette::frustum_culled, n_frustum});
  p.legend.push_back({"occlusion-culled", palette::occlusion_culled, n_occlusion});
  p.legend.push_back({f.truth.empty() ? "missed (truth not computed)" : "missed: visible, not drawn", palette::missed,
                      n_missed});
  return p;
}

}  // namespace

std::span<const DebugViewInfo> debug_views() { return kViews; }

std::vector<std::uint8_t> occlusion_buffer_rgba(const OcclusionBuffer& buffer, int width, int height) {
  const std::span<const float> keys = buffer.keys();
  float lo = std::numeric_limits<float>::infinity(), hi = -lo;
  for (float k : keys)
    if (k != std::numeric_limits<float>::infinity()) lo = std::min(lo, k), hi = std::max(hi, k);
  std::vector<std::uint8_t> out(std::size_t(width) * std::size_t(height) * 4);
  for (int y = 0; y < height; ++y) {
    // Pixel rows top first; texel rows bottom first.
    const int ty = std::min(buffer.height() - 1, (height - 1 - y) * buffer.height() / height);
    for (int x = 0; x < width; ++x) {
      const int tx = std::min(buffer.width() - 1, x * buffer.width() / width);
      const float k = buffer.key_at(tx, ty);
      std::uint8_t* p = out.data() + (std::size_t(y) * std::size_t(width) + std::size_t(x)) * 4;
      if (k == std::numeric_limits<float>::infinity()) {
        p[0] = 25, p[1] = 25, p[2] = 90;
      } else {
        const float t = hi > lo ? (k - lo) / (hi - lo) : 0.0f;  // 0 nearest, 1 farthest
        const auto g = std::uint8_t(std::lround(235.0f - 175.0f * t));
        p[0] = p[1] = p[2] = g;
      }
      p[3] = 255;
    }
  }
  return out;
}

DebugView parse_debug_view(std::string_view name) {
  for (const DebugViewInfo& v : kViews)
    if (v.name == name) return v.view;
  std::string names;
  for (const DebugViewInfo& v : kViews) names += (names.empty() ? "" : ", ") + std::string(v.name);
  throw InputError(fmt::format("unknown view '{}' (valid: {})", name, names));
}

std::string_view debug_view_name(DebugView view) {
  for (const DebugViewInfo& v : kViews)
    if (v.view == view) return v.name;
  return "?";
}

bool view_fits(DebugView view, const AlgorithmInfo& algorithm) {
  if (view == DebugView::cells) return algorithm.name == "grid";
  if (view == DebugView::tiles) return algorithm.scenes == SceneKind::tiled;
  return true;
}

glm::vec3 palette::sequence(std::size_t k) {
  // Hues a golden angle apart, at two alternating brightnesses.
  const float h = std::fmod(0.61803398875f * float(k) + 0.1f, 1.0f) * 6.0f;
  const float v = k % 2 == 0 ? 0.95f : 0.7f, s = 0.75f;
  const float c = v * s, x = c * (1.0f - std::fabs(std::fmod(h, 2.0f) - 1.0f)), m = v - c;
  glm::vec3 rgb;
  switch (int(h)) {
    case 0: rgb = {c, x, 0}; break;
    case 1: rgb = {x, c, 0}; break;
    case 2: rgb = {0, c, x}; break;
    case 3: rgb = {0, x, c}; break;
    case 4: rgb = {x, 0, c}; break;
    default: rgb = {c, 0, x}; break;
  }
  return rgb + glm::vec3(m);
}

std::vector<QueryOutcome> classify_queries(const Scene& scene, const FrameLog& log) {
  std::vector<QueryOutcome> out(log.queries.size(), QueryOutcome::unanswered);
  std::vector<Aabb> enclosing(log.queries.size());
  for (std::size_t q = 0; q < log.queries.size(); ++q) {
    const FrameLog::Query& query = log.queries[q];
    if (!query.samples) continue;
    if (*query.samples == 0) {
      out[q] = QueryOutcome::occluded;
      continue;
    }
    out[q] = QueryOutcome::wasted;
    for (const Aabb& b : query.boxes) enclosing[q].extend(b);
  }
  for (const FrameLog::Draw& d : log.draws) {
    for (std::size_t q = 0; q < log.queries.size(); ++q) {
      if (out[q] != QueryOutcome::wasted) continue;
      const FrameLog::Query& query = log.queries[q];
      const bool after = d.query == std::int64_t(q) || d.event > query.answered;
      if (!after) continue;
      for (ObjectId id : d.objects) {
        if (covers(query, enclosing[q], scene.object(id).bounds.center())) {
          out[q] = QueryOutcome::visible;
          break;
        }
      }
    }
  }
  return out;
}

Picture make_picture(DebugView view, const DebugFrame& frame, float aspect) {
  switch (view) {
    case DebugView::color: return over_frame(frame);
    case DebugView::queries: return queries_picture(frame);
    case DebugView::multiqueries: return multiqueries_picture(frame);
    case DebugView::batches: return batches_picture(frame);
    case DebugView::overview: return overview_picture(frame, aspect);
    case DebugView::cells: return regions_picture(frame, "cells", aspect);
    case DebugView::tiles: return regions_picture(frame, "tiles", aspect);
  }
  return over_frame(frame);
}

}  // namespace occull
