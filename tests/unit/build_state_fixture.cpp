#include "build_state_fixture.h"

#include "build_validation.h"
#include "state_tracker.h"
#include "vk_dispatch_table.h"

namespace asval {

namespace {

constexpr VkDeviceAddress kAddressSpacing = 0x1000000;  // buffers up to 16 MiB never share addresses

template <typename H>
H Fake(uint64_t v) {
  return reinterpret_cast<H>(v);
}

VKAPI_ATTR VkDeviceAddress VKAPI_CALL FakeBufferAddress(VkDevice, const VkBufferDeviceAddressInfo* info) {
  return reinterpret_cast<uint64_t>(info->buffer) * kAddressSpacing;
}

VKAPI_ATTR VkDeviceAddress VKAPI_CALL FakeStructureAddress(VkDevice,
                                                           const VkAccelerationStructureDeviceAddressInfoKHR* info) {
  return reinterpret_cast<uint64_t>(info->accelerationStructure) * 0x100;
}

VKAPI_ATTR void VKAPI_CALL FakeBuildSizes(VkDevice, VkAccelerationStructureBuildTypeKHR,
                                          const VkAccelerationStructureBuildGeometryInfoKHR* info, const uint32_t* counts,
                                          VkAccelerationStructureBuildSizesInfoKHR* sizes) {
  uint64_t primitives = 0;
  for (uint32_t j = 0; j < info->geometryCount; ++j) primitives += counts[j];
  sizes->accelerationStructureSize = FakeSizes::Structure(primitives);
  sizes->buildScratchSize = FakeSizes::BuildScratch(primitives);
  sizes->updateScratchSize = FakeSizes::update_scratch_zero ? 0 : FakeSizes::kUpdateScratch;
  ++FakeSizes::queries;
}

VKAPI_ATTR void VKAPI_CALL FakeFormatProperties(VkPhysicalDevice, VkFormat format, VkFormatProperties* properties) {
  *properties = VkFormatProperties{};
  if (format == VK_FORMAT_R32G32B32_SFLOAT) {
    properties->bufferFeatures = VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR;
  }
}

DeviceDispatchTable FakeDispatch() {
  DeviceDispatchTable d{};
  d.GetBufferDeviceAddress = &FakeBufferAddress;
  d.GetAccelerationStructureDeviceAddressKHR = &FakeStructureAddress;
  return d;
}

VKAPI_ATTR VkBool32 VKAPI_CALL Collect(VkDebugUtilsMessageSeverityFlagBitsEXT, VkDebugUtilsMessageTypeFlagsEXT,
                                       const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* fixture = static_cast<BuildStateFixture*>(user);
  fixture->ids.push_back(data->pMessageIdName);
  fixture->texts.push_back(data->pMessage);
  return VK_FALSE;
}

}  // namespace

BuildStateFixture::BuildStateFixture() {
  FakeSizes::update_scratch_zero = false;
  FakeSizes::queries = 0;
  DeviceFeatures& f = state.features;
  f.acceleration_structure = f.acceleration_structure_host_commands = f.acceleration_structure_indirect_build = true;
  f.buffer_device_address = f.ray_query = true;
  VkPhysicalDeviceAccelerationStructurePropertiesKHR& limits = state.properties.acceleration_structure;
  limits.maxGeometryCount = 1 << 24;
  limits.maxInstanceCount = 1 << 24;
  limits.maxPrimitiveCount = 1 << 29;
  limits.minAccelerationStructureScratchOffsetAlignment = 128;
  VkPhysicalDeviceMemoryProperties& memory = state.properties.memory;
  memory.memoryHeapCount = 2;
  memory.memoryHeaps[1].flags = VK_MEMORY_HEAP_MULTI_INSTANCE_BIT;
  memory.memoryTypeCount = 3;
  memory.memoryTypes[0] = {VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT, 0};
  memory.memoryTypes[1] = {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0};
  memory.memoryTypes[2] = {VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT, 1};
  state.build_sizes.Init(Fake<VkDevice>(1), &FakeBuildSizes);
  state.format_features.Init(Fake<VkPhysicalDevice>(2), &FakeFormatProperties);

  VkDebugUtilsMessengerCreateInfoEXT messenger{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  messenger.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
  messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
  messenger.pfnUserCallback = &Collect;
  messenger.pUserData = this;
  reporter.AddMessenger(Fake<VkDebugUtilsMessengerEXT>(1), messenger);
}

VkDeviceMemory BuildStateFixture::Memory(VkDeviceSize size, uint32_t type, uint32_t device_mask) {
  VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
  flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT | (device_mask ? VK_MEMORY_ALLOCATE_DEVICE_MASK_BIT : 0);
  flags.deviceMask = device_mask;
  const VkMemoryAllocateInfo info{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags, size, type};
  const auto memory = Fake<VkDeviceMemory>(next_handle_++);
  RecordAllocateMemory(state, info, memory);
  return memory;
}

VkBuffer BuildStateFixture::Buffer(VkDeviceSize size, VkBufferUsageFlags usage, VkDeviceMemory memory,
                                   VkDeviceSize offset) {
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = usage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
  const auto buffer = Fake<VkBuffer>(next_handle_++);
  RecordCreateBuffer(state, info, buffer);
  RecordBindBufferMemory(state, FakeDispatch(), Fake<VkDevice>(1), buffer, memory, offset);
  return buffer;
}

VkDeviceAddress BuildStateFixture::AddressOf(VkBuffer buffer) const {
  return reinterpret_cast<uint64_t>(buffer) * kAddressSpacing;
}

VkAccelerationStructureKHR BuildStateFixture::Structure(VkBuffer buffer, VkDeviceSize offset, VkDeviceSize size,
                                                        VkAccelerationStructureTypeKHR type) {
  VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  info.buffer = buffer;
  info.offset = offset;
  info.size = size;
  info.type = type;
  const auto as = Fake<VkAccelerationStructureKHR>(next_handle_++);
  RecordCreateAccelerationStructure(state, FakeDispatch(), Fake<VkDevice>(1), info, as);
  return as;
}

void BuildStateFixture::DestroyStructure(VkAccelerationStructureKHR as) { RecordDestroyAccelerationStructure(state, as); }

bool BuildStateFixture::Validate(const BuildCommand& cmd) {
  const CheckContext ctx{state, reporter, kCheckAddresses | kCheckAliasing | kCheckHost};
  return ValidateBuildCommand(ctx, cmd);  // the three families only: the context enables no other
}

std::vector<std::string> BuildStateFixture::Take() {
  std::vector<std::string> out;
  out.swap(ids);
  texts.clear();
  return out;
}

BuildCommand HostBuild(uint32_t count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                       const VkAccelerationStructureBuildRangeInfoKHR* const* ranges) {
  BuildCommand cmd{BuildCommandKind::kHostBuild, "vkBuildAccelerationStructuresKHR"};
  cmd.device = Fake<VkDevice>(1);
  cmd.info_count = count;
  cmd.infos = infos;
  cmd.ranges = ranges;
  return cmd;
}

BuildCommand IndirectBuild(uint32_t count, const VkAccelerationStructureBuildGeometryInfoKHR* infos,
                           const VkDeviceAddress* addresses, const uint32_t* strides, const uint32_t* const* max_counts) {
  BuildCommand cmd{BuildCommandKind::kCmdBuildIndirect, "vkCmdBuildAccelerationStructuresIndirectKHR"};
  cmd.device = Fake<VkDevice>(1);
  cmd.command_buffer = Fake<VkCommandBuffer>(3);
  cmd.info_count = count;
  cmd.infos = infos;
  cmd.indirect_addresses = addresses;
  cmd.indirect_strides = strides;
  cmd.max_primitive_counts = max_counts;
  return cmd;
}

VkAccelerationStructureGeometryKHR TriangleGeometry(uint64_t vertices) {
  VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  auto& t = g.geometry.triangles;
  t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
  t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
  t.vertexData.deviceAddress = vertices;
  t.vertexStride = 12;
  t.maxVertex = 2;
  t.indexType = VK_INDEX_TYPE_NONE_KHR;
  return g;
}

VkAccelerationStructureGeometryKHR InstanceGeometry(uint64_t instances) {
  VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  g.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  g.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
  g.geometry.instances.arrayOfPointers = VK_FALSE;
  g.geometry.instances.data.deviceAddress = instances;
  return g;
}

VkAccelerationStructureBuildGeometryInfoKHR OneGeometryInfo(VkAccelerationStructureTypeKHR type,
                                                            const VkAccelerationStructureGeometryKHR* geometry) {
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  info.type = type;
  info.flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;
  info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  info.geometryCount = 1;
  info.pGeometries = geometry;
  return info;
}

}  // namespace asval
