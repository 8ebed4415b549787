// Family "host": rules of vkBuildAccelerationStructuresKHR alone (host pointers for inputs and scratch, the memory
// of the structures, deferred operations). Lavapipe has no accelerationStructureHostCommands: every host build here
// also breaks that feature rule (labelled with it), and only calls a layer skips may be made. The "feature-only"
// cases are the valid twins of this family on such a device: host builds whose only fault is the missing feature,
// shaped like what the host checks could confuse (null inputs of empty geometries, scratch inside a mapping, many
// instances of one BLAS).
#include <cstring>
#include <vector>

#include "corpus.h"
#include "memory_placement_helpers.h"
#include "record_checks_helpers.h"

namespace {

using asval_test::CallHostBuild;
using asval_test::DriverSizes;
using asval_test::Scene;

constexpr VkAccelerationStructureTypeKHR kBottom = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
constexpr const char* kHostFeature = "VUID-vkBuildAccelerationStructuresKHR-accelerationStructureHostCommands-03581";

// A host build of one geometry with host pointers everywhere; the destination and its size from the scene.
struct HostBuild {
  float vertices[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  uint32_t indices[3] = {0, 1, 2};
  VkAabbPositionsKHR box = {0, 0, 0, 1, 1, 1};
  VkAccelerationStructureInstanceKHR instance{};
  std::vector<unsigned char> scratch = std::vector<unsigned char>(1 << 16);
  VkAccelerationStructureGeometryKHR geometry{};
  VkAccelerationStructureBuildGeometryInfoKHR info{};
  VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};

  HostBuild(Scene& scene, VkAccelerationStructureGeometryKHR g) : geometry(g) {
    switch (geometry.geometryType) {
      case VK_GEOMETRY_TYPE_TRIANGLES_KHR:
        geometry.geometry.triangles.vertexData.hostAddress = vertices;
        if (geometry.geometry.triangles.indexType != VK_INDEX_TYPE_NONE_KHR) {
          geometry.geometry.triangles.indexData.hostAddress = indices;
        }
        geometry.geometry.triangles.transformData.hostAddress = nullptr;
        break;
      case VK_GEOMETRY_TYPE_AABBS_KHR:
        geometry.geometry.aabbs.data.hostAddress = &box;
        break;
      default:
        instance.transform.matrix[0][0] = instance.transform.matrix[1][1] = instance.transform.matrix[2][2] = 1.0f;
        instance.mask = 0xff;
        instance.accelerationStructureReference = reinterpret_cast<uint64_t>(scene.blas());
        geometry.geometry.instances.data.hostAddress = &instance;
        break;
    }
    const auto type = geometry.geometryType == VK_GEOMETRY_TYPE_INSTANCES_KHR
                          ? VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR
                          : kBottom;
    info = Scene::Info(type, {geometry});
    info.pGeometries = &geometry;
    scene.Prepare(info, {1});
    info.scratchData.hostAddress = scratch.data();
  }
  // Instances are copied into mapped memory for the call: without accelerationStructureHostCommands (lavapipe)
  // asval reads a host build's inputs only inside the app's mappings (layer/checks/host_reads.h).
  void Call(vkkit::Device& device) {
    if (geometry.geometryType != VK_GEOMETRY_TYPE_INSTANCES_KHR || geometry.geometry.instances.arrayOfPointers ||
        geometry.geometry.instances.data.hostAddress != &instance) {
      CallHostBuild(device, {info}, {&range});
      return;
    }
    vkkit::Buffer mapped = device.CreateBuffer(sizeof(instance), VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
    std::memcpy(mapped.mapped, &instance, sizeof(instance));
    geometry.geometry.instances.data.hostAddress = mapped.mapped;
    CallHostBuild(device, {info}, {&range});
    geometry.geometry.instances.data.hostAddress = &instance;
    device.Destroy(mapped);
  }
};

// ---- scratch

CORPUS_CASE(NullScratchBuild, "host-null-scratch-build", "host",
            "a host BLAS build with a null scratchData.hostAddress although the driver asks for build scratch",
            {"VUID-vkBuildAccelerationStructuresKHR-pInfos-03725", kHostFeature}) {
  Scene scene(device);
  HostBuild build(scene, scene.Triangles());
  build.info.scratchData.hostAddress = nullptr;
  build.Call(device);
}

CORPUS_CASE(NullScratchUpdate, "host-null-scratch-update", "host",
            "a BLAS built on the device, then refitted on the host with a null scratchData.hostAddress although the "
            "driver asks for update scratch",
            {"VUID-vkBuildAccelerationStructuresKHR-pInfos-03726", kHostFeature}) {
  Scene scene(device);
  VkAccelerationStructureGeometryKHR g = scene.Triangles();
  VkAccelerationStructureBuildGeometryInfoKHR info = Scene::Info(kBottom, {g});
  info.pGeometries = &g;
  scene.Prepare(info, {1});
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  scene.BuildNow({info}, {&range});
  VkAccelerationStructureGeometryKHR host = scene.OnHost(g);
  info.pGeometries = &host;
  info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  info.srcAccelerationStructure = info.dstAccelerationStructure;
  info.scratchData.hostAddress = nullptr;
  CallHostBuild(device, {info}, {&range});
}

CORPUS_CASE(ScratchPastMapping, "host-scratch-past-end-of-mapping", "host",
            "a host BLAS build whose scratch pointer lies 16 bytes before the end of the 4096 bytes the program "
            "mapped of a larger allocation",
            {"VUID-vkBuildAccelerationStructuresKHR-pInfos-03725", kHostFeature}) {
  Scene scene(device);
  HostBuild build(scene, scene.Triangles());
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = 1 << 16;
  alloc.memoryTypeIndex = device.FindMemoryType(~0u, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  vkkit::Check(vkAllocateMemory(device.handle(), &alloc, nullptr, &memory), "vkAllocateMemory");
  void* mapped = nullptr;
  vkkit::Check(vkMapMemory(device.handle(), memory, 0, 4096, 0, &mapped), "vkMapMemory");
  build.info.scratchData.hostAddress = static_cast<char*>(mapped) + 4096 - 16;
  build.Call(device);
  vkUnmapMemory(device.handle(), memory);
  vkFreeMemory(device.handle(), memory, nullptr);
}

// ---- null input pointers of geometries that build primitives

CORPUS_CASE(NullVertices, "host-null-vertex-pointer", "host",
            "a host BLAS build of one triangle whose vertexData.hostAddress is null",
            {"VUID-vkBuildAccelerationStructuresKHR-pInfos-03771", kHostFeature}) {
  Scene scene(device);
  HostBuild build(scene, scene.Triangles());
  build.geometry.geometry.triangles.vertexData.hostAddress = nullptr;
  build.Call(device);
}

CORPUS_CASE(NullIndices, "host-null-index-pointer", "host",
            "a host build of one indexed triangle (UINT32) whose indexData.hostAddress is null",
            {"VUID-vkBuildAccelerationStructuresKHR-pInfos-03772", kHostFeature}) {
  Scene scene(device);
  HostBuild build(scene, scene.IndexedTriangles(VK_INDEX_TYPE_UINT32));
  build.geometry.geometry.triangles.indexData.hostAddress = nullptr;
  build.Call(device);
}

CORPUS_CASE(NullAabbs, "host-null-aabb-pointer", "host",
            "a host build of one AABB whose data.hostAddress is null",
            {"VUID-vkBuildAccelerationStructuresKHR-pInfos-03774", kHostFeature}) {
  Scene scene(device);
  HostBuild build(scene, scene.Aabbs());
  build.geometry.geometry.aabbs.data.hostAddress = nullptr;
  build.Call(device);
}

CORPUS_CASE(NullInstances, "host-null-instance-pointer", "host",
            "a host TLAS build of one instance whose data.hostAddress is null",
            {"VUID-vkBuildAccelerationStructuresKHR-pInfos-03778", kHostFeature}) {
  Scene scene(device);
  HostBuild build(scene, scene.Instances());
  build.geometry.geometry.instances.data.hostAddress = nullptr;
  build.Call(device);
}

// ---- referenced structures

CORPUS_CASE(DestroyedReference, "host-instance-of-destroyed-blas", "host",
            "a host TLAS build whose instance holds the handle of a BLAS destroyed before the call",
            {"VUID-vkBuildAccelerationStructuresKHR-pInfos-03779", kHostFeature}) {
  Scene scene(device);
  HostBuild build(scene, scene.Instances());
  vkkit::AccelerationStructure gone = device.CreateAccelerationStructure(kBottom, 256);
  build.instance.accelerationStructureReference = reinterpret_cast<uint64_t>(gone.handle);
  device.Destroy(gone);
  build.Call(device);
}

CORPUS_CASE(DestroyedReferenceByPointer, "host-instance-pointer-to-destroyed-blas", "host",
            "a host TLAS build with arrayOfPointers whose second pointed-to instance holds a destroyed BLAS handle",
            {"VUID-vkBuildAccelerationStructuresKHR-pInfos-03779", kHostFeature}) {
  Scene scene(device);
  HostBuild build(scene, scene.Instances(true));
  vkkit::AccelerationStructure gone = device.CreateAccelerationStructure(kBottom, 256);
  VkAccelerationStructureInstanceKHR second = build.instance;
  second.accelerationStructureReference = reinterpret_cast<uint64_t>(gone.handle);
  // The two instances and the array of pointers to them in mapped memory (see HostBuild::Call).
  struct Mapped {
    VkAccelerationStructureInstanceKHR instances[2];
    const VkAccelerationStructureInstanceKHR* pointers[2];
  };
  vkkit::Buffer mapped = device.CreateBuffer(sizeof(Mapped), VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  Mapped* m = static_cast<Mapped*>(mapped.mapped);
  m->instances[0] = build.instance;
  m->instances[1] = second;
  m->pointers[0] = &m->instances[0];
  m->pointers[1] = &m->instances[1];
  build.geometry.geometry.instances.arrayOfPointers = VK_TRUE;
  build.geometry.geometry.instances.data.hostAddress = m->pointers;
  build.range.primitiveCount = 2;
  scene.Prepare(build.info, {2});  // a destination sized for 2 instances
  // Destroyed only now: a structure created after it (the destination above) could take its handle value (lavapipe's
  // handles are heap addresses), and the reference would then name a live structure.
  device.Destroy(gone);
  build.info.scratchData.hostAddress = build.scratch.data();
  build.Call(device);
  device.Destroy(mapped);
}

// ---- feature-only twins: nothing but the missing feature is wrong

CORPUS_CASE(EmptyGeometriesNullInputs, "host-feature-only-null-inputs-of-empty-geometries", "host",
            "a host BLAS build of two triangle geometries of 0 primitives each, whose vertex pointers are null "
            "(nothing is read), with a host scratch vector",
            {kHostFeature}) {
  Scene scene(device);
  std::vector<unsigned char> scratch(1 << 16);
  VkAccelerationStructureGeometryKHR geometries[2] = {scene.Triangles(), scene.Triangles()};
  geometries[0].geometry.triangles.vertexData.hostAddress = nullptr;
  geometries[1].geometry.triangles.vertexData.hostAddress = nullptr;
  VkAccelerationStructureBuildGeometryInfoKHR info = Scene::Info(kBottom, {geometries[0], geometries[1]});
  info.pGeometries = geometries;
  scene.Prepare(info, {0, 0});
  info.scratchData.hostAddress = scratch.data();
  const VkAccelerationStructureBuildRangeInfoKHR ranges[2] = {{0, 0, 0, 0}, {0, 0, 0, 0}};
  CallHostBuild(device, {info}, {ranges});
}

CORPUS_CASE(ScratchInsideMapping, "host-feature-only-scratch-inside-mapping", "host",
            "a host BLAS build whose scratch is the first bytes of a 64 KiB mapping of host-visible memory (the "
            "whole driver scratch size fits)",
            {kHostFeature}) {
  Scene scene(device);
  HostBuild build(scene, scene.Triangles());
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = 1 << 16;
  alloc.memoryTypeIndex = device.FindMemoryType(~0u, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  vkkit::Check(vkAllocateMemory(device.handle(), &alloc, nullptr, &memory), "vkAllocateMemory");
  void* mapped = nullptr;
  vkkit::Check(vkMapMemory(device.handle(), memory, 0, VK_WHOLE_SIZE, 0, &mapped), "vkMapMemory");
  build.info.scratchData.hostAddress = mapped;
  build.Call(device);
  vkUnmapMemory(device.handle(), memory);
  vkFreeMemory(device.handle(), memory, nullptr);
}

CORPUS_CASE(ManyInstancesOneBlas, "host-feature-only-1000-instances-of-one-blas", "host",
            "a host TLAS build of 1000 instances of one live BLAS, sized by the driver, with host scratch", {kHostFeature}) {
  Scene scene(device);
  constexpr uint32_t kInstances = 1000;
  VkAccelerationStructureInstanceKHR prototype{};
  prototype.transform.matrix[0][0] = prototype.transform.matrix[1][1] = prototype.transform.matrix[2][2] = 1.0f;
  prototype.mask = 0xff;
  prototype.accelerationStructureReference = reinterpret_cast<uint64_t>(scene.blas());
  // In mapped memory, where asval reads them without host commands (see HostBuild::Call).
  vkkit::Buffer mapped = device.CreateBuffer(kInstances * sizeof(prototype), VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  auto* instances = static_cast<VkAccelerationStructureInstanceKHR*>(mapped.mapped);
  for (uint32_t i = 0; i < kInstances; ++i) instances[i] = prototype;
  VkAccelerationStructureGeometryKHR g = scene.Instances();
  g.geometry.instances.data.hostAddress = instances;
  VkAccelerationStructureBuildGeometryInfoKHR info = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, {g});
  info.pGeometries = &g;
  const VkAccelerationStructureBuildSizesInfoKHR sizes = DriverSizes(device, info, {kInstances});
  info.dstAccelerationStructure =
      scene.NewStructure(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, sizes.accelerationStructureSize);
  std::vector<unsigned char> scratch(sizes.buildScratchSize);
  info.scratchData.hostAddress = scratch.data();
  const VkAccelerationStructureBuildRangeInfoKHR range{kInstances, 0, 0, 0};
  CallHostBuild(device, {info}, {&range});
  device.Destroy(mapped);
}

}  // namespace
