#version 450
// Shading as gl::Renderer's: sun, sky and `lights` extra Blinn-Phong point
// lights around the fragment, fog toward the background.
#include "frame.glsl"
layout(push_constant) uniform Draw {
  mat4 model;
  vec4 color;
  uint object;
  int lights;
} draw;
layout(location = 0) in vec3 v_world;
layout(location = 1) in vec3 v_normal;
layout(location = 0) out vec4 o_color;
layout(location = 1) out uint o_id;
void main() {
  vec3 n = normalize(v_normal);
  vec3 to_eye = normalize(frame.eye.xyz - v_world);
  const vec3 sun = normalize(vec3(0.45, 0.8, 0.35));
  float diffuse = max(dot(n, sun), 0.0);
  float sky = 0.5 + 0.5 * n.y;
  vec4 color = draw.color;
  int lights = draw.lights;
  vec3 c = color.rgb * (0.25 + 0.25 * sky + 0.6 * diffuse);
  for (int i = 0; i < lights; ++i) {
    float fi = float(i);
    vec3 light = v_world + vec3(sin(fi * 1.7) * 8.0, 4.0 + 2.0 * cos(fi * 2.3), cos(fi * 1.3) * 8.0);
    vec3 l = light - v_world;
    float d2 = dot(l, l);
    l *= inversesqrt(d2);
    vec3 h = normalize(l + to_eye);
    float spec = pow(max(dot(n, h), 0.0), 32.0);
    c += (color.rgb * max(dot(n, l), 0.0) + vec3(spec)) * (0.4 / (1.0 + 0.08 * d2)) / float(lights);
  }
  float fog = clamp(length(frame.eye.xyz - v_world) / frame.fog_distance, 0.0, 1.0);
  c = mix(c, frame.background.rgb, fog * fog * 0.6);
  o_color = vec4(c, color.a);
  o_id = draw.object + 1u;
}
