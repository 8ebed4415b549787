// Enum and flag names as the messages print them.
#include <catch2/catch_test_macros.hpp>

#include <cstring>
#include <string>

#include "vk_enum_string.h"

namespace {

TEST_CASE("enum values print their vulkan_core.h names") {
  CHECK(std::string(asval::string_VkFormat(VK_FORMAT_R32G32B32_SFLOAT)) == "VK_FORMAT_R32G32B32_SFLOAT");
  CHECK(std::string(asval::string_VkResult(VK_ERROR_OUT_OF_DEVICE_MEMORY)) == "VK_ERROR_OUT_OF_DEVICE_MEMORY");
  CHECK(std::string(asval::string_VkResult(VK_OPERATION_DEFERRED_KHR)) == "VK_OPERATION_DEFERRED_KHR");
  CHECK(std::string(asval::string_VkIndexType(VK_INDEX_TYPE_NONE_KHR)) == "VK_INDEX_TYPE_NONE_KHR");
  CHECK(std::string(asval::string_VkGeometryTypeKHR(VK_GEOMETRY_TYPE_AABBS_KHR)) == "VK_GEOMETRY_TYPE_AABBS_KHR");
  CHECK(std::string(asval::string_VkQueryType(VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR)) ==
        "VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR");
  CHECK(std::string(asval::string_VkBuildAccelerationStructureModeKHR(VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR)) ==
        "VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR");
}

TEST_CASE("an alias value prints the name it aliases") {
  // VK_INDEX_TYPE_NONE_NV aliases VK_INDEX_TYPE_NONE_KHR: one case label, the KHR name.
  CHECK(std::string(asval::string_VkIndexType(VK_INDEX_TYPE_NONE_NV)) == "VK_INDEX_TYPE_NONE_KHR");
  CHECK(std::string(asval::string_VkAccelerationStructureTypeKHR(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_NV)) ==
        "VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR");
}

TEST_CASE("unknown enum values say so") {
  CHECK(std::string(asval::string_VkFormat(static_cast<VkFormat>(0x7FFFFFF0))) == "Unhandled VkFormat");
  CHECK(std::string(asval::string_VkGeometryTypeKHR(static_cast<VkGeometryTypeKHR>(77))) ==
        "Unhandled VkGeometryTypeKHR");
  CHECK(std::string(asval::string_VkResult(static_cast<VkResult>(-12345))) == "Unhandled VkResult");
}

TEST_CASE("flags print their bit names joined by |, unknown bits as hex") {
  char buf[256];
  CHECK(std::string(asval::string_VkBufferUsageFlags(
            VK_BUFFER_USAGE_STORAGE_BUFFER_BIT | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT, buf, sizeof(buf))) ==
        "VK_BUFFER_USAGE_STORAGE_BUFFER_BIT|VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT");
  CHECK(std::string(asval::string_VkBuildAccelerationStructureFlagsKHR(
            VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR | 0x40000000u, buf, sizeof(buf))) ==
        "VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR|0x40000000");
  CHECK(std::string(asval::string_VkGeometryFlagsKHR(0x80000000u, buf, sizeof(buf))) == "0x80000000");
  CHECK(std::string(asval::string_VkGeometryInstanceFlagsKHR(0, buf, sizeof(buf))) == "0");
  CHECK(std::string(asval::string_VkMemoryPropertyFlags(VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT, buf, sizeof(buf))) ==
        "VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT");
  CHECK(std::string(asval::string_VkMemoryAllocateFlags(VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT, buf, sizeof(buf))) ==
        "VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT");
  CHECK(std::string(asval::string_VkAccelerationStructureCreateFlagsKHR(
            VK_ACCELERATION_STRUCTURE_CREATE_DEVICE_ADDRESS_CAPTURE_REPLAY_BIT_KHR, buf, sizeof(buf))) ==
        "VK_ACCELERATION_STRUCTURE_CREATE_DEVICE_ADDRESS_CAPTURE_REPLAY_BIT_KHR");
}

TEST_CASE("flag strings are cut to the buffer and stay NUL-terminated") {
  char buf[12];
  std::memset(buf, 'x', sizeof(buf));
  const char* text = asval::string_VkBufferUsageFlags(VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, buf, sizeof(buf));
  CHECK(text == buf);
  CHECK(std::string(buf) == "VK_BUFFER_U");  // 11 characters and the NUL
  char one[1] = {'x'};
  asval::string_VkBufferUsageFlags(VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, one, sizeof(one));
  CHECK(one[0] == '\0');
  char none[1] = {'x'};
  asval::string_VkBufferUsageFlags(VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, none, 0);
  CHECK(none[0] == 'x');  // n == 0: nothing written
}

TEST_CASE("object types name their handle type") {
  CHECK(std::string(asval::ObjectTypeName(VK_OBJECT_TYPE_BUFFER)) == "VkBuffer");
  CHECK(std::string(asval::ObjectTypeName(VK_OBJECT_TYPE_ACCELERATION_STRUCTURE_KHR)) == "VkAccelerationStructureKHR");
  CHECK(std::string(asval::ObjectTypeName(VK_OBJECT_TYPE_COMMAND_BUFFER)) == "VkCommandBuffer");
  CHECK(std::string(asval::ObjectTypeName(VK_OBJECT_TYPE_DEBUG_UTILS_MESSENGER_EXT)) == "VkDebugUtilsMessengerEXT");
  CHECK(std::string(asval::ObjectTypeName(VK_OBJECT_TYPE_UNKNOWN)) == "Unhandled VkObjectType");
  CHECK(std::string(asval::string_VkObjectType(VK_OBJECT_TYPE_BUFFER)) == "VK_OBJECT_TYPE_BUFFER");
}

}  // namespace
