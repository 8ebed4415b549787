#version 460
#extension GL_EXT_ray_query : require
// Reads an array of structures (set 2, binding 5) by index, and a second binding (set 0, binding 1).
layout(local_size_x = 1) in;
layout(set = 2, binding = 5) uniform accelerationStructureEXT scenes[4];
layout(set = 0, binding = 1) uniform accelerationStructureEXT other;
layout(set = 0, binding = 0, std430) buffer Out { uint value; };
void main() {
  rayQueryEXT query;
  rayQueryInitializeEXT(query, scenes[value & 3u], 0, 0xff, vec3(0.0), 0.0, vec3(0.0, 0.0, 1.0), 1.0);
  rayQueryInitializeEXT(query, other, 0, 0xff, vec3(0.0), 0.0, vec3(0.0, 0.0, 1.0), 1.0);
}
