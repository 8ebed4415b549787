#version 460
#extension GL_EXT_ray_query : require
// A ray query in a fragment shader (traces_test.cpp: draws): the ray of ray_query.comp, one fragment of a 1x1
// framebuffer with no attachments; writes 1 into its storage buffer (binding 1) when it hits a triangle.
layout(set = 0, binding = 0) uniform accelerationStructureEXT scene;
layout(set = 0, binding = 1, std430) writeonly buffer Out { uint hit; };
void main() {
  rayQueryEXT query;
  rayQueryInitializeEXT(query, scene, gl_RayFlagsOpaqueEXT, 0xff, vec3(0.25, 0.25, 1.0), 0.0, vec3(0.0, 0.0, -1.0),
                        10.0);
  while (rayQueryProceedEXT(query)) {
  }
  hit = rayQueryGetIntersectionTypeEXT(query, true) == gl_RayQueryCommittedIntersectionTriangleEXT ? 1u : 0u;
}
