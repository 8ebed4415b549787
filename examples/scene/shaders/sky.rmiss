#version 460
// Primary rays that hit nothing see the sky.
#extension GL_EXT_ray_tracing : require

layout(location = 0) rayPayloadInEXT vec3 radiance;

void main() {
  float h = clamp(gl_WorldRayDirectionEXT.y * 0.5 + 0.5, 0.0, 1.0);
  radiance = mix(vec3(0.85, 0.80, 0.75), vec3(0.30, 0.50, 0.85), h);
}
