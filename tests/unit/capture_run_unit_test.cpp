// The capture point of a run of build commands (issue 27, capture_run.h, capture_run_end.h), over a fake next
// dispatch table that counts what the layer records: one pair of barriers per run whatever it holds (or, in a
// primary, the run's start event set, waited for and reset), the copies whose source went away left out and
// counted, and the reduce jobs' blocks that a run grows.
#include <catch2/catch_test_macros.hpp>

#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "capture_recording.h"
#include "capture_reduce_jobs.h"
#include "capture_run_end.h"
#include "record_checks_harness.h"

namespace asval::test {
namespace {

template <typename H>
H Fake(uintptr_t v) {
  return reinterpret_cast<H>(v);
}

// What the layer recorded through the fake next element of the chain; `order` names each command in turn
// (copy, barrier, set, wait, reset, with the event's and the stages' values where it has them).
struct Recorded {
  int barriers = 0, copies = 0, binds = 0, dispatches = 0;
  VkPipeline last_bound = VK_NULL_HANDLE;
  uint32_t dispatched_jobs = 0;
  std::vector<std::string> order;
};
Recorded recorded;

std::string Hex(uint64_t v) {
  char text[24];
  std::snprintf(text, sizeof(text), "%llx", static_cast<unsigned long long>(v));
  return text;
}

void VKAPI_CALL CountCopy(VkCommandBuffer, VkBuffer, VkBuffer, uint32_t, const VkBufferCopy*) {
  ++recorded.copies;
  recorded.order.push_back("copy");
}
void VKAPI_CALL CountBarrier(VkCommandBuffer, VkPipelineStageFlags src, VkPipelineStageFlags dst, VkDependencyFlags,
                             uint32_t, const VkMemoryBarrier*, uint32_t, const VkBufferMemoryBarrier*, uint32_t,
                             const VkImageMemoryBarrier*) {
  ++recorded.barriers;
  recorded.order.push_back("barrier " + Hex(src) + "->" + Hex(dst));
}
void VKAPI_CALL RecordSet(VkCommandBuffer, VkEvent event, VkPipelineStageFlags stages) {
  recorded.order.push_back("set " + Hex(reinterpret_cast<uint64_t>(event)) + " " + Hex(stages));
}
void VKAPI_CALL RecordWait(VkCommandBuffer, uint32_t count, const VkEvent* events, VkPipelineStageFlags src,
                           VkPipelineStageFlags dst, uint32_t, const VkMemoryBarrier*, uint32_t,
                           const VkBufferMemoryBarrier*, uint32_t, const VkImageMemoryBarrier*) {
  recorded.order.push_back("wait " + std::to_string(count) + " " + Hex(reinterpret_cast<uint64_t>(events[0])) + " " +
                           Hex(src) + "->" + Hex(dst));
}
void VKAPI_CALL RecordReset(VkCommandBuffer, VkEvent event, VkPipelineStageFlags stages) {
  recorded.order.push_back("reset " + Hex(reinterpret_cast<uint64_t>(event)) + " " + Hex(stages));
}
void VKAPI_CALL CountBind(VkCommandBuffer, VkPipelineBindPoint, VkPipeline pipeline) {
  ++recorded.binds;
  recorded.last_bound = pipeline;
}
void VKAPI_CALL CountDispatch(VkCommandBuffer, uint32_t, uint32_t, uint32_t, uint32_t, uint32_t jobs, uint32_t) {
  ++recorded.dispatches;
  recorded.dispatched_jobs += jobs;
}

// Host memory standing in for the pool's slabs, each in the reducer's table (so jobs may go there).
class TableSlabs : public CaptureSlabOwner {
 public:
  bool Take(VkDeviceSize bytes, CaptureSlab* slab) override {
    bytes = std::max<VkDeviceSize>(bytes, VkDeviceSize{1} << 20);
    storage_.push_back(std::make_unique<std::vector<uint8_t>>(static_cast<std::size_t>(bytes)));
    slab->mapped = storage_.back()->data();
    slab->buffer = Fake<VkBuffer>(1000 + storage_.size());
    slab->size = bytes;
    slab->table_index = static_cast<uint32_t>(storage_.size() - 1);
    slab->address = 0x100000000ull * storage_.size();
    return true;
  }
  void Return(const CaptureSlab&) override { ++slabs_returned; }
  int slabs_returned = 0;
  // Events 0xe1, 0xe2, ... (none once `events_left` is 0); those given back are counted.
  VkEvent TakeEvent() override {
    if (events_left == 0) return VK_NULL_HANDLE;
    --events_left;
    return Fake<VkEvent>(0xe0 + ++events_taken);
  }
  void ReturnEvent(VkEvent) override { ++events_returned; }
  int events_left = 8, events_taken = 0, events_returned = 0;

 private:
  std::vector<std::unique_ptr<std::vector<uint8_t>>> storage_;
};

struct Rig {
  RecordHarness h;
  DeviceDispatchTable next{};
  std::shared_ptr<CapturePool> pool;
  std::unique_ptr<MemoryAliases> aliases;
  CaptureCounters counters;
  CommandBufferState recording{VK_NULL_HANDLE, VK_COMMAND_BUFFER_LEVEL_PRIMARY, false};
  std::shared_ptr<TableSlabs> slabs = std::make_shared<TableSlabs>();

  Rig() {
    recorded = Recorded{};
    next.CmdCopyBuffer = CountCopy;
    next.CmdPipelineBarrier = CountBarrier;
    next.CmdBindPipeline = CountBind;
    next.CmdDispatchBase = CountDispatch;
    next.CmdSetEvent = RecordSet;
    next.CmdWaitEvents = RecordWait;
    next.CmdResetEvent = RecordReset;
    pool = std::make_shared<CapturePool>(VK_NULL_HANDLE, next, VkPhysicalDeviceMemoryProperties{});
    aliases = std::make_unique<MemoryAliases>(VK_NULL_HANDLE, next, std::vector<uint32_t>{}, VkDeviceSize{1} << 30);
  }
  CaptureContext Context() {
    return CaptureContext{h.state(), next, *pool, *aliases, kCaptureUpdates, VkDeviceSize{1} << 20, counters};
  }
  std::atomic<uint32_t>& open_runs() { return h.state().command_buffers.open_capture_runs(); }
  CaptureLog& log() { return recording.CaptureLogFor(slabs); }
};

CaptureCopy CopyFrom(VkBuffer src, uint32_t info) {
  CaptureCopy c;
  c.src = src;
  c.dst = Fake<VkBuffer>(0x900);
  c.region = VkBufferCopy{0, 0, 16};
  c.info = info;
  return c;
}

const VkCommandBuffer kCb = Fake<VkCommandBuffer>(0x20);

TEST_CASE("capture run unit: a run's copies and dispatches are recorded between one pair of barriers, once",
          "[unit][capture]") {
  Rig rig;
  CaptureRun& run = rig.recording.capture_run;
  for (uint32_t i = 0; i < 3; ++i) run.copies.push_back(CopyFrom(Fake<VkBuffer>(0x500 + i), UINT32_MAX));
  const VkPipeline layer_pipeline = Fake<VkPipeline>(0x77);
  run.dispatches.push_back(CaptureDispatch{layer_pipeline, 0, 64, 1});  // a block closed while the run grew
  run.block.ok = true;
  run.block.dispatch = CaptureDispatch{layer_pipeline, 64, 5, 2};  // the open one
  run.Open(rig.open_runs());
  run.Open(rig.open_runs());  // open already: counted once
  CHECK(rig.open_runs().load() == 1);
  rig.recording.compute_pipeline = Fake<VkPipeline>(0x55);  // the app's, bound again after the layer's

  RecordCaptureRun(rig.Context(), kCb, rig.recording);
  CHECK(recorded.barriers == 2);
  CHECK(recorded.copies == 3);
  CHECK(recorded.dispatches == 2);
  CHECK(recorded.dispatched_jobs == 64 + 5);
  CHECK(recorded.binds == 2);  // the layer's pipeline once, then the app's
  CHECK(recorded.last_bound == Fake<VkPipeline>(0x55));
  CHECK(rig.counters.capture_points.load() == 1);
  CHECK(rig.open_runs().load() == 0);
  CHECK_FALSE(run.IsOpen());
  CHECK(run.Empty());

  // Closed: the next command that ends a run records nothing.
  RecordCaptureRun(rig.Context(), kCb, rig.recording);
  CHECK(recorded.barriers == 2);
  CHECK(rig.counters.capture_points.load() == 1);
}

TEST_CASE("capture run unit: a command buffer begun again drops its open run, uncounted", "[unit][capture]") {
  Rig rig;
  CaptureRun& run = rig.recording.capture_run;
  run.copies.push_back(CopyFrom(Fake<VkBuffer>(0x500), UINT32_MAX));
  run.Open(rig.open_runs());
  rig.recording.Reset();
  CHECK(rig.open_runs().load() == 0);
  CHECK(run.Empty());
  RecordCaptureRun(rig.Context(), kCb, rig.recording);
  CHECK(recorded.barriers == 0);
}

TEST_CASE("capture run unit: copies whose source buffer was destroyed before the capture point are left out, their "
          "infos counted as not captured",
          "[unit][capture]") {
  Rig rig;
  CaptureLog& log = rig.log();
  CapturedGeometry g;
  const uint32_t info = log.AddInfo(CapturedInfo{}, &g, nullptr, 16) - 1;
  rig.counters.infos_captured = 1;
  CaptureRun& run = rig.recording.capture_run;
  // The app's dedicated buffer (memory null): unknown to the shadow state, so gone.
  run.copies.push_back(CopyFrom(Fake<VkBuffer>(0x501), info));
  run.copies.push_back(CopyFrom(Fake<VkBuffer>(0x502), info));  // the same info's second range: counted once
  run.aliases_epoch = rig.aliases->Epoch();
  run.Open(rig.open_runs());

  SECTION("no buffer destroyed since: the copies are recorded as planned (no lookup)") {
    RecordCaptureRun(rig.Context(), kCb, rig.recording);
    CHECK(recorded.copies == 2);
    CHECK(log.infos[info].complete);
    CHECK(rig.counters.NotCapturedFor(CaptureSkip::kUnknownAddress) == 0);
  }
  SECTION("a buffer destroyed since: the dead sources' copies are left out") {
    rig.aliases->BufferDestroyed();
    RecordCaptureRun(rig.Context(), kCb, rig.recording);
    CHECK(recorded.copies == 0);
    CHECK(recorded.barriers == 0);  // nothing left to record
    CHECK_FALSE(log.infos[info].complete);
    CHECK(rig.counters.infos_captured.load() == 0);
    CHECK(rig.counters.NotCapturedFor(CaptureSkip::kUnknownAddress) == 1);
    CHECK(rig.counters.capture_points.load() == 0);
  }
  CHECK(rig.open_runs().load() == 0);
}

TEST_CASE("capture run unit: a run's job block is taken larger than one command needs, so later commands share it",
          "[unit][capture]") {
  Rig rig;
  CaptureLog& log = rig.log();
  const VkPipeline pipeline = Fake<VkPipeline>(0x77);
  JobBlock block;
  REQUIRE(AcquireJobs(block, log, 3, 64, pipeline));
  CHECK(block.capacity == 64);
  CHECK(block.Room() == 64);
  for (int i = 0; i < 3; ++i) AddJob(block, ReduceJob{});
  CHECK(block.Room() == 61);
  CHECK(block.dispatch.jobs == 3);
  // Never more than one dispatch holds; the jobs asked for at least.
  REQUIRE(AcquireJobs(block, log, 10, kReduceMaxJobsPerDispatch * 2, pipeline));
  CHECK(block.capacity == kReduceMaxJobsPerDispatch);
  CHECK(block.dispatch.jobs == 0);
  REQUIRE(AcquireJobs(block, log, 100, 64, pipeline));
  CHECK(block.capacity == 100);
  // No pipeline, or more jobs than one dispatch holds: none (the captures are then copied).
  CHECK_FALSE(AcquireJobs(block, log, 3, 64, VK_NULL_HANDLE));
  CHECK_FALSE(block.ok);
  CHECK(block.Room() == 0);
  CHECK_FALSE(AcquireJobs(block, log, kReduceMaxJobsPerDispatch + 1, 64, pipeline));
}


// Issue 27 on a GPU: a capture point that waited for the run's builds (a barrier from ALL_COMMANDS) added its whole
// dispatch to the frame. In a primary the run's start event is set before its first build and the capture point
// waits for it, so the captures wait for what came before the run only (docs/capture.md).
TEST_CASE("capture run unit: a primary's run sets its start event before its first build; the capture point waits "
          "for it, then resets it after its barrier",
          "[unit][capture]") {
  Rig rig;
  CaptureRun& run = rig.recording.capture_run;
  rig.log();  // the recording's log, which takes the events
  const std::string all = Hex(VK_PIPELINE_STAGE_ALL_COMMANDS_BIT);
  const std::string transfer = Hex(VK_PIPELINE_STAGE_TRANSFER_BIT);
  const std::string after =
      Hex(VK_PIPELINE_STAGE_TRANSFER_BIT) + "->" + Hex(VK_PIPELINE_STAGE_HOST_BIT | VK_PIPELINE_STAGE_ALL_COMMANDS_BIT);

  SECTION("a primary: set when the run opens (once), waited for and reset at its capture point") {
    run.copies.push_back(CopyFrom(Fake<VkBuffer>(0x500), UINT32_MAX));
    recording::KeepOpen(rig.Context(), kCb, rig.recording, 0);
    run.copies.push_back(CopyFrom(Fake<VkBuffer>(0x501), UINT32_MAX));
    recording::KeepOpen(rig.Context(), kCb, rig.recording, 1);  // the run's second build: open already
    CHECK(recorded.order == std::vector<std::string>{"set e1 " + all});
    RecordCaptureRun(rig.Context(), kCb, rig.recording);
    CHECK(recorded.order == std::vector<std::string>{"set e1 " + all, "wait 1 e1 " + all + "->" + transfer, "copy",
                                                     "copy", "barrier " + after, "reset e1 " + all});
    CHECK(run.start_event == VK_NULL_HANDLE);
    // The next run takes an event of its own (the first is reset only once its wait has executed).
    recorded.order.clear();
    run.copies.push_back(CopyFrom(Fake<VkBuffer>(0x502), UINT32_MAX));
    recording::KeepOpen(rig.Context(), kCb, rig.recording, 0);
    CHECK(recorded.order == std::vector<std::string>{"set e2 " + all});
    RecordCaptureRun(rig.Context(), kCb, rig.recording);
    CHECK(recorded.order.back() == "reset e2 " + all);
    // Given back with the log, once no submission reads the recording.
    rig.recording.Reset();
    CHECK(rig.slabs->events_returned == 2);
  }
  SECTION("every copy left out: nothing is captured, and the event is still reset") {
    CaptureLog& log = rig.log();
    CapturedGeometry g;
    const uint32_t info = log.AddInfo(CapturedInfo{}, &g, nullptr, 16) - 1;
    run.copies.push_back(CopyFrom(Fake<VkBuffer>(0x501), info));  // a dedicated buffer unknown to the state: gone
    recording::KeepOpen(rig.Context(), kCb, rig.recording, 0);
    rig.aliases->BufferDestroyed();
    RecordCaptureRun(rig.Context(), kCb, rig.recording);
    CHECK(recorded.order == std::vector<std::string>{"set e1 " + all, "reset e1 " + all});
  }
  SECTION("no event to be had: the capture point waits with a barrier") {
    rig.slabs->events_left = 0;
    run.copies.push_back(CopyFrom(Fake<VkBuffer>(0x500), UINT32_MAX));
    recording::KeepOpen(rig.Context(), kCb, rig.recording, 0);
    RecordCaptureRun(rig.Context(), kCb, rig.recording);
    CHECK(recorded.order == std::vector<std::string>{"barrier " + all + "->" + transfer, "copy", "barrier " + after});
  }
}

TEST_CASE("capture run unit: a secondary, and a recording begun with SIMULTANEOUS_USE, wait with a barrier (no event)",
          "[unit][capture]") {
  Rig rig;
  const std::string all = Hex(VK_PIPELINE_STAGE_ALL_COMMANDS_BIT);
  const std::string transfer = Hex(VK_PIPELINE_STAGE_TRANSFER_BIT);
  const auto capture = [&](CommandBufferState& recording) {
    recording.CaptureLogFor(rig.slabs);
    recording.capture_run.copies.push_back(CopyFrom(Fake<VkBuffer>(0x500), UINT32_MAX));
    recording::KeepOpen(rig.Context(), kCb, recording, 0);
    RecordCaptureRun(rig.Context(), kCb, recording);
  };
  SECTION("a secondary (the Khronos layer 1.3.239 misreads a wait on an event set in the same secondary)") {
    CommandBufferState secondary{VK_NULL_HANDLE, VK_COMMAND_BUFFER_LEVEL_SECONDARY, false};
    capture(secondary);
  }
  SECTION("SIMULTANEOUS_USE: one execution's set could release another's wait") {
    rig.recording.simultaneous_use = true;
    capture(rig.recording);
  }
  CHECK(recorded.order.size() == 3);
  CHECK(recorded.order.front() == "barrier " + all + "->" + transfer);
  CHECK(rig.slabs->events_taken == 0);
}

TEST_CASE("capture run unit: a recording's log nobody else holds is emptied and reused by the next recording; one a "
          "submission still holds is not",
          "[unit][capture]") {
  Rig rig;
  CaptureLog& first = rig.log();
  CapturedBytes bytes;
  REQUIRE(first.Reserve(64, &bytes));
  CapturedGeometry g;
  first.AddInfo(CapturedInfo{}, &g, nullptr, 64);
  REQUIRE(first.TakeEvent() != VK_NULL_HANDLE);
  const CaptureLog* const first_address = &first;

  SECTION("nobody else holds it: emptied, its slab and event given back, the same log serves the next recording") {
    rig.recording.Reset();
    CHECK(rig.slabs->slabs_returned == 1);
    CHECK(rig.slabs->events_returned == 1);
    CaptureLog& next = rig.log();
    CHECK(&next == first_address);
    CHECK(next.infos.empty());
    CHECK(next.geometries.empty());
    CHECK(next.slabs.empty());
    CHECK(next.bytes_captured == 0);
    CHECK(next.infos.capacity() >= 1);  // the storage kept
  }
  SECTION("a submission holds it: left alone, the next recording gets a new log") {
    const std::shared_ptr<CaptureLog> held = rig.recording.capture_log;
    rig.recording.Reset();
    CHECK(rig.slabs->slabs_returned == 0);
    CHECK(held->infos.size() == 1);
    CHECK(&rig.log() != first_address);
  }
}

}  // namespace
}  // namespace asval::test
