// The record-time rule families (features, handles, structure, alignment) without a driver. Above all the
// valid twins of indirect and host builds, which lavapipe cannot run: with their features enabled, every
// valid pattern stays silent. Then what a driver-backed test cannot show: unknown state is skipped and
// counted, newer extensions' values are left alone, the largest-index read of host builds.
#include <catch2/catch_test_macros.hpp>

#include <cstring>

#include "format_features.h"
#include "record_checks_harness.h"
#include "vertex_format_alignment.h"

namespace asval::test {
namespace {

using Ranges = std::vector<VkAccelerationStructureBuildRangeInfoKHR>;

constexpr BuildCommandKind kIndirect = BuildCommandKind::kCmdBuildIndirect;
constexpr BuildCommandKind kHost = BuildCommandKind::kHostBuild;
constexpr BuildCommandKind kDirect = BuildCommandKind::kCmdBuild;

// Build inputs in host memory, aligned as the device rules want: host builds read them (indices), device
// builds only look at the numbers.
struct Inputs {
  alignas(16) float vertices[12] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0};
  alignas(16) uint32_t indices32[6] = {0, 1, 2, 1, 2, 3};
  alignas(16) uint16_t indices16[6] = {0, 1, 2, 1, 2, 3};
  alignas(16) float transforms[24] = {};
  alignas(16) float boxes[12] = {0, 0, 0, 1, 1, 1, 2, 2, 2, 3, 3, 3};
  alignas(16) VkAccelerationStructureInstanceKHR instances[2] = {};
  alignas(16) uint64_t pointers[2] = {};

  static uint64_t At(const void* p) { return reinterpret_cast<uint64_t>(p); }
};

std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> Each(const Ranges& ranges, size_t infos) {
  return std::vector<const VkAccelerationStructureBuildRangeInfoKHR*>(infos, ranges.data());
}

constexpr uint64_t kScratch = 0x100000;

TEST_CASE("record checks: valid indirect and host builds of every kind stay silent with their features enabled",
          "[unit][record]") {
  RecordHarness h;
  Inputs in;
  const VkAccelerationStructureKHR blas = h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  const VkAccelerationStructureKHR generic = h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR);
  const VkAccelerationStructureKHR tlas = h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR);
  const VkAccelerationStructureGeometryKHR triangles[3] = {
      TrianglesAt(Inputs::At(in.vertices)),
      TrianglesAt(Inputs::At(in.vertices), Inputs::At(in.indices16), VK_INDEX_TYPE_UINT16, Inputs::At(in.transforms)),
      TrianglesAt(Inputs::At(in.vertices), Inputs::At(in.indices32), VK_INDEX_TYPE_UINT32, Inputs::At(in.transforms))};
  const VkAccelerationStructureGeometryKHR* triangle_pointers[3] = {&triangles[0], &triangles[1], &triangles[2]};
  const VkAccelerationStructureGeometryKHR boxes[2] = {AabbsAt(Inputs::At(in.boxes)), AabbsAt(Inputs::At(in.boxes), 48)};
  const VkAccelerationStructureGeometryKHR instances = InstancesAt(Inputs::At(in.instances));
  const VkAccelerationStructureGeometryKHR pointers = InstancesAt(Inputs::At(in.pointers), true);
  const Ranges ranges(3, VkAccelerationStructureBuildRangeInfoKHR{1, 0, 0, 48});  // transformOffset 48: the second
  const Ranges offset_ranges(3, VkAccelerationStructureBuildRangeInfoKHR{1, 4, 0, 0});  // uint16: index 2 on

  for (BuildCommandKind kind : {kIndirect, kHost}) {
    INFO("kind " << static_cast<int>(kind));
    // Bottom level through pGeometries and ppGeometries, into a structure created generic, with transforms.
    VkAccelerationStructureBuildGeometryInfoKHR bottom =
        InfoOf(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, triangles, 3, blas, kScratch);
    VkAccelerationStructureBuildGeometryInfoKHR by_pointer = bottom;
    by_pointer.pGeometries = nullptr;
    by_pointer.ppGeometries = triangle_pointers;
    by_pointer.dstAccelerationStructure = generic;
    by_pointer.scratchData.deviceAddress = kScratch + 128;
    CHECK(h.Run(kind, {bottom, by_pointer}, Each(ranges, 2)).empty());
    // Index offsets that are multiples of the index size.
    CHECK(h.Run(kind, {bottom}, {offset_ranges.data()}).empty());
    // AABBs with strides 24 and 48; instances and instance pointers at the top.
    CHECK(h.Run(kind, {InfoOf(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, boxes, 2, blas, kScratch)},
                {ranges.data()})
              .empty());
    CHECK(h.Run(kind, {InfoOf(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, &instances, 1, tlas, kScratch)},
                {ranges.data()})
              .empty());
    CHECK(h.Run(kind, {InfoOf(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, &pointers, 1, tlas, kScratch)},
                {ranges.data()})
              .empty());
    // An in-place update, and an update into another structure.
    VkAccelerationStructureBuildGeometryInfoKHR update = bottom;
    update.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
    update.srcAccelerationStructure = blas;
    CHECK(h.Run(kind, {update}, {ranges.data()}).empty());
    update.dstAccelerationStructure = generic;
    CHECK(h.Run(kind, {update}, {ranges.data()}).empty());
    // 64 infos with their own destinations and 128-byte scratch slices.
    std::vector<VkAccelerationStructureBuildGeometryInfoKHR> many;
    for (int k = 0; k < 64; ++k) {
      many.push_back(InfoOf(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, triangles, 1,
                            h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR), kScratch + 128 * k));
    }
    CHECK(h.Run(kind, many, Each(ranges, 64)).empty());
    CHECK(h.texts().empty());
  }
  // Indirect arrays at 4-byte multiples that are not 8- or 16-byte multiples.
  CHECK(h.RunIndirect({InfoOf(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, triangles, 1, blas, kScratch)},
                      {0x10004}, {12})
            .empty());
}

TEST_CASE("record checks: the three commands report their own VUID names", "[unit][record]") {
  RecordHarness h;
  Inputs in;
  const VkAccelerationStructureGeometryKHR triangles = TrianglesAt(Inputs::At(in.vertices));
  VkAccelerationStructureBuildGeometryInfoKHR info = InfoOf(
      VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, &triangles, 1,
      h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR), kScratch);
  info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;  // without a source
  const Ranges ranges(1, VkAccelerationStructureBuildRangeInfoKHR{1, 0, 0, 0});
  CHECK(h.Run(kDirect, {info}, {ranges.data()}) ==
        std::vector<std::string>{"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-04630"});
  CHECK(h.Run(kIndirect, {info}, {ranges.data()}) ==
        std::vector<std::string>{"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-04630"});
  CHECK(h.Run(kHost, {info}, {ranges.data()}) ==
        std::vector<std::string>{"VUID-vkBuildAccelerationStructuresKHR-pInfos-04630"});
  // The features the indirect and host commands need.
  h.state().features.acceleration_structure_indirect_build = false;
  h.state().features.acceleration_structure_host_commands = false;
  info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  CHECK(h.Run(kIndirect, {info}, {ranges.data()}) ==
        std::vector<std::string>{"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-accelerationStructureIndirectBuild-03650"});
  CHECK(h.Run(kHost, {info}, {ranges.data()}) ==
        std::vector<std::string>{"VUID-vkBuildAccelerationStructuresKHR-accelerationStructureHostCommands-03581"});
  CHECK(h.Run(kDirect, {info}, {ranges.data()}).empty());
}

TEST_CASE("record checks: shared destinations and sources are found the same way in few and many infos",
          "[unit][record][03698][03403]") {
  RecordHarness h;
  Inputs in;
  const VkAccelerationStructureGeometryKHR triangles = TrianglesAt(Inputs::At(in.vertices));
  const Ranges ranges(1, VkAccelerationStructureBuildRangeInfoKHR{1, 0, 0, 0});
  // 10 infos take the pairwise path, 40 the sorted one.
  for (uint32_t count : {10u, 40u}) {
    INFO(count << " infos");
    std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos;
    for (uint32_t k = 0; k < count; ++k) {
      infos.push_back(InfoOf(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, &triangles, 1,
                             h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR), kScratch + 128 * k));
    }
    // Three infos write one structure; one info updates from another's destination; one updates in place.
    infos[7].dstAccelerationStructure = infos[2].dstAccelerationStructure;
    infos[9].dstAccelerationStructure = infos[2].dstAccelerationStructure;
    infos[4].mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
    infos[4].srcAccelerationStructure = infos[8].dstAccelerationStructure;
    infos[5].mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
    infos[5].srcAccelerationStructure = infos[5].dstAccelerationStructure;
    CHECK(h.Run(kDirect, infos, Each(ranges, count), kCheckHandles) ==
          std::vector<std::string>{"VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03698",
                                   "VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03698",
                                   "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03403"});
    REQUIRE(h.texts().size() == 3);
    CHECK(h.texts()[0].find("pInfos[7].dstAccelerationStructure") != std::string::npos);
    CHECK(h.texts()[0].find("of pInfos[2]") != std::string::npos);
    CHECK(h.texts()[1].find("pInfos[9].dstAccelerationStructure") != std::string::npos);
    CHECK(h.texts()[1].find("of pInfos[2]") != std::string::npos);
    CHECK(h.texts()[2].find("pInfos[4].srcAccelerationStructure") != std::string::npos);
    CHECK(h.texts()[2].find("of pInfos[8]") != std::string::npos);
  }
}

TEST_CASE("record checks: host builds compare the largest index they read with maxVertex (maxVertex-10774)",
          "[unit][record][10774]") {
  RecordHarness h;
  Inputs in;
  const VkAccelerationStructureKHR blas = h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  for (VkIndexType type : {VK_INDEX_TYPE_UINT16, VK_INDEX_TYPE_UINT32}) {
    INFO("index type " << type);
    const uint64_t indices = type == VK_INDEX_TYPE_UINT16 ? Inputs::At(in.indices16) : Inputs::At(in.indices32);
    VkAccelerationStructureGeometryKHR g = TrianglesAt(Inputs::At(in.vertices), indices, type);
    const VkAccelerationStructureBuildGeometryInfoKHR info =
        InfoOf(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, &g, 1, blas, kScratch);
    const VkAccelerationStructureBuildRangeInfoKHR both{2, 0, 0, 0};  // indices 0..3
    g.geometry.triangles.maxVertex = 3;
    CHECK(h.Run(kHost, {info}, {&both}).empty());
    g.geometry.triangles.maxVertex = 2;
    CHECK(h.Run(kHost, {info}, {&both}) ==
          std::vector<std::string>{"VUID-VkAccelerationStructureBuildRangeInfoKHR-maxVertex-10774"});
    // Only the range the build reads counts: the first triangle's indices are 0..2.
    const VkAccelerationStructureBuildRangeInfoKHR first{1, 0, 0, 0};
    CHECK(h.Run(kHost, {info}, {&first}).empty());
    // Device builds: the indices are device memory, not read at record time.
    CHECK(h.Run(kDirect, {info}, {&both}).empty());
  }
}

TEST_CASE("record checks: flag bits, geometry types and structures of newer extensions are not judged",
          "[unit][record]") {
  RecordHarness h;
  Inputs in;
  const VkAccelerationStructureKHR blas = h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  // VK_KHR_ray_tracing_position_fetch's ALLOW_DATA_ACCESS (0x800) and higher bits the headers do not name.
  VkAccelerationStructureGeometryKHR triangles = TrianglesAt(Inputs::At(in.vertices));
  struct Unknown {
    VkStructureType sType;
    const void* pNext;
  } unknown{static_cast<VkStructureType>(1000999000), nullptr};
  triangles.pNext = &unknown;
  triangles.geometry.triangles.pNext = &unknown;
  VkAccelerationStructureBuildGeometryInfoKHR info =
      InfoOf(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, &triangles, 1, blas, kScratch);
  info.flags |= 0x800 | 0x10000;
  const Ranges ranges(1, VkAccelerationStructureBuildRangeInfoKHR{1, 0, 0, 0});
  for (BuildCommandKind kind : {kDirect, kIndirect, kHost}) CHECK(h.Run(kind, {info}, {ranges.data()}).empty());
  // Spheres (VK_NV_ray_tracing_linear_swept_spheres, newer than the headers) in a bottom-level build.
  VkAccelerationStructureGeometryKHR spheres{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  spheres.geometryType = static_cast<VkGeometryTypeKHR>(1000429004);
  std::memset(&spheres.geometry, 0x7, sizeof(spheres.geometry));  // whatever its data is, it is not read
  const VkAccelerationStructureBuildGeometryInfoKHR sphere_info =
      InfoOf(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, &spheres, 1, blas, kScratch);
  const Ranges odd(1, VkAccelerationStructureBuildRangeInfoKHR{1, 3, 0, 5});
  for (BuildCommandKind kind : {kDirect, kIndirect, kHost}) CHECK(h.Run(kind, {sphere_info}, {odd.data()}).empty());
}

TEST_CASE("record checks: unknown state is skipped and counted, never guessed", "[unit][record]") {
  RecordHarness h;
  Inputs in;
  const Ranges ranges(1, VkAccelerationStructureBuildRangeInfoKHR{1, 0, 0, 0});
  VkAccelerationStructureGeometryKHR triangles = TrianglesAt(Inputs::At(in.vertices));
  auto skipped = [&] { return h.state().checks_skipped_unknown_state.load(); };

  // A destination on a sparse buffer (bound through vkQueueBindSparse, which the layer does not follow).
  VkAccelerationStructureBuildGeometryInfoKHR info =
      InfoOf(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, &triangles, 1,
             h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, /*bound=*/false,
                            VK_BUFFER_CREATE_SPARSE_BINDING_BIT),
             kScratch);
  uint64_t before = skipped();
  CHECK(h.Run(kDirect, {info}, {ranges.data()}).empty());
  CHECK(skipped() == before + 1);
  // The same structure on an ordinary buffer without memory is a finding.
  info.dstAccelerationStructure = h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, /*bound=*/false);
  CHECK(h.Run(kDirect, {info}, {ranges.data()}) ==
        std::vector<std::string>{"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03707"});

  // A vertex format newer than the headers (VK_FORMAT_A1B5G5R5_UNORM_PACK16_KHR): no feature query, no
  // component size; the driver is not asked about it.
  info.dstAccelerationStructure = h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  triangles.geometry.triangles.vertexFormat = static_cast<VkFormat>(1000470000);
  const int queries = RecordHarness::format_queries;
  before = skipped();
  CHECK(h.Run(kDirect, {info}, {ranges.data()}).empty());
  CHECK(skipped() > before);
  CHECK(RecordHarness::format_queries == queries);

  // No limits reported (an instance without properties2): the limit rules skip.
  triangles.geometry.triangles.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
  h.state().properties.acceleration_structure = VkPhysicalDeviceAccelerationStructurePropertiesKHR{};
  const Ranges huge(1, VkAccelerationStructureBuildRangeInfoKHR{1u << 30, 0, 0, 0});
  triangles.geometry.triangles.maxVertex = UINT32_MAX;
  before = skipped();
  CHECK(h.Run(kDirect, {info}, {huge.data()}, kCheckStructure).empty());
  CHECK(skipped() > before);

  // A protected pool exists, but this command buffer was never seen allocated.
  h.state().command_buffers.CreatePool(reinterpret_cast<VkCommandPool>(0x31), VK_COMMAND_POOL_CREATE_PROTECTED_BIT);
  before = skipped();
  CHECK(h.Run(kDirect, {info}, {ranges.data()}, kCheckFeatures).empty());
  CHECK(skipped() == before + 1);
}

TEST_CASE("record checks: a protected command buffer is found through its pool (commandBuffer-09547)",
          "[unit][record][09547]") {
  RecordHarness h;
  Inputs in;
  const VkAccelerationStructureGeometryKHR triangles = TrianglesAt(Inputs::At(in.vertices));
  const VkAccelerationStructureBuildGeometryInfoKHR info =
      InfoOf(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, &triangles, 1,
             h.AddStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR), kScratch);
  const Ranges ranges(1, VkAccelerationStructureBuildRangeInfoKHR{1, 0, 0, 0});
  CommandBufferMap& map = h.state().command_buffers;
  const auto plain = reinterpret_cast<VkCommandPool>(0x30), guarded = reinterpret_cast<VkCommandPool>(0x31);
  map.CreatePool(plain, 0);
  map.CreatePool(guarded, VK_COMMAND_POOL_CREATE_PROTECTED_BIT);
  const auto cb = reinterpret_cast<VkCommandBuffer>(0x20);  // the harness records into command buffer 0x20
  map.Allocate(VkCommandBufferAllocateInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, nullptr, plain,
                                           VK_COMMAND_BUFFER_LEVEL_PRIMARY, 1},
               &cb);
  CHECK(h.Run(kDirect, {info}, {ranges.data()}).empty());
  CHECK(h.Run(kIndirect, {info}, {ranges.data()}).empty());
  map.Free(1, &cb);
  map.Allocate(VkCommandBufferAllocateInfo{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO, nullptr, guarded,
                                           VK_COMMAND_BUFFER_LEVEL_PRIMARY, 1},
               &cb);
  CHECK(h.Run(kDirect, {info}, {ranges.data()}) ==
        std::vector<std::string>{"VUID-vkCmdBuildAccelerationStructuresKHR-commandBuffer-09547"});
  CHECK(h.Run(kIndirect, {info}, {ranges.data()}) ==
        std::vector<std::string>{"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-commandBuffer-09547"});
  CHECK(h.Run(kHost, {info}, {ranges.data()}).empty());  // host builds have no command buffer
}

TEST_CASE("vertex format alignment: component size, or the size of a packed format", "[unit][record]") {
  // Hand-written (vertex_formats_unit_test covers every acceleration-structure vertex format).
  CHECK(AlignmentOfVertexFormat(VK_FORMAT_R16G16_SNORM).bytes == 2);
  CHECK_FALSE(AlignmentOfVertexFormat(VK_FORMAT_R16G16_SNORM).packed);
  CHECK(AlignmentOfVertexFormat(VK_FORMAT_A2B10G10R10_UNORM_PACK32).bytes == 4);
  CHECK(AlignmentOfVertexFormat(VK_FORMAT_A2B10G10R10_UNORM_PACK32).packed);
  CHECK(AlignmentOfVertexFormat(VK_FORMAT_R8G8B8_UNORM).bytes == 1);
  CHECK(AlignmentOfVertexFormat(VK_FORMAT_R64G64B64_SFLOAT).bytes == 8);
  CHECK(AlignmentOfVertexFormat(VK_FORMAT_B10G11R11_UFLOAT_PACK32).packed);
  CHECK(AlignmentOfVertexFormat(VK_FORMAT_R5G6B5_UNORM_PACK16).bytes == 2);
  CHECK(AlignmentOfVertexFormat(VK_FORMAT_D32_SFLOAT).bytes == 0);
  CHECK(AlignmentOfVertexFormat(VK_FORMAT_BC1_RGB_UNORM_BLOCK).bytes == 0);
  CHECK(AlignmentOfVertexFormat(static_cast<VkFormat>(1000470000)).bytes == 0);
  CHECK(IndexTypeSize(VK_INDEX_TYPE_UINT16) == 2);
  CHECK(IndexTypeSize(VK_INDEX_TYPE_NONE_KHR) == 0);
  CHECK(IndexTypeSize(static_cast<VkIndexType>(12345)) == -1);
}

VKAPI_ATTR void VKAPI_CALL CountingFormatProperties(VkPhysicalDevice, VkFormat format, VkFormatProperties* properties) {
  ++RecordHarness::format_queries;
  *properties = VkFormatProperties{};
  properties->bufferFeatures = static_cast<VkFormatFeatureFlags>(format);  // distinct per format, to tell them apart
}

TEST_CASE("format features are asked of the driver once per format", "[unit][record][03797]") {
  FormatFeatureCache cache;
  CHECK(!cache.BufferFeatures(VK_FORMAT_R32G32B32_SFLOAT));  // not initialised: no driver to ask
  cache.Init(reinterpret_cast<VkPhysicalDevice>(0x77), &CountingFormatProperties);
  const int before = RecordHarness::format_queries;
  for (int k = 0; k < 3; ++k) {
    CHECK(cache.BufferFeatures(VK_FORMAT_R32G32B32_SFLOAT) == VkFormatFeatureFlags{VK_FORMAT_R32G32B32_SFLOAT});
    CHECK(cache.BufferFeatures(VK_FORMAT_UNDEFINED) == VkFormatFeatureFlags{0});
    CHECK(cache.BufferFeatures(VK_FORMAT_A4R4G4B4_UNORM_PACK16) ==
          VkFormatFeatureFlags{static_cast<uint32_t>(VK_FORMAT_A4R4G4B4_UNORM_PACK16)});
    CHECK(!cache.BufferFeatures(static_cast<VkFormat>(1000470000)));  // newer than the headers: never asked
  }
  CHECK(RecordHarness::format_queries == before + 3);
}

}  // namespace
}  // namespace asval::test
