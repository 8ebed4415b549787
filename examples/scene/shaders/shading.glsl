// Shading shared by the two closest-hit shaders: albedo from the instance's material, a shadow ray towards
// the sun, and distance fog.
layout(set = 0, binding = 0) uniform accelerationStructureEXT scene;
layout(location = 0) rayPayloadInEXT vec3 radiance;
layout(location = 1) rayPayloadEXT float lit;

const vec3 kSunDirection = normalize(vec3(0.45, 0.8, 0.35));

vec3 MaterialColor(uint material) {
  const vec3 palette[8] = vec3[8](vec3(0.80, 0.30, 0.25), vec3(0.25, 0.65, 0.35), vec3(0.30, 0.45, 0.85),
                                  vec3(0.90, 0.75, 0.30), vec3(0.70, 0.40, 0.80), vec3(0.35, 0.75, 0.80),
                                  vec3(0.85, 0.55, 0.30), vec3(0.60, 0.60, 0.62));
  return palette[material % 8u];
}

float Hash(uint x) {
  x ^= x >> 16; x *= 0x7feb352du; x ^= x >> 15; x *= 0x846ca68bu; x ^= x >> 16;
  return float(x & 0xFFFFu) / 65535.0;
}

float SunVisibility(vec3 position, vec3 normal) {
  lit = 0.0;
  uint flags = gl_RayFlagsOpaqueEXT | gl_RayFlagsTerminateOnFirstHitEXT | gl_RayFlagsSkipClosestHitShaderEXT;
  traceRayEXT(scene, flags, 0xFF, 0, 0, 1, position + normal * 0.01, 0.001, kSunDirection, 1000.0, 1);
  return lit;
}

vec3 Shade(vec3 albedo, vec3 position, vec3 normal) {
  if (dot(normal, gl_WorldRayDirectionEXT) > 0.0) normal = -normal;  // two-sided
  float sun = max(dot(normal, kSunDirection), 0.0) * SunVisibility(position, normal);
  vec3 color = albedo * (0.2 + 0.8 * sun);
  float fog = 1.0 - exp(-gl_HitTEXT * 0.02);
  return mix(color, vec3(0.85, 0.80, 0.75), fog);
}
