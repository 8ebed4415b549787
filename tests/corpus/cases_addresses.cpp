// Family "addresses": the bytes a build reads (vertices, indices, transforms, AABBs, instances, indirect ranges)
// and writes (scratch, destination) lie in one bound buffer with the right usage and are as large as the driver
// says. Record-time rules: the faulty build is recorded and never submitted (lavapipe has neither indirect nor
// host builds); the valid twins are built for real, the way sub-allocating programs lay their buffers out.
#include <cstdlib>
#include <cstring>
#include <memory>
#include <stdexcept>
#include <vector>

#include "corpus.h"
#include "memory_placement_helpers.h"
#include "record_checks_helpers.h"

namespace {

using asval_test::CallHostBuild;
using asval_test::Command;
using asval_test::DriverSizes;
using asval_test::IssueOne;
using asval_test::RecordIndirect;
using asval_test::Scene;
using asval_test::SharedMemory;

constexpr VkBufferUsageFlags kInput = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;
constexpr VkBufferUsageFlags kStorage = VK_BUFFER_USAGE_STORAGE_BUFFER_BIT;
// 16-aligned (every input's alignment rule holds) and below any buffer lavapipe hands out: no buffer holds it.
constexpr VkDeviceAddress kNowhere = 0x100;
// Lavapipe has no accelerationStructureIndirectBuild: every indirect build also breaks that feature rule.
constexpr const char* kIndirectFeature =
    "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-accelerationStructureIndirectBuild-03650";
constexpr VkAccelerationStructureBuildRangeInfoKHR kOne{1, 0, 0, 0};

// A one-geometry info with the destination and scratch slice the scene sizes from the driver for `count`.
struct OneGeometry {
  VkAccelerationStructureGeometryKHR geometry;
  VkAccelerationStructureBuildGeometryInfoKHR info;
  OneGeometry(Scene& scene, const VkAccelerationStructureGeometryKHR& g, uint32_t count = 1) : geometry(g) {
    const auto type = g.geometryType == VK_GEOMETRY_TYPE_INSTANCES_KHR ? VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR
                                                                        : VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    info = Scene::Info(type, {geometry});
    info.pGeometries = &geometry;
    scene.Prepare(info, {count});
  }
};

// Records one indirect build of `info` whose ranges (one geometry: `range`) lie in a real INDIRECT_BUFFER, so that
// only the input under test is wrong. Never submitted.
void RecordIndirectOne(vkkit::Device& device, const VkAccelerationStructureBuildGeometryInfoKHR& info,
                       const VkAccelerationStructureBuildRangeInfoKHR& range) {
  vkkit::Buffer ranges = device.CreateBuffer(256, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  std::memcpy(ranges.mapped, &range, sizeof(range));
  RecordIndirect(device, {info}, {ranges.address}, {16}, {{range.primitiveCount}});
  device.Destroy(ranges);
}

// ---- inputs past the end of their buffer (direct builds)

CORPUS_CASE(VertexPastEnd, "addresses-vertex-read-past-buffer", "addresses",
            "a triangle BLAS whose vertex buffer holds exactly 3 vertices, built with primitiveOffset 12 so the "
            "reads end 12 bytes past it",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03804"}) {
  Scene scene(device);
  vkkit::Buffer vertices = device.CreateBuffer(36, kInput);
  VkAccelerationStructureGeometryKHR g = scene.Triangles();
  g.geometry.triangles.vertexData.deviceAddress = vertices.address;
  OneGeometry one(scene, g);
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 12, 0, 0};
  IssueOne(device, Command::kDirect, one.info, &range);
  device.Destroy(vertices);
}

CORPUS_CASE(IndexPastEnd, "addresses-index-read-past-buffer", "addresses",
            "an indexed BLAS reading 3 uint32 indices at primitiveOffset 248 of a 256-byte index buffer",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03806"}) {
  Scene scene(device);
  vkkit::Buffer small = device.CreateBuffer(256, kInput);
  VkAccelerationStructureGeometryKHR g = scene.IndexedTriangles(VK_INDEX_TYPE_UINT32);
  g.geometry.triangles.indexData.deviceAddress = small.address;
  OneGeometry one(scene, g);
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 248, 0, 0};
  IssueOne(device, Command::kDirect, one.info, &range);
  device.Destroy(small);
}

CORPUS_CASE(TransformPastEnd, "addresses-transform-read-past-buffer", "addresses",
            "a BLAS with a transform read at transformOffset 224 of a 256-byte buffer (48 bytes needed)",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03808"}) {
  Scene scene(device);
  vkkit::Buffer small = device.CreateBuffer(256, kInput);
  VkAccelerationStructureGeometryKHR g = scene.Triangles();
  g.geometry.triangles.transformData.deviceAddress = small.address;
  OneGeometry one(scene, g);
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 224};
  IssueOne(device, Command::kDirect, one.info, &range);
  device.Destroy(small);
}

CORPUS_CASE(AabbPastEnd, "addresses-aabb-read-past-buffer", "addresses",
            "a procedural BLAS of 11 AABBs of stride 24 read from a 256-byte buffer (264 bytes needed)",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03811"}) {
  Scene scene(device);
  vkkit::Buffer small = device.CreateBuffer(256, kInput);
  VkAccelerationStructureGeometryKHR g = scene.Aabbs();
  g.geometry.aabbs.data.deviceAddress = small.address;
  OneGeometry one(scene, g, 11);
  const VkAccelerationStructureBuildRangeInfoKHR range{11, 0, 0, 0};
  IssueOne(device, Command::kDirect, one.info, &range);
  device.Destroy(small);
}

CORPUS_CASE(InstancePastEnd, "addresses-instance-read-past-buffer", "addresses",
            "a TLAS of 5 instances read from an instance buffer sized for 4",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03813"}) {
  Scene scene(device);
  vkkit::Buffer small = device.CreateBuffer(4 * sizeof(VkAccelerationStructureInstanceKHR), kInput);
  VkAccelerationStructureGeometryKHR g = scene.Instances();
  g.geometry.instances.data.deviceAddress = small.address;
  OneGeometry one(scene, g, 5);
  const VkAccelerationStructureBuildRangeInfoKHR range{5, 0, 0, 0};
  IssueOne(device, Command::kDirect, one.info, &range);
  device.Destroy(small);
}

// ---- input addresses no buffer holds (indirect builds: the ranges are in a real buffer)

CORPUS_CASE(IndirectVertexNowhere, "addresses-indirect-vertex-address-unbacked", "addresses",
            "an indirect BLAS build whose vertexData address lies in no buffer",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03804", kIndirectFeature}) {
  Scene scene(device);
  VkAccelerationStructureGeometryKHR g = scene.Triangles();
  g.geometry.triangles.vertexData.deviceAddress = kNowhere;
  OneGeometry one(scene, g);
  RecordIndirectOne(device, one.info, kOne);
}

CORPUS_CASE(IndirectIndexNowhere, "addresses-indirect-index-address-unbacked", "addresses",
            "an indirect indexed BLAS build whose indexData address lies in no buffer",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03806", kIndirectFeature}) {
  Scene scene(device);
  VkAccelerationStructureGeometryKHR g = scene.IndexedTriangles(VK_INDEX_TYPE_UINT16);
  g.geometry.triangles.indexData.deviceAddress = kNowhere;
  OneGeometry one(scene, g);
  RecordIndirectOne(device, one.info, kOne);
}

CORPUS_CASE(IndirectTransformNowhere, "addresses-indirect-transform-address-unbacked", "addresses",
            "an indirect BLAS build whose transformData address lies in no buffer",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03808", kIndirectFeature}) {
  Scene scene(device);
  VkAccelerationStructureGeometryKHR g = scene.Triangles();
  g.geometry.triangles.transformData.deviceAddress = kNowhere;
  OneGeometry one(scene, g);
  RecordIndirectOne(device, one.info, kOne);
}

CORPUS_CASE(IndirectAabbNowhere, "addresses-indirect-aabb-address-unbacked", "addresses",
            "an indirect procedural BLAS build whose AABB address lies in no buffer",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03811", kIndirectFeature}) {
  Scene scene(device);
  VkAccelerationStructureGeometryKHR g = scene.Aabbs();
  g.geometry.aabbs.data.deviceAddress = kNowhere;
  OneGeometry one(scene, g);
  RecordIndirectOne(device, one.info, kOne);
}

CORPUS_CASE(IndirectInstanceNowhere, "addresses-indirect-instance-address-unbacked", "addresses",
            "an indirect TLAS build whose instance address lies in no buffer",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03813", kIndirectFeature}) {
  Scene scene(device);
  VkAccelerationStructureGeometryKHR g = scene.Instances();
  g.geometry.instances.data.deviceAddress = kNowhere;
  OneGeometry one(scene, g);
  RecordIndirectOne(device, one.info, kOne);
}

// ---- input buffer usage

CORPUS_CASE(InputUsageDirect, "addresses-vertices-without-build-input-usage", "addresses",
            "a BLAS build reading its vertices from a STORAGE_BUFFER created without BUILD_INPUT_READ_ONLY usage",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-geometry-03673"}) {
  Scene scene(device);
  vkkit::Buffer storage = device.CreateBuffer(256, kStorage);
  VkAccelerationStructureGeometryKHR g = scene.Triangles();
  g.geometry.triangles.vertexData.deviceAddress = storage.address;
  OneGeometry one(scene, g);
  IssueOne(device, Command::kDirect, one.info, &kOne);
  device.Destroy(storage);
}

CORPUS_CASE(RasterIndexBuffer, "addresses-indices-from-raster-index-buffer", "addresses",
            "a BLAS over a raster mesh's index buffer, created with INDEX_BUFFER usage only (plus device address), "
            "not BUILD_INPUT_READ_ONLY",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-geometry-03673"}) {
  Scene scene(device);
  vkkit::Buffer raster_indices = device.CreateBuffer(256, VK_BUFFER_USAGE_INDEX_BUFFER_BIT);
  const uint32_t index_values[3] = {0, 1, 2};
  std::memcpy(raster_indices.mapped, index_values, sizeof(index_values));
  VkAccelerationStructureGeometryKHR g = scene.IndexedTriangles(VK_INDEX_TYPE_UINT32);
  g.geometry.triangles.indexData.deviceAddress = raster_indices.address;
  OneGeometry one(scene, g);
  IssueOne(device, Command::kDirect, one.info, &kOne);
  device.Destroy(raster_indices);
}

CORPUS_CASE(InputUsageIndirect, "addresses-indirect-vertices-without-build-input-usage", "addresses",
            "an indirect BLAS build reading its vertices from a buffer without BUILD_INPUT_READ_ONLY usage",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-geometry-03673", kIndirectFeature}) {
  Scene scene(device);
  vkkit::Buffer storage = device.CreateBuffer(256, kStorage);
  VkAccelerationStructureGeometryKHR g = scene.Triangles();
  g.geometry.triangles.vertexData.deviceAddress = storage.address;
  OneGeometry one(scene, g);
  RecordIndirectOne(device, one.info, kOne);
  device.Destroy(storage);
}

// ---- scratch

// One triangle BLAS info (pGeometries re-pointed at the member) and buffers of exactly the driver's scratch sizes.
struct ScratchRig {
  Scene scene;
  OneGeometry one;
  VkAccelerationStructureBuildSizesInfoKHR sizes;
  VkAccelerationStructureBuildGeometryInfoKHR info;
  vkkit::Buffer exact, exact_update, input_only;
  vkkit::Device& device;
  explicit ScratchRig(vkkit::Device& d)
      : scene(d), one(scene, scene.Triangles()), sizes(DriverSizes(d, one.info, {1})), info(one.info), device(d) {
    info.pGeometries = &one.geometry;
    exact = d.CreateBuffer(sizes.buildScratchSize, kStorage);
    exact_update = d.CreateBuffer(sizes.updateScratchSize, kStorage);
    input_only = d.CreateBuffer(sizes.buildScratchSize, kInput);
  }
  ~ScratchRig() {
    device.Destroy(exact);
    device.Destroy(exact_update);
    device.Destroy(input_only);
  }
  // The info as an in-place update (ALLOW_UPDATE is set by Scene::Info).
  void MakeUpdate() {
    info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
    info.srcAccelerationStructure = info.dstAccelerationStructure;
  }
};

CORPUS_CASE(ScratchNowhere, "addresses-scratch-address-unbacked", "addresses",
            "a BLAS build whose scratchData address lies in no buffer",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03802"}) {
  ScratchRig rig(device);
  rig.info.scratchData.deviceAddress = kNowhere;
  IssueOne(device, Command::kDirect, rig.info, &kOne);
}

CORPUS_CASE(ScratchUsage, "addresses-scratch-without-storage-usage", "addresses",
            "a BLAS build whose scratch buffer was created with BUILD_INPUT_READ_ONLY usage instead of STORAGE_BUFFER",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03674"}) {
  ScratchRig rig(device);
  rig.info.scratchData.deviceAddress = rig.input_only.address;
  IssueOne(device, Command::kDirect, rig.info, &kOne);
}

CORPUS_CASE(ScratchTooSmall, "addresses-build-scratch-too-small", "addresses",
            "a BLAS build whose scratch starts 8 bytes into a buffer of exactly buildScratchSize",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03671"}) {
  ScratchRig rig(device);
  rig.info.scratchData.deviceAddress = rig.exact.address + 8;
  IssueOne(device, Command::kDirect, rig.info, &kOne);
}

CORPUS_CASE(UpdateScratchTooSmall, "addresses-update-scratch-too-small", "addresses",
            "a BLAS refit whose scratch starts 8 bytes into a buffer of exactly updateScratchSize",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03672"}) {
  ScratchRig rig(device);
  rig.scene.BuildNow({rig.info}, {&kOne});
  rig.MakeUpdate();
  rig.info.scratchData.deviceAddress = rig.exact_update.address + 8;
  IssueOne(device, Command::kDirect, rig.info, &kOne);
}

CORPUS_CASE(IndirectScratchTooSmall, "addresses-indirect-build-scratch-too-small", "addresses",
            "an indirect BLAS build whose scratch starts 8 bytes into a buffer of exactly buildScratchSize",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-12258", kIndirectFeature}) {
  ScratchRig rig(device);
  rig.info.scratchData.deviceAddress = rig.exact.address + 8;
  RecordIndirectOne(device, rig.info, kOne);
}

CORPUS_CASE(IndirectUpdateScratchTooSmall, "addresses-indirect-update-scratch-too-small", "addresses",
            "an indirect BLAS refit whose scratch starts 8 bytes into a buffer of exactly updateScratchSize",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-12259", kIndirectFeature}) {
  ScratchRig rig(device);
  rig.scene.BuildNow({rig.info}, {&kOne});
  rig.MakeUpdate();
  rig.info.scratchData.deviceAddress = rig.exact_update.address + 8;
  RecordIndirectOne(device, rig.info, kOne);
}

CORPUS_CASE(IndirectUpdateScratchUsage, "addresses-indirect-update-scratch-without-storage-usage", "addresses",
            "an indirect BLAS refit whose scratch buffer lacks STORAGE_BUFFER usage",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-12260", kIndirectFeature}) {
  ScratchRig rig(device);
  rig.scene.BuildNow({rig.info}, {&kOne});
  rig.MakeUpdate();
  rig.info.scratchData.deviceAddress = rig.input_only.address;
  RecordIndirectOne(device, rig.info, kOne);
}

CORPUS_CASE(IndirectScratchNowhere, "addresses-indirect-scratch-address-unbacked", "addresses",
            "an indirect BLAS build whose scratchData address lies in no buffer",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-12261", kIndirectFeature}) {
  ScratchRig rig(device);
  rig.info.scratchData.deviceAddress = kNowhere;
  RecordIndirectOne(device, rig.info, kOne);
}

// ---- destination size

// A destination created 16 bytes smaller than the driver's accelerationStructureSize for the build.
VkAccelerationStructureKHR ShortDestination(vkkit::Device& device, Scene& scene,
                                            const VkAccelerationStructureBuildGeometryInfoKHR& info) {
  const VkAccelerationStructureBuildSizesInfoKHR sizes = DriverSizes(device, info, {1});
  return scene.NewStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, sizes.accelerationStructureSize - 16);
}

CORPUS_CASE(DestinationShortDirect, "addresses-destination-too-small", "addresses",
            "a BLAS built into a structure created 16 bytes smaller than accelerationStructureSize",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-10126"}) {
  Scene scene(device);
  OneGeometry one(scene, scene.Triangles());
  one.info.dstAccelerationStructure = ShortDestination(device, scene, one.info);
  IssueOne(device, Command::kDirect, one.info, &kOne);
}

CORPUS_CASE(DestinationShortIndirect, "addresses-indirect-destination-too-small", "addresses",
            "an indirect BLAS build into a structure created 16 bytes smaller than accelerationStructureSize",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03652", kIndirectFeature}) {
  Scene scene(device);
  OneGeometry one(scene, scene.Triangles());
  one.info.dstAccelerationStructure = ShortDestination(device, scene, one.info);
  RecordIndirectOne(device, one.info, kOne);
}

// Host builds: every input and the scratch are host pointers. Lavapipe has no accelerationStructureHostCommands,
// so the feature rule fires too (the call is skipped either way).
CORPUS_CASE(DestinationShortHost, "addresses-host-destination-too-small", "addresses",
            "a host BLAS build (host vertex and scratch pointers) into a structure 16 bytes smaller than "
            "accelerationStructureSize",
            {"VUID-vkBuildAccelerationStructuresKHR-pInfos-10126",
             "VUID-vkBuildAccelerationStructuresKHR-accelerationStructureHostCommands-03581"}) {
  Scene scene(device);
  const float vertices[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::vector<unsigned char> scratch(1 << 16);
  OneGeometry one(scene, scene.Triangles());
  one.geometry.geometry.triangles.vertexData.hostAddress = vertices;
  one.info.dstAccelerationStructure = ShortDestination(device, scene, one.info);
  one.info.scratchData.hostAddress = scratch.data();
  CallHostBuild(device, {one.info}, {&kOne});
}

// ---- instance count limit

CORPUS_CASE(InstanceLimitDirect, "addresses-instance-count-over-limit", "addresses",
            "a TLAS build of maxInstanceCount + 1 instances (also reading that many records past the instance buffer)",
            {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03801",
             "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03813"}) {
  Scene scene(device);
  const uint32_t limit = static_cast<uint32_t>(device.as_properties().maxInstanceCount);
  OneGeometry one(scene, scene.Instances());
  const VkAccelerationStructureBuildRangeInfoKHR range{limit + 1, 0, 0, 0};
  IssueOne(device, Command::kDirect, one.info, &range);
}

CORPUS_CASE(InstanceLimitIndirect, "addresses-indirect-instance-count-over-limit", "addresses",
            "an indirect TLAS build whose maxPrimitiveCount is maxInstanceCount + 1",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03801", kIndirectFeature}) {
  Scene scene(device);
  const uint32_t limit = static_cast<uint32_t>(device.as_properties().maxInstanceCount);
  OneGeometry one(scene, scene.Instances());
  RecordIndirectOne(device, one.info, VkAccelerationStructureBuildRangeInfoKHR{limit + 1, 0, 0, 0});
}

CORPUS_CASE(InstanceLimitHost, "addresses-host-instance-count-over-limit", "addresses",
            "a host TLAS build of maxInstanceCount + 1 instances from a host array",
            {"VUID-vkBuildAccelerationStructuresKHR-pInfos-03801",
             "VUID-vkBuildAccelerationStructuresKHR-accelerationStructureHostCommands-03581"}) {
  Scene scene(device);
  const uint32_t limit = static_cast<uint32_t>(device.as_properties().maxInstanceCount);
  std::vector<unsigned char> scratch(1 << 16);
  // Every record the count names is there (inactive, reference 0: zero pages from calloc), so only the count is
  // wrong and a layer that reads the instances reads memory the program owns.
  const size_t records = static_cast<size_t>(limit) + 1;
  std::unique_ptr<void, decltype(&std::free)> instances(std::calloc(records, sizeof(VkAccelerationStructureInstanceKHR)),
                                                        &std::free);
  if (!instances) throw std::runtime_error("cannot allocate maxInstanceCount + 1 instance records");
  OneGeometry one(scene, scene.Instances());
  one.geometry.geometry.instances.data.hostAddress = instances.get();
  one.info.scratchData.hostAddress = scratch.data();
  const VkAccelerationStructureBuildRangeInfoKHR range{limit + 1, 0, 0, 0};
  CallHostBuild(device, {one.info}, {&range});
}

// ---- indirect ranges

CORPUS_CASE(IndirectRangesPastEnd, "addresses-indirect-ranges-past-buffer", "addresses",
            "an indirect build of 2 geometries with stride 32 reading its ranges from a 48-byte INDIRECT_BUFFER",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pIndirectDeviceAddresses-03646", kIndirectFeature}) {
  Scene scene(device);
  VkAccelerationStructureGeometryKHR geometries[2] = {scene.Triangles(), scene.Triangles()};
  VkAccelerationStructureBuildGeometryInfoKHR info =
      Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {geometries[0], geometries[1]});
  info.pGeometries = geometries;
  scene.Prepare(info, {1, 1});
  vkkit::Buffer ranges = device.CreateBuffer(48, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  std::memcpy(ranges.mapped, &kOne, sizeof(kOne));
  RecordIndirect(device, {info}, {ranges.address}, {32}, {{1, 1}});
  device.Destroy(ranges);
}

CORPUS_CASE(IndirectRangesUsage, "addresses-indirect-ranges-without-indirect-usage", "addresses",
            "an indirect build reading its ranges from a STORAGE_BUFFER without INDIRECT_BUFFER usage",
            {"VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pIndirectDeviceAddresses-03647", kIndirectFeature}) {
  Scene scene(device);
  OneGeometry one(scene, scene.Triangles());
  vkkit::Buffer storage = device.CreateBuffer(64, kStorage);
  std::memcpy(storage.mapped, &kOne, sizeof(kOne));
  RecordIndirect(device, {one.info}, {storage.address}, {16}, {{1}});
  device.Destroy(storage);
}

// ---- valid twins, built for real

CORPUS_CASE(ExactInputs, "addresses-valid-exact-size-inputs", "addresses",
            "every input kind in a buffer of exactly the bytes the build reads, sub-allocated from one memory at "
            "non-zero offsets; 44-byte vertex stride, ppGeometries, a TLAS of 2 instances",
            {}) {
  Scene scene(device);
  SharedMemory memory(device, 1 << 16);
  vkkit::Buffer vertices = memory.Bind(256, 36, kInput);
  vkkit::Buffer wide = memory.Bind(512, 2 * 44 + 12, kInput);  // 3 vertices in 44-byte records, the last one short
  vkkit::Buffer indices = memory.Bind(768, 6, kInput);         // 3 uint16
  vkkit::Buffer transforms = memory.Bind(1024, 96, kInput);    // the second of two matrices is used
  vkkit::Buffer aabbs = memory.Bind(1280, 48, kInput);         // 2 boxes, stride 24
  vkkit::Buffer instances = memory.Bind(1536, 128, kInput);    // 2 instances
  const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::memcpy(vertices.mapped, positions, sizeof(positions));
  for (int v = 0; v < 3; ++v) std::memcpy(static_cast<char*>(wide.mapped) + 44 * v, positions + 3 * v, 12);
  const uint16_t index_values[3] = {0, 1, 2};
  std::memcpy(indices.mapped, index_values, sizeof(index_values));
  const VkTransformMatrixKHR identity = {{{1, 0, 0, 0}, {0, 1, 0, 0}, {0, 0, 1, 0}}};
  std::memcpy(static_cast<char*>(transforms.mapped) + 48, &identity, sizeof(identity));
  const VkAabbPositionsKHR boxes[2] = {{0, 0, 0, 1, 1, 1}, {2, 2, 2, 3, 3, 3}};
  std::memcpy(aabbs.mapped, boxes, sizeof(boxes));
  const VkAccelerationStructureDeviceAddressInfoKHR blas_info{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_DEVICE_ADDRESS_INFO_KHR, nullptr, scene.blas()};
  VkAccelerationStructureInstanceKHR instance{};
  instance.transform = identity;
  instance.mask = 0xff;
  instance.accelerationStructureReference = device.GetAccelerationStructureDeviceAddressKHR(device.handle(), &blas_info);
  std::memcpy(instances.mapped, &instance, sizeof(instance));
  std::memcpy(static_cast<char*>(instances.mapped) + 64, &instance, sizeof(instance));

  VkAccelerationStructureGeometryKHR tri = scene.Triangles();
  tri.geometry.triangles.vertexData.deviceAddress = vertices.address;
  VkAccelerationStructureGeometryKHR interleaved = scene.IndexedTriangles(VK_INDEX_TYPE_UINT16);
  interleaved.geometry.triangles.vertexData.deviceAddress = wide.address;
  interleaved.geometry.triangles.vertexStride = 44;
  interleaved.geometry.triangles.indexData.deviceAddress = indices.address;
  interleaved.geometry.triangles.transformData.deviceAddress = transforms.address;
  VkAccelerationStructureGeometryKHR boxes_geometry = scene.Aabbs();
  boxes_geometry.geometry.aabbs.data.deviceAddress = aabbs.address;
  const VkAccelerationStructureGeometryKHR* pointers[2] = {&tri, &interleaved};
  VkAccelerationStructureBuildGeometryInfoKHR triangles_info =
      Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {tri, interleaved});
  triangles_info.pGeometries = nullptr;
  triangles_info.ppGeometries = pointers;
  scene.Prepare(triangles_info, {1, 1});
  VkAccelerationStructureBuildGeometryInfoKHR aabb_info =
      Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {boxes_geometry});
  aabb_info.pGeometries = &boxes_geometry;
  scene.Prepare(aabb_info, {2});
  const VkAccelerationStructureBuildRangeInfoKHR triangle_ranges[2] = {{1, 0, 0, 0}, {1, 0, 0, 48}};
  const VkAccelerationStructureBuildRangeInfoKHR aabb_range{2, 0, 0, 0};
  scene.BuildNow({triangles_info, aabb_info}, {triangle_ranges, &aabb_range});

  VkAccelerationStructureGeometryKHR instance_geometry = scene.Instances();
  instance_geometry.geometry.instances.data.deviceAddress = instances.address;
  OneGeometry tlas(scene, instance_geometry, 2);
  const VkAccelerationStructureBuildRangeInfoKHR instance_range{2, 0, 0, 0};
  scene.BuildNow({tlas.info}, {&instance_range});
}

CORPUS_CASE(ExactDriverSizes, "addresses-valid-exact-driver-sizes", "addresses",
            "a BLAS built into a destination of exactly accelerationStructureSize with a scratch buffer of exactly "
            "buildScratchSize, then refitted with one of exactly updateScratchSize",
            {}) {
  Scene scene(device);
  VkAccelerationStructureGeometryKHR g = scene.Triangles();
  VkAccelerationStructureBuildGeometryInfoKHR info = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {g});
  info.pGeometries = &g;
  const VkAccelerationStructureBuildSizesInfoKHR sizes = DriverSizes(device, info, {1});
  info.dstAccelerationStructure =
      scene.NewStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, sizes.accelerationStructureSize);
  vkkit::Buffer build_scratch = device.CreateBuffer(sizes.buildScratchSize, kStorage);
  vkkit::Buffer update_scratch = device.CreateBuffer(sizes.updateScratchSize, kStorage);
  const VkAccelerationStructureBuildRangeInfoKHR* ranges = &kOne;
  VkAccelerationStructureBuildGeometryInfoKHR update = info;
  update.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  update.srcAccelerationStructure = info.dstAccelerationStructure;
  info.scratchData.deviceAddress = build_scratch.address;
  update.scratchData.deviceAddress = update_scratch.address;
  device.OneShot([&](VkCommandBuffer cb) {
    device.CmdBuildAccelerationStructuresKHR(cb, 1, &info, &ranges);
    asval_test::BuildBarrier(cb);
    device.CmdBuildAccelerationStructuresKHR(cb, 1, &update, &ranges);
  });
  device.Destroy(build_scratch);
  device.Destroy(update_scratch);
}

CORPUS_CASE(RecreatedEveryFrame, "addresses-valid-suballocated-recreated-every-frame", "addresses",
            "a sub-allocator's frame loop: vertex and scratch buffers bound into one VkDeviceMemory, destroyed after "
            "each frame's rebuild and re-created at alternating offsets, so addresses are reused",
            {}) {
  Scene scene(device);
  SharedMemory memory(device, 1 << 16);
  VkAccelerationStructureGeometryKHR g = scene.Triangles();
  VkAccelerationStructureBuildGeometryInfoKHR info = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {g});
  info.pGeometries = &g;
  const VkAccelerationStructureBuildSizesInfoKHR sizes = DriverSizes(device, info, {1});
  info.dstAccelerationStructure =
      scene.NewStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, sizes.accelerationStructureSize);
  const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  for (int frame = 0; frame < 6; ++frame) {
    // Frames 0, 2, 4 and 1, 3, 5 use the same offsets: the same addresses, on buffers created anew.
    const VkDeviceSize base = 4096 * (frame % 2) + 256;
    vkkit::Buffer vertices = memory.Bind(base, 36, kInput);
    vkkit::Buffer scratch = memory.Bind(base + 1024, sizes.buildScratchSize, kStorage);
    std::memcpy(vertices.mapped, positions, sizeof(positions));
    g.geometry.triangles.vertexData.deviceAddress = vertices.address;
    info.scratchData.deviceAddress = scratch.address;
    scene.BuildNow({info}, {&kOne});
    memory.DestroyBuffer(vertices);
    memory.DestroyBuffer(scratch);
  }
}

CORPUS_CASE(AliasedBuffersOneMemory, "addresses-valid-two-buffers-over-same-bytes", "addresses",
            "vertices read through one buffer while a second buffer (STORAGE only, created later) is bound over the "
            "same bytes of the memory: the address still lies in a buffer with BUILD_INPUT_READ_ONLY usage",
            {}) {
  Scene scene(device);
  SharedMemory memory(device, 1 << 16);
  vkkit::Buffer vertices = memory.Bind(512, 256, kInput);
  [[maybe_unused]] vkkit::Buffer overlay = memory.Bind(512, 256, kStorage);  // a compute pass's view of these bytes
  const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  std::memcpy(vertices.mapped, positions, sizeof(positions));
  VkAccelerationStructureGeometryKHR g = scene.Triangles();
  g.geometry.triangles.vertexData.deviceAddress = vertices.address;
  OneGeometry one(scene, g);
  scene.BuildNow({one.info}, {&kOne});
}

}  // namespace
