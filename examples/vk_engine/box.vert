#version 450
// A query box: its 36 corners of 12 triangles from the vertex index.
layout(push_constant) uniform Box { mat4 view_proj; vec4 lo; vec4 hi; } box;
void main() {
  const int c[36] = int[](0,2,3, 0,3,1, 4,5,7, 4,7,6, 0,1,5, 0,5,4, 2,6,7, 2,7,3, 0,4,6, 0,6,2, 1,3,7, 1,7,5);
  int k = c[gl_VertexIndex];
  vec3 t = vec3(k & 1, (k >> 1) & 1, (k >> 2) & 1);
  gl_Position = box.view_proj * vec4(mix(box.lo.xyz, box.hi.xyz, t), 1.0);
}
