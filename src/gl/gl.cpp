#include "gl.hpp"
#include "occull/error.hpp"

#include <algorithm>
#include <stdexcept>
#include <initializer_list>
#include <string>
#include <string_view>

namespace occull::gl {

void check_error(const char* where) {
  const GLenum e = glGetError();
  if (e == GL_NO_ERROR) return;
  char code[16];
  std::snprintf(code, sizeof code, "0x%04x", e);
  throw GlError(std::string("OpenGL error ") + code + " while " + where);
}

namespace {

GLuint compile(const char* name, GLenum stage, const std::string& source) {
  const GLuint shader = glCreateShader(stage);
  const char* src = source.c_str();
  glShaderSource(shader, 1, &src, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (!ok) {
    GLint len = 0;
    glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &len);
    std::string log(std::size_t(std::max(len, 1)), '\0');
    glGetShaderInfoLog(shader, len, nullptr, log.data());
    glDeleteShader(shader);
    throw GlError(std::string("compiling the ") + name + " " +
                             (stage == GL_VERTEX_SHADER ? "vertex" : stage == GL_COMPUTE_SHADER ? "compute" : "fragment") +
                             " shader failed: " + log);
  }
  return shader;
}

// Links the compiled `shaders` (and deletes them); throws with the log.
GLuint link(const char* name, std::initializer_list<GLuint> shaders) {
  const GLuint program = glCreateProgram();
  for (GLuint s : shaders) glAttachShader(program, s);
  glLinkProgram(program);
  for (GLuint s : shaders) glDeleteShader(s);
  GLint ok = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint len = 0;
    glGetProgramiv(program, GL_INFO_LOG_LENGTH, &len);
    std::string log(std::size_t(std::max(len, 1)), '\0');
    glGetProgramInfoLog(program, len, nullptr, log.data());
    glDeleteProgram(program);
    throw GlError(std::string("linking the ") + name + " program failed: " + log);
  }
  return program;
}

}  // namespace

GLuint make_program(const char* name, const std::string& vertex, const std::string& fragment) {
  const GLuint vs = compile(name, GL_VERTEX_SHADER, vertex);
  const GLuint fs = compile(name, GL_FRAGMENT_SHADER, fragment);
  return link(name, {vs, fs});
}

bool has_extension(const char* name) {
  GLint n = 0;
  glGetIntegerv(GL_NUM_EXTENSIONS, &n);
  for (GLint i = 0; i < n; ++i)
    if (std::string_view(reinterpret_cast<const char*>(glGetStringi(GL_EXTENSIONS, GLuint(i)))) == name) return true;
  return false;
}

GLuint make_compute_program(const char* name, const std::string& source) {
  return link(name, {compile(name, GL_COMPUTE_SHADER, source)});
}

}  // namespace occull::gl

namespace occull::gl {

void bind_for_reading(GLuint fbo, GLint alignment) {
  glBindFramebuffer(GL_READ_FRAMEBUFFER, fbo);
  glBindBuffer(GL_PIXEL_PACK_BUFFER, 0);
  glPixelStorei(GL_PACK_ALIGNMENT, alignment);
  glPixelStorei(GL_PACK_ROW_LENGTH, 0);
  glPixelStorei(GL_PACK_SKIP_ROWS, 0);
  glPixelStorei(GL_PACK_SKIP_PIXELS, 0);
}

std::vector<std::uint8_t> read_rgba_top_first(GLuint fbo, int width, int height) {
  const std::size_t row = std::size_t(width) * 4;
  std::vector<std::uint8_t> pixels(row * std::size_t(height));
  glNamedFramebufferReadBuffer(fbo, GL_COLOR_ATTACHMENT0);
  bind_for_reading(fbo, 1);
  glReadPixels(0, 0, width, height, GL_RGBA, GL_UNSIGNED_BYTE, pixels.data());
  check_error("reading the colour buffer");
  for (int y = 0; y < height / 2; ++y)
    std::swap_ranges(pixels.begin() + long(std::size_t(y) * row), pixels.begin() + long(std::size_t(y + 1) * row),
                     pixels.begin() + long(std::size_t(height - 1 - y) * row));
  return pixels;
}

}  // namespace occull::gl
