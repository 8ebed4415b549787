// A secondary executed twice by one recording of a primary (issue 25, item 5; docs/capture.md, "Executed more than
// once"), without a driver: the copy of a capture log (CaptureLog::EmptyCopy) and what vkCmdExecuteCommands' recorder
// asks of the layer's saver (RecordExecuteCommands with a CaptureSaver): the app's array passed down in parts, a copy
// per log read again, and the earlier executions' operations reading the copy. The device side (the copies recorded,
// each execution judged on its own bytes) is tested through the loader on lavapipe (capture_activity_test.cpp).
#include <catch2/catch_test_macros.hpp>

#include <algorithm>
#include <memory>
#include <vector>

#include "capture_log.h"
#include "device_state.h"
#include "history_recorder.h"
#include "history_test_builds.h"

namespace asval {
namespace {

template <typename H>
H Fake(uintptr_t v) {
  return reinterpret_cast<H>(v);
}

// Host memory standing in for the pool's slabs, of 256 bytes or what is asked when more; Take fails once
// `fail_after` slabs were taken (-1: never).
class HostSlabs : public CaptureSlabOwner {
 public:
  bool Take(VkDeviceSize bytes, CaptureSlab* slab) override {
    if (fail_after >= 0 && taken >= fail_after) return false;
    bytes = std::max<VkDeviceSize>(bytes, 256);
    storage_.push_back(std::make_unique<std::vector<uint8_t>>(static_cast<std::size_t>(bytes)));
    slab->mapped = storage_.back()->data();
    slab->buffer = Fake<VkBuffer>(1000 + storage_.size());
    slab->size = bytes;
    ++taken;
    return true;
  }
  void Return(const CaptureSlab&) override { ++returned; }
  int taken = 0;
  int returned = 0;
  int fail_after = -1;

 private:
  std::vector<std::unique_ptr<std::vector<uint8_t>>> storage_;
};

// What the recorder asked of the layer: the parts of the app's array passed down, and the copies recorded.
class RecordingSaver final : public CaptureSaver {
 public:
  void PassDown(uint32_t next) override { passed.push_back(next); }
  bool RecordCopy(const CaptureLog& from, const CaptureLog& to) override {
    copies.emplace_back(&from, &to);
    return records;
  }
  std::vector<uint32_t> passed;
  std::vector<std::pair<const CaptureLog*, const CaptureLog*>> copies;
  bool records = true;
};

TEST_CASE("capture saves unit: a log's empty copy has the same captures in slabs of its own", "[capture]") {
  auto slabs = std::make_shared<HostSlabs>();
  CaptureLog log(slabs);
  CapturedBytes a, b, c;
  REQUIRE(log.Reserve(100, &a));  // slab 0
  REQUIRE(log.Reserve(200, &b));  // slab 1: not in slab 0's 256 bytes after 112
  REQUIRE(log.Reserve(8, &c));    // slab 1, at 208
  CHECK(b.slab == 1);
  CHECK(c.slab == 1);
  CHECK(c.offset == 208);
  CapturedInfo info;
  info.geometry_count = 1;
  CapturedGeometry geometry;
  geometry.data = a;
  log.AddInfo(info, &geometry, nullptr, 100);
  log.AddBlob(c);
  std::shared_ptr<CaptureLog> copy = log.EmptyCopy();
  REQUIRE(copy);
  CHECK(slabs->taken == 4);
  REQUIRE(copy->slabs.size() == 2);
  CHECK(log.UsedBytes(0) == 100);
  CHECK(log.UsedBytes(1) == 216);
  for (uint32_t k = 0; k < 2; ++k) {
    CHECK(copy->UsedBytes(k) == log.UsedBytes(k));
    CHECK(copy->slabs[k].size >= log.UsedBytes(k));
    CHECK(copy->slabs[k].buffer != log.slabs[k].buffer);
  }
  REQUIRE(copy->infos.size() == 1);
  REQUIRE(copy->geometries.size() == 1);
  CHECK(copy->geometries[0].data.offset == a.offset);
  CHECK(copy->blobs.size() == 1);
  CHECK(copy->bytes_captured == log.bytes_captured);
  // The captured bytes are read from the copy's own slabs, at the same places.
  CHECK(copy->Bytes(copy->geometries[0].data) == copy->slabs[0].mapped + a.offset);
  copy.reset();
  CHECK(slabs->returned == 2);

  // A pool that cannot give every slab: no copy, and the slabs taken for it go back.
  slabs->fail_after = slabs->taken + 1;
  CHECK_FALSE(log.EmptyCopy());
  CHECK(slabs->returned == 3);
}

// A device whose secondary records one captured update of structure 10.
struct World {
  DeviceState state;
  std::shared_ptr<HostSlabs> slabs = std::make_shared<HostSlabs>();
  const VkCommandBuffer primary = Fake<VkCommandBuffer>(100);
  const VkCommandBuffer secondary = Fake<VkCommandBuffer>(101);
  const VkCommandBuffer other = Fake<VkCommandBuffer>(102);  // captures nothing
  CaptureLog* secondary_log = nullptr;

  World() {
    const VkCommandPool pool = Fake<VkCommandPool>(3);
    state.command_buffers.CreatePool(pool, 0);
    const VkCommandBuffer cbs[] = {primary, secondary, other};
    state.command_buffers.Allocate(VkCommandBufferAllocateInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO,
                                                               nullptr, pool, VK_COMMAND_BUFFER_LEVEL_PRIMARY, 3},
                                   cbs);
    const VkAccelerationStructureKHR as = Fake<VkAccelerationStructureKHR>(10);
    const test::Build update(as, {1}, VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR, as);
    std::shared_ptr<CommandBufferState> s = state.command_buffers.Find(secondary);
    state.command_buffers.Reset(secondary);
    CaptureLog& log = s->CaptureLogFor(slabs);
    CapturedInfo info;
    info.geometry_count = 1;
    CapturedGeometry geometry;
    REQUIRE(log.Reserve(64, &geometry.data));
    const uint32_t captured = log.AddInfo(info, &geometry, nullptr, 64);
    RecordCmdBuild(state, secondary, OpCommand::kCmdBuild, 1, &update.info, &update.range_pointer, nullptr, &captured);
    state.command_buffers.End(secondary);
    secondary_log = &log;
    state.command_buffers.Reset(other);
    state.command_buffers.End(other);
  }
  // The primary's recording of `count` secondaries.
  std::shared_ptr<const RecordedOps> Execute(std::vector<VkCommandBuffer> cbs, CaptureSaver* saver) {
    state.command_buffers.Reset(primary);
    RecordExecuteCommands(state, primary, static_cast<uint32_t>(cbs.size()), cbs.data(), saver);
    state.command_buffers.End(primary);
    return state.command_buffers.Find(primary)->Executable();
  }
};

TEST_CASE("capture saves unit: a secondary executed again has the earlier executions' captures saved first",
          "[capture]") {
  World w;
  RecordingSaver saver;
  SECTION("executed once: nothing saved, nothing split") {
    const std::shared_ptr<const RecordedOps> ops = w.Execute({w.secondary, w.other}, &saver);
    REQUIRE(ops);
    CHECK(saver.passed.empty());
    CHECK(saver.copies.empty());
    REQUIRE(ops->batch.ops().size() == 1);
    CHECK(ops->batch.ops()[0].capture_log == w.secondary_log);
  }
  SECTION("three times in one call: the array goes down before each repeat, each execution reads its own log") {
    const std::shared_ptr<const RecordedOps> ops = w.Execute({w.secondary, w.other, w.secondary, w.secondary}, &saver);
    REQUIRE(ops);
    CHECK(saver.passed == std::vector<uint32_t>{2, 3});
    REQUIRE(saver.copies.size() == 2);
    CHECK(saver.copies[0].first == w.secondary_log);
    CHECK(saver.copies[1].first == w.secondary_log);
    REQUIRE(ops->batch.ops().size() == 3);
    // The first execution's bytes were copied before the second's, the second's before the third's.
    CHECK(ops->batch.ops()[0].capture_log == saver.copies[0].second);
    CHECK(ops->batch.ops()[1].capture_log == saver.copies[1].second);
    CHECK(ops->batch.ops()[2].capture_log == w.secondary_log);
    CHECK(ops->batch.ops()[0].capture_info == ops->batch.ops()[2].capture_info);
    // The copies live as long as the primary's recording.
    int held = 0;
    for (const auto& log : ops->capture_logs) {
      held += log.get() == saver.copies[0].second || log.get() == saver.copies[1].second;
    }
    CHECK(held == 2);
  }
  SECTION("a copy that was not recorded: the executions keep sharing the log (unknown at submission)") {
    saver.records = false;
    const std::shared_ptr<const RecordedOps> ops = w.Execute({w.secondary, w.secondary}, &saver);
    REQUIRE(ops);
    REQUIRE(ops->batch.ops().size() == 2);
    CHECK(ops->batch.ops()[0].capture_log == w.secondary_log);
    CHECK(ops->batch.ops()[1].capture_log == w.secondary_log);
  }
  SECTION("no slab for the copy: nothing recorded, the log stays shared") {
    w.slabs->fail_after = w.slabs->taken;
    const std::shared_ptr<const RecordedOps> ops = w.Execute({w.secondary, w.secondary}, &saver);
    REQUIRE(ops);
    CHECK(saver.copies.empty());
    CHECK(ops->batch.ops()[0].capture_log == w.secondary_log);
    CHECK(w.state.failures().capture_memory_failures.load() == 1);
  }
  SECTION("without a saver (the device does not capture): as before") {
    const std::shared_ptr<const RecordedOps> ops = w.Execute({w.secondary, w.secondary}, nullptr);
    REQUIRE(ops);
    CHECK(ops->batch.ops()[0].capture_log == w.secondary_log);
    CHECK(ops->batch.ops()[1].capture_log == w.secondary_log);
  }
}

}  // namespace
}  // namespace asval
