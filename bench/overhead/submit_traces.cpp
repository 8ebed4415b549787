// submit_traces: what the layers cost per vkQueueSubmit of a command buffer of ray-query dispatches over one large
// top-level structure (issue 29, family traces). asval judges each dispatch at submission: the structures in the
// descriptors its pipeline reads must have had a build execute on them (docs/traces.md). The cost must follow the
// dispatches and their bound structures, not the structure's instances.
//   submit_traces SUBMISSIONS [DISPATCHES] [INSTANCES]: a top-level structure of INSTANCES (10,000) instances of one
//   triangle, built once (not measured); a command buffer of DISPATCHES (100) times bind pipeline, bind set and
//   vkCmdDispatch(1, 1, 1), recorded once and submitted SUBMISSIONS times after one submission that is not measured.
// Only vkQueueSubmit is timed and between the callgrind client requests.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "bench_device.h"
#include "ray_query.comp.h"
#include "vkkit.h"

namespace {

// The top-level structure over `count` instances of `blas`, built and waited for.
vkkit::AccelerationStructure BuildTopLevel(vkkit::Device& device, const vkkit::AccelerationStructure& blas,
                                           uint32_t count) {
  vkkit::Buffer instances = device.CreateBuffer(sizeof(VkAccelerationStructureInstanceKHR) * count,
                                                VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  auto* records = static_cast<VkAccelerationStructureInstanceKHR*>(instances.mapped);
  for (uint32_t i = 0; i < count; ++i) {
    VkAccelerationStructureInstanceKHR r{};
    r.transform.matrix[0][0] = r.transform.matrix[1][1] = r.transform.matrix[2][2] = 1.0f;
    r.transform.matrix[0][3] = static_cast<float>(i % 100) * 2.0f;
    r.transform.matrix[1][3] = static_cast<float>(i / 100) * 2.0f;
    r.mask = 0xff;
    records[i] = r;
  }
  VkAccelerationStructureDeviceAddressInfoKHR address{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR};
  address.accelerationStructure = blas.handle;
  const VkDeviceAddress reference = device.GetAccelerationStructureDeviceAddressKHR(device.handle(), &address);
  for (uint32_t i = 0; i < count; ++i) records[i].accelerationStructureReference = reference;

  VkAccelerationStructureGeometryKHR geometry{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  geometry.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  geometry.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
  geometry.geometry.instances.data.deviceAddress = instances.address;
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
  info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  info.geometryCount = 1;
  info.pGeometries = &geometry;
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  device.GetAccelerationStructureBuildSizesKHR(device.handle(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info,
                                               &count, &sizes);
  vkkit::AccelerationStructure tlas =
      device.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, sizes.accelerationStructureSize);
  vkkit::Buffer scratch = device.CreateBuffer(sizes.buildScratchSize, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  info.dstAccelerationStructure = tlas.handle;
  info.scratchData.deviceAddress = scratch.address;
  VkAccelerationStructureBuildRangeInfoKHR range{};
  range.primitiveCount = count;
  const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
  device.OneShot([&](VkCommandBuffer cb) { device.CmdBuildAccelerationStructuresKHR(cb, 1, &info, &ranges); });
  device.Destroy(scratch);
  device.Destroy(instances);
  return tlas;
}

int Run(int argc, char** argv) {
  const int submissions = argc > 1 ? std::atoi(argv[1]) : 10;
  const int dispatches = argc > 2 ? std::atoi(argv[2]) : 100;
  const uint32_t instances = argc > 3 ? static_cast<uint32_t>(std::atoi(argv[3])) : 10000;
  if (submissions < 1 || dispatches < 1 || instances < 1) {
    std::fprintf(stderr, "usage: submit_traces SUBMISSIONS [DISPATCHES] [INSTANCES]\n");
    return 2;
  }
  overhead::BenchDevice bench;
  vkkit::Device& device = bench.device();
  const VkDevice d = device.handle();

  vkkit::TriangleBuild triangle(device);
  device.OneShot([&](VkCommandBuffer cb) { triangle.Record(device, cb); });
  vkkit::AccelerationStructure tlas = BuildTopLevel(device, triangle.blas, instances);

  // The ray-query pipeline (set 0: the structure at binding 0, a storage buffer at binding 1) and its set.
  const VkDescriptorSetLayoutBinding bindings[2] = {
      {0, VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr},
      {1, VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1, VK_SHADER_STAGE_COMPUTE_BIT, nullptr}};
  VkDescriptorSetLayoutCreateInfo set_layout_info{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_LAYOUT_CREATE_INFO};
  set_layout_info.bindingCount = 2;
  set_layout_info.pBindings = bindings;
  VkDescriptorSetLayout set_layout = VK_NULL_HANDLE;
  vkkit::Check(vkCreateDescriptorSetLayout(d, &set_layout_info, nullptr, &set_layout), "vkCreateDescriptorSetLayout");
  VkPipelineLayoutCreateInfo layout_info{VK_STRUCTURE_TYPE_PIPELINE_LAYOUT_CREATE_INFO};
  layout_info.setLayoutCount = 1;
  layout_info.pSetLayouts = &set_layout;
  VkPipelineLayout layout = VK_NULL_HANDLE;
  vkkit::Check(vkCreatePipelineLayout(d, &layout_info, nullptr, &layout), "vkCreatePipelineLayout");
  VkShaderModuleCreateInfo module_info{VK_STRUCTURE_TYPE_SHADER_MODULE_CREATE_INFO};
  module_info.codeSize = sizeof(kRayQueryComp);
  module_info.pCode = kRayQueryComp;
  VkShaderModule module = VK_NULL_HANDLE;
  vkkit::Check(vkCreateShaderModule(d, &module_info, nullptr, &module), "vkCreateShaderModule");
  VkComputePipelineCreateInfo pipeline_info{VK_STRUCTURE_TYPE_COMPUTE_PIPELINE_CREATE_INFO};
  pipeline_info.stage = {VK_STRUCTURE_TYPE_PIPELINE_SHADER_STAGE_CREATE_INFO};
  pipeline_info.stage.stage = VK_SHADER_STAGE_COMPUTE_BIT;
  pipeline_info.stage.module = module;
  pipeline_info.stage.pName = "main";
  pipeline_info.layout = layout;
  VkPipeline pipeline = VK_NULL_HANDLE;
  vkkit::Check(vkCreateComputePipelines(d, VK_NULL_HANDLE, 1, &pipeline_info, nullptr, &pipeline),
               "vkCreateComputePipelines");
  vkDestroyShaderModule(d, module, nullptr);
  const VkDescriptorPoolSize pool_sizes[2] = {{VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, 1},
                                              {VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, 1}};
  VkDescriptorPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_DESCRIPTOR_POOL_CREATE_INFO};
  pool_info.maxSets = 1;
  pool_info.poolSizeCount = 2;
  pool_info.pPoolSizes = pool_sizes;
  VkDescriptorPool descriptor_pool = VK_NULL_HANDLE;
  vkkit::Check(vkCreateDescriptorPool(d, &pool_info, nullptr, &descriptor_pool), "vkCreateDescriptorPool");
  VkDescriptorSetAllocateInfo alloc{VK_STRUCTURE_TYPE_DESCRIPTOR_SET_ALLOCATE_INFO};
  alloc.descriptorPool = descriptor_pool;
  alloc.descriptorSetCount = 1;
  alloc.pSetLayouts = &set_layout;
  VkDescriptorSet set = VK_NULL_HANDLE;
  vkkit::Check(vkAllocateDescriptorSets(d, &alloc, &set), "vkAllocateDescriptorSets");
  vkkit::Buffer output = device.CreateBuffer(256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  VkWriteDescriptorSetAccelerationStructureKHR as_write{
      VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET_ACCELERATION_STRUCTURE_KHR};
  as_write.accelerationStructureCount = 1;
  as_write.pAccelerationStructures = &tlas.handle;
  const VkDescriptorBufferInfo buffer_info{output.buffer, 0, VK_WHOLE_SIZE};
  const VkWriteDescriptorSet writes[2] = {{VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, &as_write, set, 0, 0, 1,
                                           VK_DESCRIPTOR_TYPE_ACCELERATION_STRUCTURE_KHR, nullptr, nullptr, nullptr},
                                          {VK_STRUCTURE_TYPE_WRITE_DESCRIPTOR_SET, nullptr, set, 1, 0, 1,
                                           VK_DESCRIPTOR_TYPE_STORAGE_BUFFER, nullptr, &buffer_info, nullptr}};
  vkUpdateDescriptorSets(d, 2, writes, 0, nullptr);

  const VkCommandPool command_pool = overhead::CreatePool(bench.gpu(), d);
  const VkCommandBuffer cb = overhead::BeginReusable(d, command_pool);
  for (int i = 0; i < dispatches; ++i) {
    vkCmdBindPipeline(cb, VK_PIPELINE_BIND_POINT_COMPUTE, pipeline);
    vkCmdBindDescriptorSets(cb, VK_PIPELINE_BIND_POINT_COMPUTE, layout, 0, 1, &set, 0, nullptr);
    vkCmdDispatch(cb, 1, 1, 1);
  }
  vkkit::Check(vkEndCommandBuffer(cb), "vkEndCommandBuffer");

  const double seconds = overhead::TimeSubmissions(device.queue(), cb, submissions);
  std::printf("%d submissions of %d ray-query dispatches over %u instances\n", submissions, dispatches, instances);
  vkDestroyCommandPool(d, command_pool, nullptr);
  vkDestroyDescriptorPool(d, descriptor_pool, nullptr);
  vkDestroyPipeline(d, pipeline, nullptr);
  vkDestroyPipelineLayout(d, layout, nullptr);
  vkDestroyDescriptorSetLayout(d, set_layout, nullptr);
  device.Destroy(output);
  device.Destroy(tlas);
  triangle.Release(device);
  return bench.Finish(submissions, seconds);
}

}  // namespace

int main(int argc, char** argv) { return overhead::Main("submit_traces", Run, argc, argv); }
