// The copies family: record-time rules of the copy, serialization and property-query commands (mode-03410,
// buffer-03718/03719, dst-07791, mode-03412/03413, pInfo-03740/03743, queryType-06742, queryPool-02493,
// query-04880, buffer-03736). Negative tests narrow enabled_checks to "copies"; the monitor's VK_TRUE keeps
// every invalid command away from the driver.
#include <catch2/catch_test_macros.hpp>

#include "history_helpers.h"

namespace asval_test {
namespace {

// A structure created on a buffer that was never bound to memory.
struct UnboundStructure {
  explicit UnboundStructure(vkkit::Device& device) : device_(device) {
    VkBufferCreateInfo buffer_info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    buffer_info.size = 1 << 16;
    buffer_info.usage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR;
    vkkit::Check(vkCreateBuffer(device.handle(), &buffer_info, nullptr, &buffer), "vkCreateBuffer");
    VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    info.buffer = buffer;
    info.size = 1 << 16;
    info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    vkkit::Check(device.CreateAccelerationStructureKHR(device.handle(), &info, nullptr, &handle),
                 "vkCreateAccelerationStructureKHR");
  }
  ~UnboundStructure() {
    device_.DestroyAccelerationStructureKHR(device_.handle(), handle, nullptr);
    vkDestroyBuffer(device_.handle(), buffer, nullptr);
  }
  vkkit::Device& device_;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
};

// Records one command into a fresh command buffer and ends it; nothing is submitted.
void Record(vkkit::Device& device, const std::function<void(VkCommandBuffer)>& record) {
  device.OneShot(record, /*submit=*/false);
}

TEST_CASE("copies: a copy mode other than clone or compact is reported (mode-03410)", "[integration][copies]") {
  HistoryFixture f("copies");
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas a(device, inputs), b(device, inputs);
  f.monitor().Expect("VUID-VkCopyAccelerationStructureInfoKHR-mode-03410");
  Record(device, [&](VkCommandBuffer cb) {
    CmdCopy(device, cb, a.handle(), b.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR);
  });
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("copies: a copy from or to a structure whose buffer is not bound is reported (buffer-03718, buffer-03719)",
          "[integration][copies]") {
  HistoryFixture f("copies");
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas bound(device, inputs);
  UnboundStructure unbound(device);
  f.monitor().Expect("VUID-VkCopyAccelerationStructureInfoKHR-buffer-03718");
  Record(device, [&](VkCommandBuffer cb) {
    CmdCopy(device, cb, unbound.handle, bound.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
  });
  CHECK(f.monitor().Verify() == "");
  f.monitor().Expect("VUID-VkCopyAccelerationStructureInfoKHR-buffer-03719");
  Record(device, [&](VkCommandBuffer cb) {
    CmdCopy(device, cb, bound.handle(), unbound.handle, VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
  });
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("copies: a copy between structures over the same memory is reported (dst-07791)", "[integration][copies]") {
  HistoryFixture f("copies");
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas a(device, inputs);
  Blas alias(device, inputs, &a);
  f.monitor().Expect("VUID-VkCopyAccelerationStructureInfoKHR-dst-07791");
  Record(device, [&](VkCommandBuffer cb) {
    CmdCopy(device, cb, a.handle(), alias.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
  });
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("copies: serialization and deserialization with a wrong mode are reported (mode-03412, mode-03413)",
          "[integration][copies]") {
  HistoryFixture f("copies");
  vkkit::Device& device = f.device();
  Procs procs(device);
  Inputs inputs(device);
  Blas blas(device, inputs);
  vkkit::Buffer bytes = device.CreateBuffer(1 << 16, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  VkCopyAccelerationStructureToMemoryInfoKHR to{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_TO_MEMORY_INFO_KHR};
  to.src = blas.handle();
  to.dst.deviceAddress = bytes.address;
  to.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR;
  f.monitor().Expect("VUID-VkCopyAccelerationStructureToMemoryInfoKHR-mode-03412");
  Record(device, [&](VkCommandBuffer cb) { procs.CmdCopyToMemory(cb, &to); });
  CHECK(f.monitor().Verify() == "");
  VkCopyMemoryToAccelerationStructureInfoKHR from{VK_STRUCTURE_TYPE_COPY_MEMORY_TO_ACCELERATION_STRUCTURE_INFO_KHR};
  from.src.deviceAddress = bytes.address;
  from.dst = blas.handle();
  from.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR;
  f.monitor().Expect("VUID-VkCopyMemoryToAccelerationStructureInfoKHR-mode-03413");
  Record(device, [&](VkCommandBuffer cb) { procs.CmdCopyMemoryTo(cb, &from); });
  CHECK(f.monitor().Verify() == "");
  device.Destroy(bytes);
}

TEST_CASE("copies: serialized data at an address not aligned to 256 bytes is reported (pInfo-03740, pInfo-03743)",
          "[integration][copies]") {
  HistoryFixture f("copies");
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  vkkit::Buffer bytes = device.CreateBuffer(1 << 16, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  REQUIRE(bytes.address % 256 == 0);
  f.monitor().Expect("VUID-vkCmdCopyAccelerationStructureToMemoryKHR-pInfo-03740");
  Record(device, [&](VkCommandBuffer cb) { CmdSerialize(device, cb, blas.handle(), bytes.address + 128); });
  CHECK(f.monitor().Verify() == "");
  f.monitor().Expect("VUID-vkCmdCopyMemoryToAccelerationStructureKHR-pInfo-03743");
  Record(device, [&](VkCommandBuffer cb) { CmdDeserialize(device, cb, bytes.address + 16, blas.handle()); });
  CHECK(f.monitor().Verify() == "");
  device.Destroy(bytes);
}

TEST_CASE("copies: property queries with a wrong type, pool or range are reported "
          "(queryType-06742, queryPool-02493, query-04880, buffer-03736)",
          "[integration][copies]") {
  HistoryFixture f("copies");
  vkkit::Device& device = f.device();
  Procs procs(device);
  Inputs inputs(device);
  Blas blas(device, inputs);
  UnboundStructure unbound(device);
  QueryPool occlusion(device, VK_QUERY_TYPE_OCCLUSION, 1);
  QueryPool compacted(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, 1);
  f.monitor().Expect("VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-queryType-06742");
  Record(device, [&](VkCommandBuffer cb) {
    CmdWriteProperties(device, cb, {blas.handle()}, VK_QUERY_TYPE_OCCLUSION, occlusion.handle(), 0);
  });
  CHECK(f.monitor().Verify() == "");
  f.monitor().Expect("VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-queryPool-02493");
  Record(device, [&](VkCommandBuffer cb) {
    CmdWriteProperties(device, cb, {blas.handle()}, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR,
                       compacted.handle(), 0);
  });
  CHECK(f.monitor().Verify() == "");
  f.monitor().Expect("VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-query-04880");
  Record(device, [&](VkCommandBuffer cb) {
    CmdWriteProperties(device, cb, {blas.handle()}, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR,
                       compacted.handle(), 1);
  });
  CHECK(f.monitor().Verify() == "");
  f.monitor().Expect("VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-buffer-03736");
  Record(device, [&](VkCommandBuffer cb) {
    CmdWriteProperties(device, cb, {unbound.handle}, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR,
                       compacted.handle(), 0);
  });
  CHECK(f.monitor().Verify() == "");
  // The host command's type rule.
  REQUIRE(procs.HostWriteProperties);
  VkAccelerationStructureKHR handle = blas.handle();
  uint64_t value = 0;
  f.monitor().Expect("VUID-vkWriteAccelerationStructuresPropertiesKHR-queryType-06742");
  CHECK(procs.HostWriteProperties(device.handle(), 1, &handle, VK_QUERY_TYPE_OCCLUSION, sizeof(value), &value,
                                  sizeof(value)) == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("copies valid twin: valid copies, serialization and property queries stay silent", "[integration][copies]") {
  HistoryFixture f;
  vkkit::Device& device = f.device();
  Inputs inputs(device);
  Blas a(device, inputs), b(device, inputs), c(device, inputs);
  QueryPool sizes(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR, 4);
  QueryPool compacted(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, 2);
  Shape compactable;
  compactable.flags |= VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR;
  device.OneShot([&](VkCommandBuffer cb) {
    sizes.Reset(cb);
    compacted.Reset(cb);
    a.Build(cb, compactable);
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
    barrier.dstAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR;
    vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                         VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, 0, 1, &barrier, 0, nullptr, 0,
                         nullptr);
    // The last queries of each pool: firstQuery + count == queryCount.
    CmdWriteProperties(device, cb, {a.handle()}, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR,
                       sizes.handle(), 3);
    CmdWriteProperties(device, cb, {a.handle()}, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR,
                       compacted.handle(), 1);
  });
  const uint64_t size = sizes.Results(3, 1)[0];  // only query 3 was written
  REQUIRE(size > 0);
  vkkit::Buffer bytes = device.CreateBuffer(size + 256, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  device.OneShot([&](VkCommandBuffer cb) {
    CmdCopy(device, cb, a.handle(), b.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR);
    CmdCopy(device, cb, a.handle(), c.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR);
    CmdSerialize(device, cb, a.handle(), bytes.address + 256);  // aligned, not at the buffer's start
  });
  device.OneShot([&](VkCommandBuffer cb) { CmdDeserialize(device, cb, bytes.address + 256, b.handle()); });
  CHECK(f.monitor().Verify() == "");
  device.Destroy(bytes);
}

}  // namespace
}  // namespace asval_test
