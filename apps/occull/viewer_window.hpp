// occull view's window: its GLFW context with the Dear ImGui panel, and
// the camera the keys and the mouse fly (viewer.cpp runs them).
#pragma once

#include "occull/error.hpp"
#include "occull/view.hpp"

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

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

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

}  // namespace
}  // namespace occull::app
