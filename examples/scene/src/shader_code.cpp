#include "shader_code.h"

#include <cstdint>

#include "gpu.h"
// Generated into the build tree by examples/scene/CMakeLists.txt.
#include "deform.comp.h"
#include "raygen.rgen.h"
#include "shadow.rmiss.h"
#include "sky.rmiss.h"
#include "sphere.rchit.h"
#include "sphere.rint.h"
#include "triangle.rchit.h"

namespace scene {

namespace {

template <size_t N>
ShaderCode Code(const uint32_t (&words)[N]) {
  return ShaderCode{words, sizeof(words)};
}

}  // namespace

ShaderCode CodeOf(Shader shader) {
  switch (shader) {
    case Shader::kDeform: return Code(kDeformComp);
    case Shader::kRaygen: return Code(kRaygenRgen);
    case Shader::kSkyMiss: return Code(kSkyRmiss);
    case Shader::kShadowMiss: return Code(kShadowRmiss);
    case Shader::kTriangleHit: return Code(kTriangleRchit);
    case Shader::kSphereIntersection: return Code(kSphereRint);
    case Shader::kSphereHit: return Code(kSphereRchit);
  }
  return ShaderCode{nullptr, 0};
}

VkShaderModule CreateShaderModule(VkDevice device, Shader shader) {
  const ShaderCode code = CodeOf(shader);
  VkShaderModuleCreateInfo info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  info.codeSize = code.bytes;
  info.pCode = code.words;
  VkShaderModule module = VK_NULL_HANDLE;
  Check(vkCreateShaderModule(device, &info, nullptr, &module), "vkCreateShaderModule");
  return module;
}

}  // namespace scene
