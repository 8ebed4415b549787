#version 450
// Moves the vertices of every bottom-level structure of the refit benchmark, once per frame, so that each
// refit reads vertices written on the device that frame (as skinning or cloth does in an engine). All
// structures share one rest mesh; structure m's vertices follow each other in one buffer, three floats each
// (R32G32B32_SFLOAT, stride 12, what the builds read). One invocation per vertex of all structures.
layout(local_size_x = 64) in;

layout(std430, set = 0, binding = 0) readonly buffer Rest { vec4 rest[]; };       // xyz: rest position
layout(std430, set = 0, binding = 1) writeonly buffer Positions { float positions[]; };

layout(push_constant) uniform Frame {
  float time;
  uint vertices_per_mesh;
  uint total_vertices;
} frame;

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= frame.total_vertices) return;
  uint mesh = i / frame.vertices_per_mesh;
  vec3 p = rest[i % frame.vertices_per_mesh].xyz;
  // A wave whose phase differs per structure: every triangle moves, none becomes degenerate or inactive.
  p.z = 0.1 * sin(6.0 * p.x + 2.0 * frame.time + 0.37 * float(mesh));
  positions[3u * i + 0u] = p.x;
  positions[3u * i + 1u] = p.y;
  positions[3u * i + 2u] = p.z;
}
