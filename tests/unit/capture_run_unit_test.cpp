// The capture point of a run of build commands (issue 27, capture_run.h, capture_run_end.h), over a fake next
// dispatch table that counts what the layer records: one pair of barriers per run whatever it holds, the copies
// whose source went away left out and counted, and the reduce jobs' blocks that a run grows.
#include <catch2/catch_test_macros.hpp>

#include <memory>
#include <vector>

#include "capture_reduce_jobs.h"
#include "capture_run_end.h"
#include "record_checks_harness.h"

namespace asval::test {
namespace {

template <typename H>
H Fake(uintptr_t v) {
  return reinterpret_cast<H>(v);
}

// What the layer recorded through the fake next element of the chain.
struct Recorded {
  int barriers = 0, copies = 0, binds = 0, dispatches = 0;
  VkPipeline last_bound = VK_NULL_HANDLE;
  uint32_t dispatched_jobs = 0;
};
Recorded recorded;

void VKAPI_CALL CountCopy(VkCommandBuffer, VkBuffer, VkBuffer, uint32_t, const VkBufferCopy*) { ++recorded.copies; }
void VKAPI_CALL CountBarrier(VkCommandBuffer, VkPipelineStageFlags, VkPipelineStageFlags, VkDependencyFlags, uint32_t,
                             const VkMemoryBarrier*, uint32_t, const VkBufferMemoryBarrier*, uint32_t,
                             const VkImageMemoryBarrier*) {
  ++recorded.barriers;
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
  void Return(const CaptureSlab&) override {}

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

}  // namespace
}  // namespace asval::test
