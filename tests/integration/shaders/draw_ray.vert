#version 460
// The draw of ray_program.cpp (Kind::kDraw): one triangle that covers the whole (1x1) framebuffer.
void main() {
  const vec2 corner = vec2((gl_VertexIndex << 1) & 2, gl_VertexIndex & 2);
  gl_Position = vec4(corner * 2.0 - 1.0, 0.0, 1.0);
}
