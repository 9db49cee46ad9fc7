#version 450
// Query boxes and depth-only tests write nothing: the depth test decides.
void main() {}
