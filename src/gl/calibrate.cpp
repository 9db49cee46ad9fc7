#include "occull/gl/calibrate.hpp"

#include "occull/gl/renderer.hpp"
#include "occull/statistics.hpp"

#include <fmt/format.h>
#include <glm/gtc/matrix_transform.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>

namespace occull::gl {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) {
  return std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
}

// A unit square in the XY plane, centred at the origin, facing +Z.
Mesh quad_mesh() {
  Mesh m;
  m.positions = {{-0.5f, -0.5f, 0}, {0.5f, -0.5f, 0}, {0.5f, 0.5f, 0}, {-0.5f, 0.5f, 0}};
  m.normals.assign(4, glm::vec3(0, 0, 1));
  m.indices = {0, 1, 2, 0, 2, 3};
  return m;
}

// The same square as a cells x cells grid: 2 cells^2 triangles.
Mesh grid_mesh(int cells) {
  Mesh m;
  for (int j = 0; j <= cells; ++j)
    for (int i = 0; i <= cells; ++i) {
      m.positions.emplace_back(float(i) / float(cells) - 0.5f, float(j) / float(cells) - 0.5f, 0.0f);
      m.normals.emplace_back(0, 0, 1);
    }
  const auto at = [cells](int i, int j) { return std::uint32_t(j * (cells + 1) + i); };
  for (int j = 0; j < cells; ++j)
    for (int i = 0; i < cells; ++i)
      m.indices.insert(m.indices.end(), {at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j),
                                         at(i + 1, j + 1), at(i, j + 1)});
  return m;
}

glm::mat4 placed(float size, float z) {
  return glm::scale(glm::translate(glm::mat4(1.0f), {0.0f, 0.0f, z}), glm::vec3(size, size, 1.0f));
}

struct Median {
  double value = 0.0;
  double spread = 0.0;
};

Median median_of(std::vector<double> v) {
  const Summary s = summarize(std::move(v));
  return {s.median, s.median != 0.0 ? (s.max - s.min) / std::abs(s.median) : 0.0};
}

constexpr int kFullQuads = 6;  // full-screen quads per fragment measurement

}  // namespace

CalibrationResult calibrate(const CalibrationOptions& options,
                            const std::function<void(const std::string&)>& progress) {
  const auto start = Clock::now();
  const int w = options.width, h = options.height;
  const double pixels = double(w) * double(h);

  // The calibration scene: pixel-sized low and high meshes 1 m ahead, and
  // per shading class a stack of full-screen quads, far to near.
  Scene scene("calibration");
  const MeshId quad = scene.add_mesh(quad_mesh());
  const MeshId grid = scene.add_mesh(grid_mesh(224));  // 100,352 triangles
  const double high_triangles = double(scene.mesh(grid).triangle_count());
  const MaterialId plain = scene.add_material({"plain", {0.7f, 0.7f, 0.7f, 1.0f}, false, 0});
  const ObjectId small_low = scene.add_object(quad, plain, placed(0.002f, -1.0f), OccluderClass::never);
  const ObjectId small_high = scene.add_object(grid, plain, placed(0.002f, -1.0f), OccluderClass::never);
  std::map<int, std::vector<ObjectId>> full;  // class -> quads, far to near
  for (int cost : options.shading_classes) {
    const MaterialId m = scene.add_material({fmt::format("cost {}", cost), {0.6f, 0.6f, 0.6f, 1.0f}, false, cost});
    // Fewer layers for expensive shading: the fragment time is large enough to measure.
    const int layers = cost < 16 ? kFullQuads : 2;
    for (int k = 0; k < layers; ++k)
      full[cost].push_back(scene.add_object(quad, m, placed(50.0f, -(3.0f - 0.1f * float(k))), OccluderClass::never));
  }
  const Aabb small_box{{-0.001f, -0.001f, -1.001f}, {0.001f, 0.001f, -0.999f}};
  const Aabb full_box{{-20.0f, -20.0f, -6.0f}, {20.0f, 20.0f, -5.0f}};

  RendererOptions ro;
  ro.width = w;
  ro.height = h;
  ro.write_ids = false;
  Renderer r(scene, ro);
  const View view = make_view({{0, 0, 0}, 0, 0}, {60.0f, 0.1f, 100.0f}, w, h);

  const auto frame_ms = [&](const std::function<void()>& work) {
    const auto t0 = Clock::now();
    r.begin_frame(view);
    work();
    r.end_frame();
    return ms_since(t0);
  };
  const std::vector<ObjectId> many_low(2000, small_low);
  const std::vector<ObjectId> some_high(12, small_high);
  const auto draw_many_low = [&] { r.render(many_low); };
  const auto draw_some_high = [&] { r.render(some_high); };
  const auto queries = [&](const Aabb& box, int n) {
    std::vector<QueryId> ids;
    for (int i = 0; i < n; ++i) ids.push_back(r.issue_query(std::span<const Aabb>(&box, 1)));
    for (QueryId q : ids) (void)r.result(q);
  };
  const auto interleaved = [&](bool with_queries) {
    std::vector<QueryId> ids;
    for (int i = 0; i < 500; ++i) {
      r.render(std::span<const ObjectId>(&small_low, 1));
      if (with_queries) ids.push_back(r.issue_query(std::span<const Aabb>(&small_box, 1)));
    }
    for (QueryId q : ids) (void)r.result(q);
  };
  const auto latency = [&] {
    double worst = 0.0;
    for (int i = 0; i < 20; ++i) {
      r.begin_frame(view);
      const auto t0 = Clock::now();
      const QueryId q = r.issue_query(std::span<const Aabb>(&small_box, 1));
      r.flush();
      while (!r.result_available(q)) {
      }
      worst = std::max(worst, ms_since(t0));
      (void)r.result(q);
      r.end_frame();
    }
    return worst;
  };

  // Warm up every workload once (shader JIT).
  frame_ms(draw_many_low);
  frame_ms(draw_some_high);
  for (const auto& entry : full) frame_ms([&] { r.render(entry.second); });  // (clang 14 captures no bindings)
  frame_ms([&] { queries(small_box, 10); });
  frame_ms([&] { queries(full_box, 2); });

  std::map<std::string, std::vector<double>> samples;
  for (int rep = 0; rep < std::max(1, options.repeats); ++rep) {
    const double empty = frame_ms([] {});
    const double setup = std::max(0.0, (frame_ms(draw_many_low) - empty) / double(many_low.size()));
    const double triangle = std::max(
        0.0, (frame_ms(draw_some_high) - empty - double(some_high.size()) * setup) /
                 (double(some_high.size()) * high_triangles));
    samples["T_r^s"].push_back(setup);
    samples["T_r^tri"].push_back(triangle);
    for (const auto& entry : full) {
      const auto& [cost, ids] = entry;
      const double t = frame_ms([&] { r.render(entry.second); }) - empty - double(ids.size()) * (setup + 2.0 * triangle);
      samples[fmt::format("T_r^f[{}]", cost)].push_back(std::max(0.0, t / (double(ids.size()) * pixels)));
    }
    const double q_setup = std::max(0.0, (frame_ms([&] { queries(small_box, 1000); }) - empty) / 1000.0);
    samples["T_o^s"].push_back(q_setup);
    samples["T_o^f"].push_back(
        std::max(0.0, (frame_ms([&] { queries(full_box, 20); }) - empty - 20.0 * q_setup) / (20.0 * pixels)));
    samples["T_o^l"].push_back(latency());
    const double plain_ms = frame_ms([&] { interleaved(false); });
    const double with_ms = frame_ms([&] { interleaved(true); });
    samples["T_o^o"].push_back(std::max(0.0, (with_ms - plain_ms) / 500.0));
    if (progress) progress(fmt::format("calibration round {} of {} done", rep + 1, options.repeats));
  }

  CalibrationResult result;
  HardwareProfile& p = result.profile;
  p.width = w;
  p.height = h;
  const auto take = [&](const std::string& key, const std::string& name, const std::string& meaning,
                        double& into) {
    const Median m = key == "T_o^l" ? Median{*std::max_element(samples[key].begin(), samples[key].end()),
                                             median_of(samples[key]).spread}
                                    : median_of(samples[key]);
    into = m.value;
    result.values.push_back({name, meaning, m.value, m.spread});
  };
  take("T_r^s", "T_r^s", "setup per draw call", p.draw_setup_ms);
  take("T_r^tri", "T_r^tri", "per rendered triangle", p.triangle_ms);
  for (int cost : options.shading_classes)
    take(fmt::format("T_r^f[{}]", cost), fmt::format("T_r^f[{}]", cost),
         fmt::format("per shaded fragment, shading cost {}", cost), p.fragment_ms[cost]);
  take("T_o^s", "T_o^s", "setup per occlusion query", p.query_setup_ms);
  take("T_o^f", "T_o^f", "per query-box fragment", p.query_fragment_ms);
  take("T_o^l", "T_o^l", "longest query latency (max over rounds)", p.query_latency_ms);
  take("T_o^o", "T_o^o", "a query issued while rendering, over rendering alone", p.query_overhead_ms);
  result.seconds = ms_since(start) / 1000.0;
  return result;
}

std::vector<CalibrationCheck> check_calibrations(const CalibrationResult& first,
                                                 const CalibrationResult& second) {
  std::vector<CalibrationCheck> checks;
  const auto both = [&](const std::string& name, auto&& holds, auto&& figures) {
    const bool ok = holds(first.profile) && holds(second.profile);
    checks.push_back({name, ok, fmt::format("{} | {}", figures(first.profile), figures(second.profile))});
  };
  const auto ms = [](double v) {
    return v >= 0.01 ? fmt::format("{:.4f} ms", v) : fmt::format("{:.3f} ns", v * 1e6);
  };
  both("every time is finite and >= 0",
       [&](const HardwareProfile&) {
         for (const CalibrationResult* r : {&first, &second})
           for (const CalibratedValue& v : r->values)
             if (!std::isfinite(v.value_ms) || v.value_ms < 0.0) return false;
         return true;
       },
       [&](const HardwareProfile& p) { return fmt::format("{} fragment classes", p.fragment_ms.size()); });
  both("a triangle costs less than a draw call (T_r^tri < T_r^s)",
       [](const HardwareProfile& p) { return p.triangle_ms < p.draw_setup_ms; },
       [&](const HardwareProfile& p) { return fmt::format("{} < {}", ms(p.triangle_ms), ms(p.draw_setup_ms)); });
  both("fragments cost more with more shading (T_r^f by shading cost)",
       [](const HardwareProfile& p) {
         if (p.fragment_ms.size() < 2) return false;
         double last = -1.0;
         for (const auto& [cost, t] : p.fragment_ms) {
           if (t < last) return false;
           last = t;
         }
         return p.fragment_ms.rbegin()->second > p.fragment_ms.begin()->second;
       },
       [&](const HardwareProfile& p) {
         std::string s;
         for (const auto& [cost, t] : p.fragment_ms) s += fmt::format("{}[{}] {}", s.empty() ? "" : ", ", cost, ms(t));
         return s;
       });
  both("a query result takes time to arrive (T_o^l > 0)",
       [](const HardwareProfile& p) { return p.query_latency_ms > 0.0; },
       [&](const HardwareProfile& p) { return ms(p.query_latency_ms); });
  for (std::size_t i = 0; i < first.values.size() && i < second.values.size(); ++i) {
    const CalibratedValue& a = first.values[i];
    const CalibratedValue& b = second.values[i];
    const double lo = std::min(a.value_ms, b.value_ms), hi = std::max(a.value_ms, b.value_ms);
    const bool ok = a.name == b.name && hi <= 2.0 * lo && (lo > 0.0 || hi == 0.0);
    checks.push_back({fmt::format("{} repeats within a factor of 2", a.name), ok,
                      fmt::format("{} vs {}", ms(a.value_ms), ms(b.value_ms))});
  }
  return checks;
}

}  // namespace occull::gl
