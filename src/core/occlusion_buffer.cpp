// The CPU occlusion buffer: see occlusion_buffer.hpp for its rules. The
// scalar reference loops are here; occlusion_buffer_simd.cpp vectorises them.
#include "occull/occlusion_buffer.hpp"

#include "occull/depth_pyramid.hpp"  // depth_tolerance: the same margin as the pyramid's
#include "occlusion_buffer_simd.hpp"
#include "occull/error.hpp"
#include "core/format.hpp"
#include "core/fixed_point.hpp"
#include "core/worker_pool.hpp"

#include <algorithm>
#include <array>
#include <atomic>
#include <cassert>
#include <cmath>
#include <limits>
#include <bit>
#include <utility>

namespace occull {
namespace {

constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr int kSubBits = 8;
constexpr std::int64_t kSub = std::int64_t(1) << kSubBits;  // fixed-point steps per texel (rule 3)
constexpr std::int64_t kGrow = kSub / 64; // a texel grown by 1/64 on every side (rules 3, 5)
constexpr double kGrowTexels = double(kGrow) / double(kSub);

// The scalar references of occlusion_buffer_simd.hpp, kept scalar (the
// compiler would otherwise vectorise them, and they are what the vector code
// is measured against).
[[gnu::optimize("no-tree-vectorize")]] void fill_span_scalar(float* row, int count, float base, float step,
                                                             float cap) {
  for (int i = 0; i < count; ++i) {
    const float v = base + step * float(i);
    const float depth = v < cap ? v : cap;
    row[i] = row[i] < depth ? row[i] : depth;
  }
}

// fill_span_scalar keeping each texel's tag (track_sources): a nearer key
// takes `tag`, the same key the smaller tag, so the tags do not depend on the
// order of the writes. The keys as fill_span_scalar writes them.
[[gnu::optimize("no-tree-vectorize")]] void fill_span_sourced_scalar(float* row, std::uint32_t* sources, int count,
                                                                    float base, float step, float cap,
                                                                    std::uint32_t tag) {
  for (int i = 0; i < count; ++i) {
    const float v = base + step * float(i);
    const float depth = v < cap ? v : cap;
    if (depth < row[i] || (depth == row[i] && tag < sources[i])) sources[i] = tag;
    row[i] = row[i] < depth ? row[i] : depth;
  }
}

[[gnu::optimize("no-tree-vectorize")]] float max_span_scalar(const float* row, int count) {
  float best = -kInf;
  for (int i = 0; i < count; ++i) best = best > row[i] ? best : row[i];
  return best;
}

using detail::floor_div_bounded;
using detail::next_up;
using detail::surely_front_facing;

// A texel coordinate to the nearest 1/256 texel (ties to even), for |v| <
// 2^20: adding 1.5 * 2^52 leaves no fraction bits in the sum, and the
// subtraction is exact. No libm call (floor is one on baseline x86-64).
std::int64_t snap(double v) {
  constexpr double kMagic = 6755399441055744.0;  // 1.5 * 2^52
  return std::int64_t((v * double(kSub) + kMagic) - kMagic);
}

// Twice the signed area of polygon s[0, n) on screen (x, y), its terms
// summed from corner 0 on, the wrapping one last.
double twice_area(const glm::dvec3* s, int n) {
  double area = 0.0;
  for (int i = 0; i + 1 < n; ++i) area += s[i].x * s[i + 1].y - s[i + 1].x * s[i].y;
  return area + (s[n - 1].x * s[0].y - s[0].x * s[n - 1].y);
}

// The texel holding fixed-point coordinate v: floor(v / kSub), as an
// arithmetic shift (C++20 defines >> on negative values so).
constexpr std::int64_t texel_of(std::int64_t v) { return v >> kSubBits; }

// The corner after corner i of a polygon of n corners (a modulo by a
// variable costs an integer division: this path runs per polygon).
constexpr int next_corner(int i, int n) { return i + 1 == n ? 0 : i + 1; }

// Every coordinate of a clipped vertex lies within 2^19 texels of the
// buffer: 2^27 fixed-point steps, so edge functions stay within int64.
double guard_band(int width, int height) { return double(1 << 20) / double(std::max(width, height)) - 1.0; }

// A hash table of 32-bit values by key, open addressing with linear
// probing, for make_occluder_mesh's welding and edges: one allocation, no
// node a key (docs/performance.md: preparing a city's meshes took twice as
// long with std::unordered_map). Keys are never erased.
template <class Key>
class FlatTable {
 public:
  /// Room for `count` keys at most half full.
  explicit FlatTable(std::size_t count)
      : mask_(std::bit_ceil(std::max<std::size_t>(16, 2 * count)) - 1), slots_(mask_ + 1) {}
  /// The value of `key`, and whether it was added (with `value`) by this call.
  std::pair<std::uint32_t*, bool> emplace(const Key& key, std::uint32_t value) {
    Slot& s = slot(key);
    const bool added = !s.used;
    if (added) s = {key, value, true};
    return {&s.value, added};
  }
  /// The value of `key`, or null.
  [[nodiscard]] std::uint32_t* find(const Key& key) {
    Slot& s = slot(key);
    return s.used ? &s.value : nullptr;
  }

 private:
  struct Slot {
    Key key{};
    std::uint32_t value = 0;
    bool used = false;
  };
  static std::size_t hash(std::uint64_t k) noexcept {  // a 64-bit finaliser (splitmix64's)
    k = (k ^ (k >> 30)) * 0xbf58476d1ce4e5b9ull;
    k = (k ^ (k >> 27)) * 0x94d049bb133111ebull;
    return std::size_t(k ^ (k >> 31));
  }
  static std::size_t hash(const std::array<std::uint32_t, 3>& k) noexcept {
    return hash((std::uint64_t(k[0]) << 32 | k[1]) ^ (std::uint64_t(k[2]) * 0x9e3779b97f4a7c15ull));
  }
  // The slot holding `key`, or the empty one where it would go.
  Slot& slot(const Key& key) {
    for (std::size_t i = hash(key) & mask_;; i = (i + 1) & mask_)
      if (!slots_[i].used || slots_[i].key == key) return slots_[i];
  }
  std::size_t mask_;
  std::vector<Slot> slots_;
};

// What choosing polygons needs of a lens on a width × height buffer: texels
// per unit at unit view depth (the larger axis), and tan^2 of its half
// angles summed (perspective).
struct LensReach {
  double texels_per_unit;
  double tan2;
};
LensReach lens_of(const View& view, int width, int height) {
  const double fx = std::abs(double(view.proj[0][0])) * 0.5 * double(width);
  const double fy = std::abs(double(view.proj[1][1])) * 0.5 * double(height);
  return {std::max(fx, fy),
          1.0 / double(view.proj[0][0] * view.proj[0][0]) + 1.0 / double(view.proj[1][1] * view.proj[1][1])};
}

// Rule 8: `nearest` (a box's key) lies behind `farthest` (a texel's or
// tile's key) by more than depth rounding. +infinity hides nothing.
bool behind(float nearest, float farthest, bool margin) {
  return margin ? nearest > farthest + depth_tolerance(farthest) : nearest >= farthest;
}

}  // namespace

std::string simd_target_name() { return simd::target_name(); }

// An edge function of a region: a texel is inside when
// a * (x + ox) + b * (y + oy) + c > 0 (x, y its lower left corner, fixed
// point; ox, oy the corner of its square tested; >= 0 with rule 3 off).
struct OcclusionBuffer::Edge {
  std::int64_t a, b, c, ox, oy;
};

// A region's depth bound: the plane through p0 with slopes gx, gy (per
// texel), taken at (fx, fy) in each texel, plus bias, no farther than cap.
struct OcclusionBuffer::DepthPlane {
  glm::dvec3 p0;
  double gx, gy, fx, fy, bias, off_plane;
  float cap;
};

// The edges of a counter-clockwise polygon snapped to X, Y (those between
// corners snapped together left out), each tested at the corner of the grown
// texel (rule 10: centres' square) farthest outside it. Returns how many.

std::size_t OccluderMesh::count_at_least(float radius) const noexcept {
  return std::size_t(std::partition_point(inradius.begin(), inradius.end(), [&](float r) { return r >= radius; }) -
                     inradius.begin());
}

OccluderMesh make_occluder_mesh(std::span<const glm::vec3> positions, std::span<const std::uint32_t> indices,
                                double detail) {
  struct Tri {
    std::uint32_t v[3];
    glm::dvec3 normal;  // unnormalised: twice the area
    bool merged = false;
  };
  std::vector<Tri> tris;
  for (std::size_t i = 0; i + 2 < indices.size(); i += 3) {
    Tri t{{indices[i], indices[i + 1], indices[i + 2]}, {}};
    const glm::dvec3 a(positions[t.v[0]]), b(positions[t.v[1]]), c(positions[t.v[2]]);
    t.normal = glm::cross(b - a, c - a);
    if (glm::length(t.normal) > 0.0) tris.push_back(t);
  }
  // Each position welded to an id by its bits (meshes that do not share
  // vertices match too), and each directed edge keyed by its ends' ids.
  std::vector<std::uint32_t> weld(positions.size());
  {
    FlatTable<std::array<std::uint32_t, 3>> ids(positions.size());
    for (std::size_t v = 0; v < positions.size(); ++v) {
      const glm::vec3& p = positions[v];
      weld[v] = *ids.emplace({std::bit_cast<std::uint32_t>(p.x), std::bit_cast<std::uint32_t>(p.y),
                              std::bit_cast<std::uint32_t>(p.z)},
                             std::uint32_t(v)).first;
    }
  }
  const auto key = [&](std::uint32_t a, std::uint32_t b) { return std::uint64_t(weld[a]) << 32 | weld[b]; };
  FlatTable<std::uint64_t> edges(tris.size() * 3);  // each directed edge's first triangle
  for (std::size_t t = 0; t < tris.size(); ++t)
    for (int k = 0; k < 3; ++k) (void)edges.emplace(key(tris[t].v[k], tris[t].v[(k + 1) % 3]), std::uint32_t(t));

  struct Poly {
    std::uint32_t c[4];
    float radius;
    OccluderMesh::Bounds bounds;
  };
  std::vector<Poly> polys;
  const auto add = [&](const std::uint32_t* c, int n) {
    double area2 = 0.0, perimeter = 0.0;
    glm::dvec3 sum(0.0);
    for (int k = 0; k < n; ++k) {
      const glm::dvec3 a(positions[c[k]]), b(positions[c[(k + 1) % n]]);
      sum += glm::cross(a, b);
      perimeter += glm::length(b - a);
    }
    area2 = glm::length(sum);
    glm::dvec3 centre(0.0);
    for (int k = 0; k < n; ++k) centre += glm::dvec3(positions[c[k]]);
    centre /= double(n);
    double radius = 0.0;
    for (int k = 0; k < n; ++k) radius = std::max(radius, glm::length(glm::dvec3(positions[c[k]]) - centre));
    const glm::dvec3 normal = sum / area2;
    Poly p{{c[0], c[1], c[2], n == 4 ? c[3] : OccluderMesh::no_corner},
           float(area2 / perimeter),
           {glm::vec3(normal), float(glm::dot(normal, centre)), glm::vec3(centre), float(radius * (1.0 + 1e-6)),
            float(0.5 * area2)}};
    polys.push_back(p);
  };
  for (std::size_t t = 0; t < tris.size(); ++t) {
    if (tris[t].merged) continue;
    tris[t].merged = true;
    bool done = false;
    for (int k = 0; k < 3 && !done; ++k) {
      const std::uint32_t a = tris[t].v[k], b = tris[t].v[(k + 1) % 3], c = tris[t].v[(k + 2) % 3];
      const std::uint32_t* across = edges.find(key(b, a));
      if (across == nullptr || tris[*across].merged) continue;
      Tri& u = tris[*across];
      const glm::dvec3 n1 = glm::normalize(tris[t].normal), n2 = glm::normalize(u.normal);
      if (glm::dot(n1, n2) < 1.0 - 1e-9) continue;  // not one plane
      std::uint32_t d = u.v[0];
      for (std::uint32_t w : u.v)
        if (weld[w] != weld[a] && weld[w] != weld[b]) d = w;
      const std::uint32_t quad[4] = {a, d, b, c};
      bool convex = true;
      for (int q = 0; q < 4; ++q) {
        const glm::dvec3 p0(positions[quad[q]]), p1(positions[quad[(q + 1) % 4]]), p2(positions[quad[(q + 2) % 4]]);
        convex &= glm::dot(glm::cross(p1 - p0, p2 - p1), n1) > 0.0;
      }
      if (!convex) continue;
      u.merged = true;
      add(quad, 4);
      done = true;
    }
    if (!done) add(tris[t].v, 3);
  }
  std::stable_sort(polys.begin(), polys.end(), [](const Poly& x, const Poly& y) { return x.radius > y.radius; });
  if (detail > 0.0 && !polys.empty()) {
    const float smallest = float(double(polys.front().radius) / detail);
    polys.erase(std::partition_point(polys.begin(), polys.end(), [&](const Poly& p) { return p.radius >= smallest; }),
                polys.end());
  }
  OccluderMesh out;
  out.corners.reserve(polys.size() * 4);
  out.inradius.reserve(polys.size());
  // Each corner by its welded vertex (the first of the positions with the
  // same bits): a mesh that repeats a position for each polygon at it (flat
  // shading, per-face attributes) transforms it once, as a shared one.
  for (const Poly& p : polys) {
    for (const std::uint32_t c : p.c) out.corners.push_back(c == OccluderMesh::no_corner ? c : weld[c]);
    out.inradius.push_back(p.radius);
    out.bounds.push_back(p.bounds);
  }
  // Rule 11's pairs: each directed edge's polygon, kept only when the mesh
  // uses that edge once in that direction.
  constexpr std::uint32_t kMany = OccluderMesh::no_corner;
  FlatTable<std::uint64_t> directed(out.corners.size());
  const auto corner_count = [&](std::size_t p) { return out.corners[4 * p + 3] == OccluderMesh::no_corner ? 3 : 4; };
  for (std::size_t p = 0; p < out.polygons(); ++p)
    for (int k = 0, n = corner_count(p); k < n; ++k) {
      const auto [value, added] = directed.emplace(key(out.corners[4 * p + std::size_t(k)],
                                                       out.corners[4 * p + std::size_t((k + 1) % n)]),
                                                   std::uint32_t(p));
      if (!added) *value = kMany;
    }
  out.neighbours.assign(out.corners.size(), OccluderMesh::no_corner);
  for (std::size_t p = 0; p < out.polygons(); ++p)
    for (int k = 0, n = corner_count(p); k < n; ++k) {
      const std::uint32_t a = out.corners[4 * p + std::size_t(k)], b = out.corners[4 * p + std::size_t((k + 1) % n)];
      if (*directed.find(key(a, b)) != std::uint32_t(p)) continue;  // this direction used twice
      const std::uint32_t* across = directed.find(key(b, a));
      if (across != nullptr && *across != kMany && *across != std::uint32_t(p))
        out.neighbours[4 * p + std::size_t(k)] = *across;
    }
  std::vector<bool> used(positions.size(), false);
  std::size_t corners = 0, vertices = 0;
  for (const std::uint32_t c : out.corners) {
    if (c == OccluderMesh::no_corner) continue;
    ++corners;
    if (!used[c]) used[c] = true, ++vertices;
  }
  out.shared_corners = vertices > 0 && corners >= 2 * vertices;
  return out;
}

OcclusionBuffer::OcclusionBuffer(int width, int height, SimdPath simd, const detail::OcclusionRules& rules)
    : width_(width),
      height_(height),
      tiles_x_((width + tile_size - 1) / tile_size),
      tiles_y_((height + tile_size - 1) / tile_size),
      guard_(guard_band(width, height)),
      simd_(simd),
      rules_(rules),
      keys_(std::size_t(width) * std::size_t(height), kInf),
      tile_far_(std::size_t(tiles_x_) * std::size_t(tiles_y_), kInf),
      tile_dirty_(tile_far_.size(), 0),
      lanes_(1) {
  if (width < 1 || height < 1 || width > 8192 || height > 8192)
    throw UsageError(detail::format("OcclusionBuffer: {}x{} texels (each side in [1, 8192])", width, height));
}

OcclusionBuffer::OcclusionBuffer(OcclusionBuffer&&) noexcept = default;
OcclusionBuffer& OcclusionBuffer::operator=(OcclusionBuffer&&) noexcept = default;
OcclusionBuffer::~OcclusionBuffer() = default;

void OcclusionBuffer::set_threads(int threads) {
  if (threads < 1 || threads > max_threads)
    throw UsageError(detail::format("OcclusionBuffer::set_threads: {} threads (in [1, {}])", threads, max_threads));
  if (threads == this->threads()) return;
  pool_.reset();  // joins the old threads before their lanes go
  lanes_.resize(std::size_t(threads));
  for (std::size_t i = 1; i < lanes_.size(); ++i) {
    lanes_[i].own_keys.assign(keys_.size(), kInf);
    lanes_[i].own_dirty.assign(tile_dirty_.size(), 0);
    lanes_[i].own_sources.assign(sources_.size(), no_source);
  }
  if (threads > 1) pool_ = std::make_unique<detail::WorkerPool>(threads - 1);
}

void OcclusionBuffer::merge(Lane& lane) {
  for (int ty = 0; ty < tiles_y_; ++ty)
    for (int tx = 0; tx < tiles_x_; ++tx) {
      const std::size_t t = std::size_t(ty) * std::size_t(tiles_x_) + std::size_t(tx);
      if (!lane.own_dirty[t]) continue;
      lane.own_dirty[t] = 0;
      tile_dirty_[t] = 1;
      const int x0 = tx * tile_size, y0 = ty * tile_size;
      const int w = std::min(tile_size, width_ - x0), h = std::min(tile_size, height_ - y0);
      for (int y = y0; y < y0 + h; ++y) {
        const std::size_t i = std::size_t(y) * std::size_t(width_) + std::size_t(x0);
        float* to = keys_.data() + i;
        float* from = lane.own_keys.data() + i;
        if (!sources_.empty()) {  // as fill_span_sourced keeps the tags
          std::uint32_t* to_tag = sources_.data() + i;
          std::uint32_t* from_tag = lane.own_sources.data() + i;
          for (int x = 0; x < w; ++x) {
            if (from[x] < to[x] || (from[x] == to[x] && from_tag[x] < to_tag[x])) to_tag[x] = from_tag[x];
            from_tag[x] = no_source;
          }
        }
        for (int x = 0; x < w; ++x) {
          to[x] = to[x] < from[x] ? to[x] : from[x];  // as fill_span keeps the nearer
          from[x] = kInf;
        }
      }
    }
}

void OcclusionBuffer::clear(const ClipSpace& clip) {
  clip_ = clip;
  pixels_ = 0;
  inset_ = 0;
  std::fill(keys_.begin(), keys_.end(), kInf);
  std::fill(sources_.begin(), sources_.end(), no_source);
  std::fill(tile_far_.begin(), tile_far_.end(), kInf);
  std::fill(tile_dirty_.begin(), tile_dirty_.end(), std::uint8_t{0});
}

void OcclusionBuffer::clear(const View& view) {
  clear(view.clip);
  // Rule 10: k × k pixel centres per texel, only where the view says it is
  // sampled at its pixels' centres and its pixels tile the texels exactly.
  const int k = view.width / width_;
  const bool grid = k >= 1 && view.width == k * width_ && view.height == k * height_;
  if (rules_.sample_grid ? (view.samples == 1 && grid) : true) {
    pixels_ = std::max(k, 1);
    // Half a pixel in from each side, rounded down to a fixed-point step (a
    // smaller square: more conservative).
    inset_ = kSub / (2 * std::int64_t(pixels_));
  }
}

void OcclusionBuffer::track_sources(bool on) {
  if (on == tracks_sources()) return;
  if (on)
    sources_.assign(keys_.size(), no_source);
  else
    sources_ = {};
  for (std::size_t i = 1; i < lanes_.size(); ++i) {
    if (on)
      lanes_[i].own_sources.assign(keys_.size(), no_source);
    else
      lanes_[i].own_sources = {};
  }
}

double OcclusionBuffer::covered_half_side() const noexcept { return 0.5 - double(inset_) / double(kSub); }

std::size_t OcclusionBuffer::covered_texels() const noexcept {
  return std::size_t(std::count_if(keys_.begin(), keys_.end(), [](float k) { return k != kInf; }));
}

std::uint32_t OcclusionBuffer::rasterize(std::span<const glm::vec3> positions, std::span<const std::uint32_t> indices,
                                         const glm::dmat4& object_to_clip) {
  start_lanes(1);
  Lane& lane = lanes_[0];
  for (std::size_t i = 0; i + 2 < indices.size(); i += 3) {
    ClipVertex c[3];
    for (int k = 0; k < 3; ++k) {
      if (indices[i + std::size_t(k)] >= positions.size())
        throw UsageError(detail::format("OcclusionBuffer::rasterize: index {} of {} positions",
                                        indices[i + std::size_t(k)], positions.size()));
      c[k] = classify(object_to_clip * glm::dvec4(glm::dvec3(positions[indices[i + std::size_t(k)]]), 1.0));
    }
    ClipVertex* v[3] = {&c[0], &c[1], &c[2]};
    (void)raster_clipped(lane, v, 3);
  }
  return lane.count;
}

std::uint32_t OcclusionBuffer::rasterize(std::span<const glm::vec3> positions, const OccluderMesh& mesh,
                                         std::size_t count, const glm::dmat4& object_to_clip) {
  if (count > mesh.polygons())
    throw UsageError(detail::format("OcclusionBuffer::rasterize: {} polygons of a mesh of {}", count, mesh.polygons()));
  return raster_polygons(positions, mesh, nullptr, count, object_to_clip);
}

std::uint32_t OcclusionBuffer::rasterize(std::span<const glm::vec3> positions, const OccluderMesh& mesh,
                                         const View& view, const glm::mat4& object_to_world, const Aabb& bounds) {
  Lane& lane = lanes_[0];
  const std::size_t count = choose_polygons(lane.chosen, mesh, view, object_to_world, bounds);
  if (count == 0) return 0;
  const glm::dmat4 object_to_clip = glm::dmat4(view.view_proj) * glm::dmat4(object_to_world);
  return raster_polygons(positions, mesh, lane.chosen.data(), count, object_to_clip);
}

std::uint32_t OcclusionBuffer::rasterize(std::span<const OccluderDraw> draws, const View& view) {
  start_lanes(lanes_.size());
  // Each draw whole on one thread, taken in turn by whichever is free.
  std::atomic<std::size_t> next{0};
  auto job = [&](int l) {
    Lane& lane = lanes_[std::size_t(l)];
    for (std::size_t d = next.fetch_add(1, std::memory_order_relaxed); d < draws.size();
         d = next.fetch_add(1, std::memory_order_relaxed)) {
      const OccluderDraw& draw = draws[d];
      lane.source = draw.source;
      const std::size_t count = choose_polygons(lane.chosen, *draw.mesh, view, draw.object_to_world, draw.bounds);
      if (count == 0) continue;
      const glm::dmat4 object_to_clip = glm::dmat4(view.view_proj) * glm::dmat4(draw.object_to_world);
      if (draw.mesh->shared_corners) begin_vertices(lane, draw.positions.size());
      for (std::size_t i = 0; i < count; ++i)
        raster_mesh_polygon(lane, draw.positions, *draw.mesh, lane.chosen[i], object_to_clip);
    }
  };
  if (pool_)
    pool_->run(job);
  else
    job(0);
  return finish_lanes(lanes_.size());
}

std::size_t OcclusionBuffer::choose_polygons(std::vector<std::uint32_t>& list, const OccluderMesh& mesh,
                                             const View& view, const glm::mat4& object_to_world,
                                             const Aabb& bounds) const {
  const std::size_t count = polygons_worth_rasterizing(mesh, view, object_to_world, bounds);
  list.resize(count);
  if (count == 0) return 0;
  if (view.orthographic) {
    for (std::size_t p = 0; p < count; ++p) list[p] = std::uint32_t(p);
    return count;
  }
  // Per polygon, in object space: its side of the eye; its size on the
  // buffer at the nearest view depth of its bounding sphere (a length at view
  // depth z spans at most f / z * sqrt(1 + tan^2) texels, f texels per unit
  // at unit depth, tan of the lens's half angles); and its area seen at its
  // angle, which must hold the circle inscribed in what a texel needs
  // covered (half a texel, pi / 4 texels; less with rule 10): a wall seen
  // edge on along a street covers nothing.
  const glm::dmat3 m(object_to_world);
  const double flip = glm::determinant(m) < 0.0 ? -1.0 : 1.0;  // a mirroring transform turns the winding
  const glm::dvec3 eye = glm::dvec3(glm::inverse(glm::dmat4(object_to_world)) * glm::dvec4(glm::dvec3(view.eye), 1.0));
  const double stretch = std::max({glm::length(m[0]), glm::length(m[1]), glm::length(m[2])});
  const LensReach lens = lens_of(view, width_, height_);
  const double per_unit = lens.texels_per_unit * std::sqrt(1.0 + lens.tan2) * stretch;  // texels per object unit at depth 1
  // View depth of an object-space point: -(row 2 of view * object_to_world) . (p, 1).
  const glm::dmat4 to_eye = glm::dmat4(view.view) * glm::dmat4(object_to_world);
  const glm::dvec3 depth_axis(-to_eye[0][2], -to_eye[1][2], -to_eye[2][2]);
  const double depth_offset = -to_eye[3][2];
  const double depth_stretch = glm::length(depth_axis);
  const double near = double(view.near);
  const double half_side = covered_half_side(), circle = 0.785 * 4.0 * half_side * half_side;  // pi/4 of the square
  // Into a list with no branch a polygon (which side of the eye a terrain's
  // polygon faces is a coin toss to the predictor).
  std::size_t chosen = 0;
  const bool any_side = !rules_.front_faces_only;
  if (half_side <= 0.0) {  // rule 10, one pixel a texel: any polygon may hold a pixel centre
    for (std::size_t p = 0; p < count; ++p) {
      const OccluderMesh::Bounds& b = mesh.bounds[p];
      const double side = flip * (glm::dot(glm::dvec3(b.normal), eye) - double(b.offset));
      list[chosen] = std::uint32_t(p);
      chosen += std::size_t(any_side | (side > 0.0));
    }
  } else {
    for (std::size_t p = 0; p < count; ++p) {
      const OccluderMesh::Bounds& b = mesh.bounds[p];
      const double side = flip * (glm::dot(glm::dvec3(b.normal), eye) - double(b.offset));
      const glm::dvec3 centre(b.centre);
      const double z = std::max(glm::dot(depth_axis, centre) + depth_offset - depth_stretch * double(b.radius), near);
      const double texels = per_unit / z;  // per object unit, at most
      const double cosine = std::min(1.0, std::abs(side) / std::max(glm::length(eye - centre), 1e-30));
      list[chosen] = std::uint32_t(p);
      chosen += std::size_t((any_side | (side > 0.0)) & !(double(mesh.inradius[p]) * texels < half_side) &
                            !(double(b.area) * cosine * texels * texels < circle));
    }
  }
  return chosen;
}

std::uint32_t OcclusionBuffer::raster_polygons(std::span<const glm::vec3> positions, const OccluderMesh& mesh,
                                               const std::uint32_t* list, std::size_t count,
                                               const glm::dmat4& object_to_clip) {
  const auto polygon = [&](std::size_t i) { return list ? list[i] : i; };
  const std::size_t lanes = count >= parallel_polygons ? lanes_.size() : 1;
  start_lanes(lanes);
  for (std::size_t l = 0; l < lanes && mesh.shared_corners; ++l) begin_vertices(lanes_[l], positions.size());
  if (lanes == 1) {
    for (std::size_t i = 0; i < count; ++i) raster_mesh_polygon(lanes_[0], positions, mesh, polygon(i), object_to_clip);
    return lanes_[0].count;
  }
  // Runs of a few polygons, taken in turn by whichever thread is free (a
  // thread woken late takes fewer): which thread rasterizes a polygon
  // changes no texel once merged.
  constexpr std::size_t kRun = 16;
  const std::size_t runs = (count + kRun - 1) / kRun;
  std::atomic<std::size_t> next{0};
  auto job = [&](int l) {
    Lane& lane = lanes_[std::size_t(l)];
    for (std::size_t r = next.fetch_add(1, std::memory_order_relaxed); r < runs;
         r = next.fetch_add(1, std::memory_order_relaxed))
      for (std::size_t i = r * kRun, end = std::min(count, i + kRun); i < end; ++i)
        raster_mesh_polygon(lane, positions, mesh, polygon(i), object_to_clip);
  };
  pool_->run(job);
  return finish_lanes(lanes);
}

void OcclusionBuffer::start_lanes(std::size_t lanes) {
  for (std::size_t l = 0; l < lanes; ++l) {
    Lane& lane = lanes_[l];
    lane.keys = l == 0 ? keys_.data() : lane.own_keys.data();
    lane.dirty = l == 0 ? tile_dirty_.data() : lane.own_dirty.data();
    lane.sources = sources_.empty() ? nullptr : l == 0 ? sources_.data() : lane.own_sources.data();
    lane.source = source_;
    lane.count = 0;
  }
}

std::uint32_t OcclusionBuffer::finish_lanes(std::size_t lanes) {
  std::uint32_t drawn = lanes_[0].count;
  for (std::size_t l = 1; l < lanes; ++l) {
    merge(lanes_[l]);
    drawn += lanes_[l].count;
  }
  return drawn;
}

void OcclusionBuffer::begin_vertices(Lane& lane, std::size_t vertices) {
  if (lane.vertex_stamp.size() < vertices) {
    lane.vertex_stamp.resize(vertices, 0);
    lane.vertices.resize(vertices);
  }
  if (++lane.stamp == 0) {  // wrapped: no stamp may look current
    std::fill(lane.vertex_stamp.begin(), lane.vertex_stamp.end(), 0u);
    lane.stamp = 1;
  }
}

void OcclusionBuffer::mesh_corners(Lane& lane, std::span<const glm::vec3> positions, const OccluderMesh& mesh,
                                   std::size_t p, const glm::dmat4& object_to_clip, ClipVertex* local,
                                   ClipVertex** v) const {
  const std::uint32_t* corners = mesh.corners.data() + 4 * p;
  const int n = corners[3] == OccluderMesh::no_corner ? 3 : 4;
  for (int k = 0; k < n; ++k) {
    const std::uint32_t i = corners[k];
    if (!mesh.shared_corners) {  // each corner its own vertex: nothing to share
      local[k] = classify(object_to_clip * glm::dvec4(glm::dvec3(positions[i]), 1.0));
      v[k] = &local[k];
      continue;
    }
    if (lane.vertex_stamp[i] != lane.stamp) {
      lane.vertices[i] = classify(object_to_clip * glm::dvec4(glm::dvec3(positions[i]), 1.0));
      lane.vertex_stamp[i] = lane.stamp;
    }
    v[k] = &lane.vertices[i];
  }
}

void OcclusionBuffer::raster_mesh_polygon(Lane& lane, std::span<const glm::vec3> positions, const OccluderMesh& mesh,
                                          std::size_t p, const glm::dmat4& object_to_clip) const {
  const int n = mesh.corners[4 * p + 3] == OccluderMesh::no_corner ? 3 : 4;
  ClipVertex local[4];
  ClipVertex* v[4];
  mesh_corners(lane, positions, mesh, p, object_to_clip, local, v);
  // Rule 11 (which rests on rules 2-4: none of them switched off).
  if (!raster_clipped(lane, v, n) || !fused_pairs_ || mesh.neighbours.empty() || !rules_.inner_coverage ||
      !rules_.farthest_depth || !drawn_whole(v, n))
    return;
  // Each edge this polygon shares with an earlier polygon of the mesh (one
  // this call may rasterize too: one too small to cover a texel alone adds
  // little beside a larger one), so each pair once; only where a square of
  // the band can lie: one reaching the edge's rectangle grown by the growth
  // (a smaller region than the band hides less). At one pixel a texel most
  // edges hold no pixel centre in their band, and stop here.
  const std::int64_t near_side = inset_ - kGrow, far_side = kSub - inset_ + kGrow;
  for (int k = 0; k < n; ++k) {
    const std::uint32_t q = mesh.neighbours[4 * p + std::size_t(k)];
    if (q >= p) continue;  // no_corner too
    const ClipVertex &a = *v[k], &b = *v[next_corner(k, n)];
    const TexelRect r{int(std::max<std::int64_t>(0, -texel_of(far_side - (std::min(a.x, b.x) - kGrow)))),
                      int(std::min<std::int64_t>(width_ - 1, texel_of(std::max(a.x, b.x) + kGrow - near_side))),
                      int(std::max<std::int64_t>(0, -texel_of(far_side - (std::min(a.y, b.y) - kGrow)))),
                      int(std::min<std::int64_t>(height_ - 1, texel_of(std::max(a.y, b.y) + kGrow - near_side)))};
    if (r.x_lo > r.x_hi || r.y_lo > r.y_hi || (a.x == b.x && a.y == b.y)) continue;
    // The band: squares that lie wholly on neither side of the shared edge
    // (grown), i.e. that neither polygon alone covers: not wholly inside
    // the edge as this polygon runs it, nor as the other runs it back.
    const std::int64_t X[2] = {a.x, b.x}, Y[2] = {a.y, b.y};
    const Edge band[2] = {not_wholly_inside(make_edge(X, Y, 0, 1)), not_wholly_inside(make_edge(X, Y, 1, 0))};
    if (might_cover(band, 2, r)) fuse_edge(lane, positions, mesh, v, n, k, q, r, band, object_to_clip);
  }
}

// The squares that are not wholly inside edge e (grown): e at the corner
// farthest outside it, e(corner) <= 0, is -e(corner) + 1 > 0.
OcclusionBuffer::Edge OcclusionBuffer::not_wholly_inside(const Edge& e) { return {-e.a, -e.b, -e.c + 1, e.ox, e.oy}; }

// Whether polygon corners c lie where the GPU draws them unclipped (inside
// the near plane, and within twice the viewport's extent: rule 11 assumes
// the GPU's guard band reaches that far).
bool OcclusionBuffer::drawn_whole(ClipVertex* const* c, int count) const {
  for (int i = 0; i < count; ++i) {
    const glm::dvec4& x = c[i]->clip;
    if (!c[i]->inside || !(std::abs(x.x) <= 2.0 * x.w) || !(std::abs(x.y) <= 2.0 * x.w)) return false;
  }
  return true;
}

// False when no texel of a rectangle of a few texels lies inside every edge
// (strictly: rule 3); true for a larger one, whose rows fill_region bounds
// without testing each texel.
bool OcclusionBuffer::might_cover(const Edge* edges, int count, const TexelRect& r) {
  if ((r.x_hi - r.x_lo + 1) * (r.y_hi - r.y_lo + 1) > kFewTexels) return true;
  for (std::int64_t ty = r.y_lo; ty <= r.y_hi; ++ty)
    for (std::int64_t tx = r.x_lo; tx <= r.x_hi; ++tx) {
      bool inside = true;
      for (int e = 0; e < count && inside; ++e)
        inside = edges[e].a * (tx * kSub + edges[e].ox) + edges[e].b * (ty * kSub + edges[e].oy) + edges[e].c > 0;
      if (inside) return true;
    }
  return false;
}

// Rule 11: the band along the edge k of polygon A (corners v) that it shares
// with polygon q (B).
void OcclusionBuffer::fuse_edge(Lane& lane, std::span<const glm::vec3> positions, const OccluderMesh& mesh,
                                ClipVertex* const* v, int n, int k, std::uint32_t q, const TexelRect& r,
                                const Edge* band, const glm::dmat4& object_to_clip) const {
  const int k1 = next_corner(k, n);
  std::int64_t XA[4], YA[4];
  for (int i = 0; i < n; ++i) XA[i] = v[i]->x, YA[i] = v[i]->y;
  // Inside A's other edges and B's, grown: on A's side of the shared edge
  // that is inside A, on B's inside B, wherever the GPU's snapping puts it.
  // A's first: a band holding no square inside them stops before B is read.
  Edge edges[kMaxEdges] = {band[0], band[1]};
  int count = 2;
  for (int i = 0; i < n && rules_.fusion_other_edges; ++i) {
    const int i1 = next_corner(i, n);
    if (i != k && !(XA[i] == XA[i1] && YA[i] == YA[i1])) edges[count++] = make_edge(XA, YA, i, i1);
  }
  if (!might_cover(edges, count, r)) return;

  const int m = mesh.corners[4 * std::size_t(q) + 3] == OccluderMesh::no_corner ? 3 : 4;
  ClipVertex local[4];
  ClipVertex* w[4];
  mesh_corners(lane, positions, mesh, q, object_to_clip, local, w);
  if (!drawn_whole(w, m)) return;
  std::int64_t XB[4], YB[4];
  glm::dvec3 sA[4], sB[4];
  for (int i = 0; i < n; ++i) sA[i] = v[i]->window;
  for (int i = 0; i < m; ++i) XB[i] = w[i]->x, YB[i] = w[i]->y, sB[i] = w[i]->window;
  // B's edge j runs back along A's edge k (the same positions snap alike).
  int j = -1;
  for (int i = 0; i < m; ++i)
    if (XB[i] == XA[k1] && YB[i] == YA[k1] && XB[next_corner(i, m)] == XA[k] && YB[next_corner(i, m)] == YA[k]) j = i;
  if (j < 0) return;
  if (!(surely_front_facing(XA, YA, n) && surely_front_facing(XB, YB, m))) return;
  for (int i = 0; i < m && rules_.fusion_other_edges; ++i) {
    const int i1 = next_corner(i, m);
    if (i != j && !(XB[i] == XB[i1] && YB[i] == YB[i1])) edges[count++] = make_edge(XB, YB, i, i1);
  }
  DepthPlane plane, other;
  if (!depth_plane(sA, n, plane) || !depth_plane(sB, m, other)) return;
  const double length = glm::length(glm::dvec2(sA[k1].x - sA[k].x, sA[k1].y - sA[k].y));  // texels
  if (!(length >= 1.0 / 64.0)) return;
  if (rules_.fusion_depth) {
    // A fragment of the band is A's or B's: B's plane differs from A's by
    // their slopes' difference times the distance to the edge (no more than
    // the grown square's diagonal), plus what both planes miss the shared
    // corners by, which grows along the edge as far as the band's squares
    // reach past them (under 3 texels: the edge's rectangle grown by a
    // square).
    const double side = 1.0 - 2.0 * double(inset_) / double(kSub) + 2.0 * kGrowTexels;
    plane.bias += other.bias + (std::abs(plane.gx - other.gx) + std::abs(plane.gy - other.gy)) * side * 1.5 +
                  (plane.off_plane + other.off_plane) * (2.0 + 6.0 / length);
    plane.cap = std::max(plane.cap, other.cap);
  }
  fill_region(lane, edges, count, r, [&] { return &plane; });
}

namespace {
constexpr int kPlanes = 5;  // the near plane, then the guard band's four sides
}  // namespace

// Texel coordinates and the depth key (window depth, negated with reversed-Z)
// of a point in front of the near plane.
glm::dvec3 OcclusionBuffer::project(const glm::dvec4& c) const {
  const double ndc_z = c.z / c.w;
  const double depth = clip_.depth == DepthRange::zero_to_one ? ndc_z : ndc_z * 0.5 + 0.5;
  return {(c.x / c.w * 0.5 + 0.5) * double(width_), (c.y / c.w * 0.5 + 0.5) * double(height_),
          clip_.reversed_z ? -depth : depth};
}

OcclusionBuffer::ClipVertex OcclusionBuffer::classify(const glm::dvec4& c) const {
  const double guard = guard_;
  ClipVertex out{};
  out.clip = c;
  out.outside = unsigned(c.x > c.w) | unsigned(c.x < -c.w) << 1 | unsigned(c.y > c.w) << 2 | unsigned(c.y < -c.w) << 3;
  const double near = !rules_.clip_near ? c.w - 1e-5
                      : clip_.reversed_z ? c.w - c.z
                                         : c.z - clip_.near_depth() * c.w;
  out.crossing_near = !(near >= 0.0) || !(c.w > 0.0);
  out.inside = !out.crossing_near && guard * c.w - c.x >= 0.0 && guard * c.w + c.x >= 0.0 &&
               guard * c.w - c.y >= 0.0 && guard * c.w + c.y >= 0.0;
  if (out.inside) {  // projected now: the polygons chosen face the eye, and nearly all such corners are drawn
    out.window = project(c);
    out.x = snap(out.window.x);
    out.y = snap(out.window.y);
  }
  return out;
}

// Rule 1: clips a convex polygon at the near plane and the guard band (in
// double, Sutherland-Hodgman), then rasterizes what is left. True when the
// polygon needed no clipping and faces the eye (its corners projected).
bool OcclusionBuffer::raster_clipped(Lane& lane, ClipVertex* const* v, int vertices) const {
  const double guard = guard_;
  const double near_depth = clip_.near_depth();
  const auto distance = [&](const glm::dvec4& c, int plane) -> double {
    switch (plane) {
      case 0:
        if (!rules_.clip_near) return c.w - 1e-5;
        return clip_.reversed_z ? c.w - c.z : c.z - near_depth * c.w;
      case 1: return guard * c.w - c.x;
      case 2: return guard * c.w + c.x;
      case 3: return guard * c.w - c.y;
      default: return guard * c.w + c.y;
    }
  };
  constexpr int kMax = 4 + kPlanes;
  // Shortcuts that change no texel: a polygon wholly past one side of the
  // viewport is dropped, and so is a back-facing one lying wholly beyond
  // the near plane (its orientation on screen is the sign of det[x y w] of
  // three corners when every w > 0; a polygon's corners are coplanar).
  unsigned all_out = 0xf;
  bool crossing_near = false, inside = true;
  for (int i = 0; i < vertices; ++i) {
    all_out &= v[i]->outside;
    crossing_near |= v[i]->crossing_near;
    inside &= v[i]->inside;
  }
  if (all_out != 0) return false;
  if (!crossing_near && rules_.front_faces_only) {
    const glm::dvec3 a(v[0]->clip.x, v[0]->clip.y, v[0]->clip.w), b(v[1]->clip.x, v[1]->clip.y, v[1]->clip.w),
        c(v[2]->clip.x, v[2]->clip.y, v[2]->clip.w);
    if (!(glm::dot(a, glm::cross(b, c)) > 0.0)) return false;
  }
  glm::dvec3 s[kMax];
  if (inside) {  // most: no plane to clip at, and the corners are projected and snapped already
    std::int64_t X[4], Y[4];
    for (int i = 0; i < vertices; ++i) {
      s[i] = v[i]->window, X[i] = v[i]->x, Y[i] = v[i]->y;
    }
    if (rules_.front_faces_only) {
      if (!(twice_area(s, vertices) > 0.0)) return false;  // rule 2: front faces only
      raster_snapped(lane, s, X, Y, vertices);
      return true;
    }
    raster_polygon(lane, s, vertices);
    return false;
  }
  glm::dvec4 poly[kMax], next[kMax];
  int n = vertices;
  for (int i = 0; i < n; ++i) poly[i] = v[i]->clip;
  for (int p = 0; p < kPlanes; ++p) {
    double d[kMax];
    bool any_out = false, none_in = true;
    for (int i = 0; i < n; ++i) {
      d[i] = distance(poly[i], p);
      any_out |= d[i] < 0.0;
      none_in &= d[i] < 0.0;
    }
    if (none_in) return false;
    if (!any_out) continue;
    int m = 0;
    for (int i = 0; i < n; ++i) {
      const int j = next_corner(i, n);
      if (d[i] >= 0.0) next[m++] = poly[i];
      if ((d[i] >= 0.0) != (d[j] >= 0.0)) next[m++] = poly[i] + (poly[j] - poly[i]) * (d[i] / (d[i] - d[j]));
    }
    n = m;
    std::copy(next, next + n, poly);
  }
  for (int i = 0; i < n; ++i) s[i] = project(poly[i]);
  raster_polygon(lane, s, n);
  return false;
}

void OcclusionBuffer::raster_polygon(Lane& lane, const glm::dvec3* in, int n) const {
  constexpr int kMax = 9;
  assert(n >= 3 && n <= kMax);
  // Rule 2: front faces only (counter-clockwise with y up).
  const double area = twice_area(in, n);
  glm::dvec3 v[kMax];
  if (area > 0.0) {
    std::copy(in, in + n, v);
  } else {
    if (rules_.front_faces_only || !(area < 0.0)) return;
    std::reverse_copy(in, in + n, v);
  }
  // Rule 3: vertices snapped to 1/256 texel, edge functions exact in int64.
  std::int64_t X[kMax], Y[kMax];
  for (int k = 0; k < n; ++k) {
    X[k] = snap(v[k].x);
    Y[k] = snap(v[k].y);
  }
  raster_snapped(lane, v, X, Y, n);
}

OcclusionBuffer::Edge OcclusionBuffer::make_edge(const std::int64_t* X, const std::int64_t* Y, int i, int j) const {
  Edge e;
  e.a = Y[i] - Y[j];
  e.b = X[j] - X[i];
  e.c = -(e.a * X[i] + e.b * Y[i]);
  if (rules_.inner_coverage) {  // the grown texel's (rule 10: centres' square's) corner
    e.ox = e.a > 0 ? inset_ - kGrow : kSub - inset_ + kGrow;
    e.oy = e.b > 0 ? inset_ - kGrow : kSub - inset_ + kGrow;
  } else {
    e.ox = e.oy = kSub / 2;  // the texel's centre (rule 3 broken)
  }
  return e;
}

[[gnu::always_inline]] inline int OcclusionBuffer::polygon_edges(const std::int64_t* X, const std::int64_t* Y, int n, Edge* edges) const {
  int edge_count = 0;
  for (int i = 0; i < n; ++i) {
    const int j = next_corner(i, n);
    if (X[i] == X[j] && Y[i] == Y[j]) continue;  // snapped onto its neighbour
    edges[edge_count++] = make_edge(X, Y, i, j);
  }
  return edge_count;
}

// Rule 4: the depth plane through the three corners spanning the largest
// triangle, at the grown texel's farthest corner; the bias covers float
// evaluation and the other corners' distance off the plane. False for a
// polygon with no area.
[[gnu::always_inline]] inline bool OcclusionBuffer::depth_plane(const glm::dvec3* v, int n, DepthPlane& out) const {
  int best = 1;
  double best_area = 0.0;
  for (int k = 1; k + 1 < n; ++k) {
    const double a2 = (v[k].x - v[0].x) * (v[k + 1].y - v[0].y) - (v[k + 1].x - v[0].x) * (v[k].y - v[0].y);
    if (a2 > best_area) best_area = a2, best = k;
  }
  const glm::dvec3 p0 = v[0], p1 = v[best], p2 = v[best + 1];
  const double det = (p1.x - p0.x) * (p2.y - p0.y) - (p2.x - p0.x) * (p1.y - p0.y);
  if (!(det > 0.0)) return false;
  const double gx = ((p1.z - p0.z) * (p2.y - p0.y) - (p2.z - p0.z) * (p1.y - p0.y)) / det;
  const double gy = ((p1.x - p0.x) * (p2.z - p0.z) - (p2.x - p0.x) * (p1.z - p0.z)) / det;
  double z_far = -std::numeric_limits<double>::infinity(), z_near = std::numeric_limits<double>::infinity();
  double off_plane = 0.0;
  for (int k = 0; k < n; ++k) {
    z_far = std::max(z_far, v[k].z);
    z_near = std::min(z_near, v[k].z);
    off_plane = std::max(off_plane, std::abs(v[k].z - (p0.z + gx * (v[k].x - p0.x) + gy * (v[k].y - p0.y))));
  }
  out = {p0, gx, gy, 0.5, 0.5, 0.0, off_plane, kInf};
  if (rules_.farthest_depth) {
    const double inset = double(inset_) / double(kSub);  // rule 10
    out.fx = gx > 0.0 ? 1.0 - inset + kGrowTexels : inset - kGrowTexels;
    out.fy = gy > 0.0 ? 1.0 - inset + kGrowTexels : inset - kGrowTexels;
    out.bias = (std::max(std::abs(z_far), std::abs(z_near)) + (z_far - z_near)) * 0x1p-20 + off_plane;  // exact, as ldexp
    out.cap = float(z_far);
    if (double(out.cap) < z_far) out.cap = next_up(out.cap);
  }
  return true;
}

// A front-facing convex polygon, counter-clockwise, its corners snapped to X, Y.
void OcclusionBuffer::raster_snapped(Lane& lane, const glm::dvec3* v, const std::int64_t* X, const std::int64_t* Y,
                                     int n) const {
  std::int64_t snapped_area = 0;
  for (int k = 0; k < n; ++k) snapped_area += X[k] * Y[next_corner(k, n)] - X[next_corner(k, n)] * Y[k];
  if (snapped_area <= 0) return;  // degenerate once snapped
  const std::int64_t min_x = *std::min_element(X, X + n), max_x = *std::max_element(X, X + n);
  const std::int64_t min_y = *std::min_element(Y, Y + n), max_y = *std::max_element(Y, Y + n);
  // A polygon narrower than a grown texel (rule 10: its centres' square) on
  // either axis covers none (a shortcut: the edge functions would find none).
  const std::int64_t reach = rules_.inner_coverage ? kSub - 2 * inset_ + 2 * kGrow : 0;
  if (max_x - min_x < reach || max_y - min_y < reach) return;
  ++lane.count;
  // The texels whose grown square (rule 10: their centres' square) fits in
  // the polygon's bounding rectangle: no other can lie inside every edge
  // (what lies inside every edge of a polygon lies inside the polygon). A
  // shortcut: small polygons holding no such square stop here.
  const std::int64_t near_side = rules_.inner_coverage ? inset_ - kGrow : 0;
  const std::int64_t far_side = rules_.inner_coverage ? kSub - inset_ + kGrow : kSub;
  const auto first = [&](std::int64_t lo) { return -texel_of(near_side - lo); };  // ceil((lo - near) / kSub)
  const auto last = [&](std::int64_t hi) { return texel_of(hi - (rules_.inner_coverage ? far_side : 0)); };
  const int x_lo = int(std::max<std::int64_t>(0, rules_.inner_coverage ? first(min_x) : texel_of(min_x)));
  const int x_hi = int(std::min<std::int64_t>(width_ - 1, last(max_x)));
  const int y_lo = int(std::max<std::int64_t>(0, rules_.inner_coverage ? first(min_y) : texel_of(min_y)));
  const int y_hi = int(std::min<std::int64_t>(height_ - 1, last(max_y)));
  if (x_lo > x_hi || y_lo > y_hi) return;
  // Edge i runs from vertex i to i+1. (A polygon that snapping left not
  // quite convex is covered where it is inside every edge: a part of it.)
  Edge edges[kMaxEdges];
  const int edge_count = polygon_edges(X, Y, n, edges);
  DepthPlane plane;
  fill_region(lane, edges, edge_count, {x_lo, x_hi, y_lo, y_hi},
              [&]() -> const DepthPlane* { return depth_plane(v, n, plane) ? &plane : nullptr; });
}

// Writes the depth bound into every texel of r inside every edge. The
// depth plane is asked of plane_of() at the first row holding such a texel
// (null: nothing written): at one pixel a texel most small polygons hold
// none, and their plane, two divisions, is never needed.
template <class PlaneOf>
[[gnu::always_inline]] inline void OcclusionBuffer::fill_region(Lane& lane, const Edge* edges, int edge_count,
                                                                 const TexelRect& r, PlaneOf&& plane_of) const {
  const int x_lo = r.x_lo, x_hi = r.x_hi, y_lo = r.y_lo, y_hi = r.y_hi;
  const bool strict = rules_.inner_coverage;
  const DepthPlane* plane = nullptr;
  // Each edge bounds a row's covered texels on one side: e(tx) = s*tx + r(ty),
  // s = 256 a, r linear in ty. The bound floor(N/D) (N = -r, D = s when s > 0;
  // N = r, D = -s when s < 0) is stepped from row to row exactly, quotient
  // and remainder, with no division per row.
  // A region over a few texels (most, at one pixel a texel) is cheaper
  // tested texel by texel: the same edge functions, no division.
  const bool few = (x_hi - x_lo + 1) * (y_hi - y_lo + 1) <= kFewTexels;
  struct Bound {
    int side;  // +1: a lower bound (s > 0), -1: an upper bound (s < 0), 0: the edge is horizontal
    std::int64_t q, rem, dq, drem, d, r, dr;
  } bounds[kMaxEdges];
  for (int k = 0; k < edge_count && !few; ++k) {
    const Edge& e = edges[k];
    Bound& b = bounds[k];
    const std::int64_t s = e.a * kSub;
    b.r = e.a * e.ox + e.b * (std::int64_t(y_lo) * kSub + e.oy) + e.c;
    b.dr = e.b * kSub;
    b.side = s > 0 ? 1 : s < 0 ? -1 : 0;
    if (b.side == 0) {  // only r matters; the rest is stepped as the others', harmlessly
      b.q = b.rem = b.dq = b.drem = 0, b.d = 1;
      continue;
    }
    b.d = s > 0 ? s : -s;
    const std::int64_t n0 = s > 0 ? -b.r : b.r, dn = s > 0 ? -b.dr : b.dr;
    b.q = floor_div_bounded(n0, b.d);
    b.rem = n0 - b.q * b.d;
    b.dq = floor_div_bounded(dn, b.d);
    b.drem = dn - b.dq * b.d;
  }
  for (int ty = y_lo; ty <= y_hi; ++ty) {
    std::int64_t lo = x_lo, hi = x_hi;
    if (few) {  // e(tx) = s*tx + r(ty) > 0 at every edge (>= 0 at centres), as the bounds below
      lo = x_hi + 1, hi = x_lo - 1;
      for (std::int64_t tx = x_lo; tx <= x_hi; ++tx) {
        bool inside = true;
        for (int k = 0; k < edge_count && inside; ++k) {
          const Edge& e = edges[k];
          const std::int64_t f = e.a * (tx * kSub + e.ox) + e.b * (std::int64_t(ty) * kSub + e.oy) + e.c;
          inside = strict ? f > 0 : f >= 0;
        }
        if (inside) lo = std::min(lo, tx), hi = tx;
      }
    }
    for (int k = 0; k < edge_count && !few; ++k) {
      Bound& b = bounds[k];
      if (b.side > 0) {  // covered where tx > N/D (>= at centres)
        lo = std::max(lo, strict ? b.q + 1 : b.q + (b.rem != 0));
      } else if (b.side < 0) {  // covered where tx < N/D (<= at centres)
        hi = std::min(hi, strict ? b.q + (b.rem != 0) - 1 : b.q);
      } else if (strict ? b.r <= 0 : b.r < 0) {
        lo = hi + 1;
      }
      // On to the next row.
      b.r += b.dr;
      b.q += b.dq;
      b.rem += b.drem;
      const std::int64_t carry = b.rem >= b.d;  // no branch: which way it goes is a coin toss a row
      b.rem -= b.d & -carry;
      b.q += carry;
    }
    if (lo > hi) continue;
    if (!plane && !(plane = plane_of())) return;
    const double base_d = plane->p0.z + plane->gx * (double(lo) + plane->fx - plane->p0.x) +
                          plane->gy * (double(ty) + plane->fy - plane->p0.y) + plane->bias;
    float base = float(base_d);
    if (double(base) < base_d) base = next_up(base);
    const std::size_t at = std::size_t(ty) * std::size_t(width_) + std::size_t(lo);
    float* row = lane.keys + at;
    const int span = int(hi - lo + 1);
    if (lane.sources && simd_ == SimdPath::best && span >= kShortSpan)
      simd::fill_span_sourced(row, lane.sources + at, span, base, float(plane->gx), plane->cap, lane.source);
    else if (lane.sources)
      fill_span_sourced_scalar(row, lane.sources + at, span, base, float(plane->gx), plane->cap, lane.source);
    else if (simd_ == SimdPath::best && span >= kShortSpan)
      simd::fill_span(row, span, base, float(plane->gx), plane->cap);
    else  // a short span here, as the vector code fills its tail: no dispatch through a pointer
      fill_span_scalar(row, span, base, float(plane->gx), plane->cap);
    std::uint8_t* dirty = lane.dirty + std::size_t(ty / tile_size) * std::size_t(tiles_x_);
    for (int t = int(lo) / tile_size; t <= int(hi) / tile_size; ++t) dirty[t] = 1;
  }
}

std::size_t OcclusionBuffer::polygons_worth_rasterizing(const OccluderMesh& mesh, const View& view,
                                                        const glm::mat4& object_to_world, const Aabb& bounds) const {
  // Texels per unit at unit view depth, times 1 + tan^2 of the lens's half
  // angles: off axis a length grows by up to that, and a point at distance
  // d lies at a view depth of at least d / sqrt(1 + tan^2).
  const LensReach lens = lens_of(view, width_, height_);
  const double tan2 = view.orthographic ? 0.0 : lens.tan2;
  const glm::mat3 m(object_to_world);
  const double stretch = std::max({glm::length(m[0]), glm::length(m[1]), glm::length(m[2])});
  const double depth = view.orthographic ? 1.0 : std::max(double(distance(view.eye, bounds)), double(view.near));
  const double texels_per_unit = stretch * lens.texels_per_unit * (1.0 + tan2) / depth;
  return mesh.count_at_least(float(covered_half_side() / texels_per_unit));
}

float OcclusionBuffer::tile_farthest(int tx, int ty) {
  const std::size_t t = std::size_t(ty) * std::size_t(tiles_x_) + std::size_t(tx);
  if (tile_dirty_[t]) {
    const int x0 = tx * tile_size, y0 = ty * tile_size;
    const int w = std::min(tile_size, width_ - x0), h = std::min(tile_size, height_ - y0);
    float far = -kInf;
    for (int y = y0; y < y0 + h; ++y) {
      const float* row = keys_.data() + std::size_t(y) * std::size_t(width_) + std::size_t(x0);
      const float m = simd_ == SimdPath::best ? simd::max_span(row, w) : max_span_scalar(row, w);
      far = far > m ? far : m;
    }
    tile_far_[t] = far;
    tile_dirty_[t] = 0;
  }
  return tile_far_[t];
}

bool OcclusionBuffer::occluded(const Aabb& box, const glm::mat4& view_proj, std::vector<std::uint32_t>* sources) {
  if (box.empty()) return false;
  const BoxFootprint f = project_box(box, view_proj, clip_, width_, height_);
  if (f.reaches_eye && rules_.reaching_eye_visible) return false;  // rule 7
  if (f.projected == 0) return false;
  // Rule 6: the nearest corner, as a key.
  float nearest = clip_.reversed_z ? -f.max_depth : f.min_depth;
  if (!rules_.nearest_corner) {  // broken: the centre's depth
    const float depth = window_depth(box.center(), view_proj, clip_);
    nearest = clip_.reversed_z ? -depth : depth;
  }
  const float min_x = f.min_x, max_x = f.max_x, min_y = f.min_y, max_y = f.max_y;
  // Rule 5: every texel the rectangle touches, grown for rounding. (Clamped
  // as floats first: a corner just past the near plane projects far off.)
  const auto texel = [](float v, int size) { return int(std::clamp(std::floor(v), -1.0f, float(size))); };
  constexpr float grow = float(kGrowTexels);
  int x0, x1, y0, y1;
  if (rules_.outer_rectangle && inset_ > 0) {
    // Rule 10: the texels whose centres' square [t + in, t + 1 - in] the grown rectangle reaches.
    const float in = float(double(inset_) / double(kSub));
    const auto last = [&](float v, int size) { return texel(v - in, size); };
    const auto first = [&](float v, int size) { return int(std::clamp(std::ceil(v - 1.0f + in), -1.0f, float(size))); };
    x0 = first(min_x - grow, width_), x1 = last(max_x + grow, width_);
    y0 = first(min_y - grow, height_), y1 = last(max_y + grow, height_);
    if (x0 > x1 || y0 > y1) return false;  // holds no pixel centre: not the buffer's to say (holds_no_sample)
  } else if (rules_.outer_rectangle) {
    x0 = texel(min_x - grow, width_), x1 = texel(max_x + grow, width_);
    y0 = texel(min_y - grow, height_), y1 = texel(max_y + grow, height_);
  } else {  // texels whose centre lies in the rectangle (rule 5 broken)
    x0 = texel(std::ceil(min_x - 0.5f), width_), x1 = texel(max_x - 0.5f, width_);
    y0 = texel(std::ceil(min_y - 0.5f), height_), y1 = texel(max_y - 0.5f, height_);
    if (x0 > x1 || y0 > y1) return true;  // no texel: nothing tested, nothing found visible
  }
  if (x1 < 0 || y1 < 0 || x0 >= width_ || y0 >= height_) return false;  // off the buffer: the caller's frustum decides
  x0 = std::max(x0, 0), y0 = std::max(y0, 0);
  x1 = std::min(x1, width_ - 1), y1 = std::min(y1, height_ - 1);
  const bool margin = rules_.depth_margin;
  for (int ty = y0 / tile_size; ty <= y1 / tile_size; ++ty)
    for (int tx = x0 / tile_size; tx <= x1 / tile_size; ++tx) {
      if (rules_.tiles && behind(nearest, tile_farthest(tx, ty), margin)) continue;  // the whole tile hides the box
      const int ax = std::max(x0, tx * tile_size), bx = std::min(x1, tx * tile_size + tile_size - 1);
      const int ay = std::max(y0, ty * tile_size), by = std::min(y1, ty * tile_size + tile_size - 1);
      for (int y = ay; y <= by; ++y) {
        const float* row = keys_.data() + std::size_t(y) * std::size_t(width_) + std::size_t(ax);
        const float far = simd_ == SimdPath::best ? simd::max_span(row, bx - ax + 1) : max_span_scalar(row, bx - ax + 1);
        if (!behind(nearest, far, margin)) return false;
      }
    }
  if (sources && !sources_.empty()) {  // the tags of the texels compared, each run once
    std::uint32_t last = no_source;
    for (int y = y0; y <= y1; ++y) {
      const std::uint32_t* row = sources_.data() + std::size_t(y) * std::size_t(width_);
      for (int x = x0; x <= x1; ++x)
        if (row[x] != last && row[x] != no_source) sources->push_back(last = row[x]);
    }
  }
  return true;
}

}  // namespace occull
