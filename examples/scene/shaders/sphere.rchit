#version 460
// Spheres from the procedural geometry, with their real normal.
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
#include "shading.glsl"

hitAttributeEXT vec3 object_normal;

void main() {
  vec3 position = gl_WorldRayOriginEXT + gl_WorldRayDirectionEXT * gl_HitTEXT;
  vec3 normal = normalize(mat3(gl_ObjectToWorldEXT) * object_normal);
  radiance = Shade(MaterialColor(uint(gl_InstanceCustomIndexEXT)), position, normal);
}
