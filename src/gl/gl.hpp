// Internal: OpenGL 4.5 core declarations (linked through GLVND's libOpenGL,
// no loader needed) and small helpers.
#pragma once

#ifndef GL_GLEXT_PROTOTYPES
#define GL_GLEXT_PROTOTYPES 1
#endif
#include <GL/gl.h>
#include <GL/glext.h>

#include <string>

namespace occull::gl {

/// Throws std::runtime_error naming `where` if the GL error flag is set.
void check_error(const char* where);

/// Compiles and links a program from vertex and fragment source; throws
/// std::runtime_error with the info log on failure.
GLuint make_program(const char* name, const std::string& vertex, const std::string& fragment);

}  // namespace occull::gl
