#include "record_checks_harness.h"

#include <memory>

namespace asval::test {

int RecordHarness::format_queries = 0;

namespace {

// The formats the spec makes mandatory for acceleration-structure vertex buffers.
VKAPI_ATTR void VKAPI_CALL FakeFormatProperties(VkPhysicalDevice, VkFormat format, VkFormatProperties* properties) {
  ++RecordHarness::format_queries;
  *properties = VkFormatProperties{};
  switch (format) {
    case VK_FORMAT_R32G32_SFLOAT:
    case VK_FORMAT_R32G32B32_SFLOAT:
    case VK_FORMAT_R16G16_SFLOAT:
    case VK_FORMAT_R16G16B16A16_SFLOAT:
    case VK_FORMAT_R16G16_SNORM:
    case VK_FORMAT_R16G16B16A16_SNORM:
      properties->bufferFeatures = VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR;
      break;
    default:
      break;
  }
}

ReportSettings Unlimited() {
  ReportSettings settings;
  settings.duplicate_message_limit = 0;
  return settings;
}

template <typename H>
H Handle(uint64_t value) {
  return reinterpret_cast<H>(value);
}

}  // namespace

RecordHarness::RecordHarness() : reporter_(Unlimited()) {
  DeviceFeatures& f = state_.features;
  f.acceleration_structure = f.acceleration_structure_host_commands = f.acceleration_structure_indirect_build = true;
  f.buffer_device_address = f.ray_query = true;
  VkPhysicalDeviceAccelerationStructurePropertiesKHR& limits = state_.properties.acceleration_structure;
  limits.maxGeometryCount = (1u << 24) - 1;
  limits.maxInstanceCount = (1u << 24) - 1;
  limits.maxPrimitiveCount = (1u << 29) - 1;
  limits.minAccelerationStructureScratchOffsetAlignment = 128;
  state_.format_features.Init(Handle<VkPhysicalDevice>(0x77), &FakeFormatProperties);
  VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
  info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT;
  info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
  info.pfnUserCallback = &RecordHarness::Callback;
  info.pUserData = this;
  reporter_.AddMessenger(Handle<VkDebugUtilsMessengerEXT>(0x1), info);
}

VKAPI_ATTR VkBool32 VKAPI_CALL RecordHarness::Callback(VkDebugUtilsMessageSeverityFlagBitsEXT,
                                                       VkDebugUtilsMessageTypeFlagsEXT,
                                                       const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* self = static_cast<RecordHarness*>(user);
  self->ids_.push_back(data->pMessageIdName);
  self->texts_.push_back(data->pMessage);
  return VK_TRUE;
}

VkAccelerationStructureKHR RecordHarness::AddStructure(VkAccelerationStructureTypeKHR type, bool bound,
                                                       VkBufferCreateFlags buffer_flags) {
  auto buffer = std::make_shared<BufferState>();
  buffer->handle = Handle<VkBuffer>(next_handle_++);
  buffer->size = 1 << 20;
  buffer->usage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
  buffer->create_flags = buffer_flags;
  buffer->bound = bound;
  if (bound) buffer->memory = Handle<VkDeviceMemory>(next_handle_++);
  auto as = std::make_shared<AccelerationStructureState>();
  as->handle = Handle<VkAccelerationStructureKHR>(next_handle_++);
  as->buffer = buffer->handle;
  as->size = buffer->size;
  as->type = type;
  state_.buffers.insert_or_assign(buffer->handle, std::move(buffer));
  const VkAccelerationStructureKHR handle = as->handle;
  state_.acceleration_structures.insert_or_assign(handle, std::move(as));
  return handle;
}

std::vector<std::string> RecordHarness::Collect(const BuildCommand& cmd, uint32_t families) {
  ids_.clear();
  texts_.clear();
  const CheckContext ctx{state_, reporter_, families};
  ValidateBuildCommand(ctx, cmd);
  return ids_;
}

std::vector<std::string> RecordHarness::RunCheck(const std::function<void(const CheckContext&)>& check,
                                                 uint32_t families) {
  ids_.clear();
  texts_.clear();
  check(CheckContext{state_, reporter_, families});
  return ids_;
}

std::vector<std::string> RecordHarness::Run(BuildCommandKind kind,
                                            const std::vector<VkAccelerationStructureBuildGeometryInfoKHR>& infos,
                                            const std::vector<const VkAccelerationStructureBuildRangeInfoKHR*>& ranges,
                                            uint32_t families) {
  static const char* const kNames[] = {"vkCmdBuildAccelerationStructuresKHR",
                                       "vkCmdBuildAccelerationStructuresIndirectKHR", "vkBuildAccelerationStructuresKHR"};
  BuildCommand cmd{kind, kNames[static_cast<int>(kind)]};
  cmd.device = Handle<VkDevice>(0x10);
  if (kind != BuildCommandKind::kHostBuild) cmd.command_buffer = Handle<VkCommandBuffer>(0x20);
  cmd.info_count = static_cast<uint32_t>(infos.size());
  cmd.infos = infos.data();
  std::vector<VkDeviceAddress> addresses(infos.size(), 0x10000);
  std::vector<uint32_t> strides(infos.size(), 16);
  if (kind == BuildCommandKind::kCmdBuildIndirect) {
    cmd.indirect_addresses = addresses.data();
    cmd.indirect_strides = strides.data();
  } else {
    cmd.ranges = ranges.data();
  }
  return Collect(cmd, families);
}

std::vector<std::string> RecordHarness::RunIndirect(const std::vector<VkAccelerationStructureBuildGeometryInfoKHR>& infos,
                                                    const std::vector<VkDeviceAddress>& addresses,
                                                    const std::vector<uint32_t>& strides, uint32_t families) {
  BuildCommand cmd{BuildCommandKind::kCmdBuildIndirect, "vkCmdBuildAccelerationStructuresIndirectKHR"};
  cmd.device = Handle<VkDevice>(0x10);
  cmd.command_buffer = Handle<VkCommandBuffer>(0x20);
  cmd.info_count = static_cast<uint32_t>(infos.size());
  cmd.infos = infos.data();
  cmd.indirect_addresses = addresses.data();
  cmd.indirect_strides = strides.data();
  return Collect(cmd, families);
}

VkAccelerationStructureGeometryKHR TrianglesAt(uint64_t vertices, uint64_t indices, VkIndexType index_type,
                                               uint64_t transform) {
  VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  auto& tri = g.geometry.triangles;
  tri.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
  tri.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
  tri.vertexData.deviceAddress = vertices;
  tri.vertexStride = 12;
  tri.maxVertex = 2;
  tri.indexType = index_type;
  tri.indexData.deviceAddress = indices;
  tri.transformData.deviceAddress = transform;
  return g;
}

VkAccelerationStructureGeometryKHR AabbsAt(uint64_t data, VkDeviceSize stride) {
  VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  g.geometryType = VK_GEOMETRY_TYPE_AABBS_KHR;
  g.geometry.aabbs.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR;
  g.geometry.aabbs.data.deviceAddress = data;
  g.geometry.aabbs.stride = stride;
  return g;
}

VkAccelerationStructureGeometryKHR InstancesAt(uint64_t data, bool array_of_pointers) {
  VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  g.geometryType = VK_GEOMETRY_TYPE_INSTANCES_KHR;
  g.geometry.instances.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_INSTANCES_DATA_KHR;
  g.geometry.instances.arrayOfPointers = array_of_pointers ? VK_TRUE : VK_FALSE;
  g.geometry.instances.data.deviceAddress = data;
  return g;
}

VkAccelerationStructureBuildGeometryInfoKHR InfoOf(VkAccelerationStructureTypeKHR type,
                                                   const VkAccelerationStructureGeometryKHR* geometries, uint32_t count,
                                                   VkAccelerationStructureKHR dst, uint64_t scratch) {
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  info.type = type;
  info.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR | VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;
  info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  info.dstAccelerationStructure = dst;
  info.geometryCount = count;
  info.pGeometries = geometries;
  info.scratchData.deviceAddress = scratch;
  return info;
}

}  // namespace asval::test
