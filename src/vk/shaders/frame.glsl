// The pass's uniforms (vk::Renderer's FrameUniforms), shared by its shaders.
layout(set = 0, binding = 0) uniform Frame {
  mat4 view_proj;        // eye-relative, Vulkan clip space (depth 0..1, y as OpenGL's)
  vec4 eye;              // xyz
  vec4 background;       // rgb
  vec2 half_viewport;    // pixels
  float fog_distance;
  float margin;          // query boxes' silhouette margin, pixels
} frame;
