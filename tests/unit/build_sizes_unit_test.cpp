// The size cache and the size-dependent rules without a driver: what is cached and what is not, when the
// layer does not ask the driver at all, and the valid twins of indirect builds (lavapipe has none).
#include <catch2/catch_test_macros.hpp>

#include <vector>

#include "build_sizes.h"
#include "build_state_fixture.h"

namespace asval {
namespace {

constexpr VkBufferUsageFlags kInput = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;
constexpr VkAccelerationStructureTypeKHR kBottom = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;

BuildSignature Signature(const VkAccelerationStructureBuildGeometryInfoKHR& info, const std::vector<uint32_t>& counts) {
  return BuildSignature{VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info, counts.data(), sizeof(uint32_t)};
}

TEST_CASE("size cache: a steady stream of the same build asks the driver once", "[sizes][cache]") {
  BuildStateFixture f;
  const VkAccelerationStructureGeometryKHR g = TriangleGeometry(0x1000);
  VkAccelerationStructureBuildGeometryInfoKHR info = OneGeometryInfo(kBottom, &g);
  const std::vector<uint32_t> counts = {7};
  BuildSizes sizes;
  CHECK_FALSE(f.state.build_sizes.Find(Signature(info, counts), &sizes));
  REQUIRE(f.state.build_sizes.Query(Signature(info, counts)));
  for (int call = 0; call < 1000; ++call) {
    // Handles, addresses and mode do not change the signature.
    info.mode = call % 2 ? VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR : VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    info.dstAccelerationStructure = reinterpret_cast<VkAccelerationStructureKHR>(uint64_t{0x100} + call);
    info.scratchData.deviceAddress = 0x10000 * call;
    REQUIRE(f.state.build_sizes.Find(Signature(info, counts), &sizes));
  }
  CHECK(sizes.acceleration_structure_size == FakeSizes::Structure(7));
  CHECK(sizes.build_scratch_size == FakeSizes::BuildScratch(7));
  CHECK(f.state.build_sizes.queries() == 1);
  CHECK(FakeSizes::queries == 1);
}

TEST_CASE("size cache: a build of 256 geometries is found, and a change in its last count is seen", "[sizes][cache]") {
  // Longer than the lookup's stack buffer (102 geometries): read into the per-thread buffer, in one pass.
  BuildStateFixture f;
  const std::vector<VkAccelerationStructureGeometryKHR> geometries(256, TriangleGeometry(0x1000));
  VkAccelerationStructureBuildGeometryInfoKHR info = OneGeometryInfo(kBottom, geometries.data());
  info.geometryCount = 256;
  std::vector<uint32_t> counts(256, 1);
  BuildSizes sizes;
  CHECK_FALSE(f.state.build_sizes.Find(Signature(info, counts), &sizes));
  REQUIRE(f.state.build_sizes.Query(Signature(info, counts)));
  REQUIRE(f.state.build_sizes.Find(Signature(info, counts), &sizes));
  CHECK(sizes.acceleration_structure_size == FakeSizes::Structure(256));
  counts.back() = 2;
  CHECK_FALSE(f.state.build_sizes.Find(Signature(info, counts), &sizes));
  counts.back() = 1;
  CHECK(f.state.build_sizes.Find(Signature(info, counts), &sizes));
  CHECK(f.state.build_sizes.queries() == 1);
}

TEST_CASE("size cache: an array seen last time is compared byte for byte, and any change is still seen",
          "[sizes][cache]") {
  // From 4 geometries, the arrays' slot compares the geometry structs and counts raw (memcmp) first; a raw
  // difference goes to the word compare, so only what the signature holds may change the answer.
  BuildStateFixture f;
  std::vector<VkAccelerationStructureGeometryKHR> geometries(8, TriangleGeometry(0x1000));
  VkAccelerationStructureBuildGeometryInfoKHR info = OneGeometryInfo(kBottom, geometries.data());
  info.geometryCount = 8;
  std::vector<uint32_t> counts(8, 2);
  BuildSizes sizes;
  REQUIRE(f.state.build_sizes.Query(Signature(info, counts)));
  REQUIRE(f.state.build_sizes.Find(Signature(info, counts), &sizes));
  REQUIRE(f.state.build_sizes.Find(Signature(info, counts), &sizes));  // the raw compare answers
  geometries[3].geometry.triangles.vertexData.deviceAddress = 0x9000;  // not in the signature: still found
  CHECK(f.state.build_sizes.Find(Signature(info, counts), &sizes));
  geometries[5].geometry.triangles.maxVertex += 1;
  CHECK_FALSE(f.state.build_sizes.Find(Signature(info, counts), &sizes));
  geometries[5].geometry.triangles.maxVertex -= 1;
  CHECK(f.state.build_sizes.Find(Signature(info, counts), &sizes));
  counts[6] = 3;
  CHECK_FALSE(f.state.build_sizes.Find(Signature(info, counts), &sizes));
  counts[6] = 2;
  const VkAccelerationStructureGeometryMotionTrianglesDataNV motion{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_MOTION_TRIANGLES_DATA_NV};
  geometries[7].geometry.triangles.pNext = &motion;
  CHECK_FALSE(f.state.build_sizes.Find(Signature(info, counts), &sizes));
  geometries[7].geometry.triangles.pNext = nullptr;
  info.flags |= VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR;
  CHECK_FALSE(f.state.build_sizes.Find(Signature(info, counts), &sizes));
  info.flags = OneGeometryInfo(kBottom, geometries.data()).flags;
  info.geometryCount = 7;
  CHECK_FALSE(f.state.build_sizes.Find(Signature(info, counts), &sizes));
  info.geometryCount = 8;
  REQUIRE(f.state.build_sizes.Find(Signature(info, counts), &sizes));
  CHECK(sizes.acceleration_structure_size == FakeSizes::Structure(16));
  CHECK(f.state.build_sizes.queries() == 1);
}

TEST_CASE("size cache: counts, formats, flags and geometry counts are part of the signature", "[sizes][cache]") {
  BuildStateFixture f;
  VkAccelerationStructureGeometryKHR g = TriangleGeometry(0x1000);
  VkAccelerationStructureBuildGeometryInfoKHR info = OneGeometryInfo(kBottom, &g);
  BuildSizes sizes;
  REQUIRE(f.state.build_sizes.Query(Signature(info, {1})));
  CHECK_FALSE(f.state.build_sizes.Find(Signature(info, {2}), &sizes));
  g.geometry.triangles.maxVertex = 3;
  CHECK_FALSE(f.state.build_sizes.Find(Signature(info, {1}), &sizes));
  g.geometry.triangles.maxVertex = 2;
  info.flags |= VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR;
  CHECK_FALSE(f.state.build_sizes.Find(Signature(info, {1}), &sizes));
  info.flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;
  CHECK(f.state.build_sizes.Find(Signature(info, {1}), &sizes));
  // Extension structures may change the sizes: never cached, never matched.
  const VkAccelerationStructureGeometryMotionTrianglesDataNV motion{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_MOTION_TRIANGLES_DATA_NV};
  g.geometry.triangles.pNext = &motion;
  CHECK_FALSE(f.state.build_sizes.Find(Signature(info, {1}), &sizes));
  REQUIRE(f.state.build_sizes.Query(Signature(info, {1})));
  CHECK_FALSE(f.state.build_sizes.Find(Signature(info, {1}), &sizes));
}

TEST_CASE("size cache: builds of more geometries than fit on the stack", "[sizes][cache]") {
  BuildStateFixture f;
  std::vector<VkAccelerationStructureGeometryKHR> geometries(200, TriangleGeometry(0x1000));
  VkAccelerationStructureBuildGeometryInfoKHR info = OneGeometryInfo(kBottom, geometries.data());
  info.geometryCount = 200;
  std::vector<uint32_t> counts(200, 3);
  const std::optional<BuildSizes> sizes = f.state.build_sizes.Query(Signature(info, counts));
  REQUIRE(sizes);
  CHECK(sizes->acceleration_structure_size == FakeSizes::Structure(600));
  BuildSizes found;
  CHECK(f.state.build_sizes.Find(Signature(info, counts), &found));
  counts[199] = 4;
  CHECK_FALSE(f.state.build_sizes.Find(Signature(info, counts), &found));
}

TEST_CASE("sizes: the layer does not ask the driver when the query itself would be invalid", "[sizes]") {
  BuildStateFixture f;
  VkAccelerationStructureGeometryKHR g = TriangleGeometry(0x1000);
  VkAccelerationStructureBuildGeometryInfoKHR info = OneGeometryInfo(kBottom, &g);
  CHECK(SizeQueryIsValid(f.state, Signature(info, {1})));
  SECTION("neither rayQuery nor rayTracingPipeline enabled") { f.state.features.ray_query = false; }
  SECTION("both PREFER_FAST_TRACE and PREFER_FAST_BUILD") {
    info.flags |= VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR |
                  VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR;
  }
  SECTION("a vertex format without acceleration-structure support") {
    g.geometry.triangles.vertexFormat = VK_FORMAT_R16G16_SFLOAT;
  }
  SECTION("a stride that is not a multiple of the component size") { g.geometry.triangles.vertexStride = 13; }
  SECTION("a generic structure type") { info.type = VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR; }
  SECTION("more primitives than maxPrimitiveCount") {
    f.state.properties.acceleration_structure.maxPrimitiveCount = 4;
    CHECK_FALSE(SizeQueryIsValid(f.state, Signature(info, {5})));
  }
  CHECK_FALSE(SizeQueryIsValid(f.state, Signature(info, {5})));
}

TEST_CASE("sizes: without a size, the size rules are skipped and counted, never guessed", "[sizes]") {
  BuildStateFixture f;
  f.state.features.ray_query = false;  // the query would be invalid: no sizes
  const VkDeviceMemory memory = f.Memory(1 << 20);
  const VkBuffer storage = f.Buffer(1 << 16, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR, memory);
  const VkBuffer input = f.Buffer(1024, kInput, memory, 1 << 16);
  const VkBuffer indirect = f.Buffer(1024, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, memory, 2 << 16);
  VkAccelerationStructureGeometryKHR g = TriangleGeometry(f.AddressOf(input));
  VkAccelerationStructureBuildGeometryInfoKHR info = OneGeometryInfo(kBottom, &g);
  info.dstAccelerationStructure = f.Structure(storage, 0, 16, kBottom);  // far too small, but unknown
  info.scratchData.deviceAddress = 0x100;                               // no buffer: size unknown
  const uint32_t counts[1] = {1};
  const uint32_t* max_counts[1] = {counts};
  const VkDeviceAddress ranges = f.AddressOf(indirect);
  const uint32_t stride = 16;
  const uint64_t skipped = f.state.checks_skipped_unknown_state.load();
  f.Validate(IndirectBuild(1, &info, &ranges, &stride, max_counts));
  CHECK(f.Take().empty());
  CHECK(f.state.checks_skipped_unknown_state.load() > skipped);
  CHECK(FakeSizes::queries == 0);
}

// Indirect builds: lavapipe has no accelerationStructureIndirectBuild, so their valid twin runs here.
TEST_CASE("indirect valid twin: inputs, ranges, scratch slices and destinations all in place", "[sizes][valid]") {
  BuildStateFixture f;
  const VkDeviceMemory memory = f.Memory(1 << 24);
  const VkBuffer storage = f.Buffer(1 << 20, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR, memory);
  const VkBuffer scratch = f.Buffer(1 << 20, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT, memory, 1 << 20);
  const VkBuffer input = f.Buffer(4096, kInput, memory, 2 << 20);
  const VkBuffer indirect = f.Buffer(4096, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, memory, 3 << 20);
  constexpr uint32_t kInfos = 256;
  const VkAccelerationStructureGeometryKHR g = TriangleGeometry(f.AddressOf(input));
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos(kInfos, OneGeometryInfo(kBottom, &g));
  const uint32_t max_count[1] = {10};
  std::vector<const uint32_t*> max_counts(kInfos, max_count);
  std::vector<VkDeviceAddress> addresses(kInfos, f.AddressOf(indirect));
  std::vector<uint32_t> strides(kInfos, 16);
  for (uint32_t i = 0; i < kInfos; ++i) {
    infos[i].dstAccelerationStructure = f.Structure(storage, 4096 * i, FakeSizes::Structure(10), kBottom);
    infos[i].scratchData.deviceAddress = f.AddressOf(scratch) + 1024 * i;  // slices of 1024 >= 128 + 160
  }
  f.Validate(IndirectBuild(kInfos, infos.data(), addresses.data(), strides.data(), max_counts.data()));
  CHECK(f.Take().empty());
  CHECK(FakeSizes::queries == 1);  // one signature for all 256 infos
}

TEST_CASE("indirect valid twin: a zero-size scratch needs no scratch address", "[sizes][valid]") {
  BuildStateFixture f;
  FakeSizes::update_scratch_zero = true;
  const VkDeviceMemory memory = f.Memory(1 << 20);
  const VkBuffer storage = f.Buffer(1 << 16, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR, memory);
  const VkBuffer input = f.Buffer(1024, kInput, memory, 1 << 16);
  const VkBuffer indirect = f.Buffer(1024, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT, memory, 2 << 16);
  const VkAccelerationStructureGeometryKHR g = TriangleGeometry(f.AddressOf(input));
  VkAccelerationStructureBuildGeometryInfoKHR info = OneGeometryInfo(kBottom, &g);
  info.dstAccelerationStructure = f.Structure(storage, 0, FakeSizes::Structure(1), kBottom);
  info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  info.srcAccelerationStructure = info.dstAccelerationStructure;
  info.scratchData.deviceAddress = 0;
  const uint32_t counts[1] = {1};
  const uint32_t* max_counts[1] = {counts};
  const VkDeviceAddress ranges = f.AddressOf(indirect);
  const uint32_t stride = 16;
  f.Validate(IndirectBuild(1, &info, &ranges, &stride, max_counts));
  CHECK(f.Take().empty());
}

}  // namespace
}  // namespace asval
