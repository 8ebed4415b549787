// Family "alignment": scratch to minAccelerationStructureScratchOffsetAlignment, vertex data to the format's
// component size, indices to their size, transforms and instances to 16, AABBs and instance pointers to 8, the
// instances an array of pointers names to 16, indirect addresses and strides to 4. Lavapipe has no indirect
// builds, so the indirect cases also carry 03650.
#include <cstring>
#include <memory>
#include <vector>

#include "corpus.h"
#include "history_helpers.h"
#include "memory_placement_helpers.h"
#include "record_checks_helpers.h"

namespace {

using asval_test::Command;
using asval_test::IssueWithRealRanges;
using asval_test::Scene;

constexpr auto kBottom = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
constexpr auto kTop = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR;
constexpr const char* kIndirectFeature =
    "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-accelerationStructureIndirectBuild-03650";

// One geometry of a build of `type`, its destination and scratch sized by the driver for one primitive.
struct OneGeometry {
  OneGeometry(Scene& scene, const VkAccelerationStructureGeometryKHR& g, VkAccelerationStructureTypeKHR type = kBottom)
      : geometry(g) {
    info = Scene::Info(type, {geometry});
    info.pGeometries = &geometry;
    scene.Prepare(info, {1});
  }
  // Records the build (never submitted: the faults are caught at record time); indirect ranges in a real buffer.
  void Record(vkkit::Device& device, Command command) {
    const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
    IssueWithRealRanges(device, command, {info}, {&range});
  }
  VkAccelerationStructureGeometryKHR geometry;
  VkAccelerationStructureBuildGeometryInfoKHR info;
};

void MisalignedScratch(vkkit::Device& device, Command command) {
  Scene scene(device);
  OneGeometry build(scene, scene.Triangles());
  build.info.scratchData.deviceAddress += device.as_properties().minAccelerationStructureScratchOffsetAlignment / 2;
  build.Record(device, command);
}

void MisalignedVertices(vkkit::Device& device, Command command) {
  Scene scene(device);
  OneGeometry build(scene, scene.Triangles());
  build.geometry.geometry.triangles.vertexData.deviceAddress += 2;  // R32G32B32_SFLOAT: 4-byte components
  build.Record(device, command);
}

void MisalignedIndices(vkkit::Device& device, Command command) {
  Scene scene(device);
  OneGeometry build(scene, scene.IndexedTriangles(VK_INDEX_TYPE_UINT32));
  // 32-bit indices read from where the 16-bit ones are: 2-aligned only.
  build.geometry.geometry.triangles.indexData.deviceAddress = scene.Address(Scene::kIndices16);
  build.Record(device, command);
}

void MisalignedTransform(vkkit::Device& device, Command command) {
  Scene scene(device);
  OneGeometry build(scene, scene.Triangles());
  build.geometry.geometry.triangles.transformData.deviceAddress = scene.Address(Scene::kTransforms + 8);
  build.Record(device, command);
}

void MisalignedAabbs(vkkit::Device& device, Command command) {
  Scene scene(device);
  OneGeometry build(scene, scene.Aabbs());
  build.geometry.geometry.aabbs.data.deviceAddress += 4;
  build.Record(device, command);
}

void MisalignedInstances(vkkit::Device& device, Command command) {
  Scene scene(device);
  OneGeometry build(scene, scene.Instances(), kTop);
  build.geometry.geometry.instances.data.deviceAddress += 8;
  build.Record(device, command);
}

void MisalignedInstancePointers(vkkit::Device& device, Command command) {
  Scene scene(device);
  OneGeometry build(scene, scene.Instances(/*array_of_pointers=*/true), kTop);
  build.geometry.geometry.instances.data.deviceAddress += 4;
  build.Record(device, command);
}

// An indirect build of one triangle whose range is read from `address` with `stride` (in a real indirect buffer).
void IndirectFrom(vkkit::Device& device, VkDeviceSize address_offset, uint32_t stride) {
  Scene scene(device);
  OneGeometry build(scene, scene.Triangles());
  vkkit::Buffer ranges = device.CreateBuffer(64, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  std::memcpy(static_cast<char*>(ranges.mapped) + address_offset, &range, sizeof range);
  asval_test::RecordIndirect(device, {build.info}, {ranges.address + address_offset}, {stride}, {{1}});
  device.Destroy(ranges);
}

}  // namespace

CORPUS_CASE(AlignmentScratch, "alignment-scratch-misaligned", "alignment",
            "a BLAS build whose scratch address is half the required scratch alignment past an aligned one",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710"}) {
  MisalignedScratch(device, Command::kDirect);
}
CORPUS_CASE(AlignmentScratchIndirect, "alignment-scratch-misaligned-indirect", "alignment",
            "an indirect BLAS build whose scratch address is misaligned",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03710", kIndirectFeature}) {
  MisalignedScratch(device, Command::kIndirect);
}

CORPUS_CASE(AlignmentVertices, "alignment-vertex-data-misaligned", "alignment",
            "R32G32B32_SFLOAT vertices read from 2 bytes past a 4-aligned address",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03711"}) {
  MisalignedVertices(device, Command::kDirect);
}
CORPUS_CASE(AlignmentVerticesIndirect, "alignment-vertex-data-misaligned-indirect", "alignment",
            "an indirect build reading R32G32B32_SFLOAT vertices from a 2-aligned address",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03711", kIndirectFeature}) {
  MisalignedVertices(device, Command::kIndirect);
}

CORPUS_CASE(AlignmentIndices, "alignment-index-data-misaligned", "alignment",
            "32-bit indices read from a 2-aligned address", {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03712"}) {
  MisalignedIndices(device, Command::kDirect);
}
CORPUS_CASE(AlignmentIndicesIndirect, "alignment-index-data-misaligned-indirect", "alignment",
            "an indirect build reading 32-bit indices from a 2-aligned address",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03712", kIndirectFeature}) {
  MisalignedIndices(device, Command::kIndirect);
}

CORPUS_CASE(AlignmentTransform, "alignment-transform-misaligned", "alignment",
            "a triangle geometry whose transform is 8 bytes past a 16-aligned address",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03810"}) {
  MisalignedTransform(device, Command::kDirect);
}
CORPUS_CASE(AlignmentTransformIndirect, "alignment-transform-misaligned-indirect", "alignment",
            "an indirect build whose transform is 8 bytes past a 16-aligned address",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03810", kIndirectFeature}) {
  MisalignedTransform(device, Command::kIndirect);
}

CORPUS_CASE(AlignmentAabbs, "alignment-aabb-data-misaligned", "alignment",
            "AABBs read from a 4-aligned (not 8-aligned) address",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03714"}) {
  MisalignedAabbs(device, Command::kDirect);
}
CORPUS_CASE(AlignmentAabbsIndirect, "alignment-aabb-data-misaligned-indirect", "alignment",
            "an indirect build reading AABBs from a 4-aligned address",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03714", kIndirectFeature}) {
  MisalignedAabbs(device, Command::kIndirect);
}

CORPUS_CASE(AlignmentInstances, "alignment-instance-data-misaligned", "alignment",
            "a TLAS build reading its instance array from 8 bytes past a 16-aligned address",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03715"}) {
  MisalignedInstances(device, Command::kDirect);
}
CORPUS_CASE(AlignmentInstancesIndirect, "alignment-instance-data-misaligned-indirect", "alignment",
            "an indirect TLAS build reading its instance array from an 8-aligned address",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03715", kIndirectFeature}) {
  MisalignedInstances(device, Command::kIndirect);
}

CORPUS_CASE(AlignmentInstancePointers, "alignment-instance-pointer-array-misaligned", "alignment",
            "a TLAS build over an array of instance pointers at a 4-aligned (not 8-aligned) address",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03716"}) {
  MisalignedInstancePointers(device, Command::kDirect);
}
CORPUS_CASE(AlignmentInstancePointersIndirect, "alignment-instance-pointer-array-misaligned-indirect", "alignment",
            "an indirect TLAS build over an array of instance pointers at a 4-aligned address",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03716", kIndirectFeature}) {
  MisalignedInstancePointers(device, Command::kIndirect);
}

CORPUS_CASE(AlignmentIndirectAddress, "alignment-indirect-range-address-misaligned", "alignment",
            "an indirect build whose range info is read from a 2-aligned address",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pIndirectDeviceAddresses-03648", kIndirectFeature}) {
  IndirectFrom(device, 2, 16);
}

CORPUS_CASE(AlignmentIndirectStride, "alignment-indirect-stride-misaligned", "alignment",
            "an indirect build whose range stride is 18", 
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pIndirectStrides-03787", kIndirectFeature}) {
  IndirectFrom(device, 0, 18);
}

namespace {

// A TLAS built from an array of instance pointers written on the host; each pointer names a record of `blas`
// at `offsets` of a records buffer. Submitted: the pointers are judged as the device reads them.
void TlasFromPointers(vkkit::Device& device, const std::vector<VkDeviceSize>& offsets) {
  asval_test::Inputs inputs(device);
  asval_test::Blas blas(device, inputs);
  asval_test::Tlas tlas(device);
  device.OneShot([&](VkCommandBuffer cb) { blas.Build(cb, asval_test::Shape{}); });
  constexpr VkBufferUsageFlags kInput = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;
  vkkit::Buffer records = device.CreateBuffer(512, kInput);
  vkkit::Buffer pointers = device.CreateBuffer(8 * offsets.size(), kInput);
  std::memset(records.mapped, 0, 512);
  for (size_t i = 0; i < offsets.size(); ++i) {
    VkAccelerationStructureInstanceKHR instance{};
    instance.transform.matrix[0][0] = instance.transform.matrix[1][1] = instance.transform.matrix[2][2] = 1.0f;
    instance.transform.matrix[0][3] = 4.0f * static_cast<float>(i);
    instance.mask = 0xff;
    instance.accelerationStructureReference = blas.address();
    std::memcpy(static_cast<char*>(records.mapped) + offsets[i], &instance, sizeof instance);
    const VkDeviceAddress pointer = records.address + offsets[i];
    std::memcpy(static_cast<char*>(pointers.mapped) + 8 * i, &pointer, sizeof pointer);
  }
  device.OneShot([&](VkCommandBuffer cb) {
    asval_test::BuildInfo b =
        tlas.Info(pointers, static_cast<uint32_t>(offsets.size()), VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
    b.geometries[0].geometry.instances.arrayOfPointers = VK_TRUE;
    asval_test::RecordBuilds(device, cb, {&b});
  });
  device.Destroy(pointers);
  device.Destroy(records);
}

}  // namespace

CORPUS_CASE(AlignmentPointedInstance, "alignment-pointed-instance-misaligned", "alignment",
            "a TLAS over an array of two instance pointers, the second naming a record 8 bytes past a 16-byte "
            "boundary",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03717"}) {
  TlasFromPointers(device, {0, 136});
}

namespace {

// One mesh's data packed back to back in one buffer, as a loader that appends every array writes it: 3 uint16
// indices (6 bytes), 3 float vertices (36 bytes), a 3x4 transform. Where each array starts depends on the packing.
struct PackedMesh {
  PackedMesh(vkkit::Device& d, VkDeviceSize vertices_at, VkDeviceSize transform_at) : device(d) {
    buffer = device.CreateBuffer(256, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
    auto* bytes = static_cast<char*>(buffer.mapped);
    std::memset(bytes, 0, 256);
    const uint16_t indices[3] = {0, 1, 2};
    const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
    const VkTransformMatrixKHR identity = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}};
    std::memcpy(bytes, indices, sizeof indices);
    std::memcpy(bytes + vertices_at, positions, sizeof positions);
    std::memcpy(bytes + transform_at, &identity, sizeof identity);
    geometry = VkAccelerationStructureGeometryKHR{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
    geometry.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
    geometry.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
    auto& tri = geometry.geometry.triangles;
    tri.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
    tri.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    tri.vertexStride = 12;
    tri.vertexData.deviceAddress = buffer.address + vertices_at;
    tri.maxVertex = 2;
    tri.indexType = VK_INDEX_TYPE_UINT16;
    tri.indexData.deviceAddress = buffer.address;
    tri.transformData.deviceAddress = buffer.address + transform_at;
  }
  ~PackedMesh() { device.Destroy(buffer); }
  // Builds the mesh into a BLAS of the scene's, submitted and waited for.
  void Build(Scene& scene) {
    OneGeometry build(scene, geometry);
    const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
    scene.BuildNow({build.info}, {&range});
  }
  vkkit::Device& device;
  vkkit::Buffer buffer;
  VkAccelerationStructureGeometryKHR geometry;
};

}  // namespace

CORPUS_CASE(AlignmentVerticesAfterIndices, "alignment-vertices-packed-after-16-bit-indices", "alignment",
            "a mesh packed in one buffer: 3 uint16 indices, float vertices right after them at byte 6, a transform "
            "at byte 48; built and submitted",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03711"}) {
  Scene scene(device);
  PackedMesh(device, 6, 48).Build(scene);
}

CORPUS_CASE(AlignmentTransformAfterVertices, "alignment-transform-packed-after-vertices", "alignment",
            "a mesh packed in one buffer: 3 uint16 indices, float vertices at byte 8, the transform right after "
            "them at byte 44; built and submitted",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03810"}) {
  Scene scene(device);
  PackedMesh(device, 8, 44).Build(scene);
}

// Valid twins: every input at exactly the alignment it needs, no more.

// Scratch slices packed as tightly as the device allows: each one's offset rounded up to
// minAccelerationStructureScratchOffsetAlignment only (8 bytes on lavapipe), not to 128 or 256.
CORPUS_CASE(AlignmentTightScratchSlices, "alignment-scratch-slices-at-minimum-alignment", "alignment",
            "8 BLAS builds in one call, their scratch slices packed back to back in one buffer, each rounded up to "
            "the device's minimum scratch alignment only",
            {}) {
  Scene scene(device);
  const VkDeviceSize alignment = device.as_properties().minAccelerationStructureScratchOffsetAlignment;
  std::vector<std::unique_ptr<OneGeometry>> builds;
  std::vector<VkDeviceSize> offsets;
  VkDeviceSize size = 0;
  for (int k = 0; k < 8; ++k) {
    builds.push_back(std::make_unique<OneGeometry>(scene, scene.Triangles()));
    offsets.push_back(size);
    size = asval_test::RoundUp(size + asval_test::DriverSizes(device, builds.back()->info, {1}).buildScratchSize,
                               alignment);
  }
  vkkit::Buffer scratch = device.CreateBuffer(size, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos;
  for (int k = 0; k < 8; ++k) {
    builds[k]->info.scratchData.deviceAddress = scratch.address + offsets[k];
    infos.push_back(builds[k]->info);
  }
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  scene.BuildNow(infos, std::vector<const VkAccelerationStructureBuildRangeInfoKHR*>(8, &range));
  device.Destroy(scratch);
}

CORPUS_CASE(AlignmentPackedMeshPadded, "alignment-packed-mesh-padded", "alignment",
            "a mesh packed in one buffer with each array padded to its alignment: uint16 indices at 0, vertices at "
            "byte 8, the transform at byte 48; built and submitted",
            {}) {
  Scene scene(device);
  PackedMesh(device, 8, 48).Build(scene);
}

CORPUS_CASE(AlignmentMinimalTriangleInputs, "alignment-minimal-triangle-input-alignment", "alignment",
            "BLAS builds with vertices 4-aligned (not 8), 16-bit indices 2-aligned (not 4), a transform 16-aligned "
            "(not 32) and scratch at exactly the required alignment past a 128-byte slice",
            {}) {
  Scene scene(device);
  VkAccelerationStructureGeometryKHR shifted = scene.Triangles();
  shifted.geometry.triangles.vertexData.deviceAddress = scene.Address(Scene::kVertices + 4);
  VkAccelerationStructureGeometryKHR transformed = scene.Triangles();
  transformed.geometry.triangles.transformData.deviceAddress = scene.Address(Scene::kTransforms + 48);
  OneGeometry a(scene, shifted), b(scene, scene.IndexedTriangles(VK_INDEX_TYPE_UINT16)), c(scene, transformed);
  // Scratch moved by the alignment into a slice with room to spare (prepared for a build twice as large).
  OneGeometry d(scene, scene.Triangles());
  scene.Prepare(d.info, {2});
  d.info.scratchData.deviceAddress += device.as_properties().minAccelerationStructureScratchOffsetAlignment;
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  scene.BuildNow({a.info, b.info, c.info, d.info}, {&range, &range, &range, &range});
}

// 16-bit components need 2-byte alignment only: a layer that holds every vertex format to 4 bytes reports this.
CORPUS_CASE(AlignmentHalfFloatVertices, "alignment-half-float-vertices-2-aligned", "alignment",
            "a BLAS of R16G16B16A16_SFLOAT vertices read from a 2-aligned (not 4-aligned) address", {}) {
  Scene scene(device);
  VkAccelerationStructureGeometryKHR half = scene.Triangles();
  half.geometry.triangles.vertexFormat = VK_FORMAT_R16G16B16A16_SFLOAT;
  half.geometry.triangles.vertexData.deviceAddress = scene.Address(Scene::kVertices + 2);
  OneGeometry build(scene, half);
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  scene.BuildNow({build.info}, {&range});
}

// Byte and packed formats (both supported for builds on lavapipe): byte components need no alignment at all, a packed
// format's whole 4-byte texel does.
CORPUS_CASE(AlignmentByteAndPackedVertices, "alignment-byte-vertices-odd-address-packed-4-aligned", "alignment",
            "a BLAS of R8G8B8A8_SNORM vertices read from an odd address, and one of A2B10G10R10_UNORM_PACK32 vertices "
            "from a 4-aligned (not 8-aligned) address",
            {}) {
  Scene scene(device);
  VkAccelerationStructureGeometryKHR bytes = scene.Triangles();
  bytes.geometry.triangles.vertexFormat = VK_FORMAT_R8G8B8A8_SNORM;
  bytes.geometry.triangles.vertexStride = 4;
  bytes.geometry.triangles.vertexData.deviceAddress = scene.Address(Scene::kVertices + 1);
  VkAccelerationStructureGeometryKHR packed = scene.Triangles();
  packed.geometry.triangles.vertexFormat = VK_FORMAT_A2B10G10R10_UNORM_PACK32;
  packed.geometry.triangles.vertexStride = 4;
  packed.geometry.triangles.vertexData.deviceAddress = scene.Address(Scene::kVertices + 4);
  OneGeometry a(scene, bytes), b(scene, packed);
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  scene.BuildNow({a.info, b.info}, {&range, &range});
}

// A packed format's texel is one 4-byte word: the newest wording of 03711 aligns a packed format's vertices to the
// whole texel, so 2 bytes past a 4-byte boundary is misaligned.
CORPUS_CASE(AlignmentPackedVerticesMisaligned, "alignment-packed-vertices-2-aligned", "alignment",
            "a BLAS of A2B10G10R10_UNORM_PACK32 vertices read from a 2-aligned (not 4-aligned) address",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03711"}) {
  Scene scene(device);
  VkAccelerationStructureGeometryKHR packed = scene.Triangles();
  packed.geometry.triangles.vertexFormat = VK_FORMAT_A2B10G10R10_UNORM_PACK32;
  packed.geometry.triangles.vertexStride = 4;
  OneGeometry build(scene, packed);
  build.geometry.geometry.triangles.vertexData.deviceAddress += 2;
  build.Record(device, Command::kDirect);
}

CORPUS_CASE(AlignmentMinimalInstanceInputs, "alignment-minimal-aabb-and-instance-alignment", "alignment",
            "an AABB BLAS from the second box (8-aligned, not 16), a TLAS from the second instance (64 bytes in) "
            "and a TLAS from the second pointer (8-aligned, not 16)",
            {}) {
  Scene scene(device);
  VkAccelerationStructureGeometryKHR second_box = scene.Aabbs();
  second_box.geometry.aabbs.data.deviceAddress = scene.Address(Scene::kAabbs + 24);
  VkAccelerationStructureGeometryKHR second_instance = scene.Instances();
  second_instance.geometry.instances.data.deviceAddress = scene.Address(Scene::kInstances + 64);
  VkAccelerationStructureGeometryKHR second_pointer = scene.Instances(/*array_of_pointers=*/true);
  second_pointer.geometry.instances.data.deviceAddress = scene.Address(Scene::kPointers + 8);
  OneGeometry boxes(scene, second_box), top(scene, second_instance, kTop), pointed(scene, second_pointer, kTop);
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  scene.BuildNow({boxes.info}, {&range});
  scene.BuildNow({top.info, pointed.info}, {&range, &range});
}

CORPUS_CASE(AlignmentPointedInstancesAligned, "alignment-pointed-instances-out-of-order", "alignment",
            "a TLAS over an array of three instance pointers naming 16-aligned records in reverse order", {}) {
  TlasFromPointers(device, {320, 144, 0});
}
