// The layer's footprint (layer/state/footprint.h) over a hand-made DeviceState: every count is the number of
// objects the test itself made, peaks included (a container that shrank still says how large it was), and the
// ASVAL-Layer-Footprint message (layer/checks/footprint_report.h) carries them to the JSON report.
#include <catch2/catch_test_macros.hpp>

#include <array>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "device_state.h"
#include "footprint.h"
#include "footprint_report.h"
#include "reporter.h"
#include "state_tracker.h"
#include "temp_report.h"
#include "vk_dispatch_table.h"

namespace asval {
namespace {

template <typename H>
H Fake(uintptr_t v) {
  return reinterpret_cast<H>(v);
}

VKAPI_ATTR VkDeviceAddress VKAPI_CALL FakeBufferAddress(VkDevice, const VkBufferDeviceAddressInfo* info) {
  return reinterpret_cast<uintptr_t>(info->buffer) * 0x100000;
}

// Slabs of host memory: what capture logs take, as the capture pool would give them.
class HostSlabs : public CaptureSlabOwner {
 public:
  bool Take(VkDeviceSize bytes, CaptureSlab* slab) override {
    storage_.push_back(std::vector<uint8_t>(static_cast<std::size_t>(bytes)));
    slab->mapped = storage_.back().data();
    slab->size = bytes;
    ++taken;
    return true;
  }
  void Return(const CaptureSlab&) override { ++returned; }
  int taken = 0;
  int returned = 0;

 private:
  std::vector<std::vector<uint8_t>> storage_;
};

// Stand-ins for layer/capture's pool and tracker (ComputeFootprint asks each to add what it holds).
struct FakePool {
  void AddFootprint(CaptureFootprint* out) {
    out->slabs += 5;
    out->slabs_in_use += 2;
    out->slab_bytes += 5 * (VkDeviceSize{4} << 20);
    out->peak_slabs_in_use += 3;
  }
};
struct FakeTracker {
  void AddFootprint(CaptureFootprint* out) const {
    out->pending_submissions += 1;
    out->peak_pending_submissions += 4;
    out->spare_fences += 2;
  }
};

VkBufferCreateInfo BufferInfo(VkDeviceSize size) {
  VkBufferCreateInfo info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
  info.size = size;
  info.usage = VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT | VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR;
  return info;
}

// 2 memories, 3 buffers (2 bound with an address), 2 query pools, 3 command buffers of which 2 published a
// recording (3 and 1 operations; the first with a capture log of 2 slabs holding a 100-byte blob), 4 history
// records of which 1 forgotten, 2 serialized blobs, 3 query slots.
struct World {
  DeviceState state;
  DeviceDispatchTable dispatch{};
  const VkDevice device = Fake<VkDevice>(1);
  std::shared_ptr<HostSlabs> slabs = std::make_shared<HostSlabs>();
  std::array<VkCommandBuffer, 3> cbs{Fake<VkCommandBuffer>(41), Fake<VkCommandBuffer>(42), Fake<VkCommandBuffer>(43)};

  World() {
    dispatch.GetBufferDeviceAddress = &FakeBufferAddress;
    VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
    flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
    const VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags, 1 << 20, 0};
    RecordAllocateMemory(state, alloc, Fake<VkDeviceMemory>(100));
    RecordAllocateMemory(state, alloc, Fake<VkDeviceMemory>(101));
    for (uintptr_t b = 2; b <= 4; ++b) RecordCreateBuffer(state, BufferInfo(4096), Fake<VkBuffer>(b));
    RecordBindBufferMemory(state, dispatch, device, Fake<VkBuffer>(2), Fake<VkDeviceMemory>(100), 0);
    RecordBindBufferMemory(state, dispatch, device, Fake<VkBuffer>(3), Fake<VkDeviceMemory>(101), 0);

    VkQueryPoolCreateInfo query{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
    query.queryType = VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR;
    query.queryCount = 4;
    RecordCreateQueryPool(state, query, Fake<VkQueryPool>(60));
    RecordCreateQueryPool(state, query, Fake<VkQueryPool>(61));

    const VkCommandPool pool = Fake<VkCommandPool>(30);
    state.command_buffers.CreatePool(pool, 0);
    VkCommandBufferAllocateInfo allocate{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
    allocate.commandPool = pool;
    allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
    allocate.commandBufferCount = static_cast<uint32_t>(cbs.size());
    state.command_buffers.Allocate(allocate, cbs.data());
    Record(cbs[0], 3, /*capture_slabs=*/2);
    Record(cbs[1], 1, 0);  // cbs[2] never recorded

    HistoryStore& store = state.history.store;
    std::unique_lock<std::mutex> lock = store.Lock();
    for (uintptr_t as = 10; as <= 13; ++as) store.Set(Fake<VkAccelerationStructureKHR>(as), AsHistory{}, nullptr);
    store.Forget(Fake<VkAccelerationStructureKHR>(13));
    SerializedBlob blob;
    blob.host_address = &blob;
    store.AddBlob(blob, nullptr);
    store.AddBlob(blob, nullptr);
    for (uint32_t q = 0; q < 3; ++q) store.SetSlot(Fake<VkQueryPool>(60), q, QuerySlot{}, nullptr);
  }

  void Record(VkCommandBuffer cb, int operations, int capture_slabs) {
    std::shared_ptr<CommandBufferState> s = state.command_buffers.Find(cb);
    REQUIRE(s);
    s->Reset();
    for (int k = 0; k < operations; ++k) s->recording.Append(AsOp{});
    if (capture_slabs > 0) {
      CaptureLog& log = s->CaptureLogFor(slabs);
      CapturedBytes where;
      // Each reservation fills a slab of its own size, so the next one takes another.
      for (int k = 0; k < capture_slabs; ++k) REQUIRE(log.Reserve(256, &where));
      log.AddBlob(CapturedBytes{0, 0, 100, true});
    }
    s->Publish();
  }
};

TEST_CASE("footprint unit: the counts are the objects the state holds, with the peaks of what shrank",
          "[footprint]") {
  World w;
  const LayerFootprint f = ComputeStateFootprint(w.state);
  CHECK(f.memories == 2);
  CHECK(f.buffers == 3);
  CHECK(f.structures == 0);
  CHECK(f.address_ranges == 2);
  CHECK(f.host_mappings == 0);
  CHECK(f.command_buffers == 3);
  CHECK(f.recorded_operations == 4);
  // The log is held by the command buffer and by its published recording: counted once.
  CHECK(f.capture_logs == 1);
  CHECK(f.capture_log_slabs == 2);
  CHECK(w.slabs->taken == 2);
  CHECK(f.capture_log_bytes == 100);
  CHECK(f.history_records == 3);
  CHECK(f.history_record_slots == 4);  // the forgotten record's slot stays, for reuse
  CHECK(f.peak_history_records == 4);
  CHECK(f.serialized_blobs == 2);
  CHECK(f.peak_serialized_blobs == 2);
  CHECK(f.query_slots == 3);
  CHECK(f.peak_query_slots == 3);
  CHECK(f.query_pools == 2);
  CHECK(f.deferred_operations == 0);
  CHECK(f.capture.slabs == 0);  // the state's part only

  // A forgotten pool's slots and a freed command buffer leave; the peaks stay.
  {
    std::unique_lock<std::mutex> lock = w.state.history.store.Lock();
    w.state.history.store.ForgetPool(Fake<VkQueryPool>(60));
    w.state.history.store.Forget(Fake<VkAccelerationStructureKHR>(10));
  }
  w.state.command_buffers.Free(1, &w.cbs[1]);
  const LayerFootprint after = ComputeStateFootprint(w.state);
  CHECK(after.query_slots == 0);
  CHECK(after.peak_query_slots == 3);
  CHECK(after.history_records == 2);
  CHECK(after.peak_history_records == 4);
  CHECK(after.command_buffers == 2);
  CHECK(after.recorded_operations == 3);
}

// The long run's footprint showed a compacted-size pool's slots staying in the history store after the pool was
// destroyed (only serialization-size pools' were forgotten): one pool per frame would grow the store for good.
TEST_CASE("footprint unit: destroying a compacted-size query pool forgets its slots; an occlusion pool's none",
          "[footprint]") {
  World w;
  RecordDestroyQueryPool(w.state, Fake<VkQueryPool>(60));
  CHECK(ComputeStateFootprint(w.state).query_slots == 0);
  CHECK(ComputeStateFootprint(w.state).query_pools == 1);

  VkQueryPoolCreateInfo occlusion{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  occlusion.queryType = VK_QUERY_TYPE_OCCLUSION;
  occlusion.queryCount = 2;
  RecordCreateQueryPool(w.state, occlusion, Fake<VkQueryPool>(62));
  {
    // Not a pool the property command may write: a slot there (which the layer never makes) is left alone.
    std::unique_lock<std::mutex> lock = w.state.history.store.Lock();
    w.state.history.store.SetSlot(Fake<VkQueryPool>(62), 0, QuerySlot{}, nullptr);
  }
  RecordDestroyQueryPool(w.state, Fake<VkQueryPool>(62));
  CHECK(ComputeStateFootprint(w.state).query_slots == 1);
  CHECK(ComputeStateFootprint(w.state).peak_query_slots == 3);
}

TEST_CASE("footprint unit: the capture's pool and tracker add what they hold", "[footprint]") {
  World w;
  FakePool pool;
  FakeTracker tracker;
  const LayerFootprint f = ComputeFootprint(w.state, &pool, &tracker);
  CHECK(f.buffers == 3);
  CHECK(f.capture.slabs == 5);
  CHECK(f.capture.slabs_in_use == 2);
  CHECK(f.capture.slab_bytes == 5 * (uint64_t{4} << 20));
  CHECK(f.capture.peak_slabs_in_use == 3);
  CHECK(f.capture.pending_submissions == 1);
  CHECK(f.capture.peak_pending_submissions == 4);
  CHECK(f.capture.spare_fences == 2);
  const LayerFootprint off = ComputeFootprint(w.state, static_cast<FakePool*>(nullptr),
                                              static_cast<FakeTracker*>(nullptr));
  CHECK(off.capture.slabs == 0);
  CHECK(off.capture.pending_submissions == 0);
}

TEST_CASE("footprint unit: ASVAL-Layer-Footprint carries the counts to the JSON report as name=value pairs",
          "[footprint]") {
  asval_test_common::TempReport file;
  {
    ReportSettings settings;
    settings.report_file = file.path;
    settings.report_info = true;
    Reporter reporter(settings);
    World w;
    FakePool pool;
    ReportFootprint(ComputeFootprint(w.state, &pool, static_cast<FakeTracker*>(nullptr)), reporter, w.device);
  }
  const std::vector<std::string> lines = file.Lines();
  REQUIRE(lines.size() == 1);
  CHECK(lines[0].find("\"severity\":\"info\",\"vuid\":\"ASVAL-Layer-Footprint\"") != std::string::npos);
  CHECK(lines[0].find(" memories=2 buffers=3 structures=0 address_ranges=2 ") != std::string::npos);
  CHECK(lines[0].find(" recorded_operations=4 capture_logs=1 capture_log_slabs=2 capture_log_bytes=100 ") !=
        std::string::npos);
  CHECK(lines[0].find(" history_records=3 history_record_slots=4 ") != std::string::npos);
  CHECK(lines[0].find(" capture_slabs=5 capture_slabs_in_use=2 capture_slab_bytes=20971520 ") != std::string::npos);
  CHECK(lines[0].find(" peak_history_records=4 ") != std::string::npos);

  // Off unless information messages are asked for: a clean run's report stays empty.
  asval_test_common::TempReport quiet;
  {
    ReportSettings settings;
    settings.report_file = quiet.path;
    Reporter reporter(settings);
    World w;
    ReportFootprint(ComputeStateFootprint(w.state), reporter, w.device);
  }
  CHECK(quiet.Lines().empty());
}

}  // namespace
}  // namespace asval
