#version 460
// A shadow ray that hits nothing reaches the light.
#extension GL_EXT_ray_tracing : require

layout(location = 1) rayPayloadInEXT float lit;

void main() { lit = 1.0; }
