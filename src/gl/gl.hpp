// Internal: OpenGL 4.5 core declarations (linked through GLVND's libOpenGL,
// no loader needed) and small helpers.
#pragma once

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/gl.h>
#include <GL/glext.h>

#include <cstdint>
#include <string>
#include <vector>

namespace occull::gl {

/// Throws GlError naming `where` if the GL error flag is set.
void check_error(const char* where);

/// Compiles and links a program from vertex and fragment source; throws
/// GlError with the info log on failure.
GLuint make_program(const char* name, const std::string& vertex, const std::string& fragment);
/// Whether the current context lists extension `name`.
[[nodiscard]] bool has_extension(const char* name);

/// The same for one compute shader.
GLuint make_compute_program(const char* name, const std::string& source);

/// State glReadPixels depends on: the framebuffer read from, no pixel-pack
/// buffer (else it writes into that buffer), tight rows of `alignment`.
void bind_for_reading(GLuint fbo, GLint alignment);

/// Colour attachment 0 of `fbo` as RGBA8, width*height pixels, top row
/// first (GL's first row is the bottom one; images start at the top).
[[nodiscard]] std::vector<std::uint8_t> read_rgba_top_first(GLuint fbo, int width, int height);

}  // namespace occull::gl
