#version 450 core
// Depth only: the rasterizer writes gl_FragCoord.z into the shadow atlas.
void main() {}
