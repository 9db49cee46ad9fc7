#version 450
// The scene pass (as gl::Renderer's single-draw program): the object's
// matrix, id and material come with its draw as push constants.
#include "frame.glsl"
layout(push_constant) uniform Draw {
  mat4 model;
  vec4 color;
  uint object;
  int lights;
} draw;
layout(location = 0) in vec3 a_position;
layout(location = 1) in vec3 a_normal;
layout(location = 0) out vec3 v_world;
layout(location = 1) out vec3 v_normal;
void main() {
  vec4 world = draw.model * vec4(a_position, 1.0);
  v_world = world.xyz;
  v_normal = mat3(draw.model) * a_normal;
  gl_Position = frame.view_proj * vec4(world.xyz - frame.eye.xyz, 1.0);
}
