// Protect mode (setting `protect`, issue 16) over a fake next element that counts the calls reaching the "driver":
// a call asval reports an error for never arrives there, the command buffer it was recorded into is never
// submitted, each withheld call is named once (ASVAL-Protect-Withheld) and counted at vkDestroyDevice; with protect
// off, or for a finding the app muted, the call goes down as before. No real driver: the hooks are called directly.
#include <catch2/catch_test_macros.hpp>

#include <nlohmann/json.hpp>

#include <cstring>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "layer_data.h"
#include "state_tracker.h"
#include "temp_report.h"
#include "vk_intercepts.h"

namespace asval {
namespace {

constexpr const char kNotice[] = "ASVAL-Protect-Withheld";
constexpr uint32_t kAllFamilies = kCheckFeatures | kCheckHandles | kCheckStructure | kCheckAlignment |
                                  kCheckAddresses | kCheckAliasing | kCheckHost | kCheckCopies | kCheckHistory;

// ---- the fake driver ------------------------------------------------------------------------------------------

// A dispatchable handle: its first word is the loader's dispatch table pointer, which the layer keys on.
struct FakeDispatchable {
  void* loader_table;
};
int g_table;  // its address is the dispatch key shared by the fake device, queue and command buffers
FakeDispatchable g_device_object{&g_table}, g_queue_object{&g_table};
// 0, 1, 3: primary; 2, 5: secondary; 4: never allocated.
FakeDispatchable g_cb_objects[6] = {{&g_table}, {&g_table}, {&g_table}, {&g_table}, {&g_table}, {&g_table}};

// What arrived at the driver.
struct Calls {
  int cmd_build = 0;
  int cmd_build_indirect = 0;
  int cmd_copy = 0;
  int cmd_copy_to_memory = 0;
  int cmd_copy_from_memory = 0;
  int cmd_write_properties = 0;
  int execute_commands = 0;
  int host_build = 0;
  int host_copy = 0;
  int host_write_properties = 0;
  // Submissions whose command buffers reached the driver; those that reached it emptied (a withheld submission's
  // synchronization, layer/loader/synchronization_only.h), and the last of those.
  int queue_submit = 0;
  int queue_submit2 = 0;
  int emptied_submit = 0;
  int emptied_submit2 = 0;
  std::vector<VkSubmitInfo> emptied;
  std::vector<VkSubmitInfo2> emptied2;
  VkFence emptied_fence = VK_NULL_HANDLE;
} g_calls;

VKAPI_ATTR void VKAPI_CALL FakeCmdBuild(VkCommandBuffer, uint32_t, const VkAccelerationStructureBuildGeometryInfoKHR*,
                                        const VkAccelerationStructureBuildRangeInfoKHR* const*) {
  ++g_calls.cmd_build;
}
VKAPI_ATTR void VKAPI_CALL FakeCmdBuildIndirect(VkCommandBuffer, uint32_t,
                                                const VkAccelerationStructureBuildGeometryInfoKHR*,
                                                const VkDeviceAddress*, const uint32_t*, const uint32_t* const*) {
  ++g_calls.cmd_build_indirect;
}
VKAPI_ATTR void VKAPI_CALL FakeCmdCopy(VkCommandBuffer, const VkCopyAccelerationStructureInfoKHR*) { ++g_calls.cmd_copy; }
VKAPI_ATTR void VKAPI_CALL FakeCmdCopyToMemory(VkCommandBuffer, const VkCopyAccelerationStructureToMemoryInfoKHR*) {
  ++g_calls.cmd_copy_to_memory;
}
VKAPI_ATTR void VKAPI_CALL FakeCmdCopyFromMemory(VkCommandBuffer, const VkCopyMemoryToAccelerationStructureInfoKHR*) {
  ++g_calls.cmd_copy_from_memory;
}
VKAPI_ATTR void VKAPI_CALL FakeCmdWriteProperties(VkCommandBuffer, uint32_t, const VkAccelerationStructureKHR*,
                                                  VkQueryType, VkQueryPool, uint32_t) {
  ++g_calls.cmd_write_properties;
}
VKAPI_ATTR void VKAPI_CALL FakeExecuteCommands(VkCommandBuffer, uint32_t, const VkCommandBuffer*) {
  ++g_calls.execute_commands;
}
VKAPI_ATTR VkResult VKAPI_CALL FakeHostBuild(VkDevice, VkDeferredOperationKHR, uint32_t,
                                             const VkAccelerationStructureBuildGeometryInfoKHR*,
                                             const VkAccelerationStructureBuildRangeInfoKHR* const*) {
  ++g_calls.host_build;
  return VK_SUCCESS;
}
VKAPI_ATTR VkResult VKAPI_CALL FakeHostCopy(VkDevice, VkDeferredOperationKHR, const VkCopyAccelerationStructureInfoKHR*) {
  ++g_calls.host_copy;
  return VK_SUCCESS;
}
VKAPI_ATTR VkResult VKAPI_CALL FakeHostWriteProperties(VkDevice, uint32_t, const VkAccelerationStructureKHR*, VkQueryType,
                                                       size_t, void*, size_t) {
  ++g_calls.host_write_properties;
  return VK_SUCCESS;
}
// A submission reaches the "driver": counted in `reached` when some batch holds a command buffer (or there is no
// batch), else in `emptied_calls`, its batches kept in `emptied`.
template <typename SubmitInfo>
VkResult CountSubmission(uint32_t count, const SubmitInfo* submits, VkFence fence,
                         uint32_t SubmitInfo::*command_buffer_count, int& reached, int& emptied_calls,
                         std::vector<SubmitInfo>& emptied) {
  uint32_t command_buffers = 0;
  for (uint32_t i = 0; i < count; ++i) command_buffers += submits[i].*command_buffer_count;
  if (command_buffers != 0 || count == 0) {
    ++reached;
    return VK_SUCCESS;
  }
  ++emptied_calls;
  emptied.assign(submits, submits + count);
  g_calls.emptied_fence = fence;
  return VK_SUCCESS;
}
VKAPI_ATTR VkResult VKAPI_CALL FakeQueueSubmit(VkQueue, uint32_t count, const VkSubmitInfo* submits, VkFence fence) {
  return CountSubmission(count, submits, fence, &VkSubmitInfo::commandBufferCount, g_calls.queue_submit,
                         g_calls.emptied_submit, g_calls.emptied);
}
VKAPI_ATTR VkResult VKAPI_CALL FakeQueueSubmit2(VkQueue, uint32_t count, const VkSubmitInfo2* submits, VkFence fence) {
  return CountSubmission(count, submits, fence, &VkSubmitInfo2::commandBufferInfoCount, g_calls.queue_submit2,
                         g_calls.emptied_submit2, g_calls.emptied2);
}
VKAPI_ATTR VkResult VKAPI_CALL FakeBegin(VkCommandBuffer, const VkCommandBufferBeginInfo*) { return VK_SUCCESS; }
VKAPI_ATTR VkResult VKAPI_CALL FakeEnd(VkCommandBuffer) { return VK_SUCCESS; }
VKAPI_ATTR VkResult VKAPI_CALL FakeReset(VkCommandBuffer, VkCommandBufferResetFlags) { return VK_SUCCESS; }
VKAPI_ATTR VkResult VKAPI_CALL FakeResetPool(VkDevice, VkCommandPool, VkCommandPoolResetFlags) { return VK_SUCCESS; }
VKAPI_ATTR void VKAPI_CALL FakeDestroyDevice(VkDevice, const VkAllocationCallbacks*) {}

constexpr VkDeviceAddress kAddressSpacing = 0x1000000;  // buffers up to 16 MiB never share addresses
VKAPI_ATTR VkDeviceAddress VKAPI_CALL FakeBufferAddress(VkDevice, const VkBufferDeviceAddressInfo* info) {
  return reinterpret_cast<uint64_t>(info->buffer) * kAddressSpacing;
}
VKAPI_ATTR VkDeviceAddress VKAPI_CALL FakeStructureAddress(VkDevice,
                                                           const VkAccelerationStructureDeviceAddressInfoKHR* info) {
  return reinterpret_cast<uint64_t>(info->accelerationStructure) * 0x100;
}
// Sizes: structure 256 + 64 per primitive, build scratch 128 + 16 per primitive, update scratch 64.
VKAPI_ATTR void VKAPI_CALL FakeBuildSizes(VkDevice, VkAccelerationStructureBuildTypeKHR,
                                          const VkAccelerationStructureBuildGeometryInfoKHR* info, const uint32_t* counts,
                                          VkAccelerationStructureBuildSizesInfoKHR* sizes) {
  uint64_t primitives = 0;
  for (uint32_t j = 0; j < info->geometryCount; ++j) primitives += counts[j];
  sizes->accelerationStructureSize = 256 + 64 * primitives;
  sizes->buildScratchSize = 128 + 16 * primitives;
  sizes->updateScratchSize = 64;
}
VKAPI_ATTR void VKAPI_CALL FakeFormatProperties(VkPhysicalDevice, VkFormat format, VkFormatProperties* properties) {
  *properties = VkFormatProperties{};
  if (format == VK_FORMAT_R32G32B32_SFLOAT) {
    properties->bufferFeatures = VK_FORMAT_FEATURE_ACCELERATION_STRUCTURE_VERTEX_BUFFER_BIT_KHR;
  }
}

template <typename H>
H Fake(uint64_t v) {
  return reinterpret_cast<H>(v);
}

// ---- what the app's messenger saw -----------------------------------------------------------------------------

struct Message {
  VkDebugUtilsMessageSeverityFlagBitsEXT severity;
  std::string id;
  std::string text;
};
struct Collected {
  std::vector<Message> messages;
  VkBool32 answer = VK_FALSE;  // what the app's callback returns
  // Run once from inside the callback, at the first error (an app that calls Vulkan from its callback).
  std::function<void()> on_first_error;
};
VKAPI_ATTR VkBool32 VKAPI_CALL Collect(VkDebugUtilsMessageSeverityFlagBitsEXT severity,
                                       VkDebugUtilsMessageTypeFlagsEXT,
                                       const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* c = static_cast<Collected*>(user);
  c->messages.push_back(Message{severity, data->pMessageIdName, data->pMessage});
  if (severity == VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT && c->on_first_error) {
    const std::function<void()> action = std::move(c->on_first_error);
    c->on_first_error = nullptr;
    action();
  }
  return c->answer;
}

ReportSettings Protect(bool on = true) {
  ReportSettings settings;
  settings.protect = on;
  return settings;
}

// ---- the device -----------------------------------------------------------------------------------------------

// A device registered with the layer over the fake driver: every family on, every feature enabled, the limits of a
// typical desktop GPU. It holds BLAS a (built by the tests), b (a copy destination), c (on a buffer that can also
// serve as scratch: the aliasing case), ha/hb (on host-visible memory, for host commands), a vertex buffer, a scratch
// buffer, an indirect buffer, and command buffers 0, 1 and 3 (primary), 2 and 5 (secondary), 4 (never allocated).
class FakeDevice {
 public:
  explicit FakeDevice(ReportSettings settings, VkBool32 answer = VK_FALSE) {
    g_calls = Calls{};
    collected.answer = answer;
    auto instance = std::make_unique<InstanceData>();
    instance->settings.enabled_checks = kAllFamilies;
    instance->settings.capture = kCaptureOff;
    instance->reporter = std::make_unique<Reporter>(settings);
    VkDebugUtilsMessengerCreateInfoEXT messenger{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    messenger.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT |
                                VK_DEBUG_UTILS_MESSAGE_SEVERITY_WARNING_BIT_EXT |
                                VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT;
    messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT | VK_DEBUG_UTILS_MESSAGE_TYPE_GENERAL_BIT_EXT;
    messenger.pfnUserCallback = &Collect;
    messenger.pUserData = &collected;
    instance->reporter->AddMessenger(Fake<VkDebugUtilsMessengerEXT>(1), messenger);
    instance_ = std::move(instance);

    auto data = std::make_unique<DeviceData>();
    data->device = device();
    data->instance = instance_.get();
    data->reporter = instance_->reporter.get();
    DeviceDispatchTable& d = data->dispatch;
    d.CmdBuildAccelerationStructuresKHR = &FakeCmdBuild;
    d.CmdBuildAccelerationStructuresIndirectKHR = &FakeCmdBuildIndirect;
    d.CmdCopyAccelerationStructureKHR = &FakeCmdCopy;
    d.CmdWriteAccelerationStructuresPropertiesKHR = &FakeCmdWriteProperties;
    d.CmdCopyAccelerationStructureToMemoryKHR = &FakeCmdCopyToMemory;
    d.CmdCopyMemoryToAccelerationStructureKHR = &FakeCmdCopyFromMemory;
    d.CmdExecuteCommands = &FakeExecuteCommands;
    d.BuildAccelerationStructuresKHR = &FakeHostBuild;
    d.CopyAccelerationStructureKHR = &FakeHostCopy;
    d.WriteAccelerationStructuresPropertiesKHR = &FakeHostWriteProperties;
    d.QueueSubmit = &FakeQueueSubmit;
    d.QueueSubmit2 = &FakeQueueSubmit2;
    d.BeginCommandBuffer = &FakeBegin;
    d.EndCommandBuffer = &FakeEnd;
    d.ResetCommandBuffer = &FakeReset;
    d.ResetCommandPool = &FakeResetPool;
    d.DestroyDevice = &FakeDestroyDevice;
    d.GetBufferDeviceAddress = &FakeBufferAddress;
    d.GetAccelerationStructureDeviceAddressKHR = &FakeStructureAddress;
    state_ = &data->state;
    dispatch_ = &data->dispatch;
    SetUpState(*state_);
    Devices().Insert(GetDispatchKey(device()), std::move(data));
  }
  ~FakeDevice() { Devices().Remove(GetDispatchKey(device())); }  // nothing left after DestroyDevice
  FakeDevice(const FakeDevice&) = delete;
  FakeDevice& operator=(const FakeDevice&) = delete;

  static VkDevice device() { return reinterpret_cast<VkDevice>(&g_device_object); }
  static VkQueue queue() { return reinterpret_cast<VkQueue>(&g_queue_object); }
  static VkCommandBuffer cb(int i) { return reinterpret_cast<VkCommandBuffer>(&g_cb_objects[i]); }

  void Begin(int i) {
    VkCommandBufferInheritanceInfo inheritance{VK_STRUCTURE_TYPE_COMMAND_BUFFER_INHERITANCE_INFO};
    VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    begin.pInheritanceInfo = &inheritance;
    REQUIRE(hooks::BeginCommandBuffer(cb(i), &begin) == VK_SUCCESS);
  }
  void End(int i) { REQUIRE(hooks::EndCommandBuffer(cb(i)) == VK_SUCCESS); }
  VkResult Submit(int i) {
    const VkCommandBuffer handle = cb(i);
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &handle;
    return hooks::QueueSubmit(queue(), 1, &submit, VK_NULL_HANDLE);
  }
  VkResult Submit2(int i) {
    VkCommandBufferSubmitInfo info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
    info.commandBuffer = cb(i);
    VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    submit.commandBufferInfoCount = 1;
    submit.pCommandBufferInfos = &info;
    return hooks::QueueSubmit2(queue(), 1, &submit, VK_NULL_HANDLE);
  }
  // The geometry count of as's last executed build, as the history keeps it; -1 when the history holds no build.
  int GeometriesOfLastBuild(VkAccelerationStructureKHR as) const {
    auto lock = state_->history.store.Lock();
    const AsHistory h = state_->history.store.Get(as);
    return h.kind == HistoryKind::kBuilt && h.build ? static_cast<int>(h.build->geometries.size()) : -1;
  }
  // Bumped by every executed change of as's contents.
  uint64_t Generation(VkAccelerationStructureKHR as) const {
    auto lock = state_->history.store.Lock();
    return state_->history.store.Get(as).generation;
  }
  std::shared_ptr<const WithheldCommand> Withheld(int i) const { return state_->command_buffers.Withheld(cb(i)); }
  const ProtectCounters& counters() const { return state_->protect_counters; }
  // An error judged at completion halts every later submission (withhold.h: HaltSubmissionsAfter).
  void Halt() { RecordSubmissionHalt(*state_, "vkCmdBuildAccelerationStructuresKHR", kHaltVuid, "pInfos[0]"); }
  static constexpr const char kHaltVuid[] = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03663";
  VkQueryPool QueryPool(VkQueryType type, uint32_t count) {
    VkQueryPoolCreateInfo info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    info.queryType = type;
    info.queryCount = count;
    const auto pool = Fake<VkQueryPool>(next_handle_++);
    RecordCreateQueryPool(*state_, info, pool);
    return pool;
  }

  // The ids of the errors delivered, in order; the notices of withheld calls.
  std::vector<std::string> Errors() const {
    std::vector<std::string> out;
    for (const Message& m : collected.messages) {
      if (m.severity == VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT) out.push_back(m.id);
    }
    return out;
  }
  std::vector<Message> Notices() const {
    std::vector<Message> out;
    for (const Message& m : collected.messages) {
      if (m.id == kNotice) out.push_back(m);
    }
    return out;
  }
  void Forget() { collected.messages.clear(); }

  VkDeviceAddress AddressOf(VkBuffer buffer) const { return reinterpret_cast<uint64_t>(buffer) * kAddressSpacing; }

  Collected collected;
  VkAccelerationStructureKHR a = VK_NULL_HANDLE, b = VK_NULL_HANDLE, c = VK_NULL_HANDLE;
  VkAccelerationStructureKHR ha = VK_NULL_HANDLE, hb = VK_NULL_HANDLE;
  VkBuffer vertices = VK_NULL_HANDLE, scratch = VK_NULL_HANDLE, indirect = VK_NULL_HANDLE, arena = VK_NULL_HANDLE;
  VkBuffer serialized = VK_NULL_HANDLE;  // room for serialized structures

 private:
  void SetUpState(DeviceState& state) {
    DeviceFeatures& f = state.features;
    f.acceleration_structure = f.acceleration_structure_host_commands = f.acceleration_structure_indirect_build = true;
    f.buffer_device_address = f.ray_query = true;
    VkPhysicalDeviceAccelerationStructurePropertiesKHR& limits = state.properties.acceleration_structure;
    limits.maxGeometryCount = (1u << 24) - 1;
    limits.maxInstanceCount = (1u << 24) - 1;
    limits.maxPrimitiveCount = (1u << 29) - 1;
    limits.minAccelerationStructureScratchOffsetAlignment = 128;
    VkPhysicalDeviceMemoryProperties& memory = state.properties.memory;
    memory.memoryHeapCount = 1;
    memory.memoryTypeCount = 2;
    memory.memoryTypes[0] = {VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT | VK_MEMORY_PROPERTY_HOST_COHERENT_BIT, 0};
    memory.memoryTypes[1] = {VK_MEMORY_PROPERTY_DEVICE_LOCAL_BIT, 0};
    state.build_sizes.Init(device(), &FakeBuildSizes);
    state.format_features.Init(Fake<VkPhysicalDevice>(2), &FakeFormatProperties);
    state.history_tracked = true;

    const VkBufferUsageFlags storage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR;
    a = Structure(Buffer(1 << 16, storage, 1), 4096);
    b = Structure(Buffer(1 << 16, storage, 1), 4096);
    arena = Buffer(1 << 20, storage | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 1);
    c = Structure(arena, 4096);
    ha = Structure(Buffer(1 << 16, storage, 0), 4096);
    hb = Structure(Buffer(1 << 16, storage, 0), 4096);
    vertices = Buffer(4096, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR, 1);
    scratch = Buffer(1 << 20, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 1);
    indirect = Buffer(4096, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, 1);
    serialized = Buffer(1 << 16, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                                     VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, 1);

    state.command_buffers.CreatePool(Fake<VkCommandPool>(3), 0);
    const VkCommandBuffer primaries[] = {cb(0), cb(1), cb(3)};
    state.command_buffers.Allocate(VkCommandBufferAllocateInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, nullptr,
                                                               Fake<VkCommandPool>(3), VK_COMMAND_BUFFER_LEVEL_PRIMARY,
                                                               3},
                                   primaries);
    const VkCommandBuffer secondaries[] = {cb(2), cb(5)};
    state.command_buffers.Allocate(VkCommandBufferAllocateInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, nullptr,
                                                               Fake<VkCommandPool>(3),
                                                               VK_COMMAND_BUFFER_LEVEL_SECONDARY, 2},
                                   secondaries);
  }

  // A buffer on memory of its own (memory type `type`), with SHADER_DEVICE_ADDRESS added to `usage`.
  VkBuffer Buffer(VkDeviceSize size, VkBufferUsageFlags usage, uint32_t type) {
    VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
    flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
    const VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags, size, type};
    const auto memory = Fake<VkDeviceMemory>(next_handle_++);
    RecordAllocateMemory(*state_, alloc, memory);
    VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    info.size = size;
    info.usage = usage | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
    const auto buffer = Fake<VkBuffer>(next_handle_++);
    RecordCreateBuffer(*state_, info, buffer);
    RecordBindBufferMemory(*state_, *dispatch_, device(), buffer, memory, 0);
    return buffer;
  }
  VkAccelerationStructureKHR Structure(VkBuffer buffer, VkDeviceSize size) {
    VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    info.buffer = buffer;
    info.size = size;
    info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    const auto as = Fake<VkAccelerationStructureKHR>(next_handle_++);
    RecordCreateAccelerationStructure(*state_, *dispatch_, device(), info, as);
    return as;
  }

  std::unique_ptr<InstanceData> instance_;
  DeviceState* state_ = nullptr;
  const DeviceDispatchTable* dispatch_ = nullptr;
  uint64_t next_handle_ = 0x100;
};

// ---- build calls ----------------------------------------------------------------------------------------------

// Host inputs: three vertices (one triangle) and room for any scratch the fake sizes ask.
const float kHostVertices[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
std::vector<uint8_t>& HostScratch() {
  static std::vector<uint8_t> bytes(1 << 16);
  return bytes;
}

// One build info over `geometries` one-triangle geometries, with its ranges and the indirect arrays, valid on
// FakeDevice as made: a BUILD (or an in-place UPDATE) of dst, updatable, inputs in the device's buffers (host
// pointers for a host build).
struct TriangleBuild {
  std::vector<VkAccelerationStructureGeometryKHR> geometries;
  std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges;
  std::vector<uint32_t> max_counts;
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  const VkAccelerationStructureBuildRangeInfoKHR* range_pointer = nullptr;
  const uint32_t* max_counts_pointer = nullptr;
  VkDeviceAddress indirect_address = 0;
  uint32_t indirect_stride = sizeof(VkAccelerationStructureBuildRangeInfoKHR);

  TriangleBuild(const FakeDevice& d, VkAccelerationStructureKHR dst, uint32_t count, bool update, bool host = false)
      : geometries(count), ranges(count, VkAccelerationStructureBuildRangeInfoKHR{1, 0, 0, 0}), max_counts(count, 1) {
    for (VkAccelerationStructureGeometryKHR& g : geometries) {
      g = VkAccelerationStructureGeometryKHR{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
      g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
      auto& t = g.geometry.triangles;
      t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
      t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
      t.vertexStride = 12;
      t.maxVertex = 2;
      t.indexType = VK_INDEX_TYPE_NONE_KHR;
      if (host) {
        t.vertexData.hostAddress = kHostVertices;
      } else {
        t.vertexData.deviceAddress = d.AddressOf(d.vertices);
      }
    }
    info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    info.flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;
    info.mode = update ? VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR : VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    info.srcAccelerationStructure = update ? dst : VK_NULL_HANDLE;
    info.dstAccelerationStructure = dst;
    info.geometryCount = count;
    info.pGeometries = geometries.data();
    if (host) {
      info.scratchData.hostAddress = HostScratch().data();
    } else {
      info.scratchData.deviceAddress = d.AddressOf(d.scratch);
    }
    range_pointer = ranges.data();
    max_counts_pointer = max_counts.data();
    indirect_address = d.AddressOf(d.indirect);
  }
  TriangleBuild(const TriangleBuild&) = delete;
  TriangleBuild& operator=(const TriangleBuild&) = delete;

  void Record(VkCommandBuffer cb) const { hooks::CmdBuildAccelerationStructuresKHR(cb, 1, &info, &range_pointer); }
  void RecordIndirect(VkCommandBuffer cb) const {
    hooks::CmdBuildAccelerationStructuresIndirectKHR(cb, 1, &info, &indirect_address, &indirect_stride,
                                                     &max_counts_pointer);
  }
  VkResult RunOnHost() const {
    return hooks::BuildAccelerationStructuresKHR(FakeDevice::device(), VK_NULL_HANDLE, 1, &info, &range_pointer);
  }
};

// Records into command buffer i a build of a whose destination is no structure (dstAccelerationStructure-03800).
void RecordInvalidBuild(FakeDevice& d, int i) {
  TriangleBuild build(d, d.a, 1, false);
  build.info.dstAccelerationStructure = Fake<VkAccelerationStructureKHR>(0xdead);
  build.Record(FakeDevice::cb(i));
}
const char kInvalidBuildVuid[] = "VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03800";

// ---- record-time cases ------------------------------------------------------------------------------------------

// One recorded command, invalid or made valid, and what must (not) reach the driver.
struct RecordCase {
  const char* family;
  std::string vuid;      // the error the invalid call is reported with
  const char* function;  // the command withheld
  int Calls::*counter;   // its count at the fake driver
  // Records the call into command buffer 0 (begun and ended around it); `valid`: the valid twin.
  std::function<void(FakeDevice&, bool valid)> record;
};

std::vector<RecordCase> RecordCases() {
  std::vector<RecordCase> cases;
  cases.push_back({"features", "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-mode-04628",
                   "vkCmdBuildAccelerationStructuresIndirectKHR", &Calls::cmd_build_indirect,
                   [](FakeDevice& d, bool valid) {
                     TriangleBuild build(d, d.a, 1, false);
                     if (!valid) build.info.mode = static_cast<VkBuildAccelerationStructureModeKHR>(5);
                     build.RecordIndirect(FakeDevice::cb(0));
                   }});
  cases.push_back({"handles", "VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03800",
                   "vkCmdBuildAccelerationStructuresKHR", &Calls::cmd_build, [](FakeDevice& d, bool valid) {
                     TriangleBuild build(d, d.a, 1, false);
                     if (!valid) build.info.dstAccelerationStructure = Fake<VkAccelerationStructureKHR>(0xdead);
                     build.Record(FakeDevice::cb(0));
                   }});
  cases.push_back({"structure", "VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03654",
                   "vkCmdBuildAccelerationStructuresKHR", &Calls::cmd_build, [](FakeDevice& d, bool valid) {
                     TriangleBuild build(d, d.a, 1, false);
                     if (!valid) build.info.type = VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR;
                     build.Record(FakeDevice::cb(0));
                   }});
  cases.push_back({"alignment", "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710",
                   "vkCmdBuildAccelerationStructuresKHR", &Calls::cmd_build, [](FakeDevice& d, bool valid) {
                     TriangleBuild build(d, d.a, 1, false);
                     if (!valid) build.info.scratchData.deviceAddress += 64;  // the limit is 128; the buffer has room
                     build.Record(FakeDevice::cb(0));
                   }});
  cases.push_back({"addresses", "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03802",
                   "vkCmdBuildAccelerationStructuresKHR", &Calls::cmd_build, [](FakeDevice& d, bool valid) {
                     TriangleBuild build(d, d.a, 1, false);
                     if (!valid) build.info.scratchData.deviceAddress = 0x7700000000ull;  // aligned, in no buffer
                     build.Record(FakeDevice::cb(0));
                   }});
  cases.push_back({"aliasing", "VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03703",
                   "vkCmdBuildAccelerationStructuresKHR", &Calls::cmd_build, [](FakeDevice& d, bool valid) {
                     // c occupies the arena's first 4096 bytes; the scratch is the arena's, past c or over it.
                     TriangleBuild build(d, d.c, 1, false);
                     build.info.scratchData.deviceAddress = d.AddressOf(d.arena) + (valid ? 65536 : 0);
                     build.Record(FakeDevice::cb(0));
                   }});
  cases.push_back({"copies", "VUID-VkCopyAccelerationStructureInfoKHR-mode-03410", "vkCmdCopyAccelerationStructureKHR",
                   &Calls::cmd_copy, [](FakeDevice& d, bool valid) {
                     TriangleBuild(d, d.a, 1, false).Record(FakeDevice::cb(0));  // the source, built before it
                     VkCopyAccelerationStructureInfoKHR copy{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR};
                     copy.src = d.a;
                     copy.dst = d.b;
                     copy.mode = valid ? VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR
                                       : VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR;
                     hooks::CmdCopyAccelerationStructureKHR(FakeDevice::cb(0), &copy);
                   }});
  cases.push_back({"copies (to memory)", "VUID-VkCopyAccelerationStructureToMemoryInfoKHR-mode-03412",
                   "vkCmdCopyAccelerationStructureToMemoryKHR", &Calls::cmd_copy_to_memory,
                   [](FakeDevice& d, bool valid) {
                     TriangleBuild(d, d.a, 1, false).Record(FakeDevice::cb(0));
                     VkCopyAccelerationStructureToMemoryInfoKHR copy{
                         VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_TO_MEMORY_INFO_KHR};
                     copy.src = d.a;
                     copy.dst.deviceAddress = d.AddressOf(d.serialized);
                     copy.mode = valid ? VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR
                                       : VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR;
                     hooks::CmdCopyAccelerationStructureToMemoryKHR(FakeDevice::cb(0), &copy);
                   }});
  cases.push_back({"copies (from memory)", "VUID-VkCopyMemoryToAccelerationStructureInfoKHR-mode-03413",
                   "vkCmdCopyMemoryToAccelerationStructureKHR", &Calls::cmd_copy_from_memory,
                   [](FakeDevice& d, bool valid) {
                     VkCopyMemoryToAccelerationStructureInfoKHR copy{
                         VK_STRUCTURE_TYPE_COPY_MEMORY_TO_ACCELERATION_STRUCTURE_INFO_KHR};
                     copy.src.deviceAddress = d.AddressOf(d.serialized);
                     copy.dst = d.b;
                     copy.mode = valid ? VK_COPY_ACCELERATION_STRUCTURE_MODE_DESERIALIZE_KHR
                                       : VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR;
                     hooks::CmdCopyMemoryToAccelerationStructureKHR(FakeDevice::cb(0), &copy);
                   }});
  cases.push_back({"copies (properties)", "VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-query-04880",
                   "vkCmdWriteAccelerationStructuresPropertiesKHR", &Calls::cmd_write_properties,
                   [](FakeDevice& d, bool valid) {
                     TriangleBuild(d, d.a, 1, false).Record(FakeDevice::cb(0));
                     const VkQueryPool pool = d.QueryPool(VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SIZE_KHR, 1);
                     // One query in the pool: firstQuery 1 is past it.
                     hooks::CmdWriteAccelerationStructuresPropertiesKHR(
                         FakeDevice::cb(0), 1, &d.a, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SIZE_KHR, pool, valid ? 0 : 1);
                   }});
  return cases;
}

TEST_CASE("protect: a record-time error of each family keeps the command and its command buffer from the driver",
          "[protect]") {
  for (const RecordCase& c : RecordCases()) {
    DYNAMIC_SECTION("family " << c.family << ", " << c.function) {
      FakeDevice d(Protect());
      d.Begin(0);
      c.record(d, false);
      d.End(0);
      CHECK(g_calls.*c.counter == 0);
      CHECK(d.Errors() == std::vector<std::string>{c.vuid});
      const std::vector<Message> notices = d.Notices();
      REQUIRE(notices.size() == 1);
      CHECK(notices[0].severity == VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT);
      CHECK(notices[0].text.find(c.function) != std::string::npos);
      CHECK(notices[0].text.find(c.vuid) != std::string::npos);  // names the finding
      const std::shared_ptr<const WithheldCommand> mark = d.Withheld(0);
      REQUIRE(mark);
      CHECK(mark->function == c.function);
      CHECK(mark->vuid == c.vuid);
      CHECK(d.counters().commands_withheld.load() == 1);

      d.Forget();
      CHECK(d.Submit(0) == VK_ERROR_VALIDATION_FAILED_EXT);
      CHECK(g_calls.queue_submit == 0);
      CHECK(d.Errors().empty());
      const std::vector<Message> submit_notices = d.Notices();
      REQUIRE(submit_notices.size() == 1);
      CHECK(submit_notices[0].text.find("pSubmits[0].pCommandBuffers[0]") != std::string::npos);
      CHECK(submit_notices[0].text.find(c.vuid) != std::string::npos);
      CHECK(d.counters().submissions_withheld.load() == 1);
    }
    DYNAMIC_SECTION("family " << c.family << ", " << c.function << ": the valid twin") {
      FakeDevice d(Protect());
      d.Begin(0);
      c.record(d, true);
      d.End(0);
      CHECK(g_calls.*c.counter == 1);
      CHECK_FALSE(d.Withheld(0));
      CHECK(d.Submit(0) == VK_SUCCESS);
      CHECK(g_calls.queue_submit == 1);
      CHECK(d.Errors().empty());
      CHECK(d.Notices().empty());
      CHECK(d.counters().commands_withheld.load() == 0);
      CHECK(d.counters().submissions_withheld.load() == 0);
    }
  }
}

// Host commands: the error's VUID, the command that must not run, and the call itself.
struct HostCase {
  const char* family;
  std::string vuid;
  const char* function;
  int Calls::*counter;
  int prior_calls;  // calls of the same kind made valid before it (the source's build)
  std::function<VkResult(FakeDevice&, bool valid)> call;
};

std::vector<HostCase> HostCases() {
  std::vector<HostCase> cases;
  cases.push_back({"host", "VUID-vkBuildAccelerationStructuresKHR-pInfos-03725", "vkBuildAccelerationStructuresKHR",
                   &Calls::host_build, 0, [](FakeDevice& d, bool valid) {
                     TriangleBuild build(d, d.ha, 1, false, true);
                     if (!valid) build.info.scratchData.hostAddress = nullptr;  // it needs 144 bytes
                     return build.RunOnHost();
                   }});
  cases.push_back({"history (host)", "VUID-vkBuildAccelerationStructuresKHR-pInfos-03758",
                   "vkBuildAccelerationStructuresKHR", &Calls::host_build, 1, [](FakeDevice& d, bool valid) {
                     REQUIRE(TriangleBuild(d, d.ha, 1, false, true).RunOnHost() == VK_SUCCESS);
                     // An update of ha, built with one geometry: with two it contradicts that build.
                     return TriangleBuild(d, d.ha, valid ? 1 : 2, true, true).RunOnHost();
                   }});
  cases.push_back({"copies (host)", "VUID-VkCopyAccelerationStructureInfoKHR-mode-03410", "vkCopyAccelerationStructureKHR",
                   &Calls::host_copy, 0, [](FakeDevice& d, bool valid) {
                     REQUIRE(TriangleBuild(d, d.ha, 1, false, true).RunOnHost() == VK_SUCCESS);
                     VkCopyAccelerationStructureInfoKHR copy{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR};
                     copy.src = d.ha;
                     copy.dst = d.hb;
                     copy.mode = valid ? VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR
                                       : VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR;
                     return hooks::CopyAccelerationStructureKHR(FakeDevice::device(), VK_NULL_HANDLE, &copy);
                   }});
  cases.push_back({"copies (host properties)", "VUID-vkWriteAccelerationStructuresPropertiesKHR-queryType-06742",
                   "vkWriteAccelerationStructuresPropertiesKHR", &Calls::host_write_properties, 0,
                   [](FakeDevice& d, bool valid) {
                     REQUIRE(TriangleBuild(d, d.ha, 1, false, true).RunOnHost() == VK_SUCCESS);
                     VkDeviceSize size = 0;
                     return hooks::WriteAccelerationStructuresPropertiesKHR(
                         FakeDevice::device(), 1, &d.ha,
                         valid ? VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SIZE_KHR : VK_QUERY_TYPE_OCCLUSION, sizeof(size),
                         &size, sizeof(size));
                   }});
  return cases;
}

TEST_CASE("protect: a host command with an error returns VK_ERROR_VALIDATION_FAILED_EXT without running", "[protect]") {
  for (const HostCase& c : HostCases()) {
    DYNAMIC_SECTION("family " << c.family << ", " << c.function) {
      FakeDevice d(Protect());
      CHECK(c.call(d, false) == VK_ERROR_VALIDATION_FAILED_EXT);
      CHECK(g_calls.*c.counter == c.prior_calls);
      CHECK(d.Errors() == std::vector<std::string>{c.vuid});
      const std::vector<Message> notices = d.Notices();
      REQUIRE(notices.size() == 1);
      CHECK(notices[0].text.find(c.function) != std::string::npos);
      CHECK(notices[0].text.find(c.vuid) != std::string::npos);
      CHECK(d.counters().host_commands_withheld.load() == 1);
    }
    DYNAMIC_SECTION("family " << c.family << ", " << c.function << ": the valid twin") {
      FakeDevice d(Protect());
      CHECK(c.call(d, true) == VK_SUCCESS);
      CHECK(g_calls.*c.counter == c.prior_calls + 1);
      CHECK(d.Errors().empty());
      CHECK(d.Notices().empty());
      CHECK(d.counters().host_commands_withheld.load() == 0);
    }
  }
}

TEST_CASE("protect: a withheld host update leaves the structure's history as it was", "[protect]") {
  FakeDevice d(Protect());
  REQUIRE(TriangleBuild(d, d.ha, 1, false, true).RunOnHost() == VK_SUCCESS);
  const uint64_t generation = d.Generation(d.ha);
  REQUIRE(generation != 0);
  CHECK(TriangleBuild(d, d.ha, 2, true, true).RunOnHost() == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(d.Generation(d.ha) == generation);
  CHECK(d.GeometriesOfLastBuild(d.ha) == 1);
  CHECK(TriangleBuild(d, d.ha, 1, true, true).RunOnHost() == VK_SUCCESS);
  CHECK(g_calls.host_build == 2);
  CHECK(d.Errors() == std::vector<std::string>{"VUID-vkBuildAccelerationStructuresKHR-pInfos-03758"});
}

// ---- submit-time cases ------------------------------------------------------------------------------------------

// Command buffer 0: a build of a with one geometry, submitted. Command buffer 1: a rebuild of a with two
// geometries, then an update of a with one: each valid when recorded, the update invalid in execution order.
void RecordRebuildThenUpdate(FakeDevice& d) {
  d.Begin(0);
  TriangleBuild(d, d.a, 1, false).Record(FakeDevice::cb(0));
  d.End(0);
  REQUIRE(d.Submit(0) == VK_SUCCESS);
  d.Begin(1);
  TriangleBuild(d, d.a, 2, false).Record(FakeDevice::cb(1));
  TriangleBuild(d, d.a, 1, true).Record(FakeDevice::cb(1));
  d.End(1);
  REQUIRE(d.Errors().empty());
  REQUIRE(g_calls.cmd_build == 3);
}

// An update of a with one geometry in command buffer 3: valid only if a's last executed build had one geometry.
void RecordUpdateOfOneGeometry(FakeDevice& d) {
  d.Begin(3);
  TriangleBuild(d, d.a, 1, true).Record(FakeDevice::cb(3));
  d.End(3);
}

TEST_CASE("protect: a submission with an error in execution order is withheld and its history undone", "[protect]") {
  const std::string vuid = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758";
  FakeDevice d(Protect());
  RecordRebuildThenUpdate(d);
  const uint64_t generation = d.Generation(d.a);
  CHECK(d.Submit(1) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(d.Generation(d.a) == generation);
  CHECK(g_calls.queue_submit == 1);  // the first submission only
  CHECK(d.Errors() == std::vector<std::string>{vuid});
  const std::vector<Message> notices = d.Notices();
  REQUIRE(notices.size() == 1);
  CHECK(notices[0].text.find("vkQueueSubmit") != std::string::npos);
  CHECK(notices[0].text.find(vuid) != std::string::npos);
  CHECK(d.counters().submissions_withheld.load() == 1);
  CHECK(d.counters().commands_withheld.load() == 0);
  CHECK_FALSE(d.Withheld(1));  // a submit-time finding marks nothing
  CHECK(d.GeometriesOfLastBuild(d.a) == 1);

  // Judged as if the rebuild had never executed: an update with two geometries contradicts the first build...
  d.Forget();
  d.Begin(3);
  TriangleBuild(d, d.a, 2, true).Record(FakeDevice::cb(3));
  d.End(3);
  CHECK(d.Submit(3) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(d.Errors() == std::vector<std::string>{vuid});
  CHECK(g_calls.queue_submit == 1);
  // ...and one with one geometry is valid.
  d.Forget();
  RecordUpdateOfOneGeometry(d);
  CHECK(d.Submit(3) == VK_SUCCESS);
  CHECK(g_calls.queue_submit == 2);
  CHECK(d.Errors().empty());
  CHECK(d.Notices().empty());
}

TEST_CASE("protect: vkQueueSubmit2 withholds a submission with an error in execution order", "[protect]") {
  const std::string vuid = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758";
  FakeDevice d(Protect());
  RecordRebuildThenUpdate(d);
  const uint64_t generation = d.Generation(d.a);
  CHECK(d.Submit2(1) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(d.Generation(d.a) == generation);
  CHECK(g_calls.queue_submit2 == 0);
  CHECK(d.Errors() == std::vector<std::string>{vuid});
  const std::vector<Message> notices = d.Notices();
  REQUIRE(notices.size() == 1);
  CHECK(notices[0].text.find("vkQueueSubmit2") != std::string::npos);
  CHECK(d.counters().submissions_withheld.load() == 1);
  d.Forget();
  RecordUpdateOfOneGeometry(d);
  CHECK(d.Submit2(3) == VK_SUCCESS);
  CHECK(g_calls.queue_submit2 == 1);
  CHECK(d.Errors().empty());
}

TEST_CASE("protect: past the duplicate limit a submit-time error still withholds its submission", "[protect]") {
  const std::string vuid = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758";
  ReportSettings settings = Protect();
  settings.duplicate_message_limit = 1;
  FakeDevice d(settings);
  RecordRebuildThenUpdate(d);
  CHECK(d.Submit(1) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(d.Submit(1) == VK_ERROR_VALIDATION_FAILED_EXT);  // the same error again: not reported, still withheld
  CHECK(g_calls.queue_submit == 1);
  CHECK(d.Errors() == std::vector<std::string>{vuid});
  CHECK(d.Notices().size() == 2);
  CHECK(d.counters().submissions_withheld.load() == 2);
}

TEST_CASE("protect off: a submit-time error is reported and the submission goes down, its history kept",
          "[protect]") {
  const std::string vuid = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758";
  FakeDevice d(ReportSettings{});
  RecordRebuildThenUpdate(d);
  const uint64_t generation = d.Generation(d.a);
  CHECK(d.Submit(1) == VK_SUCCESS);
  CHECK(g_calls.queue_submit == 2);
  CHECK(d.Errors() == std::vector<std::string>{vuid});
  CHECK(d.Notices().empty());
  CHECK(d.Generation(d.a) > generation);  // what executed is in the history (protect mode undoes it)
}

TEST_CASE("protect: a submission with a marked command buffer after a clean one applies nothing of either",
          "[protect]") {
  FakeDevice d(Protect());
  d.Begin(0);
  TriangleBuild(d, d.a, 1, false).Record(FakeDevice::cb(0));
  d.End(0);
  REQUIRE(d.Submit(0) == VK_SUCCESS);
  d.Begin(1);
  TriangleBuild(d, d.a, 2, false).Record(FakeDevice::cb(1));  // valid: a rebuild with two geometries
  d.End(1);
  d.Begin(0);
  RecordInvalidBuild(d, 0);
  d.End(0);
  d.Forget();
  const VkCommandBuffer both[] = {FakeDevice::cb(1), FakeDevice::cb(0)};
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.commandBufferCount = 2;
  submit.pCommandBuffers = both;
  const uint64_t generation = d.Generation(d.a);
  CHECK(hooks::QueueSubmit(FakeDevice::queue(), 1, &submit, VK_NULL_HANDLE) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(d.Generation(d.a) == generation);
  CHECK(d.GeometriesOfLastBuild(d.a) == 1);
  CHECK(g_calls.queue_submit == 1);
  const std::vector<Message> notices = d.Notices();
  REQUIRE(notices.size() == 1);
  CHECK(notices[0].text.find("pSubmits[0].pCommandBuffers[1]") != std::string::npos);
  // The rebuild in command buffer 1 never executed: an update with one geometry is valid.
  d.Forget();
  RecordUpdateOfOneGeometry(d);
  CHECK(d.Submit(3) == VK_SUCCESS);
  CHECK(g_calls.queue_submit == 2);
  CHECK(d.Errors().empty());
}

TEST_CASE("protect: vkQueueSubmit2 withholds a marked command buffer", "[protect]") {
  FakeDevice d(Protect());
  d.Begin(0);
  TriangleBuild build(d, d.a, 1, false);
  build.info.type = VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR;
  build.Record(FakeDevice::cb(0));
  d.End(0);
  d.Forget();
  CHECK(d.Submit2(0) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(g_calls.queue_submit2 == 0);
  const std::vector<Message> notices = d.Notices();
  REQUIRE(notices.size() == 1);
  CHECK(notices[0].text.find("pSubmits[0].pCommandBufferInfos[0].commandBuffer") != std::string::npos);
}

TEST_CASE("protect: a property query of a structure built without compaction is withheld at submission",
          "[protect]") {
  const std::string vuid = "VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-accelerationStructures-03431";
  for (const bool valid : {false, true}) {
    INFO((valid ? "valid twin" : "invalid"));
    FakeDevice d(Protect());
    // a is built without ALLOW_COMPACTION, b with it; both submitted.
    d.Begin(0);
    TriangleBuild(d, d.a, 1, false).Record(FakeDevice::cb(0));
    TriangleBuild compactable(d, d.b, 1, false);
    compactable.info.flags |= VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR;
    compactable.Record(FakeDevice::cb(0));
    d.End(0);
    REQUIRE(d.Submit(0) == VK_SUCCESS);
    const VkQueryPool pool = d.QueryPool(VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, 1);
    const VkAccelerationStructureKHR queried = valid ? d.b : d.a;
    d.Begin(1);
    hooks::CmdWriteAccelerationStructuresPropertiesKHR(FakeDevice::cb(1), 1, &queried,
                                                       VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, pool, 0);
    d.End(1);
    CHECK(g_calls.cmd_write_properties == 1);  // valid when recorded
    if (valid) {
      CHECK(d.Submit(1) == VK_SUCCESS);
      CHECK(g_calls.queue_submit == 2);
      CHECK(d.Errors().empty());
      CHECK(d.Notices().empty());
    } else {
      CHECK(d.Submit(1) == VK_ERROR_VALIDATION_FAILED_EXT);
      CHECK(g_calls.queue_submit == 1);
      CHECK(d.Errors() == std::vector<std::string>{vuid});
      const std::vector<Message> notices = d.Notices();
      REQUIRE(notices.size() == 1);
      CHECK(notices[0].text.find(vuid) != std::string::npos);
      CHECK(d.counters().submissions_withheld.load() == 1);
    }
  }
}

// ---- marks: secondaries, reset --------------------------------------------------------------------------------

TEST_CASE("protect: a withheld command in a secondary withholds the primary that executes it", "[protect]") {
  FakeDevice d(Protect());
  d.Begin(2);
  RecordInvalidBuild(d, 2);
  d.End(2);
  CHECK(g_calls.cmd_build == 0);
  CHECK(d.Withheld(2));
  d.Begin(0);
  CHECK_FALSE(d.Withheld(0));
  const VkCommandBuffer secondary = FakeDevice::cb(2);
  hooks::CmdExecuteCommands(FakeDevice::cb(0), 1, &secondary);
  d.End(0);
  CHECK(g_calls.execute_commands == 1);  // vkCmdExecuteCommands itself is valid: it goes down
  const std::shared_ptr<const WithheldCommand> mark = d.Withheld(0);
  REQUIRE(mark);
  CHECK(mark->vuid == kInvalidBuildVuid);
  d.Forget();
  CHECK(d.Submit(0) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(g_calls.queue_submit == 0);
  const std::vector<Message> notices = d.Notices();
  REQUIRE(notices.size() == 1);
  CHECK(notices[0].text.find(kInvalidBuildVuid) != std::string::npos);
  CHECK(d.counters().commands_withheld.load() == 1);
  CHECK(d.counters().submissions_withheld.load() == 1);
}

// Command buffer 0, marked and its submission withheld, then `reset` and recorded again with a valid build: the
// submission goes down.
void ExpectMarkClearedBy(const std::function<void(FakeDevice&)>& reset) {
  FakeDevice d(Protect());
  d.Begin(0);
  RecordInvalidBuild(d, 0);
  d.End(0);
  REQUIRE(d.Withheld(0));
  CHECK(d.Submit(0) == VK_ERROR_VALIDATION_FAILED_EXT);
  reset(d);
  CHECK_FALSE(d.Withheld(0));
  TriangleBuild(d, d.a, 1, false).Record(FakeDevice::cb(0));
  d.End(0);
  CHECK(g_calls.cmd_build == 1);
  d.Forget();
  CHECK(d.Submit(0) == VK_SUCCESS);
  CHECK(g_calls.queue_submit == 1);
  CHECK(d.Errors().empty());
  CHECK(d.Notices().empty());
}

TEST_CASE("protect: the mark passes through nested secondaries (VK_EXT_nested_command_buffer)", "[protect]") {
  FakeDevice d(Protect());
  d.Begin(5);
  RecordInvalidBuild(d, 5);
  d.End(5);
  const VkCommandBuffer inner = FakeDevice::cb(5), outer = FakeDevice::cb(2);
  d.Begin(2);
  hooks::CmdExecuteCommands(outer, 1, &inner);
  d.End(2);
  d.Begin(0);
  hooks::CmdExecuteCommands(FakeDevice::cb(0), 1, &outer);
  d.End(0);
  REQUIRE(d.Withheld(0));
  CHECK(d.Withheld(0)->vuid == kInvalidBuildVuid);
  CHECK(d.Submit(0) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(g_calls.queue_submit == 0);
}

TEST_CASE("protect: vkResetCommandBuffer clears the mark", "[protect]") {
  ExpectMarkClearedBy([](FakeDevice& d) {
    REQUIRE(hooks::ResetCommandBuffer(FakeDevice::cb(0), 0) == VK_SUCCESS);
    CHECK_FALSE(d.Withheld(0));  // before it is begun again
    d.Begin(0);
  });
}

TEST_CASE("protect: vkBeginCommandBuffer (an implicit reset) clears the mark", "[protect]") {
  ExpectMarkClearedBy([](FakeDevice& d) { d.Begin(0); });
}

TEST_CASE("protect: vkResetCommandPool clears the marks of its command buffers", "[protect]") {
  ExpectMarkClearedBy([](FakeDevice& d) {
    REQUIRE(hooks::ResetCommandPool(FakeDevice::device(), Fake<VkCommandPool>(3), 0) == VK_SUCCESS);
    CHECK_FALSE(d.Withheld(0));
    d.Begin(0);
  });
}

TEST_CASE("protect: a command withheld from a command buffer the layer never saw allocated is named as such",
          "[protect]") {
  FakeDevice d(Protect());
  REQUIRE(hooks::BeginCommandBuffer(FakeDevice::cb(4), nullptr) == VK_SUCCESS);
  RecordInvalidBuild(d, 4);
  CHECK(g_calls.cmd_build == 0);
  CHECK(d.Errors() == std::vector<std::string>{kInvalidBuildVuid});
  const std::vector<Message> notices = d.Notices();
  REQUIRE(notices.size() == 1);
  CHECK(notices[0].text.find("never saw this command buffer allocated") != std::string::npos);
  CHECK(d.counters().commands_withheld.load() == 1);
  CHECK_FALSE(d.Withheld(4));
}

TEST_CASE("protect: a callback that records a valid command from inside a report: only the invalid one is withheld",
          "[protect]") {
  FakeDevice d(Protect());
  d.Begin(1);
  d.collected.on_first_error = [&d] { TriangleBuild(d, d.a, 1, false).Record(FakeDevice::cb(1)); };
  d.Begin(0);
  RecordInvalidBuild(d, 0);
  d.End(0);
  d.End(1);
  CHECK(g_calls.cmd_build == 1);  // the valid one, recorded from the callback
  CHECK(d.Withheld(0));
  CHECK_FALSE(d.Withheld(1));
  CHECK(d.Notices().size() == 1);
  CHECK(d.Submit(1) == VK_SUCCESS);
  CHECK(d.Submit(0) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(g_calls.queue_submit == 1);
}

TEST_CASE("protect: a callback that records an invalid command from inside a report: both are withheld",
          "[protect]") {
  FakeDevice d(Protect());
  d.Begin(1);
  d.collected.on_first_error = [&d] { RecordInvalidBuild(d, 1); };
  d.Begin(0);
  RecordInvalidBuild(d, 0);
  d.End(0);
  d.End(1);
  CHECK(g_calls.cmd_build == 0);
  CHECK(d.Withheld(0));
  CHECK(d.Withheld(1));
  CHECK(d.Notices().size() == 2);
  CHECK(d.counters().commands_withheld.load() == 2);
}

// ---- protect off, the app's callback, the reporter's filters ----------------------------------------------------

TEST_CASE("protect off (the default): the error is reported and the command reaches the driver", "[protect]") {
  CHECK_FALSE(ReportSettings{}.protect);
  FakeDevice d(ReportSettings{});
  d.Begin(0);
  RecordInvalidBuild(d, 0);
  d.End(0);
  CHECK(g_calls.cmd_build == 1);
  CHECK(d.Errors() == std::vector<std::string>{kInvalidBuildVuid});
  CHECK_FALSE(d.Withheld(0));
  CHECK(d.Submit(0) == VK_SUCCESS);
  CHECK(g_calls.queue_submit == 1);
  CHECK(d.Notices().empty());
  CHECK(d.counters().commands_withheld.load() == 0);
}

TEST_CASE("protect off: a callback returning VK_TRUE skips the command without marking its command buffer",
          "[protect]") {
  FakeDevice d(Protect(false), VK_TRUE);
  d.Begin(0);
  RecordInvalidBuild(d, 0);
  d.End(0);
  CHECK(g_calls.cmd_build == 0);
  CHECK(d.Errors() == std::vector<std::string>{kInvalidBuildVuid});
  CHECK_FALSE(d.Withheld(0));
  CHECK(d.Submit(0) == VK_SUCCESS);
  CHECK(g_calls.queue_submit == 1);
  CHECK(d.Notices().empty());
  CHECK(d.counters().commands_withheld.load() == 0);
}

TEST_CASE("protect: past the duplicate limit an error is still withheld, and each withheld call has its notice",
          "[protect]") {
  ReportSettings settings = Protect();
  settings.duplicate_message_limit = 1;
  FakeDevice d(settings);
  d.Begin(0);
  RecordInvalidBuild(d, 0);
  RecordInvalidBuild(d, 0);
  d.End(0);
  CHECK(g_calls.cmd_build == 0);
  CHECK(d.Errors() == std::vector<std::string>{kInvalidBuildVuid});  // reported once
  CHECK(d.Notices().size() == 2);
  CHECK(d.counters().commands_withheld.load() == 2);
  d.Begin(1);
  RecordInvalidBuild(d, 1);  // a third, in another command buffer: marked too
  d.End(1);
  CHECK(g_calls.cmd_build == 0);
  CHECK(d.Notices().size() == 3);
  CHECK(d.Submit(1) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(g_calls.queue_submit == 0);
  CHECK(d.Notices().size() == 4);
}

TEST_CASE("protect: an error muted by message_id_filter is not withheld", "[protect]") {
  ReportSettings settings = Protect();
  settings.message_id_filter = {kInvalidBuildVuid};
  FakeDevice d(settings);
  d.Begin(0);
  RecordInvalidBuild(d, 0);
  d.End(0);
  CHECK(g_calls.cmd_build == 1);
  CHECK(d.Errors().empty());
  CHECK(d.Notices().empty());
  CHECK_FALSE(d.Withheld(0));
  CHECK(d.Submit(0) == VK_SUCCESS);
  CHECK(g_calls.queue_submit == 1);
}

TEST_CASE("protect: a callback returning VK_TRUE with protect on: withheld, marked and announced", "[protect]") {
  FakeDevice d(Protect(), VK_TRUE);
  d.Begin(0);
  RecordInvalidBuild(d, 0);
  d.End(0);
  CHECK(g_calls.cmd_build == 0);
  CHECK(d.Errors() == std::vector<std::string>{kInvalidBuildVuid});
  CHECK(d.Withheld(0));
  CHECK(d.Notices().size() == 1);
  CHECK(d.Submit(0) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(g_calls.queue_submit == 0);
}

TEST_CASE("protect: muting ASVAL-Protect-Withheld hides the notice, not the protection", "[protect]") {
  ReportSettings settings = Protect();
  settings.message_id_filter = {kNotice};
  FakeDevice d(settings);
  d.Begin(0);
  RecordInvalidBuild(d, 0);
  d.End(0);
  CHECK(g_calls.cmd_build == 0);
  CHECK(d.Errors() == std::vector<std::string>{kInvalidBuildVuid});
  CHECK(d.Notices().empty());
  CHECK(d.Withheld(0));
  CHECK(d.Submit(0) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(g_calls.queue_submit == 0);
  CHECK(d.counters().commands_withheld.load() == 1);
  CHECK(d.counters().submissions_withheld.load() == 1);
}

TEST_CASE("protect: with errors filtered out of report_flags nothing is withheld", "[protect]") {
  ReportSettings settings = Protect();
  settings.report_errors = false;
  FakeDevice d(settings);
  d.Begin(0);
  RecordInvalidBuild(d, 0);
  d.End(0);
  CHECK(g_calls.cmd_build == 1);
  CHECK(d.Errors().empty());
  CHECK(d.Notices().empty());
  CHECK_FALSE(d.Withheld(0));
  CHECK(d.Submit(0) == VK_SUCCESS);
  CHECK(g_calls.queue_submit == 1);
}

TEST_CASE("protect: the notice is delivered whether report_flags includes info or not", "[protect]") {
  for (const bool info : {false, true}) {
    INFO("report_info " << info);
    ReportSettings settings = Protect();
    settings.report_info = info;
    FakeDevice d(settings);
    d.Begin(0);
    RecordInvalidBuild(d, 0);
    d.End(0);
    CHECK(g_calls.cmd_build == 0);
    const std::vector<Message> notices = d.Notices();
    REQUIRE(notices.size() == 1);
    CHECK(notices[0].severity == VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT);
  }
}

// ---- counts: the summary at vkDestroyDevice, the JSON report ----------------------------------------------------

// Two recorded commands withheld (command buffers 0 and 1), one submission withheld (0), one host build withheld.
void WithholdTwoCommandsOneSubmissionOneHostBuild(FakeDevice& d) {
  d.Begin(0);
  RecordInvalidBuild(d, 0);
  d.End(0);
  d.Begin(1);
  RecordInvalidBuild(d, 1);
  d.End(1);
  REQUIRE(d.Submit(0) == VK_ERROR_VALIDATION_FAILED_EXT);
  TriangleBuild host(d, d.ha, 1, false, true);
  host.info.scratchData.hostAddress = nullptr;
  REQUIRE(host.RunOnHost() == VK_ERROR_VALIDATION_FAILED_EXT);
  REQUIRE(g_calls.cmd_build + g_calls.host_build + g_calls.queue_submit == 0);
}

TEST_CASE("protect: ASVAL-History-Summary at vkDestroyDevice counts what was withheld", "[protect]") {
  FakeDevice d(Protect());
  WithholdTwoCommandsOneSubmissionOneHostBuild(d);
  CHECK(d.Notices().size() == 4);
  d.Forget();
  hooks::DestroyDevice(FakeDevice::device(), nullptr);
  std::vector<std::string> summaries;
  for (const Message& m : d.collected.messages) {
    if (m.id == "ASVAL-History-Summary" && m.text.find("Protect mode") != std::string::npos) summaries.push_back(m.text);
  }
  REQUIRE(summaries.size() == 1);
  CHECK(summaries[0].find("recorded_commands_withheld=2 submissions_withheld=1 host_commands_withheld=1") !=
        std::string::npos);
}

TEST_CASE("protect: no protect summary when nothing was withheld", "[protect]") {
  FakeDevice d(Protect());
  d.Begin(0);
  TriangleBuild(d, d.a, 1, false).Record(FakeDevice::cb(0));
  d.End(0);
  REQUIRE(d.Submit(0) == VK_SUCCESS);
  hooks::DestroyDevice(FakeDevice::device(), nullptr);
  for (const Message& m : d.collected.messages) CHECK(m.text.find("Protect mode") == std::string::npos);
}

TEST_CASE("protect: the JSON report has one ASVAL-Protect-Withheld line per withheld call", "[protect]") {
  asval_test_common::TempReport report;
  ReportSettings settings = Protect();
  settings.report_file = report.path;
  {
    FakeDevice d(settings);
    WithholdTwoCommandsOneSubmissionOneHostBuild(d);
    // Flushed as written: an app that dies now (a hang, a crash) leaves every line in the file.
    int notices_so_far = 0;
    for (const std::string& line : report.Lines()) {
      if (nlohmann::json::parse(line).value("vuid", "") == kNotice) ++notices_so_far;
    }
    CHECK(notices_so_far == 4);
    hooks::DestroyDevice(FakeDevice::device(), nullptr);
  }  // the reporter (and its file) closes with the instance
  int notices = 0, errors = 0, summaries = 0;
  std::vector<std::string> notice_functions;
  for (const std::string& line : report.Lines()) {
    INFO(asval_test_common::Printable(line));
    const nlohmann::json j = nlohmann::json::parse(line);
    const std::string vuid = j.value("vuid", "");
    if (vuid == kNotice) {
      ++notices;
      CHECK(j.value("severity", "") == "info");
      notice_functions.push_back(j.value("function", ""));
    }
    if (vuid == kInvalidBuildVuid || vuid == "VUID-vkBuildAccelerationStructuresKHR-pInfos-03725") ++errors;
    if (vuid == "ASVAL-History-Summary" &&
        j.value("message", "").find("recorded_commands_withheld=2 submissions_withheld=1 host_commands_withheld=1") !=
            std::string::npos) {
      ++summaries;
    }
  }
  CHECK(notices == 4);  // two recorded commands, one submission, one host build
  CHECK(notice_functions ==
        std::vector<std::string>{"vkCmdBuildAccelerationStructuresKHR", "vkCmdBuildAccelerationStructuresKHR",
                                 "vkQueueSubmit", "vkBuildAccelerationStructuresKHR"});
  CHECK(errors == 3);   // the errors themselves: two recorded, one host
  CHECK(summaries == 1);
}


// ---- a withheld submission still completes the app's synchronization -------------------------------------------

// The waits, signals and fence of one batch the tests submit: a binary wait (with its stage), a binary signal and a
// timeline signal of value 7 (its value in a chained VkTimelineSemaphoreSubmitInfo).
struct SynchronizedBatch {
  VkSemaphore waits[1] = {Fake<VkSemaphore>(0x51)};
  VkPipelineStageFlags stages[1] = {VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR};
  VkSemaphore signals[2] = {Fake<VkSemaphore>(0x52), Fake<VkSemaphore>(0x53)};
  uint64_t wait_values[1] = {0};
  uint64_t signal_values[2] = {0, 7};
  VkTimelineSemaphoreSubmitInfo timeline{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
  VkCommandBuffer cb;
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  VkFence fence = Fake<VkFence>(0x54);

  explicit SynchronizedBatch(int i) : cb(FakeDevice::cb(i)) {
    timeline.waitSemaphoreValueCount = 1;
    timeline.pWaitSemaphoreValues = wait_values;
    timeline.signalSemaphoreValueCount = 2;
    timeline.pSignalSemaphoreValues = signal_values;
    submit.pNext = &timeline;
    submit.waitSemaphoreCount = 1;
    submit.pWaitSemaphores = waits;
    submit.pWaitDstStageMask = stages;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cb;
    submit.signalSemaphoreCount = 2;
    submit.pSignalSemaphores = signals;
  }
  VkResult Submit() const { return hooks::QueueSubmit(FakeDevice::queue(), 1, &submit, fence); }
  // What reached the driver in its place: the same batch with no command buffer, and the same fence.
  void ExpectEmptiedTwin() const {
    REQUIRE(g_calls.emptied_submit == 1);
    REQUIRE(g_calls.emptied.size() == 1);
    const VkSubmitInfo& down = g_calls.emptied[0];
    CHECK(down.commandBufferCount == 0);
    CHECK(down.pCommandBuffers == nullptr);
    CHECK(down.waitSemaphoreCount == 1);
    CHECK(down.pWaitSemaphores == waits);
    CHECK(down.pWaitDstStageMask == stages);
    CHECK(down.signalSemaphoreCount == 2);
    CHECK(down.pSignalSemaphores == signals);
    CHECK(down.pNext == &timeline);  // the timeline values, as the app chained them
    CHECK(g_calls.emptied_fence == fence);
    CHECK(g_calls.queue_submit == 0);
  }
};

TEST_CASE("protect: a submission withheld for a marked command buffer goes down emptied, with its waits, signals "
          "and fence",
          "[protect][synchronization]") {
  FakeDevice d(Protect());
  d.Begin(0);
  RecordInvalidBuild(d, 0);
  d.End(0);
  d.Forget();
  const SynchronizedBatch batch(0);
  CHECK(batch.Submit() == VK_ERROR_VALIDATION_FAILED_EXT);
  batch.ExpectEmptiedTwin();
  CHECK(d.counters().submissions_withheld.load() == 1);
  const std::vector<Message> notices = d.Notices();
  REQUIRE(notices.size() == 1);
  CHECK(notices[0].text.find("its batches went down empty") != std::string::npos);
}

TEST_CASE("protect: a submission withheld for an error in execution order goes down emptied, its history undone",
          "[protect][synchronization]") {
  FakeDevice d(Protect());
  RecordRebuildThenUpdate(d);  // command buffer 1: an update that contradicts the first build
  const uint64_t generation = d.Generation(d.a);
  const SynchronizedBatch batch(1);
  CHECK(batch.Submit() == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(d.Generation(d.a) == generation);
  REQUIRE(g_calls.emptied_submit == 1);
  CHECK(g_calls.emptied[0].commandBufferCount == 0);
  CHECK(g_calls.emptied[0].pSignalSemaphores == batch.signals);
  CHECK(g_calls.emptied_fence == batch.fence);
  CHECK(g_calls.queue_submit == 1);  // RecordRebuildThenUpdate's first submission only
}

TEST_CASE("protect: after a halt every submission goes down emptied; with protect off a VK_TRUE skip passes nothing",
          "[protect][synchronization]") {
  SECTION("halted") {
    FakeDevice d(Protect());
    d.Begin(0);
    TriangleBuild(d, d.a, 1, false).Record(FakeDevice::cb(0));  // valid
    d.End(0);
    d.Halt();
    d.Forget();
    const SynchronizedBatch batch(0);
    CHECK(batch.Submit() == VK_ERROR_VALIDATION_FAILED_EXT);
    batch.ExpectEmptiedTwin();
    // A call with no batch at all still signals its fence.
    CHECK(hooks::QueueSubmit(FakeDevice::queue(), 0, nullptr, batch.fence) == VK_ERROR_VALIDATION_FAILED_EXT);
    CHECK(g_calls.queue_submit == 1);  // the empty call reached the driver as it was
    CHECK(d.counters().submissions_withheld.load() == 2);
  }
  SECTION("protect off, the app's callback skips the submission") {
    FakeDevice d(Protect(false), VK_TRUE);
    RecordRebuildThenUpdate(d);
    const SynchronizedBatch batch(1);
    CHECK(batch.Submit() == VK_ERROR_VALIDATION_FAILED_EXT);
    CHECK(g_calls.emptied_submit == 0);  // the app chose the skip, as with the Khronos layer
  }
}

TEST_CASE("protect: vkQueueSubmit2 withheld goes down emptied with its semaphore infos and fence",
          "[protect][synchronization]") {
  FakeDevice d(Protect());
  d.Begin(0);
  RecordInvalidBuild(d, 0);
  d.End(0);
  d.Forget();
  VkSemaphoreSubmitInfo wait{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
  wait.semaphore = Fake<VkSemaphore>(0x61);
  wait.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
  VkSemaphoreSubmitInfo signal{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
  signal.semaphore = Fake<VkSemaphore>(0x62);
  signal.value = 3;
  VkCommandBufferSubmitInfo cb_info{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
  cb_info.commandBuffer = FakeDevice::cb(0);
  VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  submit.waitSemaphoreInfoCount = 1;
  submit.pWaitSemaphoreInfos = &wait;
  submit.commandBufferInfoCount = 1;
  submit.pCommandBufferInfos = &cb_info;
  submit.signalSemaphoreInfoCount = 1;
  submit.pSignalSemaphoreInfos = &signal;
  const VkFence fence = Fake<VkFence>(0x63);
  CHECK(hooks::QueueSubmit2(FakeDevice::queue(), 1, &submit, fence) == VK_ERROR_VALIDATION_FAILED_EXT);
  REQUIRE(g_calls.emptied_submit2 == 1);
  const VkSubmitInfo2& down = g_calls.emptied2[0];
  CHECK(down.commandBufferInfoCount == 0);
  CHECK(down.waitSemaphoreInfoCount == 1);
  CHECK(down.pWaitSemaphoreInfos == &wait);
  CHECK(down.signalSemaphoreInfoCount == 1);
  CHECK(down.pSignalSemaphoreInfos == &signal);
  CHECK(g_calls.emptied_fence == fence);
  CHECK(g_calls.queue_submit2 == 0);
}

}  // namespace
}  // namespace asval
