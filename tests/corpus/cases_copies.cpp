// Family "copies": the copy, compaction, serialization and property-query commands. Record-time faults are recorded
// in a command buffer that is submitted like the program's others (a layer that reports them skips the command);
// faults about what the copied structure holds (never built, sizes read back) are judged when the submission
// executes, so those cases submit and wait. The valid twins are the round trips programs do: compaction with the
// size read back, serialization into exactly the size read back, clones, all in sub-allocated buffers.
#include <cstring>
#include <functional>
#include <memory>
#include <vector>

#include "corpus.h"
#include "history_helpers.h"
#include "memory_placement_helpers.h"

namespace {

using asval_test::Blas;
using asval_test::CmdCopy;
using asval_test::CmdDeserialize;
using asval_test::CmdSerialize;
using asval_test::CmdWriteProperties;
using asval_test::Commands;
using asval_test::Inputs;
using asval_test::Procs;
using asval_test::QueryPool;
using asval_test::Shape;
using asval_test::SharedMemory;
using asval_test::Tlas;

constexpr auto kClone = VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR;
constexpr auto kCompact = VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR;
constexpr auto kCompactedSize = VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR;
constexpr auto kSerializationSize = VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR;
constexpr VkBufferUsageFlags kBytes = VK_BUFFER_USAGE_TRANSFER_SRC_BIT | VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;

Shape Compactable() {
  Shape s;
  s.flags |= VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR;
  return s;
}

// Records what `record` records into a new command buffer, submits it and waits (when the layers let it through).
void Submit(vkkit::Device& device, const std::function<void(VkCommandBuffer)>& record) {
  Commands commands(device);
  VkCommandBuffer cb = commands.Begin();
  record(cb);
  commands.End(cb);
  commands.Submit(cb);
}

// AS-build/copy writes before AS reads (copies, queries, builds).
void AsBarrier(VkCommandBuffer cb) {
  VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  barrier.srcAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR | VK_ACCESS_TRANSFER_WRITE_BIT;
  barrier.dstAccessMask = VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_KHR | VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_KHR;
  // Copies and property queries run in the build stage (synchronization 1 has no copy stage of its own).
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR | VK_PIPELINE_STAGE_TRANSFER_BIT,
                       VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, 0, 1, &barrier, 0, nullptr, 0, nullptr);
}

// Builds `blas` with `shape` and reads one property of it back, as the first command buffer of a compaction or
// serialization flow does.
uint64_t BuildAndQuery(vkkit::Device& device, Blas& blas, const Shape& shape, VkQueryType type) {
  QueryPool pool(device, type, 1);
  Submit(device, [&](VkCommandBuffer cb) {
    pool.Reset(cb);
    blas.Build(cb, shape);
    AsBarrier(cb);
    CmdWriteProperties(device, cb, {blas.handle()}, type, pool.handle(), 0);
  });
  return pool.Results()[0];
}

// A structure created on a buffer never bound to memory.
struct UnboundStructure {
  explicit UnboundStructure(vkkit::Device& d) : device(d) {
    VkBufferCreateInfo buffer_info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    buffer_info.size = 1 << 16;
    buffer_info.usage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR;
    vkkit::Check(vkCreateBuffer(d.handle(), &buffer_info, nullptr, &buffer), "vkCreateBuffer");
    VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    info.buffer = buffer;
    info.size = 1 << 16;
    info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    vkkit::Check(d.CreateAccelerationStructureKHR(d.handle(), &info, nullptr, &handle),
                 "vkCreateAccelerationStructureKHR");
  }
  ~UnboundStructure() {
    device.DestroyAccelerationStructureKHR(device.handle(), handle, nullptr);
    vkDestroyBuffer(device.handle(), buffer, nullptr);
  }
  vkkit::Device& device;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
};

// A BLAS built for real, and a second one to copy into.
struct BuiltPair {
  Inputs inputs;
  Blas src, dst;
  explicit BuiltPair(vkkit::Device& device) : inputs(device), src(device, inputs), dst(device, inputs) {
    device.OneShot([&](VkCommandBuffer cb) { src.Build(cb, Shape{}); });
  }
};

// ---- record-time faults

CORPUS_CASE(CopyWrongMode, "copies-clone-with-serialize-mode", "copies",
            "vkCmdCopyAccelerationStructureKHR between two built BLASes with mode SERIALIZE instead of CLONE",
            {"VUID-VkCopyAccelerationStructureInfoKHR-mode-03410"}) {
  BuiltPair p(device);
  Submit(device, [&](VkCommandBuffer cb) {
    CmdCopy(device, cb, p.src.handle(), p.dst.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR);
  });
}

CORPUS_CASE(CopyFromUnbound, "copies-clone-from-unbound-structure", "copies",
            "a clone whose source structure was created on a buffer never bound to memory",
            {"VUID-VkCopyAccelerationStructureInfoKHR-buffer-03718"}) {
  BuiltPair p(device);
  UnboundStructure unbound(device);
  Submit(device, [&](VkCommandBuffer cb) { CmdCopy(device, cb, unbound.handle, p.dst.handle(), kClone); });
}

CORPUS_CASE(CopyToUnbound, "copies-clone-to-unbound-structure", "copies",
            "a clone of a built BLAS into a structure created on a buffer never bound to memory",
            {"VUID-VkCopyAccelerationStructureInfoKHR-buffer-03719"}) {
  BuiltPair p(device);
  UnboundStructure unbound(device);
  Submit(device, [&](VkCommandBuffer cb) { CmdCopy(device, cb, p.src.handle(), unbound.handle, kClone); });
}

CORPUS_CASE(CopyOverItself, "copies-clone-onto-structure-over-same-memory", "copies",
            "a clone of a built BLAS into another structure created over the same bytes of the same buffer",
            {"VUID-VkCopyAccelerationStructureInfoKHR-dst-07791"}) {
  Inputs inputs(device);
  Blas a(device, inputs);
  Blas alias(device, inputs, &a);
  device.OneShot([&](VkCommandBuffer cb) { a.Build(cb, Shape{}); });
  Submit(device, [&](VkCommandBuffer cb) { CmdCopy(device, cb, a.handle(), alias.handle(), kClone); });
}

CORPUS_CASE(SerializeWrongMode, "copies-serialize-with-clone-mode", "copies",
            "vkCmdCopyAccelerationStructureToMemoryKHR of a built BLAS with mode CLONE instead of SERIALIZE",
            {"VUID-VkCopyAccelerationStructureToMemoryInfoKHR-mode-03412"}) {
  BuiltPair p(device);
  Procs procs(device);
  vkkit::Buffer bytes = device.CreateBuffer(1 << 16, kBytes);
  VkCopyAccelerationStructureToMemoryInfoKHR to{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_TO_MEMORY_INFO_KHR};
  to.src = p.src.handle();
  to.dst.deviceAddress = bytes.address;
  to.mode = kClone;
  Submit(device, [&](VkCommandBuffer cb) { procs.CmdCopyToMemory(cb, &to); });
  device.Destroy(bytes);
}

CORPUS_CASE(DeserializeWrongMode, "copies-deserialize-with-serialize-mode", "copies",
            "a BLAS serialized into a buffer, then vkCmdCopyMemoryToAccelerationStructureKHR back with mode SERIALIZE "
            "instead of DESERIALIZE",
            {"VUID-VkCopyMemoryToAccelerationStructureInfoKHR-mode-03413"}) {
  BuiltPair p(device);
  Procs procs(device);
  vkkit::Buffer bytes = device.CreateBuffer(1 << 16, kBytes);
  Submit(device, [&](VkCommandBuffer cb) { CmdSerialize(device, cb, p.src.handle(), bytes.address); });
  VkCopyMemoryToAccelerationStructureInfoKHR from{VK_STRUCTURE_TYPE_COPY_MEMORY_TO_ACCELERATION_STRUCTURE_INFO_KHR};
  from.src.deviceAddress = bytes.address;
  from.dst = p.dst.handle();
  from.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR;
  Submit(device, [&](VkCommandBuffer cb) { procs.CmdCopyMemoryTo(cb, &from); });
  device.Destroy(bytes);
}

CORPUS_CASE(SerializeUnaligned, "copies-serialize-to-unaligned-address", "copies",
            "a built BLAS serialized to 128 bytes into a buffer (serialized data must be 256-byte aligned)",
            {"VUID-vkCmdCopyAccelerationStructureToMemoryKHR-pInfo-03740"}) {
  BuiltPair p(device);
  vkkit::Buffer bytes = device.CreateBuffer(1 << 16, kBytes);
  Submit(device, [&](VkCommandBuffer cb) { CmdSerialize(device, cb, p.src.handle(), bytes.address + 128); });
  device.Destroy(bytes);
}

CORPUS_CASE(DeserializeUnaligned, "copies-deserialize-from-unaligned-address", "copies",
            "a BLAS serialized at 256-byte alignment, then deserialized from 16 bytes further on",
            {"VUID-vkCmdCopyMemoryToAccelerationStructureKHR-pInfo-03743"}) {
  BuiltPair p(device);
  vkkit::Buffer bytes = device.CreateBuffer(1 << 16, kBytes);
  Submit(device, [&](VkCommandBuffer cb) { CmdSerialize(device, cb, p.src.handle(), bytes.address + 256); });
  Submit(device, [&](VkCommandBuffer cb) { CmdDeserialize(device, cb, bytes.address + 256 + 16, p.dst.handle()); });
  device.Destroy(bytes);
}

CORPUS_CASE(QueryWrongType, "copies-properties-into-occlusion-query", "copies",
            "vkCmdWriteAccelerationStructuresPropertiesKHR of a built BLAS with queryType OCCLUSION",
            {"VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-queryType-06742"}) {
  BuiltPair p(device);
  QueryPool occlusion(device, VK_QUERY_TYPE_OCCLUSION, 1);
  Submit(device, [&](VkCommandBuffer cb) {
    occlusion.Reset(cb);
    CmdWriteProperties(device, cb, {p.src.handle()}, VK_QUERY_TYPE_OCCLUSION, occlusion.handle(), 0);
  });
}

CORPUS_CASE(QueryPoolMismatch, "copies-serialization-size-into-compacted-size-pool", "copies",
            "a serialization-size query written into a pool created for compacted sizes",
            {"VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-queryPool-02493"}) {
  BuiltPair p(device);
  QueryPool compacted(device, kCompactedSize, 1);
  Submit(device, [&](VkCommandBuffer cb) {
    compacted.Reset(cb);
    CmdWriteProperties(device, cb, {p.src.handle()}, kSerializationSize, compacted.handle(), 0);
  });
}

CORPUS_CASE(QueryPastPool, "copies-properties-past-end-of-pool", "copies",
            "a compacted-size query of one built BLAS at firstQuery 1 of a pool of 1 query",
            {"VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-query-04880"}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, Compactable()); });
  QueryPool compacted(device, kCompactedSize, 1);
  Submit(device, [&](VkCommandBuffer cb) {
    compacted.Reset(cb);
    CmdWriteProperties(device, cb, {blas.handle()}, kCompactedSize, compacted.handle(), 1);
  });
}

CORPUS_CASE(QueryUnbound, "copies-properties-of-unbound-structure", "copies",
            "a serialization-size query of a structure whose buffer was never bound to memory",
            {"VUID-vkCmdWriteAccelerationStructuresPropertiesKHR-buffer-03736"}) {
  UnboundStructure unbound(device);
  QueryPool pool(device, kSerializationSize, 1);
  Submit(device, [&](VkCommandBuffer cb) {
    pool.Reset(cb);
    CmdWriteProperties(device, cb, {unbound.handle}, kSerializationSize, pool.handle(), 0);
  });
}

CORPUS_CASE(HostQueryWrongType, "copies-host-properties-occlusion-type", "copies",
            "vkWriteAccelerationStructuresPropertiesKHR on the host for a built BLAS with queryType OCCLUSION",
            {"VUID-vkWriteAccelerationStructuresPropertiesKHR-queryType-06742",
             // lavapipe has no accelerationStructureHostCommands: every host command breaks its feature rule too
             "VUID-vkWriteAccelerationStructuresPropertiesKHR-accelerationStructureHostCommands-03585"}) {
  BuiltPair p(device);
  Procs procs(device);
  VkAccelerationStructureKHR handle = p.src.handle();
  uint64_t value = 0;
  procs.HostWriteProperties(device.handle(), 1, &handle, VK_QUERY_TYPE_OCCLUSION, sizeof(value), &value,
                            sizeof(value));
}

// ---- faults of what executes

CORPUS_CASE(SerializeTooSmall, "copies-serialize-into-buffer-smaller-than-size-read-back", "copies",
            "a BLAS built and its serialization size read back, then serialized into a buffer 256 bytes smaller",
            {"VUID-VkCopyAccelerationStructureToMemoryInfoKHR-dst-03561"}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  const uint64_t size = BuildAndQuery(device, blas, Shape{}, kSerializationSize);
  vkkit::Buffer small = device.CreateBuffer(size > 512 ? size - 256 : 256, kBytes);
  Submit(device, [&](VkCommandBuffer cb) { CmdSerialize(device, cb, blas.handle(), small.address); });
  device.Destroy(small);
}

CORPUS_CASE(CopyNeverBuilt, "copies-clone-of-never-built-structure", "copies",
            "a clone submitted from a BLAS that was created but never built",
            {"VUID-VkCopyAccelerationStructureInfoKHR-src-04963"}) {
  Inputs inputs(device);
  Blas never_built(device, inputs), dst(device, inputs);
  Submit(device, [&](VkCommandBuffer cb) { CmdCopy(device, cb, never_built.handle(), dst.handle(), kClone); });
}

CORPUS_CASE(CompactNotCompactable, "copies-compact-without-allow-compaction", "copies",
            "a BLAS built without ALLOW_COMPACTION, then compacted",
            {"VUID-VkCopyAccelerationStructureInfoKHR-src-03411"}) {
  BuiltPair p(device);
  Submit(device, [&](VkCommandBuffer cb) { CmdCopy(device, cb, p.src.handle(), p.dst.handle(), kCompact); });
}

CORPUS_CASE(SerializeNeverBuilt, "copies-serialize-never-built-structure", "copies",
            "a serialization submitted of a BLAS created but never built",
            {"VUID-VkCopyAccelerationStructureToMemoryInfoKHR-src-04959"}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  vkkit::Buffer bytes = device.CreateBuffer(1 << 16, kBytes);
  Submit(device, [&](VkCommandBuffer cb) { CmdSerialize(device, cb, blas.handle(), bytes.address); });
  device.Destroy(bytes);
}

// ---- valid twins, executed

VkDeviceAddress AddressOf(vkkit::Device& device, VkAccelerationStructureKHR as) {
  const VkAccelerationStructureDeviceAddressInfoKHR info{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR, nullptr, as};
  return device.GetAccelerationStructureDeviceAddressKHR(device.handle(), &info);
}

// An instance buffer (one identity instance per reference), as a TLAS build reads it.
vkkit::Buffer InstancesOf(vkkit::Device& device, const std::vector<VkDeviceAddress>& references) {
  vkkit::Buffer buffer = device.CreateBuffer(
      references.size() * sizeof(VkAccelerationStructureInstanceKHR),
      VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  for (size_t i = 0; i < references.size(); ++i) {
    VkAccelerationStructureInstanceKHR instance{};
    instance.transform.matrix[0][0] = instance.transform.matrix[1][1] = instance.transform.matrix[2][2] = 1.0f;
    instance.transform.matrix[0][3] = static_cast<float>(i) * 4.0f;
    instance.mask = 0xff;
    instance.accelerationStructureReference = references[i];
    std::memcpy(static_cast<char*>(buffer.mapped) + i * sizeof(instance), &instance, sizeof(instance));
  }
  return buffer;
}

CORPUS_CASE(CompactionRoundTrip, "copies-valid-compaction-round-trip", "copies",
            "2 BLASes built with ALLOW_COMPACTION, compacted sizes queried, compacted into structures of exactly those "
            "sizes sub-allocated side by side in one buffer, originals destroyed, a TLAS built over the compacted "
            "copies",
            {}) {
  Inputs inputs(device);
  auto a = std::make_unique<Blas>(device, inputs);
  auto b = std::make_unique<Blas>(device, inputs);
  QueryPool pool(device, kCompactedSize, 2);
  Shape two = Compactable();
  two.geometries = 2;
  Submit(device, [&](VkCommandBuffer cb) {
    pool.Reset(cb);
    a->Build(cb, Compactable());
    b->Build(cb, two);
    AsBarrier(cb);
    CmdWriteProperties(device, cb, {a->handle(), b->handle()}, kCompactedSize, pool.handle(), 0);
  });
  const std::vector<uint64_t> sizes = pool.Results();
  SharedMemory memory(device, 1 << 20);
  const VkDeviceSize second = asval_test::RoundUp(sizes[0], 256);
  vkkit::Buffer storage = memory.Bind(4096, second + sizes[1], VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
  const VkAccelerationStructureKHR a_compact =
      memory.Structure(storage, 0, sizes[0], VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  const VkAccelerationStructureKHR b_compact =
      memory.Structure(storage, second, sizes[1], VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  Submit(device, [&](VkCommandBuffer cb) {
    CmdCopy(device, cb, a->handle(), a_compact, kCompact);
    CmdCopy(device, cb, b->handle(), b_compact, kCompact);
  });
  a.reset();
  b.reset();
  Tlas tlas(device);
  vkkit::Buffer instances = InstancesOf(device, {AddressOf(device, a_compact), AddressOf(device, b_compact)});
  Submit(device, [&](VkCommandBuffer cb) {
    tlas.Record(cb, instances, 2, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
  });
  device.Destroy(instances);
}

CORPUS_CASE(SerializationRoundTrip, "copies-valid-serialization-round-trip", "copies",
            "a BLAS built, its serialization size queried, serialized into exactly that many bytes at offset 256 of "
            "a sub-allocated buffer, deserialized into a new structure used by a TLAS build",
            {}) {
  Inputs inputs(device);
  Blas blas(device, inputs), restored(device, inputs);
  const uint64_t size = BuildAndQuery(device, blas, Shape{}, kSerializationSize);
  SharedMemory memory(device, 1 << 20);
  vkkit::Buffer bytes = memory.Bind(256, size, kBytes);
  Submit(device, [&](VkCommandBuffer cb) { CmdSerialize(device, cb, blas.handle(), bytes.address); });
  Submit(device, [&](VkCommandBuffer cb) { CmdDeserialize(device, cb, bytes.address, restored.handle()); });
  Tlas tlas(device);
  vkkit::Buffer instances = tlas.MakeInstances({&restored});
  Submit(device, [&](VkCommandBuffer cb) {
    tlas.Record(cb, instances, 1, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
  });
  device.Destroy(instances);
}

CORPUS_CASE(CompactIntoRecycledMemory, "copies-valid-compact-into-recycled-memory", "copies",
            "a BLAS compacted every frame into a new exact-size structure at the same offset of one VkDeviceMemory "
            "(the last frame's structure and buffer destroyed, addresses reused), the compacted copy then cloned to "
            "the next offset",
            {}) {
  Inputs inputs(device);
  Blas original(device, inputs);
  const uint64_t size = BuildAndQuery(device, original, Compactable(), kCompactedSize);
  const VkDeviceSize stride = asval_test::RoundUp(size, 256);
  SharedMemory memory(device, 1 << 20);
  for (int frame = 0; frame < 3; ++frame) {
    vkkit::Buffer storage =
        memory.Bind(256, 2 * stride, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
    const VkAccelerationStructureKHR compacted =
        memory.Structure(storage, 0, size, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
    const VkAccelerationStructureKHR clone =
        memory.Structure(storage, stride, size, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
    Submit(device, [&](VkCommandBuffer cb) {
      CmdCopy(device, cb, original.handle(), compacted, kCompact);
      AsBarrier(cb);
      CmdCopy(device, cb, compacted, clone, kClone);
    });
    memory.DestroyStructure(compacted);
    memory.DestroyStructure(clone);
    memory.DestroyBuffer(storage);
  }
}

CORPUS_CASE(CloneChainSameSubmission, "copies-valid-clone-chain-in-one-submission", "copies",
            "a BLAS built, cloned, and the clone cloned again, in one command buffer with barriers; then the clones "
            "refitted",
            {}) {
  Inputs inputs(device);
  Blas src(device, inputs), first(device, inputs), second(device, inputs);
  Submit(device, [&](VkCommandBuffer cb) {
    src.Build(cb, Shape{});
    AsBarrier(cb);
    CmdCopy(device, cb, src.handle(), first.handle(), kClone);
    AsBarrier(cb);
    CmdCopy(device, cb, first.handle(), second.handle(), kClone);
    AsBarrier(cb);
    first.Update(cb, Shape{});
    second.Update(cb, Shape{});
  });
}

CORPUS_CASE(QueriesAtPoolEnd, "copies-valid-queries-at-end-of-pools", "copies",
            "compacted-size and serialization-size queries of 2 built BLASes written into the last queries of their "
            "pools (firstQuery + count == queryCount)",
            {}) {
  Inputs inputs(device);
  Blas a(device, inputs), b(device, inputs);
  QueryPool sizes(device, kSerializationSize, 4);
  QueryPool compacted(device, kCompactedSize, 3);
  Submit(device, [&](VkCommandBuffer cb) {
    sizes.Reset(cb);
    compacted.Reset(cb);
    a.Build(cb, Compactable());
    b.Build(cb, Compactable());
    AsBarrier(cb);
    CmdWriteProperties(device, cb, {a.handle(), b.handle()}, kSerializationSize, sizes.handle(), 2);
    CmdWriteProperties(device, cb, {a.handle(), b.handle()}, kCompactedSize, compacted.handle(), 1);
  });
  sizes.Results(2, 2);
  compacted.Results(1, 2);
}

CORPUS_CASE(RebuiltThenSerialized, "copies-valid-serialize-after-rebuild-with-new-size", "copies",
            "a BLAS's serialization size read back, the BLAS rebuilt with 2 geometries and its size read back again, "
            "then serialized into a buffer of exactly the new size (the first size no longer describes it)",
            {}) {
  Inputs inputs(device);
  Blas blas(device, inputs);
  BuildAndQuery(device, blas, Shape{}, kSerializationSize);
  Shape two;
  two.geometries = 2;
  const uint64_t size = BuildAndQuery(device, blas, two, kSerializationSize);
  vkkit::Buffer bytes = device.CreateBuffer(size, kBytes);
  Submit(device, [&](VkCommandBuffer cb) { CmdSerialize(device, cb, blas.handle(), bytes.address); });
  device.Destroy(bytes);
}

}  // namespace
