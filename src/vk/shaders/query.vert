#version 450
// Query boxes, as gl::Renderer's (src/gl/renderer_resources.cpp, kQueryVertex):
// the box's faces, then a band along each silhouette edge widened by
// frame.margin pixels on either side at that edge's depth.
#include "frame.glsl"
layout(location = 0) in vec3 a_p;
layout(location = 1) in vec3 a_q;
layout(location = 2) in vec3 a_band;
layout(location = 3) in vec3 a_min;
layout(location = 4) in vec3 a_max;

float pick(vec3 v, int i) { return i == 0 ? v.x : (i == 1 ? v.y : v.z); }

bool facing(int axis, bool hi, vec3 extent) {
  vec3 eye = frame.eye.xyz;
  bool faces = hi ? pick(eye, axis) > pick(a_max, axis) : pick(eye, axis) < pick(a_min, axis);
  return faces && pick(extent, (axis + 1) % 3) > 0.0 && pick(extent, (axis + 2) % 3) > 0.0;
}

void main() {
  vec3 eye = frame.eye.xyz;
  vec4 a = frame.view_proj * vec4(mix(a_min, a_max, a_p) - eye, 1.0);
  if (a_band.x == 0.0) {
    gl_Position = a;
    return;
  }
  vec4 b = frame.view_proj * vec4(mix(a_min, a_max, a_q) - eye, 1.0);
  bool at_b = a_band.y > 0.5;
  int e = a_p.x != a_q.x ? 0 : (a_p.y != a_q.y ? 1 : 2);
  int f = (e + 1) % 3, g = (e + 2) % 3;
  vec3 extent = a_max - a_min;
  const float min_w = 1e-5;
  bool silhouette = facing(f, pick(a_p, f) > 0.5, extent) != facing(g, pick(a_p, g) > 0.5, extent);
  if (frame.margin <= 0.0 || !silhouette || max(a.w, b.w) <= min_w) {
    gl_Position = at_b ? b : a;
    return;
  }
  if (a.w < min_w) a = mix(a, b, (min_w - a.w) / (b.w - a.w));
  if (b.w < min_w) b = mix(b, a, (min_w - b.w) / (a.w - b.w));
  vec2 d = (b.xy / b.w - a.xy / a.w) * frame.half_viewport;
  float len = length(d);
  vec2 t = len > 1e-6 ? d / len : vec2(1.0, 0.0);
  vec2 n = vec2(-t.y, t.x);
  vec4 here = at_b ? b : a;
  vec2 offset = frame.margin * (a_band.z * n + (at_b ? t : -t));
  here.xy += offset / frame.half_viewport * here.w;
  gl_Position = here;
}
