// Family "host": rules of vkBuildAccelerationStructuresKHR alone, through the real loader on lavapipe, which has no
// accelerationStructureHostCommands: only calls the layer skips (an expected finding, the monitor returns VK_TRUE)
// are made here. Host builds that reach a driver run on asval's test driver (test_driver_host_test.cpp); the valid
// twins of the rest run on hand-built state in tests/unit/host_build_unit_test.cpp, as do the rules lavapipe's
// memory cannot break (it has one memory type, host-visible; no device groups).
#include <catch2/catch_test_macros.hpp>

#include <cstring>
#include <vector>

#include "host_build_helpers.h"

namespace asval_test {
namespace {

constexpr VkAccelerationStructureTypeKHR kBottom = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;

TEST_CASE("pInfos-03725 / 03726: a null scratch host address is reported when the driver needs scratch",
          "[integration][host][03725][03726]") {
  CheckFixture f("host");
  vkkit::Device& device = f.device();
  Scene scene(device);
  HostBuild build(scene, scene.Triangles());
  build.info.scratchData.hostAddress = nullptr;
  SECTION("03725: a build") { f.monitor().Expect("VUID-vkBuildAccelerationStructuresKHR-pInfos-03725"); }
  SECTION("03726: an update") {
    build.info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
    build.info.srcAccelerationStructure = build.info.dstAccelerationStructure;
    f.monitor().Expect("VUID-vkBuildAccelerationStructuresKHR-pInfos-03726");
  }
  build.Call(device);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("pInfos-03725: host scratch that runs past the end of the app's mapping is reported",
          "[integration][host][03725]") {
  CheckFixture f("host");
  vkkit::Device& device = f.device();
  Scene scene(device);
  HostBuild build(scene, scene.Triangles());
  // The app maps the first 4096 bytes of an allocation. (Lavapipe may place two allocations' mappings next to
  // each other; the layer accepts scratch that continues into an adjacent mapping, so the test maps part of
  // one allocation, whose next byte is no mapping.)
  VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO};
  alloc.allocationSize = 1 << 16;
  // Host-visible (lavapipe's only type; on discrete GPUs type 0 is often device-local and cannot be mapped).
  alloc.memoryTypeIndex = device.FindMemoryType(~0u, VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT);
  VkDeviceMemory memory = VK_NULL_HANDLE;
  REQUIRE(vkAllocateMemory(device.handle(), &alloc, nullptr, &memory) == VK_SUCCESS);
  void* mapped = nullptr;
  REQUIRE(vkMapMemory(device.handle(), memory, 0, 4096, 0, &mapped) == VK_SUCCESS);
  // 16 bytes before the end of the mapping: less than any scratch size the driver asks for.
  build.info.scratchData.hostAddress = static_cast<char*>(mapped) + 4096 - 16;
  f.monitor().Expect("VUID-vkBuildAccelerationStructuresKHR-pInfos-03725");
  build.Call(device);
  const std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].text.find("points into the mapping of VkDeviceMemory") != std::string::npos);
  vkUnmapMemory(device.handle(), memory);
  vkFreeMemory(device.handle(), memory, nullptr);
}

TEST_CASE("pInfos-03771 / 03772 / 03774 / 03778: null input host addresses are reported",
          "[integration][host][03771][03772][03774][03778]") {
  CheckFixture f("host");
  vkkit::Device& device = f.device();
  Scene scene(device);
  SECTION("03771: vertexData") {
    HostBuild build(scene, scene.Triangles());
    build.geometry.geometry.triangles.vertexData.hostAddress = nullptr;
    f.monitor().Expect("VUID-vkBuildAccelerationStructuresKHR-pInfos-03771");
    build.Call(device);
  }
  SECTION("03772: indexData") {
    HostBuild build(scene, scene.IndexedTriangles(VK_INDEX_TYPE_UINT32));
    build.geometry.geometry.triangles.indexData.hostAddress = nullptr;
    f.monitor().Expect("VUID-vkBuildAccelerationStructuresKHR-pInfos-03772");
    build.Call(device);
  }
  SECTION("03774: AABB data") {
    HostBuild build(scene, scene.Aabbs());
    build.geometry.geometry.aabbs.data.hostAddress = nullptr;
    f.monitor().Expect("VUID-vkBuildAccelerationStructuresKHR-pInfos-03774");
    build.Call(device);
  }
  SECTION("03778: instance data") {
    HostBuild build(scene, scene.Instances());
    build.geometry.geometry.instances.data.hostAddress = nullptr;
    f.monitor().Expect("VUID-vkBuildAccelerationStructuresKHR-pInfos-03778");
    build.Call(device);
  }
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("pInfos-03779: an instance referencing a destroyed structure is reported", "[integration][host][03779]") {
  CheckFixture f("host");
  vkkit::Device& device = f.device();
  Scene scene(device);
  HostBuild build(scene, scene.Instances());
  vkkit::AccelerationStructure gone = device.CreateAccelerationStructure(kBottom, 256);
  build.instance.accelerationStructureReference = reinterpret_cast<uint64_t>(gone.handle);
  device.Destroy(gone);
  // The instance in mapped memory: without accelerationStructureHostCommands (lavapipe) the layer reads a host
  // build's inputs only inside the app's mappings (layer/checks/host_reads.h).
  vkkit::Buffer mapped = device.CreateBuffer(sizeof(build.instance), VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  std::memcpy(mapped.mapped, &build.instance, sizeof(build.instance));
  build.geometry.geometry.instances.data.hostAddress = mapped.mapped;
  f.monitor().Expect("VUID-vkBuildAccelerationStructuresKHR-pInfos-03779");
  build.Call(device);
  device.Destroy(mapped);
  const std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].text.find("instance 0") != std::string::npos);
}

}  // namespace
}  // namespace asval_test
