#pragma once
// The compute pass that moves every structure's vertices each frame (shaders/move_vertices.comp): reads the
// shared rest mesh, writes all structures' positions into one buffer, then a barrier makes them visible to the
// refits that read them.
#include <vulkan/vulkan.h>

#include <cstdint>

#include "vkkit.h"

namespace refit {

class VertexMover {
 public:
  // rest: vec4 per vertex of one mesh; positions: 3 floats per vertex of all `meshes` meshes.
  VertexMover(vkkit::Device& device, const vkkit::Buffer& rest, const vkkit::Buffer& positions,
              uint32_t vertices_per_mesh, uint32_t meshes);
  ~VertexMover();
  VertexMover(const VertexMover&) = delete;
  VertexMover& operator=(const VertexMover&) = delete;

  void Record(VkCommandBuffer cb, float time) const;

 private:
  struct PushConstants {  // move_vertices.comp's Frame block
    float time;
    uint32_t vertices_per_mesh;
    uint32_t total_vertices;
  };

  VkDevice device_;
  uint32_t vertices_per_mesh_;
  uint32_t total_vertices_;
  VkDescriptorSetLayout set_layout_ = VK_NULL_HANDLE;
  VkPipelineLayout layout_ = VK_NULL_HANDLE;
  VkPipeline pipeline_ = VK_NULL_HANDLE;
  VkDescriptorPool pool_ = VK_NULL_HANDLE;
  VkDescriptorSet set_ = VK_NULL_HANDLE;
};

}  // namespace refit
