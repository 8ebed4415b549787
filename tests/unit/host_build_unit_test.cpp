// Host builds (vkBuildAccelerationStructuresKHR) without a driver: lavapipe has no host commands, so the
// valid twins of the host rules, and the negatives that need memory lavapipe cannot give (not host-visible,
// multi-instance), run here on hand-built state. Negatives that the loader can carry are also in
// tests/integration/build_host_test.cpp.
#include <catch2/catch_test_macros.hpp>

#include <vector>

#include "build_state_fixture.h"
#include "history_recorder.h"
#include "host_copy_rules.h"
#include "host_mappings.h"

namespace asval {
namespace {

constexpr VkBufferUsageFlags kAsStorage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR;
constexpr VkAccelerationStructureTypeKHR kBottom = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
constexpr VkAccelerationStructureTypeKHR kTop = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;

// A host BLAS build over host vertices and a TLAS build over host instances of one BLAS, everything valid.
struct HostScene {
  BuildStateFixture& f;
  float vertices[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::vector<VkAccelerationStructureInstanceKHR> instances;
  std::vector<unsigned char> scratch = std::vector<unsigned char>(1 << 16);
  VkDeviceMemory memory;
  VkBuffer storage;
  VkAccelerationStructureKHR blas, tlas, built_blas;
  VkAccelerationStructureGeometryKHR triangles, instance_geometry;
  VkAccelerationStructureBuildGeometryInfoKHR infos[2];
  VkAccelerationStructureBuildRangeInfoKHR blas_range{1, 0, 0, 0};
  VkAccelerationStructureBuildRangeInfoKHR tlas_range{0, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR* ranges[2] = {&blas_range, &tlas_range};

  explicit HostScene(BuildStateFixture& fixture, uint32_t instance_count = 1000, uint32_t memory_type = 0)
      : f(fixture) {
    memory = f.Memory(1 << 20, memory_type);
    storage = f.Buffer(1 << 20, kAsStorage, memory);
    blas = f.Structure(storage, 0, FakeSizes::Structure(1), kBottom);
    tlas = f.Structure(storage, 4096, FakeSizes::Structure(instance_count), kTop);
    built_blas = f.Structure(storage, 512 * 1024, FakeSizes::Structure(1), kBottom);  // built earlier
    // Many instances of one BLAS (the one not written by this command).
    VkAccelerationStructureInstanceKHR instance{};
    instance.mask = 0xff;
    instance.accelerationStructureReference = reinterpret_cast<uint64_t>(built_blas);
    instances.assign(instance_count, instance);
    tlas_range.primitiveCount = instance_count;
    triangles = TriangleGeometry(reinterpret_cast<uint64_t>(vertices));
    instance_geometry = InstanceGeometry(reinterpret_cast<uint64_t>(instances.data()));
    infos[0] = OneGeometryInfo(kBottom, &triangles);
    infos[0].dstAccelerationStructure = blas;
    infos[0].scratchData.hostAddress = scratch.data();
    infos[1] = OneGeometryInfo(kTop, &instance_geometry);
    infos[1].dstAccelerationStructure = tlas;
    infos[1].scratchData.hostAddress = scratch.data() + 32768;
  }
  BuildCommand Command() const { return HostBuild(2, infos, ranges); }
};

TEST_CASE("host valid twin: BLAS and TLAS of 1000 instances of one BLAS, host-visible memory, scratch given",
          "[host][valid]") {
  BuildStateFixture f;
  HostScene scene(f);
  CHECK_FALSE(f.Validate(scene.Command()));
  CHECK(f.Take().empty());
  // In-place update of the BLAS (src == dst) with its update scratch.
  scene.infos[0].mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  scene.infos[0].srcAccelerationStructure = scene.blas;
  CHECK_FALSE(f.Validate(scene.Command()));
  CHECK(f.Take().empty());
}

TEST_CASE("host valid twin: a null scratch pointer is fine when the driver needs no scratch", "[host][valid]") {
  BuildStateFixture f;
  FakeSizes::update_scratch_zero = true;
  HostScene scene(f);
  scene.infos[0].mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  scene.infos[0].srcAccelerationStructure = scene.blas;
  scene.infos[0].scratchData.hostAddress = nullptr;
  f.Validate(scene.Command());
  CHECK(f.Take().empty());
}

TEST_CASE("host valid twin: null inputs of geometries that build nothing", "[host][valid]") {
  BuildStateFixture f;
  HostScene scene(f);
  scene.triangles.geometry.triangles.vertexData.hostAddress = nullptr;
  scene.blas_range.primitiveCount = 0;
  scene.instance_geometry.geometry.instances.data.hostAddress = nullptr;
  scene.tlas_range.primitiveCount = 0;
  f.Validate(scene.Command());
  CHECK(f.Take().empty());
}

TEST_CASE("pInfos-03722 / 03723 / 03724: host builds on memory that is not host-visible", "[host][03722][03723][03724]") {
  BuildStateFixture f;
  HostScene scene(f);
  const VkDeviceMemory device_local = f.Memory(1 << 20, 1);
  const VkBuffer buffer = f.Buffer(1 << 20, kAsStorage, device_local);
  SECTION("03722: the destination") {
    scene.infos[0].dstAccelerationStructure = f.Structure(buffer, 0, FakeSizes::Structure(1), kBottom);
    f.Validate(scene.Command());
    CHECK(f.Take() == std::vector<std::string>{"VUID-vkBuildAccelerationStructuresKHR-pInfos-03722"});
  }
  SECTION("03723: an update's source") {
    scene.infos[0].mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
    scene.infos[0].srcAccelerationStructure = f.Structure(buffer, 0, FakeSizes::Structure(1), kBottom);
    f.Validate(scene.Command());
    CHECK(f.Take() == std::vector<std::string>{"VUID-vkBuildAccelerationStructuresKHR-pInfos-03723"});
  }
  SECTION("03724: a structure the instances reference") {
    const VkAccelerationStructureKHR elsewhere = f.Structure(buffer, 0, FakeSizes::Structure(1), kBottom);
    scene.instances[500].accelerationStructureReference = reinterpret_cast<uint64_t>(elsewhere);
    f.Validate(scene.Command());
    REQUIRE(f.texts.size() == 1);
    CHECK(f.texts[0].find("(instance 500) references") != std::string::npos);
    CHECK(f.Take() == std::vector<std::string>{"VUID-vkBuildAccelerationStructuresKHR-pInfos-03724"});
  }
}

TEST_CASE("pInfos-03775 / 03776 / 03777: host builds on memory allocated with multiple instances",
          "[host][03775][03776][03777]") {
  BuildStateFixture f;
  HostScene scene(f);
  // Two physical devices share the memory: a device mask with two bits.
  const VkDeviceMemory shared = f.Memory(1 << 20, 0, 0b11);
  const VkBuffer buffer = f.Buffer(1 << 20, kAsStorage, shared);
  SECTION("03775: the destination") {
    scene.infos[0].dstAccelerationStructure = f.Structure(buffer, 0, FakeSizes::Structure(1), kBottom);
    f.Validate(scene.Command());
    CHECK(f.Take() == std::vector<std::string>{"VUID-vkBuildAccelerationStructuresKHR-pInfos-03775"});
  }
  SECTION("03776: an update's source") {
    scene.infos[0].mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
    scene.infos[0].srcAccelerationStructure = f.Structure(buffer, 0, FakeSizes::Structure(1), kBottom);
    f.Validate(scene.Command());
    CHECK(f.Take() == std::vector<std::string>{"VUID-vkBuildAccelerationStructuresKHR-pInfos-03776"});
  }
  SECTION("03777: a structure the instances reference") {
    scene.instances[0].accelerationStructureReference =
        reinterpret_cast<uint64_t>(f.Structure(buffer, 0, FakeSizes::Structure(1), kBottom));
    f.Validate(scene.Command());
    CHECK(f.Take() == std::vector<std::string>{"VUID-vkBuildAccelerationStructuresKHR-pInfos-03777"});
  }
}

TEST_CASE("host valid twin: one device of a group, and a one-bit device mask, are single-instance memory",
          "[host][valid]") {
  BuildStateFixture f;
  // Heap 1 is MULTI_INSTANCE, but the device was not created over several physical devices.
  HostScene scene(f, 4, 2);
  const VkDeviceMemory one_bit = f.Memory(1 << 20, 0, 0b10);
  scene.infos[0].dstAccelerationStructure =
      f.Structure(f.Buffer(1 << 20, kAsStorage, one_bit), 0, FakeSizes::Structure(1), kBottom);
  f.Validate(scene.Command());
  CHECK(f.Take().empty());
}

TEST_CASE("pInfos-03725 / 03726: a null scratch pointer when the driver needs scratch", "[host][03725][03726]") {
  BuildStateFixture f;
  HostScene scene(f);
  scene.infos[0].scratchData.hostAddress = nullptr;
  f.Validate(scene.Command());
  CHECK(f.Take() == std::vector<std::string>{"VUID-vkBuildAccelerationStructuresKHR-pInfos-03725"});
  scene.infos[0].mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  scene.infos[0].srcAccelerationStructure = scene.blas;
  f.Validate(scene.Command());
  CHECK(f.Take() == std::vector<std::string>{"VUID-vkBuildAccelerationStructuresKHR-pInfos-03726"});
}

TEST_CASE("pInfos-03725 / 03726: host scratch inside a mapping must fit before the mapping ends", "[host][03725]") {
  BuildStateFixture f;
  HostScene scene(f);
  const VkDeviceMemory a = f.Memory(4096);
  const VkDeviceMemory b = f.Memory(4096);
  static unsigned char bytes[8192];
  f.state.host_mappings.Map(a, 0, 4096, bytes);
  const VkDeviceSize needed = FakeSizes::BuildScratch(1);
  SECTION("valid twin: inside one mapping") {
    scene.infos[0].scratchData.hostAddress = bytes + 4096 - needed;
    f.Validate(scene.Command());
    CHECK(f.Take().empty());
  }
  SECTION("past the end of the mapping") {
    scene.infos[0].scratchData.hostAddress = bytes + 4096 - needed + 8;
    f.Validate(scene.Command());
    CHECK(f.Take() == std::vector<std::string>{"VUID-vkBuildAccelerationStructuresKHR-pInfos-03725"});
  }
  SECTION("valid twin: across two mappings that follow each other") {
    f.state.host_mappings.Map(b, 0, 4096, bytes + 4096);
    scene.infos[0].scratchData.hostAddress = bytes + 4096 - 8;
    f.Validate(scene.Command());
    CHECK(f.Take().empty());
  }
  SECTION("valid twin: the mapping was unmapped, nothing is known") {
    f.state.host_mappings.Unmap(a);
    scene.infos[0].scratchData.hostAddress = bytes + 4096 - 8;
    f.Validate(scene.Command());
    CHECK(f.Take().empty());
  }
}

TEST_CASE("host mappings: lookups, re-mapping, stale records", "[host][mappings]") {
  HostMappings mappings;
  const auto a = reinterpret_cast<VkDeviceMemory>(uint64_t{1});
  const auto b = reinterpret_cast<VkDeviceMemory>(uint64_t{2});
  static unsigned char bytes[4096];
  const auto base = reinterpret_cast<uintptr_t>(bytes);
  mappings.Map(a, 64, 1024, bytes);
  REQUIRE(mappings.Containing(base + 1023));
  CHECK(mappings.Containing(base + 1023)->offset == 64);
  CHECK_FALSE(mappings.Containing(base + 1024));
  CHECK(mappings.ContiguousEnd(base) == base + 1024);
  // b is mapped over a's old range: a's record was stale (a was freed or unmapped behind the layer's back).
  mappings.Map(b, 0, 2048, bytes + 512);
  CHECK_FALSE(mappings.Containing(base));
  CHECK(mappings.Containing(base + 512)->memory == b);
  CHECK(mappings.size() == 1);
  mappings.Unmap(b);
  CHECK(mappings.size() == 0);
}

TEST_CASE("pInfos-03771 / 03772 / 03774 / 03778: null input pointers of geometries that build primitives",
          "[host][03771][03772][03774][03778]") {
  BuildStateFixture f;
  HostScene scene(f);
  VkAccelerationStructureGeometryKHR aabbs{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  aabbs.geometryType = VK_GEOMETRY_TYPE_AABBS_KHR;
  aabbs.geometry.aabbs.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_AABBS_DATA_KHR;
  aabbs.geometry.aabbs.stride = 24;
  const char* expected = nullptr;
  SECTION("03771: vertexData") {
    scene.triangles.geometry.triangles.vertexData.hostAddress = nullptr;
    expected = "VUID-vkBuildAccelerationStructuresKHR-pInfos-03771";
  }
  SECTION("03772: indexData of an indexed geometry") {
    scene.triangles.geometry.triangles.indexType = VK_INDEX_TYPE_UINT32;
    expected = "VUID-vkBuildAccelerationStructuresKHR-pInfos-03772";
  }
  SECTION("03774: AABB data") {
    scene.infos[0].pGeometries = &aabbs;
    expected = "VUID-vkBuildAccelerationStructuresKHR-pInfos-03774";
  }
  SECTION("03778: instance data") {
    scene.instance_geometry.geometry.instances.data.hostAddress = nullptr;
    expected = "VUID-vkBuildAccelerationStructuresKHR-pInfos-03778";
  }
  f.Validate(scene.Command());
  CHECK(f.Take() == std::vector<std::string>{expected});
}

TEST_CASE("pInfos-03779: an instance referencing a destroyed structure; arrays of pointers are read too",
          "[host][03779]") {
  BuildStateFixture f;
  HostScene scene(f, 8);
  const VkAccelerationStructureKHR gone = f.Structure(scene.storage, 256 * 1024, FakeSizes::Structure(1), kBottom);
  f.DestroyStructure(gone);
  SECTION("array of structures") {
    scene.instances[5].accelerationStructureReference = reinterpret_cast<uint64_t>(gone);
    f.Validate(scene.Command());
    CHECK(f.Take() == std::vector<std::string>{"VUID-vkBuildAccelerationStructuresKHR-pInfos-03779"});
  }
  SECTION("array of pointers, with an inactive (reference 0) instance") {
    scene.instances[5].accelerationStructureReference = reinterpret_cast<uint64_t>(gone);
    scene.instances[6].accelerationStructureReference = 0;
    std::vector<const VkAccelerationStructureInstanceKHR*> pointers;
    for (const auto& instance : scene.instances) pointers.push_back(&instance);
    scene.instance_geometry.geometry.instances.arrayOfPointers = VK_TRUE;
    scene.instance_geometry.geometry.instances.data.hostAddress = pointers.data();
    f.Validate(scene.Command());
    const std::vector<std::string> ids = f.Take();
    CHECK(ids == std::vector<std::string>{"VUID-vkBuildAccelerationStructuresKHR-pInfos-03779"});
  }
}

TEST_CASE("None-03407 / dstAccelerationStructure-03706 valid twin: instances of a BLAS this command does not write",
          "[host][aliasing][valid]") {
  BuildStateFixture f;
  HostScene scene(f);
  f.Validate(scene.Command());
  CHECK(f.Take().empty());
}

TEST_CASE("None-03407: host TLAS instances referencing another info's destination", "[host][aliasing][03407]") {
  BuildStateFixture f;
  HostScene scene(f, 16);
  scene.instances[3].accelerationStructureReference = reinterpret_cast<uint64_t>(scene.blas);
  f.Validate(scene.Command());
  // The BLAS's bytes are also read through the instance while info 0 writes them: 03706 as well.
  CHECK(f.Take() == std::vector<std::string>{"VUID-vkBuildAccelerationStructuresKHR-dstAccelerationStructure-03706",
                                             "VUID-vkBuildAccelerationStructuresKHR-None-03407"});
}

TEST_CASE("deferredOperation-03678: a deferred operation still running an earlier host build", "[host][03678]") {
  BuildStateFixture f;
  HostScene scene(f);
  const auto operation = reinterpret_cast<VkDeferredOperationKHR>(uint64_t{0x5000});
  BuildCommand first = scene.Command();
  first.deferred_operation = operation;
  // The first build went down and was deferred.
  FinishHostOps(f.state, HostBuildOps(first.info_count, first.infos, first.ranges), first.deferred_operation,
                VK_OPERATION_DEFERRED_KHR);
  BuildCommand second = scene.Command();
  second.deferred_operation = operation;
  f.Validate(second);
  CHECK(f.Take() == std::vector<std::string>{"VUID-vkBuildAccelerationStructuresKHR-deferredOperation-03678"});
  // Once the layer sees it complete, the operation may be reused.
  CompleteDeferredOps(f.state, operation, VK_SUCCESS);
  f.Validate(second);
  CHECK(f.Take().empty());
}

// The host copies and property writes share the host build's judge of a structure's memory (host_memory.h); here
// what the test driver cannot give through the loader: memory of several instances (a device group).
TEST_CASE("buffer-03780 / 03781 / 03782 / 03783 / 03784: host copies and property writes on memory allocated "
          "with multiple instances",
          "[host][03780][03781][03782][03783][03784]") {
  BuildStateFixture f;
  const CheckContext ctx{f.state, f.reporter, kCheckHost};
  const VkBuffer single = f.Buffer(1 << 20, kAsStorage, f.Memory(1 << 20));
  const VkBuffer shared = f.Buffer(1 << 20, kAsStorage, f.Memory(1 << 20, 0, 0b11));
  const VkAccelerationStructureKHR good = f.Structure(single, 0, 4096, kBottom);
  const VkAccelerationStructureKHR bad = f.Structure(shared, 0, 4096, kBottom);
  alignas(16) unsigned char bytes[64] = {};
  VkCopyAccelerationStructureInfoKHR copy{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR};
  copy.src = good;
  copy.dst = good;
  CHECK_FALSE(ValidateHostCopyStructures(ctx, copy));  // the valid twin: one instance, host-visible
  CHECK(f.Take().empty());
  copy.src = bad;
  ValidateHostCopyStructures(ctx, copy);
  CHECK(f.Take() == std::vector<std::string>{"VUID-vkCopyAccelerationStructureKHR-buffer-03780"});
  copy.src = good;
  copy.dst = bad;
  ValidateHostCopyStructures(ctx, copy);
  CHECK(f.Take() == std::vector<std::string>{"VUID-vkCopyAccelerationStructureKHR-buffer-03781"});
  VkCopyMemoryToAccelerationStructureInfoKHR from{VK_STRUCTURE_TYPE_COPY_MEMORY_TO_ACCELERATION_STRUCTURE_INFO_KHR};
  from.src.hostAddress = bytes;
  from.dst = bad;
  ValidateHostCopyMemoryTo(ctx, from);
  CHECK(f.Take() == std::vector<std::string>{"VUID-vkCopyMemoryToAccelerationStructureKHR-buffer-03782"});
  VkCopyAccelerationStructureToMemoryInfoKHR to{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_TO_MEMORY_INFO_KHR};
  to.src = bad;
  to.dst.hostAddress = bytes;
  ValidateHostCopyToMemory(ctx, to);
  CHECK(f.Take() == std::vector<std::string>{"VUID-vkCopyAccelerationStructureToMemoryKHR-buffer-03783"});
  const VkAccelerationStructureKHR queried[3] = {good, bad, bad};
  ValidateHostPropertyStructures(ctx, 3, queried);
  CHECK(f.Take() == std::vector<std::string>{"VUID-vkWriteAccelerationStructuresPropertiesKHR-buffer-03784"});
  CHECK_FALSE(ValidateHostPropertyStructures(ctx, 1, &good));
  CHECK(f.Take().empty());
}

TEST_CASE("host copies unit: structures the layer does not know are skipped and counted, never reported", "[host]") {
  BuildStateFixture f;
  const CheckContext ctx{f.state, f.reporter, kCheckHost};
  const auto unknown = reinterpret_cast<VkAccelerationStructureKHR>(uintptr_t{0xdead0});
  const uint64_t before = f.state.checks_skipped_unknown_state.load();
  VkCopyAccelerationStructureInfoKHR copy{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR};
  copy.src = unknown;
  copy.dst = unknown;
  CHECK_FALSE(ValidateHostCopyStructures(ctx, copy));
  CHECK_FALSE(ValidateHostPropertyStructures(ctx, 1, &unknown));
  CHECK(f.Take().empty());
  CHECK(f.state.checks_skipped_unknown_state.load() == before + 3);
}

}  // namespace
}  // namespace asval
