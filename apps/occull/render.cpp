// `occull render`: a frame of a path rendered by an algorithm to a PNG, as drawn or as a debug view.
#include "cli.hpp"
#include "occull/debug_view.hpp"
#include "occull/error.hpp"
#include "occull/gl/painter.hpp"
#include "occull/gl/renderer.hpp"
#include "occull/lab.hpp"
#include "occull/occlusion_buffer.hpp"

#include <fmt/format.h>
#include <stb_image_write.h>

#include <algorithm>
#include <charconv>

namespace occull::app {

namespace {

struct RenderArgs {
  std::string scene = "city";
  std::string path;
  std::string algo;  // empty: the scene's frustum-culling baseline
  std::string frame = "0";  // K, or A-B for a numbered sequence
  int frames = 100;
  double fps = 0.0;
  double start = 0.0;
  std::string size = "1280x720";
  std::string out = "occull.png";
  std::string view = "color";
  std::vector<std::string> opts;
  bool gl_debug = false;
  std::string api = "gl";
  std::string depth = "standard";
};

// "K" or "A-B" (inclusive), each in [0, frames).
std::pair<int, int> parse_frame_range(const std::string& text, int frames) {
  const auto dash = text.find('-');
  const auto number = [&](const std::string& part) {
    int v = 0;
    const auto [end, ec] = std::from_chars(part.data(), part.data() + part.size(), v);
    if (part.empty() || ec != std::errc() || end != part.data() + part.size())
      throw occull::InputError(fmt::format("--frame '{}' is not a frame K or a range A-B", text));
    return v;
  };
  const int first = number(text.substr(0, dash));
  const int last = dash == std::string::npos ? first : number(text.substr(dash + 1));
  if (first > last) throw occull::InputError(fmt::format("--frame {}: the range ends before it starts", text));
  if (first < 0 || last >= frames)
    throw occull::InputError(fmt::format("--frame {} is outside [0, {}] (--frames {})", text, frames - 1, frames));
  return {first, last};
}

// out.png for one frame; out-0012.png for frame 12 of a range.
std::string numbered(const std::string& out, int frame, bool range) {
  if (!range) return out;
  const auto dot = out.rfind('.');
  const auto slash = out.rfind('/');
  const bool has_ext = dot != std::string::npos && (slash == std::string::npos || dot > slash);
  return fmt::format("{}-{:04d}{}", has_ext ? out.substr(0, dot) : out, frame, has_ext ? out.substr(dot) : ".png");
}

// The views that need an algorithm of one kind refuse the others.
void check_view_fits(occull::DebugView view, const std::string& algo_spec) {
  const occull::AlgorithmInfo& info = occull::find_algorithm(occull::parse_algorithm_spec(algo_spec).name);
  if (occull::view_fits(view, info)) return;
  if (view == occull::DebugView::cells)
    throw occull::InputError(fmt::format("--view cells shows the cells of the grid culler (--algo grid), not {}",
                                         info.name));
  throw occull::InputError(fmt::format(
        "--view tiles shows tile instances of a tiled-world algorithm (tilevfc, pertile, tiles), not {}", info.name));
}

int cmd_render(const RenderArgs& a) {
  const Size size = parse_size(a.size);
  if (a.frames < 1) throw occull::InputError("--frames must be at least 1");
  const auto [first, last] = parse_frame_range(a.frame, a.frames);
  // `soc`: the frame with the CPU occlusion buffer the culler used beside it.
  const bool buffer_view = a.view == "soc";
  const occull::DebugView view = buffer_view ? occull::DebugView::color : occull::parse_debug_view(a.view);
  const occull::Options options = parse_options(a.opts);
  occull::gl::RendererOptions ropts;
  ropts.width = size.width;
  ropts.height = size.height;
  if (!(a.fps >= 0.0) || !(a.start >= 0.0))
    throw occull::InputError("--fps and --start must be numbers >= 0");
  occull::gl::ContextOptions copts;
  copts.debug = a.gl_debug;
  occull::Session session(a.scene, ropts, {}, copts, occull::parse_api(a.api));
  session.set_sampling({a.fps, a.start});
  session.set_depth(occull::parse_depth_mode(a.depth));
  const auto& path = session.path(a.path);
  if (last >= path.frames_that_fit(session.sampling()))
    throw occull::InputError(fmt::format("--frame {} at --fps {} from --start {} s lies past the end of path {} ({:.1f} s)",
                                         last, a.fps, a.start, path.name(), path.duration()));
  const std::string algo =
      a.algo.empty() ? std::string(occull::vfc_baseline(session.bundle().world != nullptr)) : a.algo;
  check_view_fits(view, algo);
  if (occull::find_algorithm(occull::parse_algorithm_spec(algo).name).lab_only)
    throw occull::InputError(fmt::format("--algo {} needs each frame's ground truth: bench runs it, render does not",
                                         algo));
  // As bench makes them: specs with options (chcpp:batch=20), nohc with the
  // calibrated profile (calibrated on first use).
  auto culler = session.make(algo, options);
  std::unique_ptr<occull::gl::Painter> painter;
  if (view != occull::DebugView::color)
    painter = std::make_unique<occull::gl::Painter>(session.bundle().scene, size.width, size.height);
  // Run the frames before the first too, so cullers with temporal state see
  // the same history they would in a benchmark.
  const bool range = first != last;
  for (int k = 0; k <= last; ++k) {
    occull::FrameLog log;
    const occull::View frame_view = session.view_at(path, k, a.frames);
    const occull::FrameStats stats =
        session.run_frame(*culler, frame_view, session.frame_time(path, k, a.frames), k >= first ? &log : nullptr);
    if (k < first) continue;
    std::vector<std::uint8_t> pixels = session.render_device().read_rgba();
    std::string legend;
    if (painter) {
      const auto frame_objects = session.recording().objects();
      const std::vector<occull::ObjectId> drawn(frame_objects.begin(), frame_objects.end());
      std::vector<occull::ObjectId> truth;
      if (view == occull::DebugView::overview)  // the verifier's view: what was missed
        for (const auto& v : session.truth_at(path, k, a.frames).visible) truth.push_back(v.id);
      const occull::DebugFrame frame{session.bundle().scene, frame_view, log, culler->regions(), drawn, truth};
      const occull::Picture picture =
          occull::make_picture(view, frame, float(size.width) / float(size.height));
      pixels = painter->paint(picture, pixels);
      for (const auto& l : picture.legend)
        legend += fmt::format("\n  {:>6}  {} (rgb {:.2f} {:.2f} {:.2f})", l.count, l.label, l.color.r, l.color.g,
                              l.color.b);
    }
    int image_width = size.width;
    if (buffer_view) {
      const occull::OcclusionBuffer* buffer = culler->occlusion_buffer();
      if (!buffer)
        throw occull::InputError(fmt::format("--view soc shows a CPU occlusion buffer and {} has none: use --algo soc, "
                                             "or chc, chcpp or nohc with cpu_test=on",
                                             algo));
      const std::vector<std::uint8_t> right = occull::occlusion_buffer_rgba(*buffer, size.width, size.height);
      std::vector<std::uint8_t> both(pixels.size() * 2);
      const std::size_t row = std::size_t(size.width) * 4;
      for (int y = 0; y < size.height; ++y) {
        std::copy_n(pixels.data() + std::size_t(y) * row, row, both.data() + std::size_t(y) * 2 * row);
        std::copy_n(right.data() + std::size_t(y) * row, row, both.data() + std::size_t(y) * 2 * row + row);
      }
      pixels = std::move(both);
      image_width = 2 * size.width;
      legend = fmt::format("\n  right: the occlusion buffer, {}x{} texels, {} covered (nearer brighter; empty: dark blue)",
                           buffer->width(), buffer->height(), buffer->covered_texels());
    }
    const std::string file = numbered(a.out, k, range);
    if (!stbi_write_png(file.c_str(), image_width, size.height, 4, pixels.data(), image_width * 4))
      throw occull::InputError(fmt::format("cannot write '{}'", file));
    fmt::print("wrote {} ({}x{}): {} / {} frame {} with {}, view {}: {} objects, {} triangles drawn, {} queries{}\n",
               file, image_width, size.height, a.scene, path.name(), k, algo, a.view, stats.objects_rendered,
               stats.triangles, stats.queries, legend);
  }
  session.release(*culler);
  return 0;
}

}  // namespace

Command add_render(CLI::App& app) {
  auto a = std::make_shared<RenderArgs>();
  auto* r = app.add_subcommand("render", "render a frame of a path with an algorithm to a PNG, as rendered or as a "
                                          "debug view of what the culler did");
  r->add_option("--scene", a->scene, "scene spec name[:key=value,...]")->capture_default_str();
  r->add_option("--path", a->path, "camera path (default: the scene's first), or file:PATH");
  r->add_option("--algo", a->algo, "algorithm (default: vfc, tilevfc on a tiled world)");
  r->add_option("--frame", a->frame,
                "frame index K (0-based) of --frames along the path, or a range A-B: one PNG per frame, "
                "numbered (out-0012.png)")
      ->capture_default_str();
  r->add_option("--frames", a->frames, "frames the path is divided into")->capture_default_str();
  r->add_option("--fps", a->fps, "frames at this rate of path time instead (0: divide the path)")
      ->capture_default_str();
  r->add_option("--start", a->start, "with --fps: path time of frame 0, seconds")->capture_default_str();
  r->add_option("--size", a->size, "image size WIDTHxHEIGHT")->capture_default_str();
  r->add_option("--out,--png", a->out, "output PNG file")->capture_default_str();
  r->add_option("--view", a->view, debug_view_help())->capture_default_str();
  r->add_option("--opt", a->opts, "algorithm option algo.key=value (repeatable)");
  r->add_flag("--gl-debug", a->gl_debug, kGlDebugHelp);
  r->add_option("--api", a->api, kApiHelp)->capture_default_str();
  r->add_option("--depth", a->depth, kDepthHelp)->capture_default_str();
  return [a] { return cmd_render(*a); };
}

}  // namespace occull::app
