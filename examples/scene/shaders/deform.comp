#version 460
// Animates the deforming meshes on the GPU, so that their refits read vertices produced on the device.
// One invocation per vertex; the vertex's mode (w of its rest position) says how it moves.
layout(local_size_x = 64) in;

struct RestVertex {
  vec4 position_mode;  // xyz: rest position; w: mode (see below)
  vec4 center_phase;   // xyz: centre of the vertex's triangle or mesh; w: phase
};

layout(std430, set = 0, binding = 0) readonly buffer Rest { RestVertex rest[]; };
layout(std430, set = 0, binding = 1) writeonly buffer Positions { vec4 positions[]; };
layout(std430, set = 0, binding = 2) readonly buffer Params {
  float time;
  uint revive_dead;  // fault injection only: gives inactive (NaN) vertices a position again
  uint vertex_count;
  uint unused;
} params;

const uint kStatic = 0u;    // does not move
const uint kWave = 1u;      // cloth: waves along x, pinned at x = 0
const uint kPulse = 2u;     // breathes around its centre
const uint kInactive = 3u;  // x is NaN in every frame: an inactive triangle stays inactive
const uint kGrow = 4u;      // a triangle that starts as a point (degenerate) and grows

void main() {
  uint i = gl_GlobalInvocationID.x;
  if (i >= params.vertex_count) return;
  vec3 p = rest[i].position_mode.xyz;
  uint mode = uint(rest[i].position_mode.w + 0.5);
  vec3 c = rest[i].center_phase.xyz;
  float phase = rest[i].center_phase.w;
  float t = params.time;
  vec3 q = p;
  if (mode == kWave) {
    q.z += 0.12 * sin(4.0 * p.x - 3.0 * t + phase) * p.x;
  } else if (mode == kPulse) {
    q = c + (p - c) * (1.0 + 0.2 * sin(2.0 * t + phase));
  } else if (mode == kGrow) {
    q = c + (p - c) * (0.5 - 0.5 * cos(1.7 * t));  // exactly the centre (a point) at t = 0
  } else if (mode == kInactive && params.revive_dead == 0u) {
    q.x = uintBitsToFloat(0x7fc00000u);  // a quiet NaN, written bit for bit
  }
  positions[i] = vec4(q, 1.0);
}
