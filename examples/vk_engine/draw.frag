#version 450
layout(location = 0) in vec3 normal;
layout(location = 0) out vec4 colour;
void main() { colour = vec4(vec3(0.3 + 0.6 * abs(normalize(normal).y)), 1.0); }
