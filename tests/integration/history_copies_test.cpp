// History through copies, serialization and property queries: clone and compaction carry the source's
// history; deserialization of device bytes leaves it unknown unless the execution-time capture verifies them by
// content once the deserialization completed (capture_serialization_test.cpp; host bytes are verified by hash:
// tests/unit/history_unit_test.cpp), the skip counted and summarized at
// vkDestroyDevice; src-04963, src-04959, src-03411, pAccelerationStructures-04964,
// accelerationStructures-03431 and dst-03561 are checked when the command executes.
#include <unistd.h>

#include <catch2/catch_test_macros.hpp>
#include <cstdio>
#include <fstream>

#include "history_helpers.h"

namespace asval_test {
namespace {

constexpr VkBuildAccelerationStructureFlagsKHR kCompactable =
    VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR | VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR;

Shape Compactable(uint32_t geometries = 1) {
  Shape s;
  s.flags = kCompactable;
  s.geometries = geometries;
  return s;
}

// Builds `blas` with `shape` and reads one property of it back (the compaction flow's first command buffer).
uint64_t BuildAndQuery(vkkit::Device& device, Blas& blas, const Shape& shape, VkQueryType type) {
  QueryPool pool(device, type, 1);
  Commands commands(device);
  VkCommandBuffer cb = commands.Begin();
  pool.Reset(cb);
  blas.Build(cb, shape);
  commands.Barrier(cb);
  CmdWriteProperties(device, cb, {blas.handle()}, type, pool.handle(), 0);
  commands.End(cb);
  REQUIRE(commands.Submit(cb) == VK_SUCCESS);
  return pool.Results()[0];
}

void Submit(vkkit::Device& device, const std::function<void(Commands&, VkCommandBuffer)>& record,
            VkResult expected = VK_SUCCESS) {
  Commands commands(device);
  VkCommandBuffer cb = commands.Begin();
  record(commands, cb);
  commands.End(cb);
  CHECK(commands.Submit(cb) == expected);
}

std::string TempPath() {
  char path[] = "/tmp/asval-history-XXXXXX";
  const int fd = mkstemp(path);
  REQUIRE(fd >= 0);
  close(fd);
  return path;
}

std::string ReadAll(const std::string& path) {
  std::ifstream in(path);
  return std::string(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
}

// ---- clone and compaction ------------------------------------------------------------------------------------

TEST_CASE("history: a compacted copy carries its source's history (03758 on the copy)",
          "[integration][history][passes-invalid-down]") {
  HistoryFixture f("history");
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  auto original = std::make_unique<Blas>(device, inputs);
  Blas compact(device, inputs);
  BuildAndQuery(device, *original, Compactable(1), VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR);
  Submit(device, [&](Commands&, VkCommandBuffer cb) {
    CmdCopy(device, cb, original->handle(), compact.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR);
  });
  original.reset();  // the originals are destroyed once compacted
  f.monitor().Expect("VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03758");
  Submit(device, [&](Commands&, VkCommandBuffer cb) { compact.Update(cb, Compactable(2)); },
         VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("history valid twin: the compaction flow, then updates of the compacted copies, stays silent",
          "[integration][history]") {
  HistoryFixture f;
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  auto a = std::make_unique<Blas>(device, inputs);
  auto b = std::make_unique<Blas>(device, inputs);
  Blas a_compact(device, inputs), b_clone(device, inputs);
  // Build with ALLOW_COMPACTION, query the compacted sizes right after the builds in the same command buffer.
  QueryPool pool(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, 2);
  Submit(device, [&](Commands& commands, VkCommandBuffer cb) {
    pool.Reset(cb);
    a->Build(cb, Compactable(1));
    b->Build(cb, Compactable(2));
    commands.Barrier(cb);
    CmdWriteProperties(device, cb, {a->handle(), b->handle()}, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR,
                       pool.handle(), 0);
  });
  const std::vector<uint64_t> sizes = pool.Results();
  CHECK(sizes[0] > 0);
  // Compact one, clone the other, in a second command buffer; destroy the originals.
  Submit(device, [&](Commands&, VkCommandBuffer cb) {
    CmdCopy(device, cb, a->handle(), a_compact.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR);
    CmdCopy(device, cb, b->handle(), b_clone.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
  });
  a.reset();
  b.reset();
  // The copies update like the originals would.
  Submit(device, [&](Commands& commands, VkCommandBuffer cb) {
    a_compact.Update(cb, Compactable(1));
    b_clone.Update(cb, Compactable(2));
    commands.Barrier(cb);
    a_compact.Update(cb, Compactable(1));
  });
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("history: copying a structure never built is reported (src-04963)",
          "[integration][history][passes-invalid-down]") {
  HistoryFixture f("history");
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas never_built(device, inputs), dst(device, inputs);
  f.monitor().Expect("VUID-VkCopyAccelerationStructureInfoKHR-src-04963");
  Submit(device, [&](Commands&, VkCommandBuffer cb) {
    CmdCopy(device, cb, never_built.handle(), dst.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
  }, VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("history valid twin: copying a structure built earlier in the same submission stays silent (src-04963)",
          "[integration][history]") {
  HistoryFixture f;
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas src(device, inputs), dst(device, inputs), dst2(device, inputs);
  Submit(device, [&](Commands& commands, VkCommandBuffer cb) {
    src.Build(cb, Shape{});
    commands.Barrier(cb);
    CmdCopy(device, cb, src.handle(), dst.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
    commands.Barrier(cb);
    // A copy of a copy.
    CmdCopy(device, cb, dst.handle(), dst2.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
  });
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("history: compacting a structure built without ALLOW_COMPACTION is reported (src-03411)",
          "[integration][history][passes-invalid-down]") {
  HistoryFixture f("history");
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas src(device, inputs), dst(device, inputs);
  Submit(device, [&](Commands&, VkCommandBuffer cb) { src.Build(cb, Shape{}); });  // no ALLOW_COMPACTION
  f.monitor().Expect("VUID-VkCopyAccelerationStructureInfoKHR-src-03411");
  Submit(device, [&](Commands&, VkCommandBuffer cb) {
    CmdCopy(device, cb, src.handle(), dst.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR);
  }, VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(f.monitor().Verify() == "");
}

// ---- property queries ----------------------------------------------------------------------------------------

TEST_CASE("history: a property query of a structure never built is reported (pAccelerationStructures-04964)",
          "[integration][history][passes-invalid-down]") {
  HistoryFixture f("history");
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  QueryPool pool(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR, 1);
  f.monitor().Expect("VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-pAccelerationStructures-04964");
  Submit(device, [&](Commands&, VkCommandBuffer cb) {
    pool.Reset(cb);
    CmdWriteProperties(device, cb, {blas.handle()}, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR,
                       pool.handle(), 0);
  }, VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("history: a compacted-size query of a structure built without ALLOW_COMPACTION is reported "
          "(accelerationStructures-03431)",
          "[integration][history][passes-invalid-down]") {
  HistoryFixture f("history");
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  QueryPool pool(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, 1);
  f.monitor().Expect("VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-accelerationStructures-03431");
  Submit(device, [&](Commands& commands, VkCommandBuffer cb) {
    pool.Reset(cb);
    blas.Build(cb, Shape{});
    commands.Barrier(cb);
    CmdWriteProperties(device, cb, {blas.handle()}, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR,
                       pool.handle(), 0);
  }, VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("history valid twin: property queries of built structures stay silent (04964, 03431)",
          "[integration][history]") {
  HistoryFixture f;
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  CHECK(BuildAndQuery(device, blas, Compactable(), VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR) > 0);
  CHECK(BuildAndQuery(device, blas, Shape{}, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR) > 0);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("history: host property queries and copies are checked when called (04964, 03431, 04963)",
          "[integration][history]") {
  HistoryFixture f("history");
  vkkit::Device& device = f.device();
  Procs procs(device);
  REQUIRE(procs.HostWriteProperties);
  REQUIRE(procs.HostCopy);
  Inputs inputs(device);
  Blas never_built(device, inputs), built(device, inputs);
  Submit(device, [&](Commands&, VkCommandBuffer cb) { built.Build(cb, Shape{}); });
  uint64_t value = 0;
  VkAccelerationStructureKHR handle = never_built.handle();
  f.monitor().Expect("VUID-vkWriteAccelerationStructuresPropertiesKHR-pAccelerationStructures-04964");
  CHECK(procs.HostWriteProperties(device.handle(), 1, &handle,
                                  VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR, sizeof(value), &value,
                                  sizeof(value)) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(f.monitor().Verify() == "");
  handle = built.handle();
  f.monitor().Expect("VUID-vkWriteAccelerationStructuresPropertiesKHR-accelerationStructures-03431");
  CHECK(procs.HostWriteProperties(device.handle(), 1, &handle, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR,
                                  sizeof(value), &value, sizeof(value)) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(f.monitor().Verify() == "");
  VkCopyAccelerationStructureInfoKHR copy{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR};
  copy.src = never_built.handle();
  copy.dst = built.handle();
  copy.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR;
  f.monitor().Expect("VUID-VkCopyAccelerationStructureInfoKHR-src-04963");
  CHECK(procs.HostCopy(device.handle(), VK_NULL_HANDLE, &copy) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(f.monitor().Verify() == "");
}

// ---- serialization -------------------------------------------------------------------------------------------

struct Serialized {
  vkkit::Buffer bytes;
  uint64_t size = 0;
};

// Builds `blas`, reads its serialization size back and serializes it into a new buffer of `size + extra`.
Serialized BuildAndSerialize(vkkit::Device& device, Blas& blas, const Shape& shape, VkDeviceSize extra = 0) {
  Serialized s;
  s.size = BuildAndQuery(device, blas, shape, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR);
  REQUIRE(s.size > 0);
  s.bytes = device.CreateBuffer(s.size + extra, VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT);
  Submit(device, [&](Commands&, VkCommandBuffer cb) { CmdSerialize(device, cb, blas.handle(), s.bytes.address); });
  return s;
}

// Regression (false positive found by an independent corpus): the layer used to restore the history of device
// bytes it had seen serialized even after vkCmdCopyBuffer overwrote them with another structure's, and then
// reported pInfos-03758 on this valid update. Device bytes can be rewritten by commands the layer does not
// follow: only bytes verified by content (the capture's hash of what was serialized there, compared with what the
// deserialization read) restore a history; these differ, so it stays unknown (skipped, counted).
TEST_CASE("history valid twin: deserializing device bytes overwritten by vkCmdCopyBuffer is not taken for what "
          "was serialized there",
          "[integration][history]") {
  HistoryFixture f;
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas one(device, inputs), two(device, inputs), restored(device, inputs);
  Shape two_geometries;
  two_geometries.geometries = 2;
  Serialized of_two = BuildAndSerialize(device, two, two_geometries);
  Serialized of_one = BuildAndSerialize(device, one, Shape{}, of_two.size);  // room for the other's bytes
  Submit(device, [&](Commands&, VkCommandBuffer cb) {
    CmdCopyBuffer(cb, of_two.bytes, of_one.bytes, of_two.size);  // of_one's buffer now holds `two`
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
    barrier.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, 0,
                         1, &barrier, 0, nullptr, 0, nullptr);
    CmdDeserialize(device, cb, of_one.bytes.address, restored.handle());
  });
  // `restored` is a copy of `two`: updating it with two geometries is valid.
  Submit(device, [&](Commands&, VkCommandBuffer cb) { restored.Update(cb, two_geometries); });
  CHECK(f.monitor().Verify() == "");
  device.Destroy(of_one.bytes);
  device.Destroy(of_two.bytes);
}

TEST_CASE("history valid twin: updating a structure deserialized from device bytes stays silent (history unknown)",
          "[integration][history]") {
  HistoryFixture f;
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas original(device, inputs), restored(device, inputs);
  Serialized s = BuildAndSerialize(device, original, Shape{});
  Submit(device, [&](Commands& commands, VkCommandBuffer cb) {
    CmdDeserialize(device, cb, s.bytes.address, restored.handle());
    commands.Barrier(cb);
    restored.Update(cb, Shape{});
  });
  CHECK(f.monitor().Verify() == "");
  device.Destroy(s.bytes);
}

TEST_CASE("history: deserializing bytes the layer did not see written leaves the history unknown, counted",
          "[integration][history]") {
  const std::string report = TempPath();
  {
    HistoryFixture f(nullptr, {{"report_file", report.c_str()}, {"report_flags", "error,warn,info"}});
    vkkit::Device& device = f.device();
    {
      Inputs inputs(device);
      Blas original(device, inputs), restored(device, inputs);
      Serialized s = BuildAndSerialize(device, original, Shape{});
      // The bytes travel through a copy the layer does not track (as if loaded from a file).
      vkkit::Buffer elsewhere =
          device.CreateBuffer(s.size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_TRANSFER_DST_BIT);
      Submit(device, [&](Commands&, VkCommandBuffer cb) {
        CmdCopyBuffer(cb, s.bytes, elsewhere, s.size);
        VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
        barrier.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
        barrier.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT;
        vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_TRANSFER_BIT,
                             VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, 0, 1, &barrier, 0, nullptr, 0,
                             nullptr);
        CmdDeserialize(device, cb, elsewhere.address, restored.handle());
      });
      // Unknown history: the update is not judged (it is valid here; an invalid one would be just as silent).
      Submit(device, [&](Commands&, VkCommandBuffer cb) { restored.Update(cb, Shape{}); });
      CHECK(f.monitor().Verify() == "");
      device.Destroy(elsewhere);
      device.Destroy(s.bytes);
    }
    f.Close();  // vkDestroyDevice writes the summary
  }
  const std::string json = ReadAll(report);
  std::remove(report.c_str());
  CHECK(json.find("\"severity\":\"info\",\"vuid\":\"ASVAL-History-Summary\"") != std::string::npos);
  CHECK(json.find("\"function\":\"vkDestroyDevice\"") != std::string::npos);
  CHECK(json.find("history checks were skipped because the history they need was unknown") != std::string::npos);
}

TEST_CASE("history: serializing a structure never built is reported (src-04959)",
          "[integration][history][passes-invalid-down]") {
  HistoryFixture f("history");
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  vkkit::Buffer bytes = device.CreateBuffer(1 << 16, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  f.monitor().Expect("VUID-VkCopyAccelerationStructureToMemoryInfoKHR-src-04959");
  Submit(device, [&](Commands&, VkCommandBuffer cb) { CmdSerialize(device, cb, blas.handle(), bytes.address); },
         VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(f.monitor().Verify() == "");
  device.Destroy(bytes);
}

TEST_CASE("copies: serializing into memory smaller than the serialization size read back is reported (dst-03561)",
          "[integration][copies][passes-invalid-down]") {
  HistoryFixture f("copies");
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  const uint64_t size =
      BuildAndQuery(device, blas, Shape{}, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR);
  REQUIRE(size > 256);
  vkkit::Buffer small = device.CreateBuffer(size - 256, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  f.monitor().Expect("VUID-VkCopyAccelerationStructureToMemoryInfoKHR-dst-03561");
  Submit(device, [&](Commands&, VkCommandBuffer cb) { CmdSerialize(device, cb, blas.handle(), small.address); },
         VK_ERROR_VALIDATION_FAILED_EXT);
  std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].text.find(std::to_string(size) + " bytes") != std::string::npos);
  device.Destroy(small);
}

TEST_CASE("copies valid twin: serializing into exactly the serialization size stays silent (dst-03561)",
          "[integration][copies]") {
  HistoryFixture f;
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Serialized s = BuildAndSerialize(device, blas, Shape{});  // a buffer of exactly the size read back
  // Rebuilt: the size read back belonged to the old contents, so a smaller buffer is not judged either.
  vkkit::Buffer small = device.CreateBuffer(256, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  Shape two;
  two.geometries = 2;
  Submit(device, [&](Commands& commands, VkCommandBuffer cb) {
    blas.Build(cb, two);
    commands.Barrier(cb);
    CmdSerialize(device, cb, blas.handle(), s.bytes.address);
  });
  CHECK(f.monitor().Verify() == "");
  device.Destroy(small);
  device.Destroy(s.bytes);
}

}  // namespace
}  // namespace asval_test
