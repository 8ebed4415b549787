#pragma once
// Runs the build-command rule families without a driver: a hand-built DeviceState (every feature on, the
// limits of a typical desktop GPU, buffers and structures inserted directly), a Reporter whose messenger
// collects VUIDs, and BuildCommands for each of the three commands. Used for the valid twins of indirect
// and host builds, which lavapipe cannot run.
#include <vulkan/vulkan.h>

#include <functional>
#include <string>
#include <vector>

#include "build_validation.h"
#include "reporter.h"

namespace asval::test {

constexpr uint32_t kRecordFamilies = kCheckFeatures | kCheckHandles | kCheckStructure | kCheckAlignment;

class RecordHarness {
 public:
  RecordHarness();

  DeviceState& state() { return state_; }

  // A structure on a buffer of its own (bound unless told otherwise). The handles are small counters.
  VkAccelerationStructureKHR AddStructure(VkAccelerationStructureTypeKHR type, bool bound = true,
                                          VkBufferCreateFlags buffer_flags = 0);
  // Counts every format the fake driver is asked about.
  static int format_queries;

  // Runs the enabled families over one command; returns the VUIDs reported, in order.
  std::vector<std::string> Run(BuildCommandKind kind, const std::vector<VkAccelerationStructureBuildGeometryInfoKHR>& infos,
                               const std::vector<const VkAccelerationStructureBuildRangeInfoKHR*>& ranges,
                               uint32_t families = kRecordFamilies);
  // Same, with the indirect arrays given.
  std::vector<std::string> RunIndirect(const std::vector<VkAccelerationStructureBuildGeometryInfoKHR>& infos,
                                       const std::vector<VkDeviceAddress>& addresses,
                                       const std::vector<uint32_t>& strides, uint32_t families = kRecordFamilies);

  // Runs any const check over this harness's state and reporter (e.g. a rule judged on captured bytes); returns
  // the VUIDs reported, in order.
  std::vector<std::string> RunCheck(const std::function<void(const CheckContext&)>& check,
                                    uint32_t families = kRecordFamilies);
  // The full text of the messages of the last Run.
  const std::vector<std::string>& texts() const { return texts_; }

 private:
  static VKAPI_ATTR VkBool32 VKAPI_CALL Callback(VkDebugUtilsMessageSeverityFlagBitsEXT,
                                                 VkDebugUtilsMessageTypeFlagsEXT,
                                                 const VkDebugUtilsMessengerCallbackDataEXT* data, void* user);
  std::vector<std::string> Collect(const BuildCommand& cmd, uint32_t families);

  DeviceState state_;
  Reporter reporter_;
  std::vector<std::string> ids_;
  std::vector<std::string> texts_;
  uint64_t next_handle_ = 0x1000;
};

// Geometries with the given addresses (device or host: the union is the same bits).
VkAccelerationStructureGeometryKHR TrianglesAt(uint64_t vertices, uint64_t indices = 0,
                                               VkIndexType index_type = VK_INDEX_TYPE_NONE_KHR, uint64_t transform = 0);
VkAccelerationStructureGeometryKHR AabbsAt(uint64_t data, VkDeviceSize stride = 24);
VkAccelerationStructureGeometryKHR InstancesAt(uint64_t data, bool array_of_pointers = false);
VkAccelerationStructureBuildGeometryInfoKHR InfoOf(VkAccelerationStructureTypeKHR type,
                                                   const VkAccelerationStructureGeometryKHR* geometries, uint32_t count,
                                                   VkAccelerationStructureKHR dst, uint64_t scratch);

}  // namespace asval::test
