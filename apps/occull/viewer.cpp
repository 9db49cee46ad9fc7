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

#include "occull/culler.hpp"
#include "occull/debug_view.hpp"
#include "occull/error.hpp"
#include "occull/gl/context.hpp"
#include "occull/gl/painter.hpp"
#include "occull/harness.hpp"

#define GLFW_INCLUDE_NONE
#include <GLFW/glfw3.h>
#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/gl.h>
#include <GL/glext.h>
#include <fmt/format.h>
#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>
#include <stb_image_write.h>

#include <algorithm>
#include <array>
#include <cfloat>
#include <chrono>
#include <cmath>
#include <deque>

namespace occull::app {
namespace {

std::string glfw_error;
void on_glfw_error(int code, const char* message) { glfw_error = fmt::format("{} (GLFW error 0x{:x})", message, code); }

// The window's context and its GLFW/ImGui set-up; released before occull's is made current.
class Window {
 public:
  Window(int width, int height, const std::string& title, bool ui) : ui_(ui) {
    glfwSetErrorCallback(on_glfw_error);
    if (!glfwInit())
      throw GlUnavailable(fmt::format("occull view needs a display: {} (set DISPLAY, or run it under xvfb-run)",
                                      glfw_error.empty() ? "GLFW could not start" : glfw_error));
    glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
    glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
    glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
    glfwWindowHint(GLFW_RESIZABLE, GLFW_FALSE);
    // EGL, as occull's own context: one API on the thread.
    glfwWindowHint(GLFW_CONTEXT_CREATION_API, GLFW_EGL_CONTEXT_API);
    window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
    if (!window_) {
      glfwWindowHint(GLFW_CONTEXT_CREATION_API, GLFW_NATIVE_CONTEXT_API);
      window_ = glfwCreateWindow(width, height, title.c_str(), nullptr, nullptr);
    }
    if (!window_) {
      glfwTerminate();
      throw GlUnavailable(fmt::format("occull view cannot open a {}x{} OpenGL 3.3 window: {}", width, height, glfw_error));
    }
    glfwMakeContextCurrent(window_);
    glfwSwapInterval(0);
    glGenTextures(1, &texture_);
    glBindTexture(GL_TEXTURE_2D, texture_);
    glTexImage2D(GL_TEXTURE_2D, 0, GL_RGBA8, width, height, 0, GL_RGBA, GL_UNSIGNED_BYTE, nullptr);
    glGenFramebuffers(1, &fbo_);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
    glFramebufferTexture2D(GL_READ_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_TEXTURE_2D, texture_, 0);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    if (ui_) {
      IMGUI_CHECKVERSION();
      ImGui::CreateContext();
      ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini in the user's folder
      ImGui::StyleColorsDark();
      ImGui_ImplGlfw_InitForOpenGL(window_, true);
      ImGui_ImplOpenGL3_Init("#version 330 core");
    }
    width_ = width;
    height_ = height;
  }
  ~Window() {
    glfwMakeContextCurrent(window_);
    if (ui_) {
      ImGui_ImplOpenGL3_Shutdown();
      ImGui_ImplGlfw_Shutdown();
      ImGui::DestroyContext();
    }
    glDeleteFramebuffers(1, &fbo_);
    glDeleteTextures(1, &texture_);
    glfwMakeContextCurrent(nullptr);
    glfwDestroyWindow(window_);
    glfwTerminate();
  }
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;

  void make_current() { glfwMakeContextCurrent(window_); }
  static void release() { glfwMakeContextCurrent(nullptr); }
  [[nodiscard]] GLFWwindow* handle() const noexcept { return window_; }
  [[nodiscard]] bool ui() const noexcept { return ui_; }

  // The image (top row first) over the whole window, texel for pixel.
  void show(const std::vector<std::uint8_t>& rgba) {
    glBindTexture(GL_TEXTURE_2D, texture_);
    glBindBuffer(GL_PIXEL_UNPACK_BUFFER, 0);
    glPixelStorei(GL_UNPACK_ALIGNMENT, 1);
    glPixelStorei(GL_UNPACK_ROW_LENGTH, 0);
    glTexSubImage2D(GL_TEXTURE_2D, 0, 0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, rgba.data());
    glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo_);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, 0);
    glDisable(GL_SCISSOR_TEST);
    glViewport(0, 0, width_, height_);
    // Row 0 of the texture is the image's top: flip on the way.
    glBlitFramebuffer(0, 0, width_, height_, 0, height_, width_, 0, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
  }

  // The window's back buffer, top row first.
  std::vector<std::uint8_t> read_back() const {
    std::vector<std::uint8_t> px(std::size_t(width_) * std::size_t(height_) * 4);
    glBindFramebuffer(GL_READ_FRAMEBUFFER, 0);
    glReadBuffer(GL_BACK);
    glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
    glPixelStorei(GL_PACK_ALIGNMENT, 1);
    glReadPixels(0, 0, width_, height_, GL_RGBA, GL_UNSIGNED_BYTE, px.data());
    const std::size_t row = std::size_t(width_) * 4;
    for (int y = 0; y < height_ / 2; ++y)
      std::swap_ranges(px.begin() + long(std::size_t(y) * row), px.begin() + long(std::size_t(y + 1) * row),
                       px.begin() + long(std::size_t(height_ - 1 - y) * row));
    return px;
  }

 private:
  GLFWwindow* window_ = nullptr;
  GLuint texture_ = 0, fbo_ = 0;
  int width_ = 0, height_ = 0;
  bool ui_;
};

// WASD / arrows move, Q/E or PageDown/PageUp down and up, Shift ×4, the
// right mouse button held turns the camera.
struct FlyCamera {
  CameraPose pose;
  float speed = 10.0f;  // scene units per second
  double last_x = 0.0, last_y = 0.0;
  bool dragging = false;

  void update(GLFWwindow* w, float dt, bool mouse_free) {
    const auto down = [w](int key) { return glfwGetKey(w, key) == GLFW_PRESS; };
    double x = 0.0, y = 0.0;
    glfwGetCursorPos(w, &x, &y);
    const bool drag = mouse_free && glfwGetMouseButton(w, GLFW_MOUSE_BUTTON_RIGHT) == GLFW_PRESS;
    if (drag && dragging) {
      pose.yaw -= float(x - last_x) * 0.004f;
      pose.pitch = std::clamp(pose.pitch - float(y - last_y) * 0.004f, -1.5f, 1.5f);
    }
    dragging = drag;
    last_x = x;
    last_y = y;
    const glm::vec3 forward(-std::sin(pose.yaw) * std::cos(pose.pitch), std::sin(pose.pitch),
                            -std::cos(pose.yaw) * std::cos(pose.pitch));
    const glm::vec3 right(std::cos(pose.yaw), 0.0f, -std::sin(pose.yaw));
    glm::vec3 move(0.0f);
    if (down(GLFW_KEY_W) || down(GLFW_KEY_UP)) move += forward;
    if (down(GLFW_KEY_S) || down(GLFW_KEY_DOWN)) move -= forward;
    if (down(GLFW_KEY_D) || down(GLFW_KEY_RIGHT)) move += right;
    if (down(GLFW_KEY_A) || down(GLFW_KEY_LEFT)) move -= right;
    if (down(GLFW_KEY_E) || down(GLFW_KEY_PAGE_UP)) move.y += 1.0f;
    if (down(GLFW_KEY_Q) || down(GLFW_KEY_PAGE_DOWN)) move.y -= 1.0f;
    const float boost = down(GLFW_KEY_LEFT_SHIFT) || down(GLFW_KEY_RIGHT_SHIFT) ? 4.0f : 1.0f;
    if (glm::length(move) > 0.0f) pose.position += glm::normalize(move) * speed * boost * dt;
  }
};

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
    if (!a.harness_only && runs_on(a, tiled)) names.push_back(a.name);
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
