#include "gl.hpp"

#include <stdexcept>
#include <string>

namespace occull::gl {

void check_error(const char* where) {
  const GLenum e = glGetError();
  if (e == GL_NO_ERROR) return;
  char code[16];
  std::snprintf(code, sizeof code, "0x%04x", e);
  throw std::runtime_error(std::string("OpenGL error ") + code + " while " + where);
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
    throw std::runtime_error(std::string("compiling the ") + name + " " +
                             (stage == GL_VERTEX_SHADER ? "vertex" : "fragment") +
                             " shader failed: " + log);
  }
  return shader;
}

}  // namespace

GLuint make_program(const char* name, const std::string& vertex, const std::string& fragment) {
  const GLuint vs = compile(name, GL_VERTEX_SHADER, vertex);
  const GLuint fs = compile(name, GL_FRAGMENT_SHADER, fragment);
  const GLuint program = glCreateProgram();
  glAttachShader(program, vs);
  glAttachShader(program, fs);
  glLinkProgram(program);
  glDeleteShader(vs);
  glDeleteShader(fs);
  GLint ok = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (!ok) {
    GLint len = 0;
    glGetProgramiv(program, GL_INFO_LOG_LENGTH, &len);
    std::string log(std::size_t(std::max(len, 1)), '\0');
    glGetProgramInfoLog(program, len, nullptr, log.data());
    glDeleteProgram(program);
    throw std::runtime_error(std::string("linking the ") + name + " program failed: " + log);
  }
  return program;
}

}  // namespace occull::gl
