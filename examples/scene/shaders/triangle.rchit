#version 460
// Triangles: the face normal is not at hand (the meshes use several vertex formats), so facets are told
// apart by a per-primitive tint and lit as if facing the sun half-way; shadows come from a real ray.
#extension GL_EXT_ray_tracing : require
#extension GL_GOOGLE_include_directive : require
#include "shading.glsl"

hitAttributeEXT vec2 barycentrics;

void main() {
  vec3 position = gl_WorldRayOriginEXT + gl_WorldRayDirectionEXT * gl_HitTEXT;
  uint material = uint(gl_InstanceCustomIndexEXT);
  vec3 albedo;
  vec3 normal;
  if (material == 0u) {  // the ground: a checkerboard in world space
    ivec2 cell = ivec2(floor(position.xz * 0.5));
    albedo = ((cell.x + cell.y) & 1) == 0 ? vec3(0.75) : vec3(0.45);
    normal = vec3(0.0, 1.0, 0.0);
  } else {
    albedo = MaterialColor(material) * (0.7 + 0.3 * Hash(uint(gl_PrimitiveID) * 7919u + uint(gl_GeometryIndexEXT)));
    normal = normalize(kSunDirection - gl_WorldRayDirectionEXT);
  }
  radiance = Shade(albedo, position, normal);
}
