// Family "structure": VkAccelerationStructureBuildGeometryInfoKHR (type, geometry arrays, geometry types and
// counts, flags), the geometry data (strides, formats, index types) and VkAccelerationStructureBuildRangeInfoKHR
// (offsets, vertex counts). These VUIDs name the structure, so one case per rule through the direct command;
// maxVertex-10774 is checked for host builds only (their indices are host memory), which lavapipe lacks.
#include <cstring>
#include <memory>
#include <utility>
#include <vector>

#include "corpus.h"
#include "record_checks_helpers.h"

namespace {

using asval_test::Command;
using asval_test::IssueOne;
using asval_test::Ranges;
using asval_test::Scene;

constexpr auto kBottom = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
constexpr auto kTop = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
constexpr VkBuildAccelerationStructureFlagsKHR kDefaultFlags =
    VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR | VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR;

// An info over `geometries` of `type`, its destination and scratch sized for `counts` primitives per geometry.
struct Build {
  Build(Scene& scene, std::vector<VkAccelerationStructureGeometryKHR> g, VkAccelerationStructureTypeKHR type = kBottom,
        std::vector<uint32_t> counts = {}, VkBuildAccelerationStructureFlagsKHR flags = kDefaultFlags)
      : geometries(std::move(g)) {
    if (counts.empty()) counts.assign(geometries.size(), 1);
    info = Scene::Info(type, geometries);
    info.flags = flags;  // before the size query: flags may change the sizes
    info.pGeometries = geometries.data();
    scene.Prepare(info, counts);
  }
  // Records the build (never submitted: the faults are caught at record time) with one range for every geometry.
  void Record(vkkit::Device& device, const VkAccelerationStructureBuildRangeInfoKHR& range = {1, 0, 0, 0}) {
    const std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges(geometries.size(), range);
    IssueOne(device, Command::kDirect, info, ranges.data());
  }
  std::vector<VkAccelerationStructureGeometryKHR> geometries;
  VkAccelerationStructureBuildGeometryInfoKHR info;
};

}  // namespace

CORPUS_CASE(StructureGenericType, "structure-build-type-generic", "structure",
            "a build whose info has type GENERIC (only structures may be created generic)",
            {"VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03654"}) {
  Scene scene(device);
  Build b(scene, {scene.Triangles()});
  b.info.type = VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR;
  b.Record(device);
}

CORPUS_CASE(StructureNoGeometryArray, "structure-geometry-count-without-array", "structure",
            "a BLAS build with geometryCount 1 but neither pGeometries nor ppGeometries set",
            {"VUID-VkAccelerationStructureBuildGeometryInfoKHR-pGeometries-03788"}) {
  Scene scene(device);
  Build b(scene, {scene.Triangles()});
  b.info.pGeometries = nullptr;
  b.Record(device);
}

CORPUS_CASE(StructureBothGeometryArrays, "structure-both-geometry-arrays", "structure",
            "a BLAS build with both pGeometries and ppGeometries set",
            {"VUID-VkAccelerationStructureBuildGeometryInfoKHR-pGeometries-03788"}) {
  Scene scene(device);
  Build b(scene, {scene.Triangles()});
  const VkAccelerationStructureGeometryKHR* pointer = b.geometries.data();
  b.info.ppGeometries = &pointer;
  b.Record(device);
}

CORPUS_CASE(StructureTopOfTriangles, "structure-tlas-of-triangles", "structure",
            "a top-level build whose geometry is triangles instead of instances",
            {"VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03789"}) {
  Scene scene(device);
  Build b(scene, {scene.Instances()}, kTop);
  b.geometries[0] = scene.Triangles();
  b.Record(device);
}

CORPUS_CASE(StructureTopTwoGeometries, "structure-tlas-two-instance-geometries", "structure",
            "a top-level build with two instance geometries",
            {"VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03790"}) {
  Scene scene(device);
  Build b(scene, {scene.Instances()}, kTop);
  const VkAccelerationStructureGeometryKHR two[2] = {scene.Instances(), scene.Instances()};
  b.info.pGeometries = two;
  b.info.geometryCount = 2;
  const std::vector<VkAccelerationStructureBuildRangeInfoKHR> ranges(2, {1, 0, 0, 0});
  IssueOne(device, Command::kDirect, b.info, ranges.data());
}

CORPUS_CASE(StructureBottomOfInstances, "structure-blas-of-instances", "structure",
            "a bottom-level build whose geometry is instances",
            {"VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03791"}) {
  Scene scene(device);
  Build b(scene, {scene.Triangles()});
  b.geometries[0] = scene.Instances();
  b.Record(device);
}

CORPUS_CASE(StructureBottomMixedTypes, "structure-blas-triangles-and-aabbs", "structure",
            "a bottom-level build with a triangle geometry and an AABB geometry",
            {"VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03792"}) {
  Scene scene(device);
  Build b(scene, {scene.Triangles(), scene.Triangles()});
  b.geometries[1] = scene.Aabbs();
  b.Record(device);
}

CORPUS_CASE(StructureTooManyGeometries, "structure-geometry-count-over-limit", "structure",
            "a BLAS build whose geometryCount is maxGeometryCount + 1",
            {"VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03793"}) {
  Scene scene(device);
  Build b(scene, {scene.Triangles()});
  // One geometry behind the absurd count (16777216 on lavapipe: an array that long would take 1.6 GB); a layer
  // judges the count before it walks the array.
  b.info.geometryCount = static_cast<uint32_t>(device.as_properties().maxGeometryCount) + 1;
  b.Record(device);
}

CORPUS_CASE(StructureTooManyAabbs, "structure-aabb-count-over-limit", "structure",
            "a BLAS build of one AABB geometry whose primitiveCount is maxPrimitiveCount + 1",
            // The boxes the count names run past the buffer's end, too (16777216 boxes would take 400 MB).
            {"VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03794",
             "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03811"}) {
  Scene scene(device);
  Build b(scene, {scene.Aabbs()});
  b.Record(device, {static_cast<uint32_t>(device.as_properties().maxPrimitiveCount) + 1, 0, 0, 0});
}

CORPUS_CASE(StructureTooManyTriangles, "structure-triangle-count-over-limit", "structure",
            "a BLAS build of one indexed-triangle geometry whose primitiveCount is maxPrimitiveCount + 1",
            // The indices the count names run past the buffer's end, too.
            {"VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03795",
             "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03806"}) {
  Scene scene(device);
  Build b(scene, {scene.IndexedTriangles(VK_INDEX_TYPE_UINT32)});
  b.Record(device, {static_cast<uint32_t>(device.as_properties().maxPrimitiveCount) + 1, 0, 0, 0});
}

CORPUS_CASE(StructureFastTraceAndBuild, "structure-prefer-fast-trace-and-fast-build", "structure",
            "a BLAS build with both PREFER_FAST_TRACE and PREFER_FAST_BUILD",
            {"VUID-VkAccelerationStructureBuildGeometryInfoKHR-flags-03796"}) {
  Scene scene(device);
  Build b(scene, {scene.Triangles()});
  b.info.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR |
                 VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR;
  b.Record(device);
}

CORPUS_CASE(StructureMicromapUpdateBoth, "structure-micromap-update-and-data-update", "structure",
            "a BLAS build with both ALLOW_OPACITY_MICROMAP_UPDATE and ALLOW_OPACITY_MICROMAP_DATA_UPDATE",
            {"VUID-VkAccelerationStructureBuildGeometryInfoKHR-flags-07334"}) {
  Scene scene(device);
  Build b(scene, {scene.Triangles()});
  b.info.flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_OPACITY_MICROMAP_UPDATE_EXT |
                 VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_OPACITY_MICROMAP_DATA_UPDATE_EXT;
  b.Record(device);
}

CORPUS_CASE(StructureVertexStrideOffComponent, "structure-vertex-stride-not-component-multiple", "structure",
            "R32G32B32_SFLOAT vertices with a stride of 14 bytes",
            {"VUID-VkAccelerationStructureGeometryTrianglesDataKHR-vertexStride-03735"}) {
  Scene scene(device);
  Build b(scene, {scene.Triangles()});
  b.geometries[0].geometry.triangles.vertexStride = 14;
  b.Record(device);
}

CORPUS_CASE(StructureVertexStrideTooLarge, "structure-vertex-stride-over-32-bits", "structure",
            "R32G32B32_SFLOAT vertices with a stride of 2^32 bytes",
            // The third vertex, 2^33 bytes in, lies past the buffer's end, too.
            {"VUID-VkAccelerationStructureGeometryTrianglesDataKHR-vertexStride-03819",
             "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03804"}) {
  Scene scene(device);
  Build b(scene, {scene.Triangles()});
  b.geometries[0].geometry.triangles.vertexStride = VkDeviceSize{1} << 32;
  b.Record(device);
}

CORPUS_CASE(StructureUnsupportedVertexFormat, "structure-vertex-format-unsupported", "structure",
            "triangles with vertex format R8_UNORM, which lavapipe cannot build from",
            {"VUID-VkAccelerationStructureGeometryTrianglesDataKHR-vertexFormat-03797"}) {
  Scene scene(device);
  Build b(scene, {scene.Triangles()});
  b.geometries[0].geometry.triangles.vertexFormat = VK_FORMAT_R8_UNORM;
  b.geometries[0].geometry.triangles.vertexStride = 4;  // a multiple of the component size: only the format breaks
  b.Record(device);
}

CORPUS_CASE(StructureUint8Indices, "structure-index-type-uint8", "structure",
            "indexed triangles with 8-bit indices",
            {"VUID-VkAccelerationStructureGeometryTrianglesDataKHR-indexType-03798"}) {
  Scene scene(device);
  Build b(scene, {scene.IndexedTriangles(VK_INDEX_TYPE_UINT32)});
  b.geometries[0].geometry.triangles.indexType = VK_INDEX_TYPE_UINT8_EXT;
  b.Record(device);
}

CORPUS_CASE(StructureAabbStrideOff8, "structure-aabb-stride-not-multiple-of-8", "structure",
            "AABBs with a stride of 28 bytes",
            {"VUID-VkAccelerationStructureGeometryAabbsDataKHR-stride-03545"}) {
  Scene scene(device);
  Build b(scene, {scene.Aabbs()});
  b.geometries[0].geometry.aabbs.stride = 28;
  b.Record(device);
}

CORPUS_CASE(StructureAabbStrideTooLarge, "structure-aabb-stride-over-32-bits", "structure",
            "AABBs with a stride of 2^32 + 8 bytes",
            {"VUID-VkAccelerationStructureGeometryAabbsDataKHR-stride-03820"}) {
  Scene scene(device);
  Build b(scene, {scene.Aabbs()});
  b.geometries[0].geometry.aabbs.stride = (VkDeviceSize{1} << 32) + 8;
  b.Record(device);
}

CORPUS_CASE(StructureIndexOffsetMisaligned, "structure-index-offset-not-index-multiple", "structure",
            "32-bit indexed triangles with primitiveOffset 2",
            {"VUID-VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03656"}) {
  Scene scene(device);
  Build b(scene, {scene.IndexedTriangles(VK_INDEX_TYPE_UINT32)});
  b.Record(device, {1, 2, 0, 0});
}

CORPUS_CASE(StructureVertexOffsetMisaligned, "structure-vertex-offset-not-component-multiple", "structure",
            "non-indexed R32G32B32_SFLOAT triangles with primitiveOffset 6",
            {"VUID-VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03657"}) {
  Scene scene(device);
  Build b(scene, {scene.Triangles()});
  b.Record(device, {1, 6, 0, 0});
}

// For a packed vertex format the offset is held to the whole texel (the newest wording of 03657), not to a component.
CORPUS_CASE(StructurePackedVertexOffset, "structure-packed-vertex-offset-not-texel-multiple", "structure",
            "non-indexed A2B10G10R10_UNORM_PACK32 triangles with primitiveOffset 2",
            {"VUID-VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03657"}) {
  Scene scene(device);
  VkAccelerationStructureGeometryKHR packed = scene.Triangles();
  packed.geometry.triangles.vertexFormat = VK_FORMAT_A2B10G10R10_UNORM_PACK32;
  packed.geometry.triangles.vertexStride = 4;
  Build b(scene, {packed});
  b.Record(device, {1, 2, 0, 0});
}

CORPUS_CASE(StructureTransformOffsetMisaligned, "structure-transform-offset-not-16", "structure",
            "triangles with a transform, transformOffset 24",
            {"VUID-VkAccelerationStructureBuildRangeInfoKHR-transformOffset-03658"}) {
  Scene scene(device);
  VkAccelerationStructureGeometryKHR transformed = scene.Triangles();
  transformed.geometry.triangles.transformData.deviceAddress = scene.Address(Scene::kTransforms);
  Build b(scene, {transformed});
  b.Record(device, {1, 0, 0, 24});
}

CORPUS_CASE(StructureAabbOffsetMisaligned, "structure-aabb-offset-not-8", "structure",
            "AABBs with primitiveOffset 4", {"VUID-VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03659"}) {
  Scene scene(device);
  Build b(scene, {scene.Aabbs()});
  b.Record(device, {1, 4, 0, 0});
}

CORPUS_CASE(StructureInstanceOffsetMisaligned, "structure-instance-offset-not-16", "structure",
            "a TLAS build with primitiveOffset 8 into the instance array",
            {"VUID-VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03660"}) {
  Scene scene(device);
  Build b(scene, {scene.Instances()}, kTop);
  b.Record(device, {1, 8, 0, 0});
}

CORPUS_CASE(StructureTooFewVertices, "structure-triangles-past-max-vertex", "structure",
            "one non-indexed triangle (3 vertices) with maxVertex 1",
            {"VUID-VkAccelerationStructureBuildRangeInfoKHR-vertexData-10418",
             "VUID-VkAccelerationStructureBuildRangeInfoKHR-None-10775"}) {
  Scene scene(device);
  Build b(scene, {scene.Triangles()});
  b.geometries[0].geometry.triangles.maxVertex = 1;
  b.Record(device);
}

CORPUS_CASE(StructureFirstVertexPastMax, "structure-first-vertex-past-max-vertex", "structure",
            "one non-indexed triangle from firstVertex 1 with maxVertex 2 (reads vertex 3)",
            {"VUID-VkAccelerationStructureBuildRangeInfoKHR-None-10775"}) {
  Scene scene(device);
  Build b(scene, {scene.Triangles()});
  b.Record(device, {1, 0, 1, 0});
}

CORPUS_CASE(StructureIndexPastMaxVertexHost, "structure-index-past-max-vertex-host", "structure",
            "a host build of indexed triangles (indices 0, 1, 2) with maxVertex 1 (lavapipe lacks host builds)",
            {"VUID-VkAccelerationStructureBuildRangeInfoKHR-maxVertex-10774",
             "VUID-vkBuildAccelerationStructuresKHR-accelerationStructureHostCommands-03581"}) {
  Scene scene(device);
  Build b(scene, {scene.IndexedTriangles(VK_INDEX_TYPE_UINT32)});
  b.geometries[0].geometry.triangles.maxVertex = 1;
  b.geometries[0] = scene.OnHost(b.geometries[0]);
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  IssueOne(device, Command::kHost, b.info, &range);
}

// Valid twins: what the structure, data and range rules could confuse. Each is built for real.

CORPUS_CASE(StructureInterleavedAndHalfVertices, "structure-interleaved-and-half-float-vertices", "structure",
            "three BLASes: 44-byte interleaved vertices, R16G16B16A16_SFLOAT read from 12-byte records, 16-bit "
            "indices at a 2-aligned (not 4-aligned) address",
            {}) {
  Scene scene(device);
  VkAccelerationStructureGeometryKHR wide = scene.Triangles();
  wide.geometry.triangles.vertexData.deviceAddress = scene.Address(Scene::kWideVertices);
  wide.geometry.triangles.vertexStride = 44;
  VkAccelerationStructureGeometryKHR half = scene.Triangles();
  half.geometry.triangles.vertexFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
  Build a(scene, {wide}), b(scene, {half}), c(scene, {scene.IndexedTriangles(VK_INDEX_TYPE_UINT16)});
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  scene.BuildNow({a.info, b.info, c.info}, {&range, &range, &range});
}

CORPUS_CASE(StructureGeometryPointersAndManyAabbs, "structure-pp-geometries-and-aabb-geometries", "structure",
            "a BLAS of two triangle geometries passed through ppGeometries, a BLAS of three AABB geometries with "
            "stride 48, and a TLAS over instance pointers",
            {}) {
  Scene scene(device);
  Build triangles(scene, {scene.Triangles(), scene.IndexedTriangles(VK_INDEX_TYPE_UINT32)});
  const VkAccelerationStructureGeometryKHR* pointers[2] = {&triangles.geometries[0], &triangles.geometries[1]};
  triangles.info.pGeometries = nullptr;
  triangles.info.ppGeometries = pointers;
  VkAccelerationStructureGeometryKHR sparse = scene.Aabbs();
  sparse.geometry.aabbs.stride = 48;  // every other box of the scene's two
  Build boxes(scene, {sparse, sparse, sparse});
  Build top(scene, {scene.Instances(/*array_of_pointers=*/true)}, kTop, {2});
  const VkAccelerationStructureBuildRangeInfoKHR one{1, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR two{2, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR ones[3] = {one, one, one};
  scene.BuildNow({triangles.info, boxes.info}, {ones, ones});
  scene.BuildNow({top.info}, {&two});
}

CORPUS_CASE(StructureOffsetsAndVertexBounds, "structure-aligned-offsets-and-exact-max-vertex", "structure",
            "builds at aligned non-zero offsets (vertex 12, transform 48, AABB 24, instance 64), maxVertex that "
            "exactly covers firstVertex 1, and an empty range with firstVertex 100",
            {}) {
  Scene scene(device);
  VkAccelerationStructureGeometryKHR transformed = scene.Triangles();
  transformed.geometry.triangles.transformData.deviceAddress = scene.Address(Scene::kTransforms);
  VkAccelerationStructureGeometryKHR shifted = scene.Triangles();
  shifted.geometry.triangles.maxVertex = 3;  // vertices 1..3 (the fourth is the buffer's zero padding)
  VkAccelerationStructureGeometryKHR indexed = scene.IndexedTriangles(VK_INDEX_TYPE_UINT32);
  indexed.geometry.triangles.maxVertex = 3;  // indices 0..2 moved by firstVertex 1
  Build a(scene, {transformed}), b(scene, {shifted}), c(scene, {indexed}), d(scene, {scene.Aabbs()}),
      e(scene, {scene.Instances()}, kTop), empty(scene, {scene.Triangles()});
  const VkAccelerationStructureBuildRangeInfoKHR transform_48{1, 0, 0, 48};
  const VkAccelerationStructureBuildRangeInfoKHR vertex_12{1, 12, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR from_one{1, 0, 1, 0};
  const VkAccelerationStructureBuildRangeInfoKHR box_24{1, 24, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR instance_64{1, 64, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR nothing{0, 0, 100, 0};
  scene.BuildNow({a.info, b.info, c.info, d.info, empty.info},
                 {&transform_48, &vertex_12, &from_one, &box_24, &nothing});
  scene.BuildNow({e.info}, {&instance_64});
}

CORPUS_CASE(StructureSixteenGeometriesNoPreference, "structure-16-geometries-flags-without-preference", "structure",
            "a BLAS of 16 triangle geometries built with no preference flag, then one with PREFER_FAST_BUILD | "
            "ALLOW_COMPACTION | LOW_MEMORY",
            {}) {
  Scene scene(device);
  Build many(scene, std::vector<VkAccelerationStructureGeometryKHR>(16, scene.Triangles()), kBottom, {}, 0);
  Build other(scene, {scene.Triangles()}, kBottom, {},
              VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR |
                  VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR |
                  VK_BUILD_ACCELERATION_STRUCTURE_LOW_MEMORY_BIT_KHR);
  const auto ranges = Ranges(16);
  scene.BuildNow({many.info, other.info}, {ranges.data(), ranges.data()});
}

namespace {

// A mesh whose two submeshes share one vertex buffer and one index buffer, as exporters write them: 6 vertices,
// then 6 uint32 indices at byte 128 (submesh 1 reads vertices 3..5 through indices 0, 1, 2). The buffer is padded
// with zeros to 8 KiB: the indices a misaligned index offset makes of these bytes (256, 512) still name vertices
// inside it, so a build that no layer stops reads nothing out of bounds.
struct SharedMeshBuffers {
  explicit SharedMeshBuffers(vkkit::Device& d) : device(d) {
    buffer = device.CreateBuffer(kSize, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
    const float positions[18] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 2, 0, 0, 3, 0, 0, 2, 1, 0};
    const uint32_t indices[6] = {0, 1, 2, 0, 1, 2};
    std::memset(buffer.mapped, 0, kSize);
    std::memcpy(buffer.mapped, positions, sizeof positions);
    std::memcpy(static_cast<char*>(buffer.mapped) + kIndices, indices, sizeof indices);
  }
  ~SharedMeshBuffers() { device.Destroy(buffer); }
  // Submesh `k`'s triangles: vertices from its first vertex, indices (when `indexed`) from the shared buffer.
  VkAccelerationStructureGeometryKHR Submesh(uint32_t k, bool indexed) const {
    VkAccelerationStructureGeometryKHR g{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    g.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
    g.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
    auto& tri = g.geometry.triangles;
    tri.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
    tri.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    tri.vertexStride = 12;
    tri.vertexData.deviceAddress = buffer.address + (indexed ? 36 * k : 0);
    tri.maxVertex = indexed ? 2 : 5;
    tri.indexType = indexed ? VK_INDEX_TYPE_UINT32 : VK_INDEX_TYPE_NONE_KHR;
    if (indexed) tri.indexData.deviceAddress = buffer.address + kIndices;
    return g;
  }
  static constexpr VkDeviceSize kIndices = 128;
  static constexpr VkDeviceSize kSize = 8192;
  vkkit::Device& device;
  vkkit::Buffer buffer;
};

}  // namespace

// primitiveOffset is in bytes; the app passed the second submesh's first index (3) instead of 3 * 4.
CORPUS_CASE(StructureIndexOffsetInIndices, "structure-submesh-index-offset-counted-in-indices", "structure",
            "a BLAS of two indexed submeshes sharing one index buffer, the second's primitiveOffset given in indices "
            "(3) instead of bytes (12); submitted",
            {"VUID-VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03656"}) {
  SharedMeshBuffers mesh(device);
  Scene scene(device);
  Build b(scene, {mesh.Submesh(0, true), mesh.Submesh(1, true)});
  const VkAccelerationStructureBuildRangeInfoKHR ranges[2] = {{1, 0, 0, 0}, {1, 3, 0, 0}};
  scene.BuildNow({b.info}, {ranges});
}

// The same mistake without indices: the second submesh's vertices start at vertex 3, passed as 3 bytes.
CORPUS_CASE(StructureVertexOffsetInVertices, "structure-submesh-vertex-offset-counted-in-vertices", "structure",
            "a BLAS of two non-indexed submeshes sharing one vertex buffer, the second's primitiveOffset given in "
            "vertices (3) instead of bytes (36); submitted",
            {"VUID-VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03657"}) {
  SharedMeshBuffers mesh(device);
  Scene scene(device);
  Build b(scene, {mesh.Submesh(0, false), mesh.Submesh(1, false)});
  const VkAccelerationStructureBuildRangeInfoKHR ranges[2] = {{1, 0, 0, 0}, {1, 3, 0, 0}};
  scene.BuildNow({b.info}, {ranges});
}

// The valid twin: the same two submeshes with their offsets in bytes.
CORPUS_CASE(StructureSubmeshOffsetsInBytes, "structure-submesh-offsets-in-bytes", "structure",
            "two BLASes of two submeshes sharing one vertex and one index buffer, the second submesh at byte offset "
            "12 of the indices, or 36 of the vertices",
            {}) {
  SharedMeshBuffers mesh(device);
  Scene scene(device);
  Build indexed(scene, {mesh.Submesh(0, true), mesh.Submesh(1, true)});
  Build plain(scene, {mesh.Submesh(0, false), mesh.Submesh(1, false)});
  const VkAccelerationStructureBuildRangeInfoKHR indexed_ranges[2] = {{1, 0, 0, 0}, {1, 12, 0, 0}};
  const VkAccelerationStructureBuildRangeInfoKHR plain_ranges[2] = {{1, 0, 0, 0}, {1, 36, 0, 0}};
  scene.BuildNow({indexed.info, plain.info}, {indexed_ranges, plain_ranges});
}

// Empty structures, as an engine builds them before its first mesh or instance is loaded: 03788 asks for a geometry
// array only when geometryCount is not 0, and a top-level build of 0 instances still has its one geometry.
CORPUS_CASE(StructureEmptyBuilds, "structure-empty-blas-and-empty-tlas", "structure",
            "a BLAS built with geometryCount 0 and no geometry array, and a TLAS built over 0 instances", {}) {
  Scene scene(device);
  Build empty_bottom(scene, {});
  empty_bottom.info.pGeometries = nullptr;
  Build empty_top(scene, {scene.Instances()}, kTop, {0});
  const VkAccelerationStructureBuildRangeInfoKHR none{0, 0, 0, 0};
  scene.BuildNow({empty_bottom.info}, {&none});
  scene.BuildNow({empty_top.info}, {&none});
}

// Every vertex format the specification requires for acceleration-structure builds, each at its natural stride
// (2D positions included): none lacks the format feature, every stride is a multiple of its component size.
CORPUS_CASE(StructureMandatoryVertexFormats, "structure-mandatory-vertex-formats", "structure",
            "six BLASes, one per mandatory vertex format (R32G32_SFLOAT, R32G32B32_SFLOAT, R16G16_SFLOAT, "
            "R16G16B16A16_SFLOAT, R16G16_SNORM, R16G16B16A16_SNORM) at its natural stride",
            {}) {
  Scene scene(device);
  const std::pair<VkFormat, VkDeviceSize> formats[] = {
      {VK_FORMAT_R32G32_SFLOAT, 8},       {VK_FORMAT_R32G32B32_SFLOAT, 12}, {VK_FORMAT_R16G16_SFLOAT, 4},
      {VK_FORMAT_R16G16B16A16_SFLOAT, 8}, {VK_FORMAT_R16G16_SNORM, 4},      {VK_FORMAT_R16G16B16A16_SNORM, 8}};
  std::vector<std::unique_ptr<Build>> builds;
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos;
  for (const auto& [format, stride] : formats) {
    VkAccelerationStructureGeometryKHR g = scene.Triangles();  // the positions' bytes, read in each format
    g.geometry.triangles.vertexFormat = format;
    g.geometry.triangles.vertexStride = stride;
    builds.push_back(std::make_unique<Build>(scene, std::vector<VkAccelerationStructureGeometryKHR>{g}));
    infos.push_back(builds.back()->info);
  }
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  scene.BuildNow(infos, std::vector<const VkAccelerationStructureBuildRangeInfoKHR*>(infos.size(), &range));
}
