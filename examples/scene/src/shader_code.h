#pragma once
// The SPIR-V of the scene's shaders, compiled from shaders/*.{comp,rgen,rmiss,rchit,rint} by glslangValidator
// at build time.
#include <vulkan/vulkan.h>

#include <cstddef>
#include <cstdint>

namespace scene {

struct ShaderCode {
  const uint32_t* words;
  size_t bytes;
};

enum class Shader { kDeform, kRaygen, kSkyMiss, kShadowMiss, kTriangleHit, kSphereIntersection, kSphereHit };

ShaderCode CodeOf(Shader shader);
VkShaderModule CreateShaderModule(VkDevice device, Shader shader);

}  // namespace scene
