#version 450
// The example engine's objects: the model matrix and the view-projection come with each draw.
layout(push_constant) uniform Draw { mat4 view_proj; mat4 model; } draw;
layout(location = 0) in vec3 p;
layout(location = 1) in vec3 n;
layout(location = 0) out vec3 normal;
void main() {
  normal = mat3(draw.model) * n;
  gl_Position = draw.view_proj * draw.model * vec4(p, 1.0);
}
