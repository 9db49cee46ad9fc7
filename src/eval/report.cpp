#include "occull/harness.hpp"

#include <fmt/format.h>

#include <ostream>

namespace occull {
namespace {

template <typename F>
double mean_of(const AlgorithmRun& run, F field) {
  if (run.frames.empty()) return 0.0;
  double sum = 0.0;
  for (const FrameStats& f : run.frames) sum += double(field(f));
  return sum / double(run.frames.size());
}

std::vector<double> frame_times(const AlgorithmRun& run) {
  std::vector<double> v;
  v.reserve(run.frames.size());
  for (const FrameStats& f : run.frames) v.push_back(f.frame_ms);
  return v;
}

}  // namespace

void print_table(const BenchResult& r, std::ostream& out) {
  out << fmt::format("scene {} ({} objects, {} triangles, BVH {} nodes built in {:.1f} ms), path {}, "
                     "{} frames at {}x{}\n",
                     r.scene, r.objects, r.triangles, r.bvh_nodes, r.bvh_build_ms, r.path, r.frames,
                     r.width, r.height);
  out << fmt::format("device: {} | {}\n\n", r.device.renderer, r.device.version);
  const AlgorithmRun* vfc = nullptr;
  for (const auto& run : r.runs)
    if (run.name == "vfc") vfc = &run;
  const double vfc_mean = vfc ? summarize(frame_times(*vfc)).mean : 0.0;

  out << fmt::format("{:<10} {:>8} {:>8} {:>8} {:>8} {:>7} {:>8} {:>10} {:>8} {:>8} {:>8}\n",
                     "algorithm", "mean ms", "median", "p95", "max", "vs vfc", "draws", "triangles",
                     "objects", "cpu ms", "gpu ms");
  for (const auto& run : r.runs) {
    const Summary s = summarize(frame_times(run));
    const std::string ratio = vfc_mean > 0 ? fmt::format("{:.2f}", s.mean / vfc_mean) : "-";
    out << fmt::format("{:<10} {:>8.2f} {:>8.2f} {:>8.2f} {:>8.2f} {:>7} {:>8.0f} {:>10.0f} {:>8.0f} {:>8.3f} {:>8.2f}\n",
                       run.name, s.mean, s.median, s.p95, s.max, ratio,
                       mean_of(run, [](const FrameStats& f) { return f.draw_calls; }),
                       mean_of(run, [](const FrameStats& f) { return f.triangles; }),
                       mean_of(run, [](const FrameStats& f) { return f.objects_rendered; }),
                       mean_of(run, [](const FrameStats& f) { return f.cpu_ms; }),
                       mean_of(run, [](const FrameStats& f) { return f.gpu_ms; }));
  }
  out << "\nper frame (means): draws, triangles, objects; cpu ms = the culler's own CPU time; "
         "gpu ms = timer query over the frame.\nvs vfc = mean frame time / vfc's mean frame time "
         "in this run.\n";
  if (r.device.renderer.find("llvmpipe") != std::string::npos)
    out << "note: llvmpipe's GL_TIME_ELAPSED leaves out most of its (deferred, multi-threaded) "
           "rasterization; judge by wall-clock frame times.\n";
}

}  // namespace occull
