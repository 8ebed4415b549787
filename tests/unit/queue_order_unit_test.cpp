// Execution order across queues (issue 25, item 8), through the hooks over a fake next element with two queues
// (lavapipe offers one queue, so the loader tests cannot show two; queue_order_test.cpp runs these on a device that
// has two and skips otherwise): a batch that waits for a timeline value signaled by a later submission on another
// queue is checked after it, the way the device runs them; and completion is processed per queue.
#include <catch2/catch_test_macros.hpp>

#include <atomic>
#include <string>
#include <thread>
#include <vector>

#include "capture_tracker.h"
#include "history_recorder.h"
#include "history_test_builds.h"
#include "layer_data.h"
#include "state_tracker.h"
#include "vk_intercepts.h"

namespace asval {
namespace {

struct FakeDispatchable {
  void* loader_table;
};
int g_table;  // its address is the dispatch key shared by the fake device, queues and command buffers
FakeDispatchable g_device_object{&g_table}, g_queue_objects[2] = {{&g_table}, {&g_table}},
    g_cb_objects[4] = {{&g_table}, {&g_table}, {&g_table}, {&g_table}};

std::atomic<int> g_submits{0};
uint64_t g_next_semaphore = 100;

VKAPI_ATTR VkResult VKAPI_CALL FakeQueueSubmit(VkQueue, uint32_t, const VkSubmitInfo*, VkFence) {
  ++g_submits;
  return VK_SUCCESS;
}
VKAPI_ATTR VkResult VKAPI_CALL FakeCreateSemaphore(VkDevice, const VkSemaphoreCreateInfo*,
                                                   const VkAllocationCallbacks*, VkSemaphore* out) {
  *out = reinterpret_cast<VkSemaphore>(++g_next_semaphore);
  return VK_SUCCESS;
}
VKAPI_ATTR VkResult VKAPI_CALL FakeSignalSemaphore(VkDevice, const VkSemaphoreSignalInfo*) { return VK_SUCCESS; }
VKAPI_ATTR void VKAPI_CALL FakeCmdBuild(VkCommandBuffer, uint32_t, const VkAccelerationStructureBuildGeometryInfoKHR*,
                                        const VkAccelerationStructureBuildRangeInfoKHR* const*) {}
VKAPI_ATTR VkResult VKAPI_CALL FakeEnd(VkCommandBuffer) { return VK_SUCCESS; }
VKAPI_ATTR VkResult VKAPI_CALL FakeBegin(VkCommandBuffer, const VkCommandBufferBeginInfo*) { return VK_SUCCESS; }

VKAPI_ATTR VkBool32 VKAPI_CALL Collect(VkDebugUtilsMessageSeverityFlagBitsEXT, VkDebugUtilsMessageTypeFlagsEXT,
                                       const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
  static_cast<std::vector<std::string>*>(user)->emplace_back(data->pMessageIdName);
  return VK_FALSE;
}

template <typename H>
H Fake(uintptr_t v) {
  return reinterpret_cast<H>(v);
}

constexpr const char* k03758 = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758";

test::Build TriangleBuild(VkAccelerationStructureKHR dst, uint32_t geometries, bool update) {
  return test::Build(dst, std::vector<uint32_t>(geometries, 1), VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR,
                     update ? dst : VK_NULL_HANDLE);
}

// One structure, four command buffers, two queues; history family only; errors collected.
class TwoQueues {
 public:
  TwoQueues() {
    auto instance = std::make_unique<InstanceData>();
    instance->settings.enabled_checks = kCheckHistory;
    instance->reporter = std::make_unique<Reporter>(ReportSettings{});
    VkDebugUtilsMessengerCreateInfoEXT messenger{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    messenger.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT;
    messenger.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
    messenger.pfnUserCallback = &Collect;
    messenger.pUserData = &vuids;
    instance->reporter->AddMessenger(Fake<VkDebugUtilsMessengerEXT>(1), messenger);
    instance_ = std::move(instance);
    auto data = std::make_unique<DeviceData>();
    data->device = device();
    data->instance = instance_.get();
    data->reporter = instance_->reporter.get();
    data->dispatch.QueueSubmit = &FakeQueueSubmit;
    data->dispatch.CreateSemaphore = &FakeCreateSemaphore;
    data->dispatch.SignalSemaphore = &FakeSignalSemaphore;
    data->dispatch.CmdBuildAccelerationStructuresKHR = &FakeCmdBuild;
    data->dispatch.BeginCommandBuffer = &FakeBegin;
    data->dispatch.EndCommandBuffer = &FakeEnd;
    data->state.history_tracked = true;
    state_ = &data->state;
    Devices().Insert(GetDispatchKey(device()), std::move(data));
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
    const VkCommandBuffer cbs[] = {cb(0), cb(1), cb(2), cb(3)};
    state_->command_buffers.Allocate(VkCommandBufferAllocateInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
                                                                 nullptr, Fake<VkCommandPool>(3),
                                                                 VK_COMMAND_BUFFER_LEVEL_PRIMARY, 4},
                                     cbs);
    g_submits = 0;
  }
  ~TwoQueues() { Devices().Remove(GetDispatchKey(device())); }

  static VkDevice device() { return reinterpret_cast<VkDevice>(&g_device_object); }
  static VkQueue queue(int q) { return reinterpret_cast<VkQueue>(&g_queue_objects[q]); }
  static VkCommandBuffer cb(int i) { return reinterpret_cast<VkCommandBuffer>(&g_cb_objects[i]); }
  static VkAccelerationStructureKHR structure() { return Fake<VkAccelerationStructureKHR>(10); }
  DeviceState& state() { return *state_; }

  // A build (or update) of the structure with `geometries` geometries, recorded into command buffer i.
  void Record(int i, uint32_t geometries, bool update) {
    const test::Build build = TriangleBuild(structure(), geometries, update);
    const VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
    REQUIRE(hooks::BeginCommandBuffer(cb(i), &begin) == VK_SUCCESS);
    hooks::CmdBuildAccelerationStructuresKHR(cb(i), 1, &build.info, &build.range_pointer);
    REQUIRE(hooks::EndCommandBuffer(cb(i)) == VK_SUCCESS);
  }
  VkSemaphore Timeline(bool exportable = false) {
    VkExportSemaphoreCreateInfo shared{VK_STRUCTURE_TYPE_EXPORT_SEMAPHORE_CREATE_INFO};
    shared.handleTypes = VK_EXTERNAL_SEMAPHORE_HANDLE_TYPE_OPAQUE_FD_BIT;
    VkSemaphoreTypeCreateInfo type{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO, exportable ? &shared : nullptr,
                                   VK_SEMAPHORE_TYPE_TIMELINE, 0};
    VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, &type};
    VkSemaphore semaphore = VK_NULL_HANDLE;
    REQUIRE(hooks::CreateSemaphore(device(), &info, nullptr, &semaphore) == VK_SUCCESS);
    return semaphore;
  }
  VkSemaphore Binary() {
    VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VkSemaphore semaphore = VK_NULL_HANDLE;
    REQUIRE(hooks::CreateSemaphore(device(), &info, nullptr, &semaphore) == VK_SUCCESS);
    return semaphore;
  }
  // Submits command buffer i on queue q, waiting for `wait` (at wait_value for a timeline) and signaling `signal`.
  VkResult Submit(int q, int i, VkSemaphore wait = VK_NULL_HANDLE, uint64_t wait_value = 0,
                  VkSemaphore signal = VK_NULL_HANDLE, uint64_t signal_value = 0) {
    const VkCommandBuffer handle = cb(i);
    const VkPipelineStageFlags stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
    VkTimelineSemaphoreSubmitInfo values{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
    values.waitSemaphoreValueCount = wait ? 1 : 0;
    values.pWaitSemaphoreValues = &wait_value;
    values.signalSemaphoreValueCount = signal ? 1 : 0;
    values.pSignalSemaphoreValues = &signal_value;
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO, &values};
    submit.waitSemaphoreCount = wait ? 1 : 0;
    submit.pWaitSemaphores = &wait;
    submit.pWaitDstStageMask = &stage;
    submit.signalSemaphoreCount = signal ? 1 : 0;
    submit.pSignalSemaphores = &signal;
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &handle;
    return hooks::QueueSubmit(queue(q), 1, &submit, VK_NULL_HANDLE);
  }
  VkResult HostSignal(VkSemaphore semaphore, uint64_t value) {
    const VkSemaphoreSignalInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_SIGNAL_INFO, nullptr, semaphore, value};
    return hooks::SignalSemaphore(device(), &info);
  }
  size_t GeometriesOfLastBuild() {
    auto lock = state_->history.store.Lock();
    const AsHistory h = state_->history.store.Get(structure());
    return h.kind == HistoryKind::kBuilt && h.build ? h.build->geometries.size() : 0;
  }

  std::vector<std::string> vuids;

 private:
  std::unique_ptr<InstanceData> instance_;
  DeviceState* state_ = nullptr;
};

TEST_CASE("order: an update waiting for a value another queue signals later is checked after that queue's build",
          "[order][history][hook]") {
  TwoQueues d;
  const VkSemaphore timeline = d.Timeline();
  d.Record(0, 1, false);
  REQUIRE(d.Submit(0, 0) == VK_SUCCESS);
  // Queue 0: an update repeating a two-geometry build, once timeline reaches 1.
  d.Record(1, 2, true);
  REQUIRE(d.Submit(0, 1, timeline, 1) == VK_SUCCESS);
  CHECK(d.vuids.empty());  // before the fix: 03758 here, against the one-geometry build the device runs before it
  CHECK(d.GeometriesOfLastBuild() == 1);  // not applied yet
  // Queue 1: the two-geometry build, which signals 1: the device runs it first.
  d.Record(2, 2, false);
  REQUIRE(d.Submit(1, 2, VK_NULL_HANDLE, 0, timeline, 1) == VK_SUCCESS);
  CHECK(d.vuids.empty());
  CHECK(d.GeometriesOfLastBuild() == 2);
  CHECK(g_submits == 3);
  CHECK(d.state().history.order.backlog() == 0);
  CHECK(d.state().history.order.counters.batches_deferred == 1);
}

TEST_CASE("order: an update that contradicts the build another queue runs before it is reported at that submission",
          "[order][history][hook]") {
  TwoQueues d;
  const VkSemaphore timeline = d.Timeline();
  d.Record(0, 2, false);
  REQUIRE(d.Submit(0, 0) == VK_SUCCESS);
  d.Record(1, 2, true);  // matches the build submitted so far, not the one that runs before it
  REQUIRE(d.Submit(0, 1, timeline, 1) == VK_SUCCESS);
  CHECK(d.vuids.empty());
  d.Record(2, 1, false);
  REQUIRE(d.Submit(1, 2, VK_NULL_HANDLE, 0, timeline, 1) == VK_SUCCESS);
  // Before the fix: nothing (the update was judged against the two-geometry build).
  CHECK(d.vuids == std::vector<std::string>{k03758});
  CHECK(g_submits == 3);  // the deferred batch had gone down; its finding cannot withhold it
}

TEST_CASE("order: later batches on the deferred batch's queue wait for it", "[order][history][hook]") {
  TwoQueues d;
  const VkSemaphore timeline = d.Timeline();
  d.Record(0, 1, false);
  REQUIRE(d.Submit(0, 0) == VK_SUCCESS);
  d.Record(1, 2, true);
  REQUIRE(d.Submit(0, 1, timeline, 1) == VK_SUCCESS);
  // Queue 0 again, no semaphore: runs after the update. A one-geometry rebuild.
  d.Record(3, 1, false);
  REQUIRE(d.Submit(0, 3) == VK_SUCCESS);
  CHECK(d.GeometriesOfLastBuild() == 1);
  CHECK(d.state().history.order.backlog() == 2);
  d.Record(2, 2, false);
  REQUIRE(d.Submit(1, 2, VK_NULL_HANDLE, 0, timeline, 1) == VK_SUCCESS);
  CHECK(d.vuids.empty());
  CHECK(d.GeometriesOfLastBuild() == 1);  // build(2) on queue 1, update(2), then the rebuild(1)
  CHECK(d.state().history.order.backlog() == 0);
}

TEST_CASE("order: a batch waiting on a binary semaphore a deferred batch signals is deferred with it",
          "[order][history][hook]") {
  TwoQueues d;
  const VkSemaphore timeline = d.Timeline();
  const VkSemaphore binary = d.Binary();
  d.Record(0, 1, false);
  REQUIRE(d.Submit(0, 0) == VK_SUCCESS);
  // Queue 0 waits for the host, then rebuilds with two geometries and signals the binary semaphore.
  d.Record(1, 2, false);
  REQUIRE(d.Submit(0, 1, timeline, 1, binary) == VK_SUCCESS);
  // Queue 1 waits for that binary semaphore, then updates with two geometries: valid once queue 0's build ran.
  d.Record(2, 2, true);
  REQUIRE(d.Submit(1, 2, binary) == VK_SUCCESS);
  CHECK(d.vuids.empty());  // before the fix: 03758 (judged against the one-geometry build)
  CHECK(d.state().history.order.backlog() == 2);
  REQUIRE(d.HostSignal(timeline, 1) == VK_SUCCESS);
  CHECK(d.vuids.empty());
  CHECK(d.GeometriesOfLastBuild() == 2);
  CHECK(d.state().history.order.backlog() == 0);
}

TEST_CASE("order: a host signal applies the waiting batch, and its finding is reported then",
          "[order][history][hook]") {
  TwoQueues d;
  const VkSemaphore timeline = d.Timeline();
  d.Record(0, 1, false);
  REQUIRE(d.Submit(0, 0) == VK_SUCCESS);
  d.Record(1, 2, true);  // contradicts the one-geometry build
  REQUIRE(d.Submit(0, 1, timeline, 5) == VK_SUCCESS);
  CHECK(d.vuids.empty());
  REQUIRE(d.HostSignal(timeline, 4) == VK_SUCCESS);  // not yet
  CHECK(d.vuids.empty());
  REQUIRE(d.HostSignal(timeline, 5) == VK_SUCCESS);
  CHECK(d.vuids == std::vector<std::string>{k03758});
}

TEST_CASE("order: a wait already met, or on a binary semaphore, is applied at once", "[order][history][hook]") {
  TwoQueues d;
  const VkSemaphore timeline = d.Timeline();
  const VkSemaphore binary = d.Binary();
  d.Record(0, 1, false);
  REQUIRE(d.Submit(0, 0, VK_NULL_HANDLE, 0, timeline, 3) == VK_SUCCESS);
  d.Record(1, 1, true);
  REQUIRE(d.Submit(1, 1, timeline, 2, binary) == VK_SUCCESS);  // 3 was signaled by an applied batch
  d.Record(2, 2, true);                                         // contradicts: reported at once
  REQUIRE(d.Submit(0, 2, binary) == VK_SUCCESS);
  CHECK(d.vuids == std::vector<std::string>{k03758});
  CHECK(d.state().history.order.counters.batches_deferred == 0);
}

TEST_CASE("order: a wait on an exportable semaphore for an unseen value is not ordered: unknown, skipped, counted",
          "[order][history][hook]") {
  TwoQueues d;
  const VkSemaphore shared = d.Timeline(true);
  d.Record(0, 1, false);
  REQUIRE(d.Submit(0, 0) == VK_SUCCESS);
  d.Record(1, 2, true);  // would contradict, but another process may signal first and run anything before it
  REQUIRE(d.Submit(0, 1, shared, 1) == VK_SUCCESS);
  d.Record(2, 2, true);
  REQUIRE(d.Submit(0, 2) == VK_SUCCESS);
  CHECK(d.vuids.empty());
  // Both updates met an unknown history: skipped and counted (before the fix: 03758 at the first).
  CHECK(d.state().history.store.rules_skipped_unknown_history.load() >= 1);
  CHECK(d.state().history.order.counters.batches_unordered == 1);
  CHECK(d.state().history.order.counters.operations_unordered == 1);
}

TEST_CASE("order: batches never signaled before the device goes are counted", "[order][history][hook]") {
  TwoQueues d;
  const VkSemaphore timeline = d.Timeline();
  d.Record(1, 2, true);
  REQUIRE(d.Submit(0, 1, timeline, 1) == VK_SUCCESS);
  {
    std::lock_guard<std::recursive_mutex> lock(d.state().history.submission_order);
    d.state().history.order.NeverResolved();
  }
  CHECK(d.state().history.order.counters.batches_never_resolved == 1);
  CHECK(d.state().history.order.backlog() == 0);
}

TEST_CASE("order: two threads, one queue's waits signaled by the other's submissions as they come",
          "[order][history][hook][threads]") {
  TwoQueues d;
  const VkSemaphore timeline = d.Timeline();
  d.Record(0, 1, false);
  REQUIRE(d.Submit(0, 0) == VK_SUCCESS);
  d.Record(1, 1, true);   // queue 0: an update, each waiting for the next value
  d.Record(2, 1, false);  // queue 1: a build, each signaling the next value
  constexpr uint64_t kRounds = 200;
  std::atomic<int> failed{0};  // Catch2's assertions are not thread-safe: counted here, checked after
  std::thread waiter([&] {
    for (uint64_t i = 1; i <= kRounds; ++i) failed += d.Submit(0, 1, timeline, i) != VK_SUCCESS;
  });
  std::thread signaler([&] {
    for (uint64_t i = 1; i <= kRounds; ++i) failed += d.Submit(1, 2, VK_NULL_HANDLE, 0, timeline, i) != VK_SUCCESS;
  });
  waiter.join();
  signaler.join();
  CHECK(failed == 0);
  CHECK(d.vuids.empty());
  CHECK(d.state().history.order.backlog() == 0);
  CHECK(g_submits == 1 + 2 * static_cast<int>(kRounds));
}

// Completion: one queue's pending submission no longer holds back another queue's completed one.
VkResult g_fence_status[4] = {VK_NOT_READY, VK_NOT_READY, VK_NOT_READY, VK_NOT_READY};
VKAPI_ATTR VkResult VKAPI_CALL FakeGetFenceStatus(VkDevice, VkFence fence) {
  return g_fence_status[reinterpret_cast<uintptr_t>(fence)];
}
VKAPI_ATTR VkResult VKAPI_CALL FakeResetFences(VkDevice, uint32_t, const VkFence*) { return VK_SUCCESS; }
VKAPI_ATTR void VKAPI_CALL FakeDestroyFence(VkDevice, VkFence, const VkAllocationCallbacks*) {}

TEST_CASE("order: completion is processed in submission order per queue", "[order][capture]") {
  DeviceDispatchTable next{};
  next.GetFenceStatus = &FakeGetFenceStatus;
  next.ResetFences = &FakeResetFences;
  next.DestroyFence = &FakeDestroyFence;
  const VkDevice device = TwoQueues::device();
  std::vector<int> processed;
  {
    CaptureTracker tracker(device, next);
    // Queue 0: the layer's fences 1, then 2; queue 1: the app's fence 3.
    for (VkResult& status : g_fence_status) status = VK_NOT_READY;
    SubmissionCaptures a, b, c;
    a.instance_checks.resize(1);  // a marker: how many instance checks says which submission was processed
    b.instance_checks.resize(2);
    c.instance_checks.resize(3);
    tracker.Track(TwoQueues::queue(0), VK_NULL_HANDLE, Fake<VkFence>(1), std::move(a));
    tracker.Track(TwoQueues::queue(0), VK_NULL_HANDLE, Fake<VkFence>(2), std::move(b));
    tracker.Track(TwoQueues::queue(1), Fake<VkFence>(3), VK_NULL_HANDLE, std::move(c));
    const auto record = [&](SubmissionCaptures& done) {
      processed.push_back(static_cast<int>(done.instance_checks.size()));
    };
    g_fence_status[3] = VK_SUCCESS;  // queue 1's work completed; queue 0's has not
    tracker.Process(CaptureTracker::Covered{}, record);
    CHECK(processed == std::vector<int>{3});  // before the fix: nothing (stopped at queue 0's first)
    g_fence_status[2] = VK_SUCCESS;           // queue 0's second reports done before its first: still in order
    tracker.Process(CaptureTracker::Covered{}, record);
    CHECK(processed == std::vector<int>{3});
    g_fence_status[1] = VK_SUCCESS;
    tracker.Process(CaptureTracker::Covered{}, record);
    CHECK(processed == std::vector<int>{3, 1, 2});
    CHECK(tracker.idle());
  }
}

}  // namespace
}  // namespace asval
