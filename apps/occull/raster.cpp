// `occull raster`: times OcclusionBuffer::rasterize over the occluders a
// camera path sees, as soc would rasterize them (the polygons that can cover
// a texel from where the camera is): on one thread with the vectorised inner
// loops and with the scalar reference, and vectorised on --threads threads.
// Buffers are cleared between frames, nothing is tested: this is the
// rasterizer's throughput alone. The three buffers must end every frame
// equal bit for bit.
#include "cli.hpp"

#include "occull/error.hpp"
#include "occull/input_limits.hpp"
#include "occull/occlusion_buffer.hpp"
#include "occull/scenes.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <map>
#include <vector>

namespace occull::app {
namespace {

struct RasterArgs {
  std::string scene = "city";
  std::string path;  // empty: the scene's first
  std::string sizes = "320x180,1280x720";
  int frames = 50;
  int repeat = 5;
  double detail = 8.0;  // as soc.detail
  bool whole_texels = false;  // rules 3-5 over whole texels instead of pixel centres (rule 10)
  bool no_fusion = false;     // each polygon alone (rule 11 off, as soc:fuse=off)
  int threads = 2;
};

int cmd_raster(const RasterArgs& a) {
  if (a.frames < 1) throw InputError("--frames must be at least 1");
  if (a.repeat < 1) throw InputError("--repeat must be at least 1");
  if (a.threads < 1 || a.threads > OcclusionBuffer::max_threads)
    throw InputError(fmt::format("--threads must be in [1, {}]", OcclusionBuffer::max_threads));
  std::vector<std::pair<int, int>> sizes;
  std::size_t pos = 0;
  while (pos <= a.sizes.size()) {
    const std::size_t comma = std::min(a.sizes.find(',', pos), a.sizes.size());
    const std::string item = a.sizes.substr(pos, comma - pos);
    int w = 0, h = 0;
    char x = 0, extra = 0;
    if (std::sscanf(item.c_str(), "%d%c%d%c", &w, &x, &h, &extra) != 3 || (x != 'x' && x != 'X') || w < 1 ||
        h < 1 || w > 8192 || h > 8192)
      throw InputError(fmt::format("--sizes: '{}' is not WIDTHxHEIGHT with sides in [1, 8192]", item));
    sizes.emplace_back(w, h);
    pos = comma + 1;
  }
  SceneBundle bundle = make_scene(a.scene);
  if (bundle.world) throw InputError("occull raster runs on scenes with a BVH, not on tiled worlds");
  const CameraPath& path = a.path.empty() ? bundle.paths.front() : bundle.path(a.path);
  Scene& scene = bundle.scene;
  std::map<MeshId, OccluderMesh> occluders;
  const auto prepare_start = std::chrono::steady_clock::now();
  std::size_t prepared_triangles = 0, prepared_polygons = 0;
  for (const Object& o : scene.objects())
    if (!o.removed && o.occluder != OccluderClass::never && !scene.material(o.material).translucent &&
        !scene.mesh(o.mesh).positions.empty() && !occluders.count(o.mesh)) {
      const Mesh& m = scene.mesh(o.mesh);
      const OccluderMesh& made = occluders.emplace(o.mesh, make_occluder_mesh(m.positions, m.indices, a.detail)).first->second;
      prepared_triangles += m.indices.size() / 3;
      prepared_polygons += made.polygons();
    }
  const double prepare_ms =
      std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - prepare_start).count();

  fmt::print("scene {}, path {}, {} frames spread over the path, best of {} timings each; "
             "SIMD: {}; coverage: {}; {}\n",
             a.scene, path.name(), a.frames, a.repeat, simd_target_name(),
             a.whole_texels ? "whole texels" : "pixel centres (a view of the buffer's size)",
             a.no_fusion ? "each polygon alone" : "pairs sharing an edge fused");
  fmt::print("occluder meshes prepared (make_occluder_mesh, once per mesh): {} meshes, {} triangles -> {} polygons in {:.1f} ms\n",
             occluders.size(), prepared_triangles, prepared_polygons, prepare_ms);
  fmt::print("{:>10} {:>9} {:>9} {:>12} {:>12} {:>12} {:>12} {:>8} {:>12} {:>12} {:>8}\n", "buffer", "submitted",
             "polygons", "simd ms", "scalar ms", "simd p/ms", "scalar p/ms", "ratio",
             fmt::format("{} thr ms", a.threads), fmt::format("{} thr p/ms", a.threads), "speedup");
  using Clock = std::chrono::steady_clock;
  for (const auto& [w, h] : sizes) {
    OcclusionBuffer best(w, h, SimdPath::best), scalar(w, h, SimdPath::scalar), threaded(w, h, SimdPath::best);
    threaded.set_threads(a.threads);
    for (OcclusionBuffer* b : {&best, &scalar, &threaded}) b->set_fused_pairs(!a.no_fusion);
    double t_best = 0.0, t_scalar = 0.0, t_threaded = 0.0;
    std::uint64_t polygons = 0, submitted = 0;
    std::vector<OcclusionBuffer::OccluderDraw> draws;
    for (int k = 0; k < a.frames; ++k) {
      const double t = path.frame_time(k, a.frames);
      animate(scene, bundle.scripted, t);
      const View view = make_view(path.sample(t), bundle.lens, w, h);
      draws.clear();
      // The view is the buffer's size: sample coverage with one pixel a texel (rule 10), as soc has at scale 1.
      const auto start_frame = [&](OcclusionBuffer& b) { a.whole_texels ? b.clear(view.clip) : b.clear(view); };
      start_frame(best);
      for (const Object& o : scene.objects()) {
        const auto it = occluders.find(o.mesh);
        if (it == occluders.end() || o.removed || o.occluder == OccluderClass::never ||
            view.frustum.classify(o.bounds) == Containment::outside)
          continue;
        const std::size_t count = best.polygons_worth_rasterizing(it->second, view, o.transform, o.bounds);
        submitted += count;
        if (count > 0) draws.push_back({scene.mesh(o.mesh).positions, &it->second, o.transform, o.bounds});
      }
      for (auto [buffer, total] :
           {std::pair{&best, &t_best}, std::pair{&scalar, &t_scalar}, std::pair{&threaded, &t_threaded}}) {
        double fastest = 1e30;
        std::uint64_t drawn = 0;
        for (int r = 0; r < a.repeat; ++r) {
          start_frame(*buffer);
          const auto start = Clock::now();
          drawn = buffer->rasterize(draws, view);
          fastest = std::min(fastest, std::chrono::duration<double, std::milli>(Clock::now() - start).count());
        }
        *total += fastest;
        if (buffer == &best) polygons += drawn;
      }
      if (!std::equal(best.keys().begin(), best.keys().end(), scalar.keys().begin()))
        throw std::logic_error("occull raster: the vectorised buffer differs from the scalar reference");
      if (!std::equal(best.keys().begin(), best.keys().end(), threaded.keys().begin()))
        throw std::logic_error("occull raster: the buffer rasterized on threads differs from one thread's");
    }
    fmt::print("{:>10} {:>9.0f} {:>9.0f} {:>12.4f} {:>12.4f} {:>12.0f} {:>12.0f} {:>7.2f}x {:>12.4f} {:>12.0f} {:>7.2f}x\n",
               fmt::format("{}x{}", w, h), double(submitted) / a.frames, double(polygons) / a.frames,
               t_best / a.frames, t_scalar / a.frames, double(polygons) / t_best, double(polygons) / t_scalar,
               t_scalar / t_best, t_threaded / a.frames, double(polygons) / t_threaded, t_best / t_threaded);
  }
  fmt::print("submitted: polygons of the occluders in the frustum that could cover a texel from where the camera is; "
             "polygons: rasterized per frame (front-facing, in the buffer, wide enough to cover a texel); ms: per "
             "frame, fused pairs' bands included (--no-fusion: without them); p/ms: polygons per millisecond; ratio: "
             "scalar / simd; speedup: simd on one thread / on --threads\n");
  return 0;
}

}  // namespace

Command add_raster(CLI::App& app) {
  auto a = std::make_shared<RasterArgs>();
  auto* ra = app.add_subcommand("raster",
                                "time the CPU occlusion buffer's rasterizer (soc) over the occluders a "
                                "camera path sees: vectorised against the scalar reference, polygons per millisecond");
  ra->add_option("--scene", a->scene, "scene spec (see occull scenes)")->capture_default_str();
  ra->add_option("--path", a->path, "camera path (default: the scene's first)");
  ra->add_option("--sizes", a->sizes, "comma-separated buffer sizes WIDTHxHEIGHT")->capture_default_str();
  ra->add_option("--frames", a->frames, "frames spread over the path")->capture_default_str();
  ra->add_option("--repeat", a->repeat, "timings of each frame; the fastest counts")->capture_default_str();
  ra->add_option("--detail", a->detail, "as soc.detail: polygons below 1/detail of their mesh's largest "
                                            "inscribed circle left out (0: all)")
      ->capture_default_str();
  ra->add_flag("--whole-texels", a->whole_texels,
               "cover whole texels (as for an MSAA view) instead of the pixel centres of a single-sampled view of the "
               "buffer's size");
  ra->add_option("--threads", a->threads,
                 "threads of the third timing (the buffer's own, OcclusionBuffer::set_threads), against one")
      ->capture_default_str();
  ra->add_flag("--no-fusion", a->no_fusion,
               "each polygon covers alone (as soc:fuse=off): the polygons sharing an edge are not fused (the buffer's rule 11)");
  return [a] { return cmd_raster(*a); };
}

}  // namespace occull::app
