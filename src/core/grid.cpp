#include "occull/grid.hpp"

#include "occull/error.hpp"
#include "core/format.hpp"

#include <algorithm>
#include <array>
#include <cmath>

namespace occull {

CellCoord GridGeometry::cell_of(const glm::vec3& p) const noexcept {
  CellCoord c;
  for (int a = 0; a < 3; ++a) {
    const double t = std::floor(double(p[a] - origin[a]) / double(cell[a]));
    c[a] = int(std::clamp(t, -1.0, double(dims[a])));
  }
  return c;
}

// ---------------------------------------------------------------------------
// UniformGrid

namespace {
constexpr int kMaxCellsPerAxis = 1 << 20;
constexpr double kMaxListings = double(1 << 26);  // object-in-cell entries of a scene's grid
}  // namespace

UniformGrid::UniformGrid(const GridGeometry& geometry) : geometry_(geometry) {}

float UniformGrid::default_cell_size(const Scene& scene) {
  std::vector<float> sizes;
  sizes.reserve(scene.objects().size());
  for (const Object& o : scene.objects()) {
    if (o.bounds.empty()) continue;
    const glm::vec3 e = o.bounds.extent();
    sizes.push_back(std::max({e.x, e.y, e.z}));
  }
  const Aabb b = scene.bounds();
  if (sizes.empty() || b.empty()) return 1.0f;
  const auto mid = sizes.begin() + std::ptrdiff_t(sizes.size() / 2);
  std::nth_element(sizes.begin(), mid, sizes.end());
  const glm::vec3 e = b.extent();
  const float longest = std::max({e.x, e.y, e.z});
  return std::max({2.0f * *mid, longest / 256.0f, 1e-3f});
}

UniformGrid UniformGrid::of_scene(const Scene& scene, float cell_size) {
  if (!(cell_size >= 0.0f) || !std::isfinite(cell_size))
    throw InputError(detail::format("grid cell size {}: must be a positive number of scene units (0: default)", cell_size));
  if (cell_size == 0.0f) cell_size = default_cell_size(scene);
  Aabb bounds = scene.bounds();
  // Where dynamic objects go: their ranges, grown by their size.
  for (ObjectId id : scene.dynamic_objects()) {
    const Aabb range = scene.dynamic_range(id);
    if (!range.empty()) bounds.extend(range.grown(glm::length(scene.object(id).bounds.extent())));
  }
  GridGeometry g;
  g.cell = glm::vec3(cell_size);
  if (bounds.empty()) bounds = Aabb{glm::vec3(0.0f), glm::vec3(0.0f)};
  g.origin = bounds.min;
  for (int a = 0; a < 3; ++a) {
    const double n = std::ceil(double(bounds.max[a] - bounds.min[a]) / double(cell_size));
    if (n > double(kMaxCellsPerAxis))
      throw InputError(detail::format("grid cell size {}: the scene's {:.0f} units along {} would need {:.0f} cells "
                                   "(at most 2^20); choose larger cells",
                                   cell_size, bounds.max[a] - bounds.min[a], "xyz"[a], n));
    g.dims[a] = std::max(1, int(n));
  }
  UniformGrid grid(g);
  const auto objects = scene.objects();
  double listings = 0.0;
  for (const Object& o : objects) {
    if (o.bounds.empty()) continue;
    const Range r = grid.range_of(o.bounds);
    listings += double(r.hi.x - r.lo.x + 1) * double(r.hi.y - r.lo.y + 1) * double(r.hi.z - r.lo.z + 1);
  }
  if (listings > double(kMaxListings))
    throw InputError(detail::format("grid cell size {}: the objects would be listed in {:.0f} cells (at most 2^26); "
                                 "choose larger cells",
                                 cell_size, listings));
  for (ObjectId id = 0; id < objects.size(); ++id)
    if (!objects[id].bounds.empty()) grid.insert(id, objects[id].bounds);
  return grid;
}

UniformGrid::Range UniformGrid::range_of(const Aabb& b) const noexcept {
  Range r;
  const GridGeometry& g = geometry_;
  for (int a = 0; a < 3; ++a) {
    const auto index = [&](float v) {
      const double t = std::floor(double(v - g.origin[a]) / double(g.cell[a]));
      return int(std::clamp(t, 0.0, double(g.dims[a] - 1)));
    };
    r.lo[a] = index(b.min[a]);
    r.hi[a] = index(b.max[a]);
  }
  return r;
}

std::uint64_t UniformGrid::key(const CellCoord& c) const noexcept {
  return (std::uint64_t(c.x) * std::uint64_t(geometry_.dims.y) + std::uint64_t(c.y)) *
             std::uint64_t(geometry_.dims.z) +
         std::uint64_t(c.z);
}

std::uint32_t UniformGrid::find(const CellCoord& c) const {
  if (!geometry_.contains(c)) return kNoCell;
  const auto it = index_.find(key(c));
  return it == index_.end() ? kNoCell : it->second;
}

namespace {

Aabb intersection(const Aabb& a, const Aabb& b) noexcept {
  return {glm::max(a.min, b.min), glm::min(a.max, b.max)};
}

bool inside(const CellCoord& c, const CellCoord& lo, const CellCoord& hi) noexcept {
  return glm::all(glm::greaterThanEqual(c, lo)) && glm::all(glm::lessThanEqual(c, hi));
}

template <class F>
void for_each_cell(const CellCoord& lo, const CellCoord& hi, F&& f) {
  for (int x = lo.x; x <= hi.x; ++x)
    for (int y = lo.y; y <= hi.y; ++y)
      for (int z = lo.z; z <= hi.z; ++z) f(CellCoord(x, y, z));
}

}  // namespace

void UniformGrid::add(const CellCoord& c, ObjectId id, const Aabb& bounds) {
  const auto [it, fresh] = index_.try_emplace(key(c), std::uint32_t(coords_.size()));
  if (fresh) {
    coords_.push_back(c);
    objects_.emplace_back();
    content_.emplace_back();
  }
  objects_[it->second].push_back(id);
  content_[it->second].extend(intersection(bounds, geometry_.cell_box(c)));
}

void UniformGrid::remove(const CellCoord& c, ObjectId id) {
  const std::uint32_t cell = find(c);
  std::vector<ObjectId>& list = objects_[cell];
  const auto it = std::find(list.begin(), list.end(), id);
  *it = list.back();
  list.pop_back();
}

void UniformGrid::insert(ObjectId id, const Aabb& bounds) {
  if (object_cells_.size() <= id) {
    object_cells_.resize(std::size_t(id) + 1);
    object_bounds_.resize(std::size_t(id) + 1);
  }
  const Range r = range_of(bounds);
  object_cells_[id] = r;
  object_bounds_[id] = bounds;
  for_each_cell(r.lo, r.hi, [&](const CellCoord& c) { add(c, id, bounds); });
}

void UniformGrid::update(ObjectId id, const Aabb& bounds) {
  if (id >= object_bounds_.size()) return insert(id, bounds);  // an object added to the scene
  if (object_bounds_[id] == bounds) return;
  const Range old = object_cells_[id];
  const Range now = range_of(bounds);
  object_cells_[id] = now;
  object_bounds_[id] = bounds;
  // A cell the object left, or one it stays in (its part there moved), has
  // its content box made again from what it holds.
  for_each_cell(old.lo, old.hi, [&](const CellCoord& c) {
    if (!inside(c, now.lo, now.hi)) remove(c, id);
    refresh_content(c);
  });
  for_each_cell(now.lo, now.hi, [&](const CellCoord& c) {
    if (!inside(c, old.lo, old.hi)) add(c, id, bounds);
  });
}

void UniformGrid::refresh_content(const CellCoord& c) {
  const std::uint32_t cell = find(c);
  const Aabb box = geometry_.cell_box(c);
  Aabb content;
  for (ObjectId o : objects_[cell]) content.extend(intersection(object_bounds_[o], box));
  content_[cell] = content;
}

// ---------------------------------------------------------------------------
// GridTraversal

namespace {

// Margin of the intersection tests, in cell edges: a cell that touches the
// frustum within it is listed.
constexpr double kMargin = 1e-4;

struct DBox {
  glm::dvec3 lo, hi;
};

// The frustum as corners and inward planes (n, d), in double precision.
struct DFrustum {
  std::array<glm::dvec3, 8> corner;  // bit 0: +x, bit 1: +y, bit 2: far (NDC)
  std::array<glm::dvec4, 6> plane;
};

// `reach`: a distance from the eye past every cell of the grid, where an
// infinite far plane is put instead.
DFrustum frustum_of(const View& view, double reach) {
  DFrustum f;
  const glm::dmat4 inv = glm::inverse(glm::dmat4(view.view_proj));
  const double z_near = view.clip.near_depth(), z_far = view.clip.far_depth();
  const bool infinite = !std::isfinite(view.far);
  for (int i = 0; i < 8; ++i) {
    const double x = (i & 1) ? 1.0 : -1.0, y = (i & 2) ? 1.0 : -1.0;
    const glm::dvec4 p = inv * glm::dvec4(x, y, (i & 4) && !infinite ? z_far : z_near, 1.0);
    f.corner[std::size_t(i)] = glm::dvec3(p) / p.w;
    if ((i & 4) && infinite) {  // along the corner's ray, out to `reach` along the view axis
      const glm::dvec3 eye(view.eye);
      f.corner[std::size_t(i)] = eye + (f.corner[std::size_t(i)] - eye) * (reach / std::max(1e-9, double(view.near)));
    }
  }
  for (int i = 0; i < 6; ++i) {
    const Plane& p = view.frustum.plane(i);
    f.plane[std::size_t(i)] = glm::dvec4(glm::dvec3(p.n), double(p.d));
  }
  return f;
}

constexpr std::array<std::array<int, 2>, 12> kEdges = {{{0, 1}, {2, 3}, {4, 5}, {6, 7}, {0, 2}, {1, 3},
                                                        {4, 6}, {5, 7}, {0, 4}, {1, 5}, {2, 6}, {3, 7}}};

// Vertices of frustum ∩ box (appended to `out`): frustum corners in the box,
// box corners in the frustum, frustum edges crossing box faces and box edges
// crossing frustum planes — every vertex of the intersection of two convex
// polyhedra is one of those. `eps`: tolerance in scene units.
void intersection_vertices(const DFrustum& f, const DBox& b, double eps, std::vector<glm::dvec3>& out) {
  const auto in_box = [&](const glm::dvec3& p) {
    return p.x >= b.lo.x - eps && p.x <= b.hi.x + eps && p.y >= b.lo.y - eps && p.y <= b.hi.y + eps &&
           p.z >= b.lo.z - eps && p.z <= b.hi.z + eps;
  };
  const auto in_frustum = [&](const glm::dvec3& p) {
    for (const glm::dvec4& pl : f.plane)
      if (glm::dot(glm::dvec3(pl), p) + pl.w < -eps) return false;
    return true;
  };
  for (const glm::dvec3& c : f.corner)
    if (in_box(c)) out.push_back(c);
  std::array<glm::dvec3, 8> box_corner;
  for (int i = 0; i < 8; ++i) {
    box_corner[std::size_t(i)] = {(i & 1) ? b.hi.x : b.lo.x, (i & 2) ? b.hi.y : b.lo.y, (i & 4) ? b.hi.z : b.lo.z};
    if (in_frustum(box_corner[std::size_t(i)])) out.push_back(box_corner[std::size_t(i)]);
  }
  for (const auto& e : kEdges) {
    const glm::dvec3& p = f.corner[std::size_t(e[0])];
    const glm::dvec3& q = f.corner[std::size_t(e[1])];
    for (int a = 0; a < 3; ++a) {
      const double span = q[a] - p[a];
      if (span == 0.0) continue;
      for (const double v : {b.lo[a], b.hi[a]}) {
        const double t = (v - p[a]) / span;
        if (t < 0.0 || t > 1.0) continue;
        glm::dvec3 x = p + (q - p) * t;
        x[a] = v;
        if (in_box(x)) out.push_back(x);
      }
    }
  }
  for (const auto& e : kEdges) {
    const glm::dvec3& p = box_corner[std::size_t(e[0])];
    const glm::dvec3& q = box_corner[std::size_t(e[1])];
    for (const glm::dvec4& pl : f.plane) {
      const double dp = glm::dot(glm::dvec3(pl), p) + pl.w;
      const double dq = glm::dot(glm::dvec3(pl), q) + pl.w;
      if ((dp < 0.0) == (dq < 0.0)) continue;
      const glm::dvec3 x = p + (q - p) * (dp / (dp - dq));
      if (in_frustum(x)) out.push_back(x);
    }
  }
}

// One axis of a piece: cells first..last visited in that order (step ±1),
// and whether they differ from the eye's cell.
struct AxisRange {
  int first = 0, last = 0, step = 1;
  bool off_eye = false;
  [[nodiscard]] int lo() const { return std::min(first, last); }
  [[nodiscard]] int hi() const { return std::max(first, last); }
};

}  // namespace

std::span<const CellRun> GridTraversal::traverse(const GridGeometry& g, const View& view, Mode mode) {
  runs_.clear();
  double reach = 0.0;  // the grid's farthest corner from the eye
  const Aabb grid_box = g.bounds();
  for (int i = 0; i < 8; ++i) reach = std::max(reach, double(glm::length(grid_box.corner(i) - view.eye)));
  const DFrustum f = frustum_of(view, reach + 1.0);
  const glm::dvec3 origin(g.origin), cell(g.cell);
  const double eps = kMargin * std::min({cell.x, cell.y, cell.z});
  const CellCoord eye = g.cell_of(view.eye);

  // Axes: slices across the dominant axis of the view direction; rows along
  // the remaining axis with more cells (long runs), stepped across the other.
  // Any such order keeps occlusion order: within a piece it is lexicographic
  // in the distances from the eye's cell.
  const glm::vec3 forward = -glm::vec3(view.view[0][2], view.view[1][2], view.view[2][2]);
  std::array<int, 3> axis = {0, 1, 2};
  std::stable_sort(axis.begin(), axis.end(),
                   [&](int a, int b) { return std::abs(forward[a]) > std::abs(forward[b]); });
  if (g.dims[axis[1]] > g.dims[axis[2]]) std::swap(axis[1], axis[2]);

  // Per axis: the eye's cell, the cells below it and those above it.
  std::array<std::vector<AxisRange>, 3> ranges;
  for (int a = 0; a < 3; ++a) {
    const int e = eye[a], n = g.dims[a];
    if (e >= 0 && e < n) ranges[std::size_t(a)].push_back({e, e, 1, false});
    if (e - 1 >= 0) ranges[std::size_t(a)].push_back({std::min(e - 1, n - 1), 0, -1, true});
    if (e + 1 <= n - 1) ranges[std::size_t(a)].push_back({std::max(e + 1, 0), n - 1, 1, true});
  }
  // The pieces, fanned out from the eye's cell.
  std::vector<std::array<AxisRange, 3>> pieces;
  for (const AxisRange& x : ranges[0])
    for (const AxisRange& y : ranges[1])
      for (const AxisRange& z : ranges[2]) pieces.push_back({x, y, z});
  std::stable_sort(pieces.begin(), pieces.end(), [](const auto& p, const auto& q) {
    const auto off = [](const auto& r) { return int(r[0].off_eye) + int(r[1].off_eye) + int(r[2].off_eye); };
    return off(p) < off(q);
  });

  // The cell along axis a holding v (less, or plus, the margin), clamped to
  // [-1, dims] so that far-away coordinates do not overflow.
  const auto cell_at = [&](int a, double v, double margin) {
    return int(std::clamp(std::floor((v - origin[a]) / cell[a] + margin), -1.0, double(g.dims[a])));
  };
  const auto cell_lo = [&](int a, double v) { return cell_at(a, v, -kMargin); };
  const auto cell_hi = [&](int a, double v) { return cell_at(a, v, kMargin); };
  // The cells of `r` within [lo, hi] (world coordinates along axis a), in
  // the piece's order; false when none.
  const auto clip_range = [&](int a, const AxisRange& r, double lo, double hi, AxisRange& out) {
    const int l = std::max(r.lo(), cell_lo(a, lo));
    const int h = std::min(r.hi(), cell_hi(a, hi));
    if (l > h) return false;
    out = r.step > 0 ? AxisRange{l, h, 1, r.off_eye} : AxisRange{h, l, -1, r.off_eye};
    return true;
  };
  const int d = axis[0], d2 = axis[1], d3 = axis[2];
  // Unit steps along the three axes, so a run's cell is computed, not
  // written through a run-time index.
  CellCoord unit_d(0), unit_d2(0), unit_d3(0);
  unit_d[d] = unit_d2[d2] = unit_d3[d3] = 1;
  // Cells t0..t1 along d2 (rows), each with its cells v0..v1 along d3.
  const auto emit_row = [&](int s, int t, int v_first, int v_last, int v_step) {
    CellRun run;
    run.start = unit_d * s + unit_d2 * t + unit_d3 * v_first;
    run.step = unit_d3 * v_step;
    run.count = std::abs(v_last - v_first) + 1;
    runs_.push_back(run);
  };

  // The frustum within cell layer s along d (widened by eps), seen along d,
  // is a convex polygon in (d2, d3): its vertices are where frustum edges
  // cross the layer's two faces, and frustum corners inside the layer. Per
  // row t along d2 (a strip widened by eps), the polygon's extent along d3
  // gives the row's cells. Both are made once per layer and shared by every
  // piece crossing it: a piece clips rows and cells to its own ranges, which
  // is the same as clipping the polygon to them first (its ranges are
  // products of intervals).
  ++stamp_;
  row_cells_.clear();
  if (slabs_.size() < std::size_t(g.dims[d])) slabs_.resize(std::size_t(g.dims[d]));
  std::vector<glm::dvec2> flat, hull;
  const auto slab_of = [&](int s) -> const Slab& {
    Slab& slab = slabs_[std::size_t(s)];
    if (slab.stamp == stamp_) return slab;
    slab.stamp = stamp_;
    slab.row_first = 0;
    slab.rows = 0;
    const double lo = origin[d] + cell[d] * double(s) - eps, hi = lo + cell[d] + 2.0 * eps;
    flat.clear();
    for (const glm::dvec3& c : f.corner)
      if (c[d] >= lo && c[d] <= hi) flat.push_back({c[d2], c[d3]});
    for (const auto& e : kEdges) {
      const glm::dvec3& p = f.corner[std::size_t(e[0])];
      const glm::dvec3& q = f.corner[std::size_t(e[1])];
      const double span = q[d] - p[d];
      if (span == 0.0) continue;
      for (const double v : {lo, hi}) {
        const double t = (v - p[d]) / span;
        if (t <= 0.0 || t >= 1.0) continue;
        flat.push_back({p[d2] + (q[d2] - p[d2]) * t, p[d3] + (q[d3] - p[d3]) * t});
      }
    }
    if (flat.empty()) return slab;
    hull.resize(2 * flat.size());
    hull.resize(convex_hull(flat, hull.data()));
    double u_lo = hull[0].x, u_hi = hull[0].x;
    for (const glm::dvec2& p : hull) {
      u_lo = std::min(u_lo, p.x);
      u_hi = std::max(u_hi, p.x);
    }
    const int t0 = std::max(0, cell_lo(d2, u_lo)), t1 = std::min(g.dims[d2] - 1, cell_hi(d2, u_hi));
    if (t0 > t1) return slab;
    slab.row_first = t0;
    slab.rows = t1 - t0 + 1;
    slab.offset = std::uint32_t(row_cells_.size());
    const std::size_t n = hull.size();
    for (int t = t0; t <= t1; ++t) {
      // The polygon within strip t: the parts of its edges with lo <= u <= hi.
      const double strip_lo = origin[d2] + cell[d2] * double(t) - eps;
      const double strip_hi = strip_lo + cell[d2] + 2.0 * eps;
      double v_lo = std::numeric_limits<double>::infinity(), v_hi = -v_lo;
      for (std::size_t i = 0; i < n; ++i) {
        const glm::dvec2 p = hull[i], q = hull[i + 1 == n ? 0 : i + 1];
        double t_in = 0.0, t_out = 1.0;
        const double du = q.x - p.x;
        if (du == 0.0) {
          if (p.x < strip_lo || p.x > strip_hi) continue;
        } else {
          const double a = (strip_lo - p.x) / du, b = (strip_hi - p.x) / du;
          t_in = std::max(t_in, std::min(a, b));
          t_out = std::min(t_out, std::max(a, b));
          if (t_in > t_out) continue;
        }
        const double v0 = p.y + (q.y - p.y) * t_in, v1 = p.y + (q.y - p.y) * t_out;
        v_lo = std::min({v_lo, v0, v1});
        v_hi = std::max({v_hi, v0, v1});
      }
      // An empty row keeps an empty range (lo > hi).
      row_cells_.push_back(v_lo <= v_hi ? glm::ivec2(cell_lo(d3, v_lo), cell_hi(d3, v_hi)) : glm::ivec2(1, 0));
    }
    return slab;
  };

  std::vector<glm::dvec3> verts;
  for (const auto& piece : pieces) {
    DBox box;
    for (int a = 0; a < 3; ++a) {
      box.lo[a] = origin[a] + cell[a] * double(piece[std::size_t(a)].lo());
      box.hi[a] = origin[a] + cell[a] * double(piece[std::size_t(a)].hi() + 1);
    }
    verts.clear();
    intersection_vertices(f, box, eps, verts);
    if (verts.empty()) continue;
    DBox extent{verts[0], verts[0]};
    for (const glm::dvec3& v : verts) {
      extent.lo = glm::min(extent.lo, v);
      extent.hi = glm::max(extent.hi, v);
    }
    std::array<AxisRange, 3> r;
    bool any = true;
    for (int a = 0; a < 3; ++a)
      any = any && clip_range(a, piece[std::size_t(a)], extent.lo[a], extent.hi[a], r[std::size_t(a)]);
    if (!any) continue;

    const AxisRange& slices = r[std::size_t(d)];
    const AxisRange& rows = r[std::size_t(d2)];
    const AxisRange& cols = r[std::size_t(d3)];
    for (int s = slices.first;; s += slices.step) {
      if (mode == Mode::box) {
        for (int t = rows.first;; t += rows.step) {
          emit_row(s, t, cols.first, cols.last, cols.step);
          if (t == rows.last) break;
        }
      } else {
        const Slab& slab = slab_of(s);
        // The piece's rows that the layer's polygon reaches, in its order.
        const int t_lo = std::max(rows.lo(), slab.row_first);
        const int t_hi = std::min(rows.hi(), slab.row_first + slab.rows - 1);
        if (t_lo <= t_hi) {
          const int t_first = rows.step > 0 ? t_lo : t_hi, t_last = rows.step > 0 ? t_hi : t_lo;
          for (int t = t_first;; t += rows.step) {
            const glm::ivec2 span = row_cells_[slab.offset + std::size_t(t - slab.row_first)];
            const int v_lo = std::max(span.x, cols.lo()), v_hi = std::min(span.y, cols.hi());
            if (v_lo <= v_hi) {
              if (cols.step > 0) emit_row(s, t, v_lo, v_hi, 1);
              else emit_row(s, t, v_hi, v_lo, -1);
            }
            if (t == t_last) break;
          }
        }
      }
      if (s == slices.last) break;
    }
  }
  return runs_;
}

}  // namespace occull
