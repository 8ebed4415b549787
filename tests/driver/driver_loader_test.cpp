// The test driver through the real loader, alone over lavapipe: what it reports, and that what it executes is what
// the device executes for the same inputs (a host build and its device twin serialize to the same bytes).
#include <catch2/catch_test_macros.hpp>
#include <cstdlib>
#include <cstring>
#include <vector>

#include "test_driver_api.h"
#include "vkkit.h"

namespace {

template <typename F>
F Load(VkDevice device, const char* name) {
  return reinterpret_cast<F>(vkGetDeviceProcAddr(device, name));
}

// An instance with the test driver alone, a device with host commands, and the host commands.
struct DriverDevice {
  vkkit::Instance instance{vkkit::InstanceOptions{{"VK_LAYER_ASVAL_test_driver"}, nullptr, false}};
  VkPhysicalDevice gpu = instance.FindRayTracingGpu();
  vkkit::Device device{instance, gpu, Options()};
  VkDevice vk = device.handle();
  PFN_vkBuildAccelerationStructuresKHR Build =
      Load<PFN_vkBuildAccelerationStructuresKHR>(vk, "vkBuildAccelerationStructuresKHR");
  PFN_vkCopyAccelerationStructureToMemoryKHR ToMemory =
      Load<PFN_vkCopyAccelerationStructureToMemoryKHR>(vk, "vkCopyAccelerationStructureToMemoryKHR");
  PFN_vkCopyMemoryToAccelerationStructureKHR FromMemory =
      Load<PFN_vkCopyMemoryToAccelerationStructureKHR>(vk, "vkCopyMemoryToAccelerationStructureKHR");
  PFN_vkCopyAccelerationStructureKHR Copy =
      Load<PFN_vkCopyAccelerationStructureKHR>(vk, "vkCopyAccelerationStructureKHR");
  PFN_vkWriteAccelerationStructuresPropertiesKHR Properties =
      Load<PFN_vkWriteAccelerationStructuresPropertiesKHR>(vk, "vkWriteAccelerationStructuresPropertiesKHR");

  static vkkit::DeviceOptions Options() {
    vkkit::DeviceOptions options;
    options.host_commands = true;
    options.indirect_build = true;
    return options;
  }

  uint64_t Property(VkAccelerationStructureKHR as, VkQueryType type) {
    uint64_t value = 0;
    vkkit::Check(Properties(vk, 1, &as, type, sizeof(value), &value, sizeof(value)), "properties");
    return value;
  }

  std::vector<unsigned char> Serialize(VkAccelerationStructureKHR as) {
    std::vector<unsigned char> bytes(Property(as, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR));
    VkCopyAccelerationStructureToMemoryInfoKHR info{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_TO_MEMORY_INFO_KHR};
    info.src = as;
    info.dst.hostAddress = bytes.data();
    info.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR;
    vkkit::Check(ToMemory(vk, VK_NULL_HANDLE, &info), "serialize");
    return bytes;
  }

  VkAccelerationStructureBuildSizesInfoKHR Sizes(const VkAccelerationStructureBuildGeometryInfoKHR& info,
                                                 uint32_t count) {
    VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
    device.GetAccelerationStructureBuildSizesKHR(vk, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_HOST_KHR, &info, &count,
                                                 &sizes);
    return sizes;
  }
};

// Two triangles, uint16 indices at primitiveOffset 4, firstVertex 2: the vertices before firstVertex and the
// bytes before the indices are garbage a correct build never reads.
struct Mesh {
  float vertices[7 * 4] = {9e9f, 9e9f, 9e9f, 0, 9e9f, 9e9f, 9e9f, 0,  // skipped by firstVertex
                           0,    0,    0,    0, 1,    0,    0,    0, 0, 1, 0, 0, 1, 1, 0.5f, 0, 2, 2, 2, 0};
  uint16_t indices[2 + 6] = {0xffff, 0xffff, 0, 1, 2, 1, 3, 2};
  VkAccelerationStructureGeometryKHR geometry{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  VkAccelerationStructureBuildRangeInfoKHR range{2, 4, 2, 0};

  Mesh() {
    geometry.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
    auto& t = geometry.geometry.triangles;
    t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
    t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
    t.vertexStride = 16;
    t.maxVertex = 6;
    t.indexType = VK_INDEX_TYPE_UINT16;
    info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
    info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
    info.geometryCount = 1;
    info.pGeometries = &geometry;
  }
};

// The payload after the serialization header (two UUIDs, three sizes and the handles' addresses): what the
// structure holds.
std::vector<unsigned char> Payload(const std::vector<unsigned char>& serialized) {
  uint64_t handles = 0;
  std::memcpy(&handles, serialized.data() + 2 * VK_UUID_SIZE + 16, sizeof(handles));
  const size_t header = 2 * VK_UUID_SIZE + 24 + 8 * handles;
  return {serialized.begin() + static_cast<std::ptrdiff_t>(header), serialized.end()};
}

TEST_CASE("test driver: reports host commands and indirect builds and creates the device with them enabled") {
  vkkit::Instance instance(vkkit::InstanceOptions{{"VK_LAYER_ASVAL_test_driver"}, nullptr, false});
  VkPhysicalDeviceAccelerationStructureFeaturesKHR as{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR};
  VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &as};
  vkGetPhysicalDeviceFeatures2(instance.FindRayTracingGpu(), &features);
  CHECK(as.accelerationStructure == VK_TRUE);
  CHECK(as.accelerationStructureHostCommands == VK_TRUE);
  CHECK(as.accelerationStructureIndirectBuild == VK_TRUE);
  DriverDevice driver;  // vkkit throws if the device cannot be created
  CHECK(driver.Build != nullptr);
}

TEST_CASE("test driver: a host build reads what the device build reads and builds the same structure") {
  DriverDevice d;
  Mesh host_mesh, device_mesh;
  const auto sizes = d.Sizes(host_mesh.info, 2);
  auto host_as = d.device.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                                      sizes.accelerationStructureSize);
  auto device_as = d.device.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                                        sizes.accelerationStructureSize);
  // Host: host addresses, host scratch.
  std::vector<unsigned char> scratch(sizes.buildScratchSize);
  auto& ht = host_mesh.geometry.geometry.triangles;
  ht.vertexData.hostAddress = host_mesh.vertices;
  ht.indexData.hostAddress = host_mesh.indices;
  host_mesh.info.dstAccelerationStructure = host_as.handle;
  host_mesh.info.scratchData.hostAddress = scratch.data();
  const VkAccelerationStructureBuildRangeInfoKHR* host_range = &host_mesh.range;
  REQUIRE(d.Build(d.vk, VK_NULL_HANDLE, 1, &host_mesh.info, &host_range) == VK_SUCCESS);
  // Device: the same bytes in buffers.
  auto vertices = d.device.CreateBuffer(sizeof(device_mesh.vertices),
                                        VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  auto indices = d.device.CreateBuffer(sizeof(device_mesh.indices),
                                       VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  auto device_scratch = d.device.CreateBuffer(sizes.buildScratchSize, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  std::memcpy(vertices.mapped, device_mesh.vertices, sizeof(device_mesh.vertices));
  std::memcpy(indices.mapped, device_mesh.indices, sizeof(device_mesh.indices));
  // The device twin names firstVertex through the vertex address (range firstVertex 0): lavapipe 25 adds a
  // range's firstVertex twice, where the specification adds it once.
  auto& dt = device_mesh.geometry.geometry.triangles;
  dt.vertexData.deviceAddress = vertices.address + device_mesh.range.firstVertex * dt.vertexStride;
  device_mesh.range.firstVertex = 0;
  dt.indexData.deviceAddress = indices.address;
  device_mesh.info.dstAccelerationStructure = device_as.handle;
  device_mesh.info.scratchData.deviceAddress = device_scratch.address;
  d.device.OneShot([&](VkCommandBuffer cb) {
    const VkAccelerationStructureBuildRangeInfoKHR* range = &device_mesh.range;
    d.device.CmdBuildAccelerationStructuresKHR(cb, 1, &device_mesh.info, &range);
  });

  const auto host_bytes = d.Serialize(host_as.handle);
  const auto device_bytes = d.Serialize(device_as.handle);
  REQUIRE(host_bytes.size() == device_bytes.size());
  CHECK(Payload(host_bytes) == Payload(device_bytes));
  CHECK(d.Property(host_as.handle, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR) ==
        d.Property(device_as.handle, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR));

  // A vertex the device build does not read changes nothing; one it reads changes the structure.
  Mesh other;
  other.vertices[0] = -5;  // before firstVertex
  other.geometry.geometry.triangles.vertexData.hostAddress = other.vertices;
  other.geometry.geometry.triangles.indexData.hostAddress = other.indices;
  other.info.dstAccelerationStructure = host_as.handle;
  other.info.scratchData.hostAddress = scratch.data();
  const VkAccelerationStructureBuildRangeInfoKHR* other_range = &other.range;
  REQUIRE(d.Build(d.vk, VK_NULL_HANDLE, 1, &other.info, &other_range) == VK_SUCCESS);
  CHECK(Payload(d.Serialize(host_as.handle)) == Payload(device_bytes));
  other.vertices[4 * 5 + 2] = 7;  // vertex 3 (index 3 + firstVertex 2), read by the second triangle
  REQUIRE(d.Build(d.vk, VK_NULL_HANDLE, 1, &other.info, &other_range) == VK_SUCCESS);
  CHECK(Payload(d.Serialize(host_as.handle)) != Payload(device_bytes));

  d.device.Destroy(vertices);
  d.device.Destroy(indices);
  d.device.Destroy(device_scratch);
  d.device.Destroy(host_as);
  d.device.Destroy(device_as);
}

TEST_CASE("test driver: a deferred host build runs when joined; host copies and deserialization round-trip") {
  DriverDevice d;
  Mesh mesh;
  const auto sizes = d.Sizes(mesh.info, 2);
  auto as = d.device.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                                 sizes.accelerationStructureSize);
  std::vector<unsigned char> scratch(sizes.buildScratchSize);
  mesh.geometry.geometry.triangles.vertexData.hostAddress = mesh.vertices;
  mesh.geometry.geometry.triangles.indexData.hostAddress = mesh.indices;
  mesh.info.dstAccelerationStructure = as.handle;
  mesh.info.scratchData.hostAddress = scratch.data();
  const VkAccelerationStructureBuildRangeInfoKHR* range = &mesh.range;

  auto create = Load<PFN_vkCreateDeferredOperationKHR>(d.vk, "vkCreateDeferredOperationKHR");
  auto join = Load<PFN_vkDeferredOperationJoinKHR>(d.vk, "vkDeferredOperationJoinKHR");
  auto result = Load<PFN_vkGetDeferredOperationResultKHR>(d.vk, "vkGetDeferredOperationResultKHR");
  auto destroy = Load<PFN_vkDestroyDeferredOperationKHR>(d.vk, "vkDestroyDeferredOperationKHR");
  VkDeferredOperationKHR operation = VK_NULL_HANDLE;
  REQUIRE(create(d.vk, nullptr, &operation) == VK_SUCCESS);
  REQUIRE(d.Build(d.vk, operation, 1, &mesh.info, &range) == VK_OPERATION_DEFERRED_KHR);
  CHECK(result(d.vk, operation) == VK_NOT_READY);
  CHECK(join(d.vk, operation) == VK_SUCCESS);
  CHECK(result(d.vk, operation) == VK_SUCCESS);
  CHECK(join(d.vk, operation) == VK_THREAD_DONE_KHR);
  destroy(d.vk, operation, nullptr);
  const auto built = d.Serialize(as.handle);
  CHECK(d.Property(as.handle, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR) != 0);

  // Serialized bytes into a new structure, and a host clone: both serialize as the original.
  auto restored = d.device.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                                       sizes.accelerationStructureSize);
  VkCopyMemoryToAccelerationStructureInfoKHR from{VK_STRUCTURE_TYPE_COPY_MEMORY_TO_ACCELERATION_STRUCTURE_INFO_KHR};
  from.src.hostAddress = built.data();
  from.dst = restored.handle;
  from.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_DESERIALIZE_KHR;
  REQUIRE(d.FromMemory(d.vk, VK_NULL_HANDLE, &from) == VK_SUCCESS);
  CHECK(Payload(d.Serialize(restored.handle)) == Payload(built));
  auto clone = d.device.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                                    sizes.accelerationStructureSize);
  VkCopyAccelerationStructureInfoKHR copy{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR};
  copy.src = as.handle;
  copy.dst = clone.handle;
  copy.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR;
  REQUIRE(d.Copy(d.vk, VK_NULL_HANDLE, &copy) == VK_SUCCESS);
  CHECK(Payload(d.Serialize(clone.handle)) == Payload(built));
  d.device.Destroy(clone);
  d.device.Destroy(restored);
  d.device.Destroy(as);
}

TEST_CASE("test driver: an indirect build reads its ranges from memory when its submission is made") {
  DriverDevice d;
  auto indirect =
      Load<PFN_vkCmdBuildAccelerationStructuresIndirectKHR>(d.vk, "vkCmdBuildAccelerationStructuresIndirectKHR");
  REQUIRE(indirect != nullptr);
  Mesh mesh;
  const auto sizes = d.Sizes(mesh.info, 2);
  auto vertices = d.device.CreateBuffer(sizeof(mesh.vertices),
                                        VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  auto indices =
      d.device.CreateBuffer(sizeof(mesh.indices), VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  auto scratch = d.device.CreateBuffer(sizes.buildScratchSize, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  auto ranges = d.device.CreateBuffer(64, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  std::memcpy(vertices.mapped, mesh.vertices, sizeof(mesh.vertices));
  std::memcpy(indices.mapped, mesh.indices, sizeof(mesh.indices));
  auto& t = mesh.geometry.geometry.triangles;
  t.vertexData.deviceAddress = vertices.address;
  t.indexData.deviceAddress = indices.address;
  auto built = d.device.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                                    sizes.accelerationStructureSize);
  auto direct = d.device.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR,
                                                     sizes.accelerationStructureSize);
  mesh.info.scratchData.deviceAddress = scratch.address;

  // One command buffer holding the indirect build, recorded once, submitted twice.
  VkCommandPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_COMMAND_POOL_CREATE_INFO};
  VkCommandPool pool = VK_NULL_HANDLE;
  REQUIRE(vkCreateCommandPool(d.vk, &pool_info, nullptr, &pool) == VK_SUCCESS);
  VkCommandBufferAllocateInfo allocate{VK_STRUCTURE_TYPE_COMMAND_BUFFER_ALLOCATE_INFO};
  allocate.commandPool = pool;
  allocate.level = VK_COMMAND_BUFFER_LEVEL_PRIMARY;
  allocate.commandBufferCount = 1;
  VkCommandBuffer cb = VK_NULL_HANDLE;
  REQUIRE(vkAllocateCommandBuffers(d.vk, &allocate, &cb) == VK_SUCCESS);
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  REQUIRE(vkBeginCommandBuffer(cb, &begin) == VK_SUCCESS);
  VkAccelerationStructureBuildGeometryInfoKHR info = mesh.info;
  info.dstAccelerationStructure = built.handle;
  const uint32_t max_count = 2;
  const uint32_t* max_counts = &max_count;
  const uint32_t stride = sizeof(VkAccelerationStructureBuildRangeInfoKHR);
  indirect(cb, 1, &info, &ranges.address, &stride, &max_counts);
  REQUIRE(vkEndCommandBuffer(cb) == VK_SUCCESS);
  VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence = VK_NULL_HANDLE;
  REQUIRE(vkCreateFence(d.vk, &fence_info, nullptr, &fence) == VK_SUCCESS);

  for (uint32_t count : {1u, 2u}) {
    // The ranges as the device reads them: written by the host before this submission.
    const VkAccelerationStructureBuildRangeInfoKHR range{count, 4, 2, 0};
    std::memcpy(ranges.mapped, &range, sizeof(range));
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = 1;
    submit.pCommandBuffers = &cb;
    REQUIRE(vkQueueSubmit(d.device.queue(), 1, &submit, fence) == VK_SUCCESS);
    REQUIRE(vkWaitForFences(d.vk, 1, &fence, VK_TRUE, UINT64_MAX) == VK_SUCCESS);
    REQUIRE(vkResetFences(d.vk, 1, &fence) == VK_SUCCESS);
    // The direct twin: the same count, firstVertex through the vertex address (lavapipe adds it twice).
    VkAccelerationStructureGeometryKHR geometry = mesh.geometry;
    geometry.geometry.triangles.vertexData.deviceAddress = vertices.address + 2 * t.vertexStride;
    VkAccelerationStructureBuildGeometryInfoKHR twin = mesh.info;
    twin.pGeometries = &geometry;
    twin.dstAccelerationStructure = direct.handle;
    const VkAccelerationStructureBuildRangeInfoKHR twin_range{count, 4, 0, 0};
    d.device.OneShot([&](VkCommandBuffer one) {
      const VkAccelerationStructureBuildRangeInfoKHR* r = &twin_range;
      d.device.CmdBuildAccelerationStructuresKHR(one, 1, &twin, &r);
    });
    CAPTURE(count);
    CHECK(Payload(d.Serialize(built.handle)) == Payload(d.Serialize(direct.handle)));
  }
  vkDestroyFence(d.vk, fence, nullptr);
  vkDestroyCommandPool(d.vk, pool, nullptr);
  d.device.Destroy(built);
  d.device.Destroy(direct);
  d.device.Destroy(ranges);
  d.device.Destroy(scratch);
  d.device.Destroy(indices);
  d.device.Destroy(vertices);
}

}  // namespace

namespace {

TEST_CASE("test driver: says it is an integrated GPU when ASVAL_TEST_DRIVER_DEVICE_TYPE asks, lavapipe's CPU else") {
  vkkit::Instance instance(vkkit::InstanceOptions{{"VK_LAYER_ASVAL_test_driver"}, nullptr, false});
  const VkPhysicalDevice gpu = instance.FindRayTracingGpu();
  const auto type = [&] {
    VkPhysicalDeviceProperties core{};
    vkGetPhysicalDeviceProperties(gpu, &core);
    VkPhysicalDeviceProperties2 both{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2};
    vkGetPhysicalDeviceProperties2(gpu, &both);
    CHECK(core.deviceType == both.properties.deviceType);
    return core.deviceType;
  };
  unsetenv("ASVAL_TEST_DRIVER_DEVICE_TYPE");
  CHECK(type() == VK_PHYSICAL_DEVICE_TYPE_CPU);
  setenv("ASVAL_TEST_DRIVER_DEVICE_TYPE", "integrated-gpu", 1);
  CHECK(type() == VK_PHYSICAL_DEVICE_TYPE_INTEGRATED_GPU);
  unsetenv("ASVAL_TEST_DRIVER_DEVICE_TYPE");
}

}  // namespace

namespace {

// VK_NV_ray_tracing's entry points, as a device that enables it gets them.
struct NvFunctions {
  explicit NvFunctions(VkDevice vk)
      : Create(Load<PFN_vkCreateAccelerationStructureNV>(vk, "vkCreateAccelerationStructureNV")),
        Destroy(Load<PFN_vkDestroyAccelerationStructureNV>(vk, "vkDestroyAccelerationStructureNV")),
        Requirements(Load<PFN_vkGetAccelerationStructureMemoryRequirementsNV>(
            vk, "vkGetAccelerationStructureMemoryRequirementsNV")),
        Bind(Load<PFN_vkBindAccelerationStructureMemoryNV>(vk, "vkBindAccelerationStructureMemoryNV")),
        Handle(Load<PFN_vkGetAccelerationStructureHandleNV>(vk, "vkGetAccelerationStructureHandleNV")),
        CmdBuild(Load<PFN_vkCmdBuildAccelerationStructureNV>(vk, "vkCmdBuildAccelerationStructureNV")),
        CmdCopy(Load<PFN_vkCmdCopyAccelerationStructureNV>(vk, "vkCmdCopyAccelerationStructureNV")),
        CmdWriteProperties(Load<PFN_vkCmdWriteAccelerationStructuresPropertiesNV>(
            vk, "vkCmdWriteAccelerationStructuresPropertiesNV")) {}
  PFN_vkCreateAccelerationStructureNV Create;
  PFN_vkDestroyAccelerationStructureNV Destroy;
  PFN_vkGetAccelerationStructureMemoryRequirementsNV Requirements;
  PFN_vkBindAccelerationStructureMemoryNV Bind;
  PFN_vkGetAccelerationStructureHandleNV Handle;
  PFN_vkCmdBuildAccelerationStructureNV CmdBuild;
  PFN_vkCmdCopyAccelerationStructureNV CmdCopy;
  PFN_vkCmdWriteAccelerationStructuresPropertiesNV CmdWriteProperties;
};

std::vector<VkExtensionProperties> DeviceExtensions(VkPhysicalDevice gpu) {
  uint32_t count = 0;
  REQUIRE(vkEnumerateDeviceExtensionProperties(gpu, nullptr, &count, nullptr) == VK_SUCCESS);
  std::vector<VkExtensionProperties> extensions(count);
  REQUIRE(vkEnumerateDeviceExtensionProperties(gpu, nullptr, &count, extensions.data()) == VK_SUCCESS);
  extensions.resize(count);
  return extensions;
}

TEST_CASE("test driver: lists VK_NV_ray_tracing and reports its properties; a device without it is unchanged") {
  vkkit::Instance instance(vkkit::InstanceOptions{{"VK_LAYER_ASVAL_test_driver"}, nullptr, false});
  const VkPhysicalDevice gpu = instance.FindRayTracingGpu();
  const auto extensions = DeviceExtensions(gpu);
  uint32_t listed = 0;
  for (const VkExtensionProperties& e : extensions) {
    if (std::strcmp(e.extensionName, VK_NV_RAY_TRACING_EXTENSION_NAME) != 0) continue;
    ++listed;
    CHECK(e.specVersion == 3);
  }
  CHECK(listed == 1);
  // One short: VK_INCOMPLETE, with as many written as asked.
  uint32_t fewer = static_cast<uint32_t>(extensions.size()) - 1;
  std::vector<VkExtensionProperties> some(fewer);
  CHECK(vkEnumerateDeviceExtensionProperties(gpu, nullptr, &fewer, some.data()) == VK_INCOMPLETE);
  CHECK(fewer == extensions.size() - 1);

  // The NV properties between two structures the driver below fills: the chain stays whole.
  VkPhysicalDeviceAccelerationStructurePropertiesKHR as{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR};
  VkPhysicalDeviceRayTracingPropertiesNV nv{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PROPERTIES_NV, &as};
  VkPhysicalDeviceProperties2 properties{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &nv};
  vkGetPhysicalDeviceProperties2(gpu, &properties);
  CHECK(properties.pNext == &nv);
  CHECK(nv.pNext == &as);
  CHECK(as.maxGeometryCount != 0);
  CHECK(nv.maxGeometryCount == 64);
  CHECK(nv.maxGeometryCount == kAsvalTestDriverNvMaxGeometryCount);
  CHECK(nv.shaderGroupHandleSize == 32);
  CHECK(nv.maxRecursionDepth == 31);
  CHECK(nv.maxShaderGroupStride == 4096);
  CHECK(nv.shaderGroupBaseAlignment == 64);
  CHECK(nv.maxInstanceCount == uint64_t{1} << 24);
  CHECK(nv.maxTriangleCount == uint64_t{1} << 29);
  CHECK(nv.maxDescriptorSetAccelerationStructures == 16);

  // A device that does not enable it has none of its commands.
  DriverDevice d;
  CHECK(vkGetDeviceProcAddr(d.vk, "vkCreateAccelerationStructureNV") == nullptr);
  CHECK(vkGetDeviceProcAddr(d.vk, "vkCmdBuildAccelerationStructureNV") == nullptr);
}

TEST_CASE("test driver: VK_NV_ray_tracing structures are created, sized, bound and handled; their commands submitted") {
  vkkit::Instance instance(vkkit::InstanceOptions{{"VK_LAYER_ASVAL_test_driver"}, nullptr, false});
  const VkPhysicalDevice gpu = instance.FindRayTracingGpu();
  vkkit::DeviceOptions options;
  options.extensions = {VK_NV_RAY_TRACING_EXTENSION_NAME};
  vkkit::Device device(instance, gpu, options);  // throws if the device cannot be created
  const VkDevice vk = device.handle();
  const NvFunctions nv(vk);
  REQUIRE(nv.Create != nullptr);
  REQUIRE(nv.Destroy != nullptr);
  REQUIRE(nv.Requirements != nullptr);
  REQUIRE(nv.Bind != nullptr);
  REQUIRE(nv.Handle != nullptr);
  REQUIRE(nv.CmdBuild != nullptr);
  REQUIRE(nv.CmdCopy != nullptr);
  REQUIRE(nv.CmdWriteProperties != nullptr);

  // Three indexed triangles over five vertices (sized by their indices: 9 / 3), one instance of them, the bottom
  // level's clone, and a compacted structure.
  const float vertices[5 * 3] = {0, 0, 0, 1, 0, 0, 0, 1, 0, 1, 1, 0, 2, 2, 0};
  const uint32_t indices[9] = {0, 1, 2, 1, 3, 2, 2, 3, 4};
  // RAY_TRACING_BIT_NV (SHADER_BINDING_TABLE_BIT_KHR) on a device without VK_KHR_ray_tracing_pipeline.
  auto geometry_data = device.CreateBuffer(sizeof(vertices) + sizeof(indices), VK_BUFFER_USAGE_RAY_TRACING_BIT_NV);
  std::memcpy(geometry_data.mapped, vertices, sizeof(vertices));
  std::memcpy(static_cast<char*>(geometry_data.mapped) + sizeof(vertices), indices, sizeof(indices));
  VkGeometryNV geometry{VK_STRUCTURE_TYPE_GEOMETRY_NV};
  geometry.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_NV;
  geometry.flags = VK_GEOMETRY_OPAQUE_BIT_NV;
  auto& t = geometry.geometry.triangles;
  t.sType = VK_STRUCTURE_TYPE_GEOMETRY_TRIANGLES_NV;
  t.vertexData = geometry_data.buffer;
  t.vertexCount = 5;
  t.vertexStride = 12;
  t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
  t.indexData = geometry_data.buffer;
  t.indexOffset = sizeof(vertices);
  t.indexCount = 9;
  t.indexType = VK_INDEX_TYPE_UINT32;
  geometry.geometry.aabbs.sType = VK_STRUCTURE_TYPE_GEOMETRY_AABB_NV;
  VkAccelerationStructureInfoNV bottom_info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_INFO_NV};
  bottom_info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_NV;
  bottom_info.flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_NV;
  bottom_info.geometryCount = 1;
  bottom_info.pGeometries = &geometry;
  VkAccelerationStructureInfoNV top_info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_INFO_NV};
  top_info.type = VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_NV;
  top_info.instanceCount = 1;
  VkAccelerationStructureInfoNV compacted_info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_INFO_NV};
  compacted_info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_NV;

  const auto create = [&](const VkAccelerationStructureInfoNV& info, VkDeviceSize compacted_size) {
    VkAccelerationStructureCreateInfoNV create_info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_NV};
    create_info.compactedSize = compacted_size;
    create_info.info = info;
    VkAccelerationStructureNV structure = VK_NULL_HANDLE;
    REQUIRE(nv.Create(vk, &create_info, nullptr, &structure) == VK_SUCCESS);
    REQUIRE(structure != VK_NULL_HANDLE);
    return structure;
  };
  const VkAccelerationStructureNV bottom = create(bottom_info, 0);
  const VkAccelerationStructureNV top = create(top_info, 0);
  const VkAccelerationStructureNV clone = create(bottom_info, 0);
  const VkAccelerationStructureNV compacted = create(compacted_info, 1000);
  const VkAccelerationStructureNV structures[] = {bottom, top, clone, compacted};

  const auto requirements = [&](VkAccelerationStructureNV structure,
                                VkAccelerationStructureMemoryRequirementsTypeNV type) {
    VkAccelerationStructureMemoryRequirementsInfoNV info{
        VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_INFO_NV};
    info.type = type;
    info.accelerationStructure = structure;
    VkMemoryRequirements2 out{VK_STRUCTURE_TYPE_MEMORY_REQUIREMENTS_2};
    nv.Requirements(vk, &info, &out);
    return out.memoryRequirements;
  };
  constexpr auto kObject = VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_OBJECT_NV;
  constexpr auto kBuild = VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_BUILD_SCRATCH_NV;
  constexpr auto kUpdate = VK_ACCELERATION_STRUCTURE_MEMORY_REQUIREMENTS_TYPE_UPDATE_SCRATCH_NV;
  // By hand: OBJECT 1024 + 128 P up to a multiple of 256, BUILD_SCRATCH 512 + 64 P, UPDATE_SCRATCH 256 + 32 P; a
  // compacted structure's OBJECT its compacted size up to a multiple of 256, its scratch that of P = 0.
  CHECK(requirements(bottom, kObject).size == 1536);  // P = 3: 1024 + 384 = 1408
  CHECK(requirements(bottom, kBuild).size == 704);
  CHECK(requirements(bottom, kUpdate).size == 352);
  CHECK(requirements(top, kObject).size == 1280);  // P = 1: 1024 + 128 = 1152
  CHECK(requirements(top, kBuild).size == 576);
  CHECK(requirements(top, kUpdate).size == 288);
  CHECK(requirements(compacted, kObject).size == 1024);
  CHECK(requirements(compacted, kBuild).size == 512);
  CHECK(requirements(compacted, kUpdate).size == 256);
  VkPhysicalDeviceMemoryProperties memory_properties{};
  vkGetPhysicalDeviceMemoryProperties(gpu, &memory_properties);
  const uint32_t every_type = (1u << memory_properties.memoryTypeCount) - 1;
  for (const VkAccelerationStructureNV structure : structures) {
    for (const auto type : {kObject, kBuild, kUpdate}) {
      const VkMemoryRequirements r = requirements(structure, type);
      CHECK(r.alignment == 256);
      CHECK(r.memoryTypeBits == every_type);
    }
  }

  // One allocation, each structure's OBJECT memory 2048 bytes apart (every OBJECT size here is at most 1536).
  VkMemoryAllocateInfo allocate{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  allocate.allocationSize = 4 * 2048;
  allocate.memoryTypeIndex = 0;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  REQUIRE(vkAllocateMemory(vk, &allocate, nullptr, &memory) == VK_SUCCESS);
  std::vector<VkBindAccelerationStructureMemoryInfoNV> binds;
  for (const VkAccelerationStructureNV structure : structures) {
    VkBindAccelerationStructureMemoryInfoNV bind{VK_STRUCTURE_TYPE_BIND_ACCELERATION_STRUCTURE_MEMORY_INFO_NV};
    bind.accelerationStructure = structure;
    bind.memory = memory;
    bind.memoryOffset = 2048 * binds.size();
    binds.push_back(bind);
  }
  REQUIRE(nv.Bind(vk, static_cast<uint32_t>(binds.size()), binds.data()) == VK_SUCCESS);

  std::vector<uint64_t> handles;
  for (const VkAccelerationStructureNV structure : structures) {
    uint64_t handle = 0;
    REQUIRE(nv.Handle(vk, structure, sizeof(handle), &handle) == VK_SUCCESS);
    CHECK(handle != 0);
    for (const uint64_t other : handles) CHECK(handle != other);
    handles.push_back(handle);
  }

  // The instance of the bottom level, and scratch for the larger build.
  auto instances = device.CreateBuffer(sizeof(VkAccelerationStructureInstanceNV), VK_BUFFER_USAGE_RAY_TRACING_BIT_NV);
  VkAccelerationStructureInstanceNV instance_data{};
  instance_data.transform.matrix[0][0] = instance_data.transform.matrix[1][1] = instance_data.transform.matrix[2][2] =
      1;
  instance_data.mask = 0xff;
  instance_data.accelerationStructureReference = handles[0];
  std::memcpy(instances.mapped, &instance_data, sizeof(instance_data));
  auto scratch = device.CreateBuffer(704, VK_BUFFER_USAGE_RAY_TRACING_BIT_NV);
  VkQueryPoolCreateInfo pool_info{VK_STRUCTURE_TYPE_QUERY_POOL_CREATE_INFO};
  pool_info.queryType = VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV;
  pool_info.queryCount = 1;
  VkQueryPool query_pool = VK_NULL_HANDLE;
  REQUIRE(vkCreateQueryPool(vk, &pool_info, nullptr, &query_pool) == VK_SUCCESS);

  device.OneShot([&](VkCommandBuffer cb) {
    vkCmdResetQueryPool(cb, query_pool, 0, 1);
    VkMemoryBarrier barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
    barrier.srcAccessMask =
        VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_NV | VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_NV;
    barrier.dstAccessMask =
        VK_ACCESS_ACCELERATION_STRUCTURE_WRITE_BIT_NV | VK_ACCESS_ACCELERATION_STRUCTURE_READ_BIT_NV;
    const auto wait_for_builds = [&] {
      vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_NV,
                           VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_NV, 0, 1, &barrier, 0, nullptr, 0,
                           nullptr);
    };
    nv.CmdBuild(cb, &bottom_info, VK_NULL_HANDLE, 0, VK_FALSE, bottom, VK_NULL_HANDLE, scratch.buffer, 0);
    wait_for_builds();
    nv.CmdBuild(cb, &top_info, instances.buffer, 0, VK_FALSE, top, VK_NULL_HANDLE, scratch.buffer, 0);
    wait_for_builds();
    nv.CmdCopy(cb, clone, bottom, VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_NV);
    nv.CmdWriteProperties(cb, 1, &bottom, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_NV, query_pool, 0);
  });  // submitted and waited for
  // Nothing was written (nv_ray_tracing.h): the query is as the reset left it, not ready, or 0 where the driver below
  // answers acceleration-structure queries as available at any time (lavapipe).
  uint64_t compacted_size = 77;
  const VkResult read = vkGetQueryPoolResults(vk, query_pool, 0, 1, sizeof(compacted_size), &compacted_size,
                                              sizeof(compacted_size), VK_QUERY_RESULT_64_BIT);
  CHECK((read == VK_NOT_READY || (read == VK_SUCCESS && compacted_size == 0)));

  vkDestroyQueryPool(vk, query_pool, nullptr);
  for (const VkAccelerationStructureNV structure : structures) nv.Destroy(vk, structure, nullptr);
  vkFreeMemory(vk, memory, nullptr);
  device.Destroy(scratch);
  device.Destroy(instances);
  device.Destroy(geometry_data);
}

}  // namespace

namespace {

TEST_CASE("test driver: lists VK_NV_ray_tracing_motion_blur and reports its features") {
  vkkit::Instance instance(vkkit::InstanceOptions{{"VK_LAYER_ASVAL_test_driver"}, nullptr, false});
  const VkPhysicalDevice gpu = instance.FindRayTracingGpu();
  uint32_t listed = 0;
  for (const VkExtensionProperties& e : DeviceExtensions(gpu)) {
    if (std::strcmp(e.extensionName, VK_NV_RAY_TRACING_MOTION_BLUR_EXTENSION_NAME) != 0) continue;
    ++listed;
    CHECK(e.specVersion == 1);
    CHECK(e.specVersion == kAsvalTestDriverMotionBlurSpecVersion);
  }
  CHECK(listed == 1);

  // The motion-blur features between two structures the driver below fills: the chain stays whole.
  VkPhysicalDeviceRayQueryFeaturesKHR ray_query{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};
  VkPhysicalDeviceRayTracingMotionBlurFeaturesNV motion_blur{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_MOTION_BLUR_FEATURES_NV, &ray_query};
  motion_blur.rayTracingMotionBlurPipelineTraceRaysIndirect = VK_TRUE;  // overwritten
  VkPhysicalDeviceAccelerationStructureFeaturesKHR as{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_FEATURES_KHR, &motion_blur};
  VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &as};
  vkGetPhysicalDeviceFeatures2(gpu, &features);
  CHECK(features.pNext == &as);
  CHECK(as.pNext == &motion_blur);
  CHECK(motion_blur.pNext == &ray_query);
  CHECK(as.accelerationStructure == VK_TRUE);
  CHECK(ray_query.rayQuery == VK_TRUE);
  CHECK(motion_blur.rayTracingMotionBlur == VK_TRUE);
  CHECK(motion_blur.rayTracingMotionBlurPipelineTraceRaysIndirect == VK_FALSE);
  // Alone first in the chain.
  VkPhysicalDeviceRayTracingMotionBlurFeaturesNV alone{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_MOTION_BLUR_FEATURES_NV};
  VkPhysicalDeviceFeatures2 only{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &alone};
  vkGetPhysicalDeviceFeatures2(gpu, &only);
  CHECK(only.pNext == &alone);
  CHECK(alone.pNext == nullptr);
  CHECK(alone.rayTracingMotionBlur == kAsvalTestDriverRayTracingMotionBlur);
  CHECK(alone.rayTracingMotionBlurPipelineTraceRaysIndirect ==
        kAsvalTestDriverRayTracingMotionBlurPipelineTraceRaysIndirect);
}

TEST_CASE("test driver: a motion bottom level is created, sized and built over lavapipe where motion blur is enabled") {
  vkkit::Instance instance(vkkit::InstanceOptions{{"VK_LAYER_ASVAL_test_driver"}, nullptr, false});
  const VkPhysicalDevice gpu = instance.FindRayTracingGpu();
  // VK_NV_ray_tracing_motion_blur requires VK_KHR_ray_tracing_pipeline; the features go below vkkit's own.
  VkPhysicalDeviceRayTracingPipelineFeaturesKHR pipeline{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_PIPELINE_FEATURES_KHR};
  pipeline.rayTracingPipeline = VK_TRUE;
  VkPhysicalDeviceRayTracingMotionBlurFeaturesNV motion_blur{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_MOTION_BLUR_FEATURES_NV, &pipeline};
  motion_blur.rayTracingMotionBlur = VK_TRUE;
  vkkit::DeviceOptions options;
  options.extensions = {VK_KHR_RAY_TRACING_PIPELINE_EXTENSION_NAME, VK_NV_RAY_TRACING_MOTION_BLUR_EXTENSION_NAME};
  options.features = &motion_blur;
  options.host_commands = true;                  // to read the built structure's serialization size
  vkkit::Device device(instance, gpu, options);  // throws if the device cannot be created
  const VkDevice vk = device.handle();
  CHECK(motion_blur.pNext == &pipeline);  // the application's chain, as it gave it
  CHECK(motion_blur.rayTracingMotionBlur == VK_TRUE);

  // One triangle at time 0 (vertexData) and moved along z at time 1 (the motion triangles' vertexData).
  const float vertices[2][3 * 3] = {{0, 0, 0, 1, 0, 0, 0, 1, 0}, {0, 0, 1, 1, 0, 1, 0, 1, 1}};
  auto vertex_buffer =
      device.CreateBuffer(sizeof(vertices), VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  std::memcpy(vertex_buffer.mapped, vertices, sizeof(vertices));
  VkAccelerationStructureGeometryMotionTrianglesDataNV motion_triangles{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_MOTION_TRIANGLES_DATA_NV};
  motion_triangles.vertexData.deviceAddress = vertex_buffer.address + sizeof(vertices[0]);
  VkAccelerationStructureGeometryKHR geometry{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  geometry.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  geometry.flags = VK_GEOMETRY_OPAQUE_BIT_KHR;
  auto& t = geometry.geometry.triangles;
  t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
  t.pNext = &motion_triangles;
  t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
  t.vertexData.deviceAddress = vertex_buffer.address;
  t.vertexStride = 3 * sizeof(float);
  t.maxVertex = 2;
  t.indexType = VK_INDEX_TYPE_NONE_KHR;
  const VkAccelerationStructureGeometryKHR* geometries[] = {&geometry};  // through ppGeometries
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  info.flags =
      VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV | VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  info.geometryCount = 1;
  info.ppGeometries = geometries;
  const uint32_t primitives = 1;
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  device.GetAccelerationStructureBuildSizesKHR(vk, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info, &primitives,
                                               &sizes);
  REQUIRE(sizes.accelerationStructureSize != 0);
  REQUIRE(sizes.buildScratchSize != 0);

  auto storage =
      device.CreateBuffer(sizes.accelerationStructureSize, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
  auto scratch = device.CreateBuffer(sizes.buildScratchSize, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  VkAccelerationStructureMotionInfoNV motion_info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_MOTION_INFO_NV};
  motion_info.maxInstances = 0;
  VkAccelerationStructureCreateInfoKHR create{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR, &motion_info};
  create.createFlags = VK_ACCELERATION_STRUCTURE_CREATE_MOTION_BIT_NV;
  create.buffer = storage.buffer;
  create.size = sizes.accelerationStructureSize;
  create.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  VkAccelerationStructureKHR structure = VK_NULL_HANDLE;
  REQUIRE(device.CreateAccelerationStructureKHR(vk, &create, nullptr, &structure) == VK_SUCCESS);
  REQUIRE(structure != VK_NULL_HANDLE);

  info.dstAccelerationStructure = structure;
  info.scratchData.deviceAddress = scratch.address;
  const VkAccelerationStructureBuildRangeInfoKHR range{primitives, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
  REQUIRE_NOTHROW(device.OneShot([&](VkCommandBuffer cb) {  // submitted and waited for: vkkit throws on an error
    device.CmdBuildAccelerationStructuresKHR(cb, 1, &info, &ranges);
  }));

  // The driver below got copies: the application's structures are as it gave them.
  CHECK(create.createFlags == VK_ACCELERATION_STRUCTURE_CREATE_MOTION_BIT_NV);
  CHECK(create.pNext == &motion_info);
  CHECK((info.flags & VK_BUILD_ACCELERATION_STRUCTURE_MOTION_BIT_NV) != 0);
  CHECK(info.ppGeometries == geometries);
  CHECK(info.pGeometries == nullptr);
  CHECK(t.pNext == &motion_triangles);
  CHECK(motion_triangles.pNext == nullptr);
  // The host build path takes motion out too: the same geometry at host addresses, built by
  // vkBuildAccelerationStructuresKHR into a second motion structure, holds what the device build holds.
  VkAccelerationStructureKHR host_structure = VK_NULL_HANDLE;
  auto host_storage =
      device.CreateBuffer(sizes.accelerationStructureSize, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
  create.buffer = host_storage.buffer;
  REQUIRE(device.CreateAccelerationStructureKHR(vk, &create, nullptr, &host_structure) == VK_SUCCESS);
  VkAccelerationStructureBuildSizesInfoKHR host_sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  device.GetAccelerationStructureBuildSizesKHR(vk, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_HOST_KHR, &info, &primitives,
                                               &host_sizes);
  std::vector<unsigned char> host_scratch(host_sizes.buildScratchSize);
  VkAccelerationStructureGeometryMotionTrianglesDataNV host_motion = motion_triangles;
  host_motion.vertexData.hostAddress = vertices[1];
  VkAccelerationStructureGeometryKHR host_geometry = geometry;
  host_geometry.geometry.triangles.pNext = &host_motion;
  host_geometry.geometry.triangles.vertexData.hostAddress = vertices[0];
  VkAccelerationStructureBuildGeometryInfoKHR host_info = info;
  host_info.ppGeometries = nullptr;
  host_info.pGeometries = &host_geometry;
  host_info.dstAccelerationStructure = host_structure;
  host_info.scratchData.hostAddress = host_scratch.data();
  const auto host_build = reinterpret_cast<PFN_vkBuildAccelerationStructuresKHR>(
      vkGetDeviceProcAddr(vk, "vkBuildAccelerationStructuresKHR"));
  REQUIRE(host_build != nullptr);
  REQUIRE(host_build(vk, VK_NULL_HANDLE, 1, &host_info, &ranges) == VK_SUCCESS);

  const auto properties = reinterpret_cast<PFN_vkWriteAccelerationStructuresPropertiesKHR>(
      vkGetDeviceProcAddr(vk, "vkWriteAccelerationStructuresPropertiesKHR"));
  const auto to_memory = reinterpret_cast<PFN_vkCopyAccelerationStructureToMemoryKHR>(
      vkGetDeviceProcAddr(vk, "vkCopyAccelerationStructureToMemoryKHR"));
  REQUIRE(properties != nullptr);
  REQUIRE(to_memory != nullptr);
  const auto serialize = [&](VkAccelerationStructureKHR as) {
    uint64_t size = 0;
    REQUIRE(properties(vk, 1, &as, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR, sizeof(size), &size,
                       sizeof(size)) == VK_SUCCESS);
    std::vector<unsigned char> bytes(size);
    VkCopyAccelerationStructureToMemoryInfoKHR copy{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_TO_MEMORY_INFO_KHR};
    copy.src = as;
    copy.dst.hostAddress = bytes.data();
    copy.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR;
    REQUIRE(to_memory(vk, VK_NULL_HANDLE, &copy) == VK_SUCCESS);
    return bytes;
  };
  const auto device_bytes = serialize(structure);
  CHECK(!device_bytes.empty());
  CHECK(Payload(serialize(host_structure)) == Payload(device_bytes));
  CHECK(host_geometry.geometry.triangles.pNext == &host_motion);

  device.DestroyAccelerationStructureKHR(vk, host_structure, nullptr);
  device.Destroy(host_storage);
  device.DestroyAccelerationStructureKHR(vk, structure, nullptr);
  device.Destroy(scratch);
  device.Destroy(storage);
  device.Destroy(vertex_buffer);
}

}  // namespace

namespace {

TEST_CASE("test driver: lists VK_EXT_opacity_micromap and reports its features and properties") {
  vkkit::Instance instance(vkkit::InstanceOptions{{"VK_LAYER_ASVAL_test_driver"}, nullptr, false});
  const VkPhysicalDevice gpu = instance.FindRayTracingGpu();
  uint32_t listed = 0;
  for (const VkExtensionProperties& e : DeviceExtensions(gpu)) {
    if (std::strcmp(e.extensionName, VK_EXT_OPACITY_MICROMAP_EXTENSION_NAME) != 0) continue;
    ++listed;
    CHECK(e.specVersion == 2);
    CHECK(e.specVersion == kAsvalTestDriverOpacityMicromapSpecVersion);
  }
  CHECK(listed == 1);

  // The micromap features between the motion-blur ones and one the driver below fills: the chain stays whole.
  VkPhysicalDeviceRayQueryFeaturesKHR ray_query{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_QUERY_FEATURES_KHR};
  VkPhysicalDeviceOpacityMicromapFeaturesEXT micromap{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_OPACITY_MICROMAP_FEATURES_EXT,
                                                      &ray_query};
  micromap.micromapCaptureReplay = VK_TRUE;  // overwritten
  micromap.micromapHostCommands = VK_TRUE;   // overwritten
  VkPhysicalDeviceRayTracingMotionBlurFeaturesNV motion_blur{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_MOTION_BLUR_FEATURES_NV, &micromap};
  VkPhysicalDeviceFeatures2 features{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_FEATURES_2, &motion_blur};
  vkGetPhysicalDeviceFeatures2(gpu, &features);
  CHECK(features.pNext == &motion_blur);
  CHECK(motion_blur.pNext == &micromap);
  CHECK(micromap.pNext == &ray_query);
  CHECK(ray_query.rayQuery == VK_TRUE);
  CHECK(motion_blur.rayTracingMotionBlur == VK_TRUE);
  CHECK(micromap.micromap == VK_TRUE);
  CHECK(micromap.micromapCaptureReplay == VK_FALSE);
  CHECK(micromap.micromapHostCommands == VK_FALSE);
  CHECK(micromap.micromap == kAsvalTestDriverMicromap);
  CHECK(micromap.micromapCaptureReplay == kAsvalTestDriverMicromapCaptureReplay);
  CHECK(micromap.micromapHostCommands == kAsvalTestDriverMicromapHostCommands);

  VkPhysicalDeviceAccelerationStructurePropertiesKHR as{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_ACCELERATION_STRUCTURE_PROPERTIES_KHR};
  VkPhysicalDeviceOpacityMicromapPropertiesEXT limits{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_OPACITY_MICROMAP_PROPERTIES_EXT,
                                                      &as};
  VkPhysicalDeviceProperties2 properties{VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_PROPERTIES_2, &limits};
  vkGetPhysicalDeviceProperties2(gpu, &properties);
  CHECK(properties.pNext == &limits);
  CHECK(limits.pNext == &as);
  CHECK(as.maxGeometryCount != 0);  // the driver below filled the structure after the micromap one
  CHECK(limits.maxOpacity2StateSubdivisionLevel == 12);
  CHECK(limits.maxOpacity4StateSubdivisionLevel == 12);
  CHECK(limits.maxOpacity2StateSubdivisionLevel == kAsvalTestDriverMaxOpacity2StateSubdivisionLevel);
  CHECK(limits.maxOpacity4StateSubdivisionLevel == kAsvalTestDriverMaxOpacity4StateSubdivisionLevel);
}

TEST_CASE("test driver: a bottom level with an opacity micromap structure is built over lavapipe where enabled") {
  vkkit::Instance instance(vkkit::InstanceOptions{{"VK_LAYER_ASVAL_test_driver"}, nullptr, false});
  const VkPhysicalDevice gpu = instance.FindRayTracingGpu();
  VkPhysicalDeviceOpacityMicromapFeaturesEXT micromap_features{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_OPACITY_MICROMAP_FEATURES_EXT};
  micromap_features.micromap = VK_TRUE;
  vkkit::DeviceOptions options;
  options.extensions = {VK_EXT_OPACITY_MICROMAP_EXTENSION_NAME};
  options.features = &micromap_features;
  vkkit::Device device(instance, gpu, options);  // throws if the device cannot be created
  const VkDevice vk = device.handle();
  CHECK(micromap_features.pNext == nullptr);  // the application's chain, as it gave it
  CHECK(micromap_features.micromap == VK_TRUE);

  // A micromap of the test driver's own, sized by the documented formula.
  const auto create_micromap = Load<PFN_vkCreateMicromapEXT>(vk, "vkCreateMicromapEXT");
  const auto destroy_micromap = Load<PFN_vkDestroyMicromapEXT>(vk, "vkDestroyMicromapEXT");
  const auto micromap_sizes = Load<PFN_vkGetMicromapBuildSizesEXT>(vk, "vkGetMicromapBuildSizesEXT");
  const auto build_micromaps = Load<PFN_vkCmdBuildMicromapsEXT>(vk, "vkCmdBuildMicromapsEXT");
  REQUIRE(create_micromap != nullptr);
  REQUIRE(destroy_micromap != nullptr);
  REQUIRE(micromap_sizes != nullptr);
  REQUIRE(build_micromaps != nullptr);
  // One 2-state triangle at subdivision level 0: one bit of data.
  const VkMicromapUsageEXT usage{1, 0, VK_OPACITY_MICROMAP_FORMAT_2_STATE_EXT};
  VkMicromapBuildInfoEXT micromap_build{VK_STRUCTURE_TYPE_MICROMAP_BUILD_INFO_EXT};
  micromap_build.type = VK_MICROMAP_TYPE_OPACITY_MICROMAP_EXT;
  micromap_build.mode = VK_BUILD_MICROMAP_MODE_BUILD_EXT;
  micromap_build.usageCountsCount = 1;
  micromap_build.pUsageCounts = &usage;
  VkMicromapBuildSizesInfoEXT micromap_size{VK_STRUCTURE_TYPE_MICROMAP_BUILD_SIZES_INFO_EXT};
  micromap_sizes(vk, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &micromap_build, &micromap_size);
  CHECK(micromap_size.micromapSize == 256 + 64 * 1);
  CHECK(micromap_size.micromapSize == AsvalTestDriverMicromapSize(micromap_build));
  CHECK(micromap_size.buildScratchSize == kAsvalTestDriverMicromapBuildScratchSize);
  CHECK(micromap_size.discardable == VK_FALSE);
  auto micromap_storage = device.CreateBuffer(micromap_size.micromapSize, VK_BUFFER_USAGE_MICROMAP_STORAGE_BIT_EXT);
  VkMicromapCreateInfoEXT micromap_create{VK_STRUCTURE_TYPE_MICROMAP_CREATE_INFO_EXT};
  micromap_create.buffer = micromap_storage.buffer;
  micromap_create.size = micromap_size.micromapSize;
  micromap_create.type = VK_MICROMAP_TYPE_OPACITY_MICROMAP_EXT;
  VkMicromapEXT micromap = VK_NULL_HANDLE;
  REQUIRE(create_micromap(vk, &micromap_create, nullptr, &micromap) == VK_SUCCESS);
  CHECK(micromap != VK_NULL_HANDLE);
  // Its build inputs (the build records nothing below: the micromap has no contents).
  const VkMicromapTriangleEXT micromap_triangle{0, 0, VK_OPACITY_MICROMAP_FORMAT_2_STATE_EXT};
  auto micromap_input = device.CreateBuffer(16, VK_BUFFER_USAGE_MICROMAP_BUILD_INPUT_READ_ONLY_BIT_EXT);
  std::memset(micromap_input.mapped, 0xff, 16);  // the data at offset 0: the triangle opaque
  std::memcpy(static_cast<unsigned char*>(micromap_input.mapped) + 8, &micromap_triangle, sizeof(micromap_triangle));
  auto micromap_scratch = device.CreateBuffer(micromap_size.buildScratchSize, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  micromap_build.dstMicromap = micromap;
  micromap_build.data.deviceAddress = micromap_input.address;
  micromap_build.triangleArray.deviceAddress = micromap_input.address + 8;
  micromap_build.triangleArrayStride = sizeof(VkMicromapTriangleEXT);
  micromap_build.scratchData.deviceAddress = micromap_scratch.address;

  // One triangle whose micromap index is a special index: the whole triangle fully opaque, no micromap needed.
  const float vertices[3 * 3] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  auto vertex_buffer =
      device.CreateBuffer(sizeof(vertices), VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  std::memcpy(vertex_buffer.mapped, vertices, sizeof(vertices));
  const auto opaque = static_cast<uint32_t>(VK_OPACITY_MICROMAP_SPECIAL_INDEX_FULLY_OPAQUE_EXT);
  auto index_buffer =
      device.CreateBuffer(sizeof(opaque), VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
  std::memcpy(index_buffer.mapped, &opaque, sizeof(opaque));
  VkAccelerationStructureTrianglesOpacityMicromapEXT triangles_micromap{
      VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_TRIANGLES_OPACITY_MICROMAP_EXT};
  triangles_micromap.indexType = VK_INDEX_TYPE_UINT32;
  triangles_micromap.indexBuffer.deviceAddress = index_buffer.address;
  triangles_micromap.indexStride = sizeof(uint32_t);
  triangles_micromap.micromap = VK_NULL_HANDLE;
  triangles_micromap.usageCountsCount = 0;
  VkAccelerationStructureGeometryKHR geometry{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_KHR};
  geometry.geometryType = VK_GEOMETRY_TYPE_TRIANGLES_KHR;
  auto& t = geometry.geometry.triangles;
  t.sType = VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_GEOMETRY_TRIANGLES_DATA_KHR;
  t.pNext = &triangles_micromap;
  t.vertexFormat = VK_FORMAT_R32G32B32_SFLOAT;
  t.vertexData.deviceAddress = vertex_buffer.address;
  t.vertexStride = 3 * sizeof(float);
  t.maxVertex = 2;
  t.indexType = VK_INDEX_TYPE_NONE_KHR;
  VkAccelerationStructureBuildGeometryInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_GEOMETRY_INFO_KHR};
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  info.flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_OPACITY_MICROMAP_UPDATE_EXT |
               VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR;
  info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR;
  info.geometryCount = 1;
  info.pGeometries = &geometry;
  const uint32_t primitives = 1;
  VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
  device.GetAccelerationStructureBuildSizesKHR(vk, VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR, &info, &primitives,
                                               &sizes);
  REQUIRE(sizes.accelerationStructureSize != 0);
  REQUIRE(sizes.buildScratchSize != 0);
  auto storage =
      device.CreateBuffer(sizes.accelerationStructureSize, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR);
  auto scratch = device.CreateBuffer(sizes.buildScratchSize, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  VkAccelerationStructureCreateInfoKHR create{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
  create.buffer = storage.buffer;
  create.size = sizes.accelerationStructureSize;
  create.type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;
  VkAccelerationStructureKHR structure = VK_NULL_HANDLE;
  REQUIRE(device.CreateAccelerationStructureKHR(vk, &create, nullptr, &structure) == VK_SUCCESS);

  info.dstAccelerationStructure = structure;
  info.scratchData.deviceAddress = scratch.address;
  const VkAccelerationStructureBuildRangeInfoKHR range{primitives, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
  REQUIRE_NOTHROW(device.OneShot([&](VkCommandBuffer cb) {  // submitted and waited for: vkkit throws on an error
    build_micromaps(cb, 1, &micromap_build);
    device.CmdBuildAccelerationStructuresKHR(cb, 1, &info, &ranges);
  }));

  // The driver below got copies: the application's structures are as it gave them.
  CHECK(info.flags == (VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_OPACITY_MICROMAP_UPDATE_EXT |
                       VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR));
  CHECK(info.pGeometries == &geometry);
  CHECK(info.ppGeometries == nullptr);
  CHECK(t.pNext == &triangles_micromap);
  CHECK(triangles_micromap.pNext == nullptr);
  CHECK(triangles_micromap.indexBuffer.deviceAddress == index_buffer.address);

  destroy_micromap(vk, micromap, nullptr);
  device.DestroyAccelerationStructureKHR(vk, structure, nullptr);
  device.Destroy(scratch);
  device.Destroy(storage);
  device.Destroy(micromap_scratch);
  device.Destroy(micromap_input);
  device.Destroy(micromap_storage);
  device.Destroy(index_buffer);
  device.Destroy(vertex_buffer);
}

TEST_CASE("test driver: VK_EXT_opacity_micromap's commands only where the extension is enabled") {
  vkkit::Instance instance(vkkit::InstanceOptions{{"VK_LAYER_ASVAL_test_driver"}, nullptr, false});
  vkkit::Device device(instance, instance.FindRayTracingGpu(), vkkit::DeviceOptions{});
  CHECK(vkGetDeviceProcAddr(device.handle(), "vkCreateMicromapEXT") == nullptr);
  CHECK(vkGetDeviceProcAddr(device.handle(), "vkCmdBuildMicromapsEXT") == nullptr);
}

}  // namespace
