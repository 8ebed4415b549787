// The vkQueueSubmit hook over a fake next element (no driver): what reaches the driver, and what the history
// keeps, when the driver rejects a submission or the app's callback asks to skip one.
#include <catch2/catch_test_macros.hpp>

#include <string>
#include <vector>

#include "history_recorder.h"
#include "history_test_builds.h"
#include "layer_data.h"
#include "state_tracker.h"
#include "vk_intercepts.h"

namespace asval {
namespace {

// A dispatchable handle: its first word is the loader's dispatch table pointer, which the layer keys on.
struct FakeDispatchable {
  void* loader_table;
};
int g_table;  // its address is the dispatch key shared by the fake device, queue and command buffers
FakeDispatchable g_device_object{&g_table}, g_queue_object{&g_table}, g_cb_objects[2] = {{&g_table}, {&g_table}};

struct Driver {
  int submits = 0;
  VkResult result = VK_SUCCESS;
} g_driver;

VKAPI_ATTR VkResult VKAPI_CALL FakeQueueSubmit(VkQueue, uint32_t, const VkSubmitInfo*, VkFence) {
  ++g_driver.submits;
  return g_driver.result;
}
VKAPI_ATTR void VKAPI_CALL FakeCmdBuild(VkCommandBuffer, uint32_t, const VkAccelerationStructureBuildGeometryInfoKHR*,
                                        const VkAccelerationStructureBuildRangeInfoKHR* const*) {}
VKAPI_ATTR VkResult VKAPI_CALL FakeEnd(VkCommandBuffer) { return VK_SUCCESS; }
VKAPI_ATTR VkResult VKAPI_CALL FakeBegin(VkCommandBuffer, const VkCommandBufferBeginInfo*) { return VK_SUCCESS; }

struct Collected {
  std::vector<std::string> vuids;
  VkBool32 answer = VK_FALSE;  // what the app's callback returns
};
VKAPI_ATTR VkBool32 VKAPI_CALL Collect(VkDebugUtilsMessageSeverityFlagBitsEXT, VkDebugUtilsMessageTypeFlagsEXT,
                                       const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  auto* c = static_cast<Collected*>(user);
  c->vuids.emplace_back(data->pMessageIdName);
  return c->answer;
}

template <typename H>
H Fake(uintptr_t v) {
  return reinterpret_cast<H>(v);
}

// `geometries` one-triangle geometries; an update of dst by itself when `update`.
test::Build TriangleBuild(VkAccelerationStructureKHR dst, uint32_t geometries, bool update) {
  return test::Build(dst, std::vector<uint32_t>(geometries, 1), VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR,
                     update ? dst : VK_NULL_HANDLE);
}

// A device registered with the layer whose next element is the fake driver above; history family only.
class FakeDevice {
 public:
  FakeDevice() {
    auto instance = std::make_unique<InstanceData>();
    instance->settings.enabled_checks = kCheckHistory;
    instance->reporter = std::make_unique<Reporter>(ReportSettings{});
    VkDebugUtilsMessengerCreateInfoEXT messenger{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    messenger.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
    messenger.pfnUserCallback = &Collect;
    messenger.pUserData = &collected;
    instance->reporter->AddMessenger(Fake<VkDebugUtilsMessengerEXT>(1), messenger);
    instance_ = std::move(instance);
    auto data = std::make_unique<DeviceData>();
    data->device = device();
    data->instance = instance_.get();
    data->reporter = instance_->reporter.get();
    data->dispatch.QueueSubmit = &FakeQueueSubmit;
    data->dispatch.CmdBuildAccelerationStructuresKHR = &FakeCmdBuild;
    data->dispatch.BeginCommandBuffer = &FakeBegin;
    data->dispatch.EndCommandBuffer = &FakeEnd;
    data->state.history_tracked = true;
    state_ = &data->state;
    Devices().Insert(GetDispatchKey(device()), std::move(data));
    // One structure on a buffer of its own, and two command buffers.
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, nullptr, 1 << 20, 0};
    RecordAllocateMemory(*state_, alloc, Fake<VkDeviceMemory>(1));
    VkBufferCreateInfo buffer{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    buffer.size = 1 << 16;
    buffer.usage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR;
    RecordCreateBuffer(*state_, buffer, Fake<VkBuffer>(2));
    DeviceDispatchTable none{};
    RecordBindBufferMemory(*state_, none, device(), Fake<VkBuffer>(2), Fake<VkDeviceMemory>(1), 0);
    VkAccelerationStructureCreateInfoKHR create{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    create.buffer = Fake<VkBuffer>(2);
    create.size = 1 << 16;
    create.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    RecordCreateAccelerationStructure(*state_, none, device(), create, structure());
    state_->command_buffers.CreatePool(Fake<VkCommandPool>(3), 0);
    const VkCommandBuffer cbs[] = {cb(0), cb(1)};
    state_->command_buffers.Allocate(VkCommandBufferAllocateInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
                                                                 nullptr, Fake<VkCommandPool>(3),
                                                                 VK_COMMAND_BUFFER_LEVEL_PRIMARY, 2},
                                     cbs);
    g_driver = Driver{};
  }
  ~FakeDevice() { Devices().Remove(GetDispatchKey(device())); }

  static VkDevice device() { return reinterpret_cast<VkDevice>(&g_device_object); }
  static VkQueue queue() { return reinterpret_cast<VkQueue>(&g_queue_object); }
  static VkCommandBuffer cb(int i) { return reinterpret_cast<VkCommandBuffer>(&g_cb_objects[i]); }
  static VkAccelerationStructureKHR structure() { return Fake<VkAccelerationStructureKHR>(10); }

  // Records `build` into command buffer i through the hooks.
  void Record(int i, const test::Build& build) {
    const VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    REQUIRE(hooks::BeginCommandBuffer(cb(i), &begin) == VK_SUCCESS);
    hooks::CmdBuildAccelerationStructuresKHR(cb(i), 1, &build.info, &build.range_pointer);
    REQUIRE(hooks::EndCommandBuffer(cb(i)) == VK_SUCCESS);
  }
  VkResult Submit(int i) {
    const VkCommandBuffer handle = cb(i);
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &handle;
    return hooks::QueueSubmit(queue(), 1, &submit, VK_NULL_HANDLE);
  }
  size_t GeometriesOfLastBuild() {
    auto lock = state_->history.store.Lock();
    const AsHistory h = state_->history.store.Get(structure());
    return h.build ? h.build->geometries.size() : 0;
  }

  Collected collected;

 private:
  std::unique_ptr<InstanceData> instance_;
  DeviceState* state_ = nullptr;
};

TEST_CASE("submit hook: a submission the driver rejects leaves the history as if it had never been made",
          "[history][hook]") {
  FakeDevice d;
  d.Record(0, TriangleBuild(FakeDevice::structure(), 1, false));
  REQUIRE(d.Submit(0) == VK_SUCCESS);
  d.Record(1, TriangleBuild(FakeDevice::structure(), 2, false));
  g_driver.result = VK_ERROR_DEVICE_LOST;
  CHECK(d.Submit(1) == VK_ERROR_DEVICE_LOST);
  CHECK(g_driver.submits == 2);
  CHECK(d.GeometriesOfLastBuild() == 1);
  // An update that repeats the build that did execute is valid.
  g_driver.result = VK_SUCCESS;
  d.Record(1, TriangleBuild(FakeDevice::structure(), 1, true));
  CHECK(d.Submit(1) == VK_SUCCESS);
  CHECK(d.collected.vuids.empty());
  CHECK(g_driver.submits == 3);
}

TEST_CASE("submit hook: a submission the app's callback skips never reaches the driver and changes nothing",
          "[history][hook]") {
  FakeDevice d;
  d.Record(0, TriangleBuild(FakeDevice::structure(), 1, false));
  REQUIRE(d.Submit(0) == VK_SUCCESS);
  // A rebuild with two geometries, then an update with one: the update contradicts the rebuild before it.
  const test::Build rebuild = TriangleBuild(FakeDevice::structure(), 2, false);
  const test::Build update = TriangleBuild(FakeDevice::structure(), 1, true);
  const VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  REQUIRE(hooks::BeginCommandBuffer(FakeDevice::cb(1), &begin) == VK_SUCCESS);
  hooks::CmdBuildAccelerationStructuresKHR(FakeDevice::cb(1), 1, &rebuild.info, &rebuild.range_pointer);
  hooks::CmdBuildAccelerationStructuresKHR(FakeDevice::cb(1), 1, &update.info, &update.range_pointer);
  REQUIRE(hooks::EndCommandBuffer(FakeDevice::cb(1)) == VK_SUCCESS);
  d.collected.answer = VK_TRUE;
  CHECK(d.Submit(1) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(d.collected.vuids == std::vector<std::string>{"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758"});
  CHECK(g_driver.submits == 1);  // only the first submission reached the driver
  CHECK(d.GeometriesOfLastBuild() == 1);
}

}  // namespace
}  // namespace asval
