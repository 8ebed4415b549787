#version 460
#extension GL_EXT_ray_query : require
// Declares a structure binding (set 1, binding 3) that no function reads: not statically used.
layout(local_size_x = 1) in;
layout(set = 1, binding = 3) uniform accelerationStructureEXT unused;
layout(set = 0, binding = 0, std430) writeonly buffer Out { uint value; };
void main() { value = 1u; }
