// occull view: a window (GLFW) with a Dear ImGui panel onto a scene, a
// culler and the debug views of occull/debug_view.hpp.
//
// The session renders in occull's own headless EGL context, as in every
// other command: the frame, its debug view and its truth are drawn there
// and read back, and the window's context only shows the image and the
// panel. So what the window shows is what `occull render --view` writes,
// pixel for pixel, and the culler runs exactly as under `bench`; the cost
// is one read-back and one upload per frame (a few MB), which is small
// next to a frame on llvmpipe. The two contexts take turns on the thread:
// each is released before the other is made current.
#include "viewer.hpp"
#include "viewer_window.hpp"

#include "occull/culler.hpp"
#include "occull/debug_view.hpp"
#include "occull/error.hpp"
#include "occull/gl/context.hpp"
#include "occull/gl/painter.hpp"
#include "occull/lab.hpp"

#include <stb_image_write.h>  // GLFW, GL, ImGui and fmt come with viewer_window.hpp

#include <algorithm>
#include <array>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <deque>

namespace occull::app {
namespace {

// What the panel switches, and the run's live figures.
struct Controls {
  int algorithm = 0;
  std::vector<std::string> algorithms;
  std::array<char, 256> options{};
  int view = 0;
  bool verify = false;
  bool recording = false;
  std::array<char, 256> record_file{};
  std::string message;
  std::deque<float> frame_ms, queries;
};

std::vector<std::string> runnable_algorithms(bool tiled) {
  std::vector<std::string> names;
  for (const AlgorithmInfo& a : algorithms())
    if (!a.lab_only && runs_on(a, tiled)) names.push_back(a.name);
  return names;
}

void write_png(const std::string& file, int w, int h, const std::vector<std::uint8_t>& rgba) {
  if (!stbi_write_png(file.c_str(), w, h, 4, rgba.data(), w * 4))
    throw InputError(fmt::format("cannot write '{}'", file));
}

}  // namespace

int run_viewer(const ViewArgs& a) {
  DebugView view_kind = parse_debug_view(a.view);
  int width = a.width, height = a.height;
  bool small_default = false;
  if (width == 0) {
    // llvmpipe draws a 1280x720 city frame in tens of milliseconds on two cores: too slow to fly.
    const std::string renderer = gl::Context::create()->info().renderer;
    if (renderer.find("llvmpipe") != std::string::npos || renderer.find("softpipe") != std::string::npos) {
      width = 640;
      height = 360;
      small_default = true;
    } else {
      glfwSetErrorCallback(on_glfw_error);
      if (glfwInit()) {
        if (const GLFWvidmode* mode = glfwGetVideoMode(glfwGetPrimaryMonitor())) {
          width = mode->width;
          height = mode->height;
        }
        glfwTerminate();
      }
      if (width == 0) {
        width = 1280;
        height = 720;
      }
    }
  }
  gl::RendererOptions ropts;
  ropts.width = width;
  ropts.height = height;
  Session session(a.scene, ropts);
  session.set_depth(parse_depth_mode(a.depth));
  if (small_default)
    fmt::print("occull view: {} is a software renderer, so the window is {}x{} (--size WIDTHxHEIGHT for another)\n",
               session.device().renderer, width, height);
  const bool tiled = session.bundle().world != nullptr;
  Controls c;
  c.algorithms = runnable_algorithms(tiled);
  const std::string first_algo = a.algo.empty() ? std::string(vfc_baseline(tiled)) : a.algo;
  const AlgorithmSpec spec = parse_algorithm_spec(first_algo);
  const auto found = std::find(c.algorithms.begin(), c.algorithms.end(), spec.name);
  if (found == c.algorithms.end()) (void)make_culler(spec.name, session.index());  // its own message
  c.algorithm = int(found - c.algorithms.begin());
  std::string options_text;
  for (const auto& [k, v] : spec.options.values())
    options_text += (options_text.empty() ? "" : ",") + k.substr(spec.name.size() + 1) + "=" + v;
  for (const std::string& o : a.opts) {
    const auto dot = o.find('.');
    if (dot == std::string::npos || o.substr(0, dot) != spec.name)
      throw InputError(fmt::format("--opt {}: occull view takes options of --algo {} (algo.key=value)", o, spec.name));
    options_text += (options_text.empty() ? "" : ",") + o.substr(dot + 1);
  }
  std::copy_n(options_text.begin(), std::min(options_text.size(), c.options.size() - 1), c.options.begin());
  if (!view_fits(view_kind, find_algorithm(spec.name)))
    throw InputError(fmt::format("--view {} does not fit --algo {} (cells: grid; tiles: tilevfc, pertile, tiles)",
                                 a.view, spec.name));
  auto make = [&]() {
    const std::string& name = c.algorithms[std::size_t(c.algorithm)];
    // "key=value,key=value" of the chosen algorithm, as its spec "name:key=value:key=value".
    const std::string typed = c.options.data();
    std::string spec_text = typed.empty() ? name : name + ":" + typed;
    std::replace(spec_text.begin(), spec_text.end(), ',', ':');
    return session.make(spec_text, {});  // as bench makes them (nohc with the calibrated profile)
  };
  std::unique_ptr<Culler> culler = make();
  std::unique_ptr<Culler> next_culler;  // chosen in the panel; replaces `culler` in occull's context
  c.view = int(view_kind);
  c.verify = a.verify;
  const std::string record_default = a.record.empty() ? "occull-flight.path" : a.record;
  std::copy_n(record_default.begin(), std::min(record_default.size(), c.record_file.size() - 1), c.record_file.begin());
  c.recording = !a.record.empty();

  const bool scripted = a.frames > 0;
  if (scripted && !(a.fps >= 0.0)) throw InputError("--fps must be a number >= 0");
  session.set_sampling({a.fps, 0.0});
  const CameraPath& path = session.path(a.path);
  if (scripted && a.frames > path.frames_that_fit(session.sampling()))
    throw InputError(fmt::format("--frames {} at --fps {} lie past the end of path {} ({:.1f} s)", a.frames, a.fps,
                                 path.name(), path.duration()));
  FlyCamera camera;
  camera.pose = path.sample(0.0);
  const Aabb bounds = session.bundle().scene.bounds();
  if (!bounds.empty()) camera.speed = std::clamp(glm::length(bounds.extent()) / 30.0f, 2.0f, 200.0f);
  gl::Painter painter(session.bundle().scene, width, height);

  session.context().release();
  auto window_owner = std::make_unique<Window>(width, height, fmt::format("occull view — {}", a.scene), !a.no_ui);
  Window& window = *window_owner;
  std::vector<CameraPath::Key> flown;
  double record_start = 0.0;
  const auto t0 = std::chrono::steady_clock::now();
  auto last = t0;
  std::vector<std::uint8_t> image;
  for (int k = 0; !glfwWindowShouldClose(window.handle()); ++k) {
    const auto now = std::chrono::steady_clock::now();
    const float dt = std::chrono::duration<float>(now - last).count();
    last = now;
    glfwPollEvents();
    const bool ui_wants_mouse = window.ui() && ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureMouse;
    const bool ui_wants_keys = window.ui() && ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureKeyboard;
    double time_s = std::chrono::duration<double>(now - t0).count();
    if (scripted) {
      time_s = session.frame_time(path, k, a.frames);
      camera.pose = path.sample(time_s);
    } else if (!ui_wants_keys) {
      camera.update(window.handle(), std::min(dt, 0.1f), !ui_wants_mouse);
    }
    if (c.recording) {
      if (flown.empty()) record_start = time_s;
      const double t = flown.empty() ? 0.0 : std::max(time_s - record_start, flown.back().time + 1e-3);
      flown.push_back({t, camera.pose, false});
    }

    // occull's context: the frame, its view, its truth.
    Window::release();
    session.context().make_current();
    if (next_culler) {
      session.release(*culler);  // its queries live on occull's context
      culler = std::move(next_culler);
    }
    const View view = session.view_of(camera.pose);  // the floating origin follows the camera
    FrameLog log;
    const FrameStats stats = session.run_frame(*culler, view, time_s, &log);
    image = session.renderer().read_rgba();
    const auto drawn_span = session.recording().objects();
    const std::vector<ObjectId> drawn(drawn_span.begin(), drawn_span.end());
    std::vector<ObjectId> truth, missed;
    if (c.verify) {
      for (const auto& v : session.truth_of(view).visible) truth.push_back(v.id);
      std::vector<ObjectId> sorted = drawn;
      std::sort(sorted.begin(), sorted.end());
      std::set_difference(truth.begin(), truth.end(), sorted.begin(), sorted.end(), std::back_inserter(missed));
    }
    const DebugView kind = DebugView(c.view);
    const DebugFrame frame{session.bundle().scene, view, log, culler->regions(), drawn, truth};
    Picture picture = make_picture(kind, frame, float(width) / float(height));
    if (kind != DebugView::overview)  // the overview shows misses its own way
      for (ObjectId id : missed) picture.objects.push_back({id, palette::missed});
    if (kind != DebugView::color || !picture.objects.empty()) image = painter.paint(picture, image);
    session.context().release();
    window.make_current();

    c.frame_ms.push_back(float(stats.frame_ms));
    c.queries.push_back(float(stats.queries));
    while (c.frame_ms.size() > 240) {
      c.frame_ms.pop_front();
      c.queries.pop_front();
    }
    window.show(image);
    if (window.ui()) {
      ImGui_ImplOpenGL3_NewFrame();
      ImGui_ImplGlfw_NewFrame();
      ImGui::NewFrame();
      ImGui::SetNextWindowPos(ImVec2(8, 8), ImGuiCond_Once);
      ImGui::SetNextWindowSize(ImVec2(250, 0), ImGuiCond_Once);
      ImGui::SetNextWindowBgAlpha(0.8f);
      ImGui::Begin("occull");
      ImGui::PushItemWidth(150);
      const auto names = [](void* data, int i, const char** out) {
        *out = static_cast<std::vector<std::string>*>(data)->at(std::size_t(i)).c_str();
        return true;
      };
      bool rebuild = ImGui::Combo("algorithm", &c.algorithm, names, &c.algorithms, int(c.algorithms.size()));
      rebuild |= ImGui::InputText("options", c.options.data(), c.options.size(), ImGuiInputTextFlags_EnterReturnsTrue);
      if (rebuild) {
        try {
          next_culler = make();  // GL-free; the old one hands its queries back in occull's context
          c.message.clear();
        } catch (const InputError& e) {
          c.message = e.what();
        }
        const AlgorithmInfo& info = find_algorithm(c.algorithms[std::size_t(c.algorithm)]);
        if (!view_fits(DebugView(c.view), info)) c.view = int(DebugView::color);
      }
      const AlgorithmInfo& info = find_algorithm(c.algorithms[std::size_t(c.algorithm)]);
      if (ImGui::BeginCombo("view", std::string(debug_view_name(DebugView(c.view))).c_str())) {
        for (const DebugViewInfo& v : debug_views()) {
          if (!view_fits(v.view, info)) continue;
          if (ImGui::Selectable(std::string(v.name).c_str(), c.view == int(v.view))) c.view = int(v.view);
          if (ImGui::IsItemHovered()) ImGui::SetTooltip("%s", std::string(v.summary).c_str());
        }
        ImGui::EndCombo();
      }
      ImGui::Checkbox("verify", &c.verify);
      if (ImGui::IsItemHovered()) ImGui::SetTooltip("ground truth every frame; missed objects in red");
      ImGui::Text("%.2f ms  %llu queries  %llu objects", stats.frame_ms, (unsigned long long)stats.queries,
                  (unsigned long long)stats.objects_rendered);
      if (c.verify) ImGui::Text("missed: %zu of %zu visible", missed.size(), truth.size());
      std::vector<float> ms(c.frame_ms.begin(), c.frame_ms.end()), qs(c.queries.begin(), c.queries.end());
      ImGui::PlotLines("frame ms", ms.data(), int(ms.size()), 0, nullptr, 0.0f, FLT_MAX, ImVec2(0, 40));
      ImGui::PlotLines("queries", qs.data(), int(qs.size()), 0, nullptr, 0.0f, FLT_MAX, ImVec2(0, 40));
      for (const Picture::Legend& l : picture.legend) {
        ImGui::ColorButton(l.label.c_str(), ImVec4(l.color.r, l.color.g, l.color.b, 1.0f),
                           ImGuiColorEditFlags_NoTooltip, ImVec2(10, 10));
        ImGui::SameLine();
        ImGui::Text("%zu %s", l.count, l.label.c_str());
      }
      ImGui::InputText("path file", c.record_file.data(), c.record_file.size());
      if (ImGui::Button(c.recording ? "stop and write" : "record the flight")) {
        if (c.recording && !flown.empty()) {
          write_path_file(CameraPath("recorded", "flown in occull view", flown), c.record_file.data());
          c.message = fmt::format("wrote {} ({} keys): bench --path file:{}", c.record_file.data(), flown.size(),
                                  c.record_file.data());
          flown.clear();
        }
        c.recording = !c.recording;
      }
      if (!c.message.empty()) ImGui::TextWrapped("%s", c.message.c_str());
      ImGui::TextWrapped("WASD/arrows move, Q/E down/up, Shift faster, right mouse button turns");
      ImGui::PopItemWidth();
      ImGui::End();
      ImGui::Render();
      ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    }
    if (scripted && k == a.frames - 1) {
      if (!a.screenshot.empty()) write_png(a.screenshot, width, height, window.read_back());
      std::string legend;
      for (const Picture::Legend& l : picture.legend) legend += fmt::format("\n  {:>6}  {}", l.count, l.label);
      fmt::print("occull view: flew {} frames of {} with {}, view {}{}{}{}\n", a.frames, path.name(),
                 c.algorithms[std::size_t(c.algorithm)], debug_view_name(DebugView(c.view)),
                 a.screenshot.empty() ? "" : "; wrote " + a.screenshot,
                 c.verify ? fmt::format("; missed {} of {} visible", missed.size(), truth.size()) : "", legend);
      break;
    }
    glfwSwapBuffers(window.handle());
  }
  if (c.recording && !flown.empty()) {
    write_path_file(CameraPath("recorded", "flown in occull view", flown), c.record_file.data());
    fmt::print("occull view: wrote {} ({} keys; replay with bench --path file:{})\n", c.record_file.data(),
               flown.size(), c.record_file.data());
  }
  window_owner.reset();
  session.context().make_current();  // the painter and the session go in their own context
  session.release(*culler);
  return 0;
}

}  // namespace occull::app
