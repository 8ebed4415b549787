// The host copies and property writes through the loader on asval's test driver (docs/testing.md), which
// executes them: their feature (family "features") and the data a property write fills (family "copies").
#include <catch2/catch_test_macros.hpp>
#include <cstring>
#include <vector>

#include "host_build_helpers.h"
#include "on_test_driver.h"

namespace asval_test {
namespace {

constexpr VkQueryType kCompacted = VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR;
constexpr VkQueryType kSerializationSize = VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR;

// The four host commands, loaded through the loader (the layers see them).
struct HostCommands {
  explicit HostCommands(VkDevice device)
      : copy(reinterpret_cast<PFN_vkCopyAccelerationStructureKHR>(
            vkGetDeviceProcAddr(device, "vkCopyAccelerationStructureKHR"))),
        to_memory(reinterpret_cast<PFN_vkCopyAccelerationStructureToMemoryKHR>(
            vkGetDeviceProcAddr(device, "vkCopyAccelerationStructureToMemoryKHR"))),
        from_memory(reinterpret_cast<PFN_vkCopyMemoryToAccelerationStructureKHR>(
            vkGetDeviceProcAddr(device, "vkCopyMemoryToAccelerationStructureKHR"))),
        properties(reinterpret_cast<PFN_vkWriteAccelerationStructuresPropertiesKHR>(
            vkGetDeviceProcAddr(device, "vkWriteAccelerationStructuresPropertiesKHR"))) {}
  PFN_vkCopyAccelerationStructureKHR copy;
  PFN_vkCopyAccelerationStructureToMemoryKHR to_memory;
  PFN_vkCopyMemoryToAccelerationStructureKHR from_memory;
  PFN_vkWriteAccelerationStructuresPropertiesKHR properties;
};

// A bottom-level structure built on the host (compactable, so that every query type applies) and two more
// structures of its size to copy into.
struct HostBuilt {
  Scene scene;
  HostBuild build;
  VkAccelerationStructureKHR source;
  VkAccelerationStructureKHR clone;
  VkAccelerationStructureKHR restored;

  explicit HostBuilt(vkkit::Device& device)
      : scene(device), build(scene, scene.Triangles()), source(build.info.dstAccelerationStructure) {
    build.info.flags |= VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR;
    REQUIRE(CallHostBuild(device, {build.info}, {&build.range}) == VK_SUCCESS);
    clone = scene.NewStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, 1 << 16);
    restored = scene.NewStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, 1 << 16);
  }
};

TEST_CASE(
    "03582 / 03583 / 03584 / 03585 valid twin on the test driver: host copies, serialization and property "
    "writes with accelerationStructureHostCommands stay silent and execute",
    "[integration][copies][features][test-driver][valid]") {
  const OnTestDriver driver;
  CheckFixture f(nullptr, OnTestDriver::HostCommands());
  vkkit::Device& device = f.device();
  HostCommands host(device.handle());
  HostBuilt built(device);

  // Both sizes into one array 16 bytes apart: dataSize is count * stride.
  alignas(16) VkDeviceSize sizes[2][2] = {};
  const VkAccelerationStructureKHR twice[2] = {built.source, built.source};
  REQUIRE(host.properties(device.handle(), 2, twice, kSerializationSize, sizeof(sizes), &sizes[0][0], 16) ==
          VK_SUCCESS);
  REQUIRE(host.properties(device.handle(), 1, &built.source, kCompacted, 8, &sizes[0][1], 8) == VK_SUCCESS);
  CHECK(sizes[0][0] != 0);
  CHECK(sizes[0][0] == sizes[1][0]);
  CHECK(sizes[0][1] != 0);

  VkCopyAccelerationStructureInfoKHR copy{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR};
  copy.src = built.source;
  copy.dst = built.clone;
  copy.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR;
  CHECK(host.copy(device.handle(), VK_NULL_HANDLE, &copy) == VK_SUCCESS);

  std::vector<VkDeviceSize> serialized(sizes[0][0] / sizeof(VkDeviceSize) + 1);  // 8-byte aligned host memory
  VkCopyAccelerationStructureToMemoryInfoKHR to{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_TO_MEMORY_INFO_KHR};
  to.src = built.source;
  to.dst.hostAddress = serialized.data();
  to.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR;
  CHECK(host.to_memory(device.handle(), VK_NULL_HANDLE, &to) == VK_SUCCESS);
  uint64_t serialized_size = 0;  // the header's own count: the device wrote it
  std::memcpy(&serialized_size, reinterpret_cast<const unsigned char*>(serialized.data()) + 2 * VK_UUID_SIZE,
              sizeof(serialized_size));
  CHECK(serialized_size == sizes[0][0]);

  VkCopyMemoryToAccelerationStructureInfoKHR from{VK_STRUCTURE_TYPE_COPY_MEMORY_TO_ACCELERATION_STRUCTURE_INFO_KHR};
  from.src.hostAddress = serialized.data();
  from.dst = built.restored;
  from.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_DESERIALIZE_KHR;
  CHECK(host.from_memory(device.handle(), VK_NULL_HANDLE, &from) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "03582 / 03583 / 03584 / 03585: host copies and property writes without accelerationStructureHostCommands "
    "are reported",
    "[integration][features][test-driver][03582][03583][03584][03585]") {
  const OnTestDriver driver;
  CheckFixture f("features");  // the driver offers host commands; this device does not enable them
  vkkit::Device& device = f.device();
  HostCommands host(device.handle());
  Scene scene(device);
  const VkAccelerationStructureKHR structure = scene.blas();
  alignas(16) unsigned char bytes[256] = {};
  SECTION("03582: vkCopyAccelerationStructureKHR") {
    VkCopyAccelerationStructureInfoKHR copy{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR};
    copy.src = structure;
    copy.dst = structure;
    f.monitor().Expect("VUID-vkCopyAccelerationStructureKHR-accelerationStructureHostCommands-03582");
    host.copy(device.handle(), VK_NULL_HANDLE, &copy);
  }
  SECTION("03583: vkCopyMemoryToAccelerationStructureKHR") {
    VkCopyMemoryToAccelerationStructureInfoKHR from{VK_STRUCTURE_TYPE_COPY_MEMORY_TO_ACCELERATION_STRUCTURE_INFO_KHR};
    from.src.hostAddress = bytes;
    from.dst = structure;
    from.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_DESERIALIZE_KHR;
    f.monitor().Expect("VUID-vkCopyMemoryToAccelerationStructureKHR-accelerationStructureHostCommands-03583");
    host.from_memory(device.handle(), VK_NULL_HANDLE, &from);
  }
  SECTION("03584: vkCopyAccelerationStructureToMemoryKHR") {
    VkCopyAccelerationStructureToMemoryInfoKHR to{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_TO_MEMORY_INFO_KHR};
    to.src = structure;
    to.dst.hostAddress = bytes;
    to.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR;
    f.monitor().Expect("VUID-vkCopyAccelerationStructureToMemoryKHR-accelerationStructureHostCommands-03584");
    host.to_memory(device.handle(), VK_NULL_HANDLE, &to);
  }
  SECTION("03585: vkWriteAccelerationStructuresPropertiesKHR") {
    f.monitor().Expect("VUID-vkWriteAccelerationStructuresPropertiesKHR-accelerationStructureHostCommands-03585");
    host.properties(device.handle(), 1, &structure, kSerializationSize, 8, bytes, 8);
  }
  CHECK(f.monitor().Verify() == "");
}

// Per query type: the VUIDs of its stride and of its pData.
struct DataRules {
  VkQueryType type;
  const char* stride;
  const char* data;
};
constexpr DataRules kDataRules[] = {
    {kCompacted, "VUID-vkWriteAccelerationStructuresPropertiesKHR-queryType-03448",
     "VUID-vkWriteAccelerationStructuresPropertiesKHR-queryType-03449"},
    {kSerializationSize, "VUID-vkWriteAccelerationStructuresPropertiesKHR-queryType-03450",
     "VUID-vkWriteAccelerationStructuresPropertiesKHR-queryType-03451"},
    {VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SIZE_KHR, "VUID-vkWriteAccelerationStructuresPropertiesKHR-queryType-06731",
     "VUID-vkWriteAccelerationStructuresPropertiesKHR-queryType-06732"},
    {VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_BOTTOM_LEVEL_POINTERS_KHR,
     "VUID-vkWriteAccelerationStructuresPropertiesKHR-queryType-06733",
     "VUID-vkWriteAccelerationStructuresPropertiesKHR-queryType-06734"},
};

TEST_CASE(
    "queryType-03448 to 06734 and dataSize-03452: host property writes whose stride, pData or dataSize the "
    "query type forbids are reported",
    "[integration][copies][test-driver][03448][03449][03450][03451][06731][06732][06733][06734][03452]") {
  const OnTestDriver driver;
  CheckFixture f("copies", OnTestDriver::HostCommands());
  vkkit::Device& device = f.device();
  HostCommands host(device.handle());
  HostBuilt built(device);
  alignas(16) unsigned char data[64] = {};
  for (const DataRules& rules : kDataRules) {
    CAPTURE(rules.stride);
    f.monitor().Expect(rules.stride);  // a stride of 12: not a multiple of 8
    host.properties(device.handle(), 1, &built.source, rules.type, 12, data, 12);
    CHECK(f.monitor().Verify() == "");
    f.monitor().Expect(rules.data);  // 4 bytes into an 8-aligned array
    host.properties(device.handle(), 1, &built.source, rules.type, 8, data + 4, 8);
    CHECK(f.monitor().Verify() == "");
    f.monitor().Expect(rules.data);  // no pointer at all
    host.properties(device.handle(), 1, &built.source, rules.type, 8, nullptr, 8);
    CHECK(f.monitor().Verify() == "");
  }
  f.monitor().Expect("VUID-vkWriteAccelerationStructuresPropertiesKHR-dataSize-03452");  // 2 * 16 > 24
  const VkAccelerationStructureKHR twice[2] = {built.source, built.source};
  host.properties(device.handle(), 2, twice, kSerializationSize, 24, data, 16);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "pInfo-03729 / 03732 / 03750 / 03751: host serialization addresses that are null or not aligned to 16 "
    "bytes are reported",
    "[integration][host][test-driver][03729][03732][03750][03751]") {
  const OnTestDriver driver;
  CheckFixture f("host", OnTestDriver::HostCommands());
  vkkit::Device& device = f.device();
  HostCommands host(device.handle());
  HostBuilt built(device);
  alignas(16) unsigned char bytes[1 << 12] = {};
  VkCopyAccelerationStructureToMemoryInfoKHR to{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_TO_MEMORY_INFO_KHR};
  to.src = built.source;
  to.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR;
  VkCopyMemoryToAccelerationStructureInfoKHR from{VK_STRUCTURE_TYPE_COPY_MEMORY_TO_ACCELERATION_STRUCTURE_INFO_KHR};
  from.dst = built.restored;
  from.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_DESERIALIZE_KHR;
  SECTION("03732: a null destination") {
    f.monitor().Expect("VUID-vkCopyAccelerationStructureToMemoryKHR-pInfo-03732");
    host.to_memory(device.handle(), VK_NULL_HANDLE, &to);
  }
  SECTION("03751: a destination 8 bytes past a multiple of 16") {
    to.dst.hostAddress = bytes + 8;
    f.monitor().Expect("VUID-vkCopyAccelerationStructureToMemoryKHR-pInfo-03751");
    host.to_memory(device.handle(), VK_NULL_HANDLE, &to);
  }
  SECTION("03729: a null source") {
    f.monitor().Expect("VUID-vkCopyMemoryToAccelerationStructureKHR-pInfo-03729");
    host.from_memory(device.handle(), VK_NULL_HANDLE, &from);
  }
  SECTION("03750: a source 4 bytes past a multiple of 16") {
    from.src.hostAddress = bytes + 4;
    f.monitor().Expect("VUID-vkCopyMemoryToAccelerationStructureKHR-pInfo-03750");
    host.from_memory(device.handle(), VK_NULL_HANDLE, &from);
  }
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "buffer-03727 / 03728 / 03730 / 03731 / 03733: host copies and property writes of structures on memory that "
    "is not host-visible are reported",
    "[integration][host][test-driver][03727][03728][03730][03731][03733]") {
  const OnTestDriver driver;
  CheckFixture f("host", OnTestDriver::HostCommands());
  vkkit::Device& device = f.device();
  HostCommands host(device.handle());
  HostBuilt built(device);
  const DeviceLocalStructure device_local(device, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, 1 << 16);
  alignas(16) unsigned char bytes[1 << 12] = {};
  VkCopyAccelerationStructureInfoKHR copy{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR};
  copy.src = built.source;
  copy.dst = built.clone;
  copy.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR;
  SECTION("03727: the source of a copy") {
    copy.src = device_local.handle();
    f.monitor().Expect("VUID-vkCopyAccelerationStructureKHR-buffer-03727");
    host.copy(device.handle(), VK_NULL_HANDLE, &copy);
  }
  SECTION("03728: the destination of a copy") {
    copy.dst = device_local.handle();
    f.monitor().Expect("VUID-vkCopyAccelerationStructureKHR-buffer-03728");
    host.copy(device.handle(), VK_NULL_HANDLE, &copy);
  }
  SECTION("03731: the structure serialized") {
    VkCopyAccelerationStructureToMemoryInfoKHR to{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_TO_MEMORY_INFO_KHR};
    to.src = device_local.handle();
    to.dst.hostAddress = bytes;
    to.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR;
    f.monitor().Expect("VUID-vkCopyAccelerationStructureToMemoryKHR-buffer-03731");
    host.to_memory(device.handle(), VK_NULL_HANDLE, &to);
  }
  SECTION("03730: the structure deserialized into") {
    VkCopyMemoryToAccelerationStructureInfoKHR from{VK_STRUCTURE_TYPE_COPY_MEMORY_TO_ACCELERATION_STRUCTURE_INFO_KHR};
    from.src.hostAddress = bytes;
    from.dst = device_local.handle();
    from.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_DESERIALIZE_KHR;
    f.monitor().Expect("VUID-vkCopyMemoryToAccelerationStructureKHR-buffer-03730");
    host.from_memory(device.handle(), VK_NULL_HANDLE, &from);
  }
  SECTION("03733: one report for the structures queried, at the first on such memory") {
    const VkAccelerationStructureKHR queried[3] = {built.source, device_local.handle(), device_local.handle()};
    alignas(16) VkDeviceSize sizes[3] = {};
    f.monitor().Expect("VUID-vkWriteAccelerationStructuresPropertiesKHR-buffer-03733");
    host.properties(device.handle(), 3, queried, kSerializationSize, sizeof(sizes), sizes, 8);
    const std::vector<Message> messages = f.monitor().Take();
    REQUIRE(messages.size() == 1);
    CHECK(messages[0].id_name == "VUID-vkWriteAccelerationStructuresPropertiesKHR-buffer-03733");
    CHECK(messages[0].text.find("pAccelerationStructures[1]") != std::string::npos);
    CHECK(messages[0].text.find("1 later elements of pAccelerationStructures") != std::string::npos);
    CHECK(messages[0].text.find("not VK_MEMORY_PROPERTY_HOST_VISIBLE_BIT") != std::string::npos);
    return;
  }
  CHECK(f.monitor().Verify() == "");
}

// A deferred operation of the device's, destroyed with the scope.
struct DeferredOperation {
  explicit DeferredOperation(VkDevice device)
      : device_(device),
        join(reinterpret_cast<PFN_vkDeferredOperationJoinKHR>(
            vkGetDeviceProcAddr(device, "vkDeferredOperationJoinKHR"))) {
    auto create =
        reinterpret_cast<PFN_vkCreateDeferredOperationKHR>(vkGetDeviceProcAddr(device, "vkCreateDeferredOperationKHR"));
    vkkit::Check(create(device, nullptr, &handle), "vkCreateDeferredOperationKHR");
  }
  ~DeferredOperation() {
    auto destroy = reinterpret_cast<PFN_vkDestroyDeferredOperationKHR>(
        vkGetDeviceProcAddr(device_, "vkDestroyDeferredOperationKHR"));
    destroy(device_, handle, nullptr);
  }
  DeferredOperation(const DeferredOperation&) = delete;
  DeferredOperation& operator=(const DeferredOperation&) = delete;

  VkDevice device_;
  PFN_vkDeferredOperationJoinKHR join;
  VkDeferredOperationKHR handle = VK_NULL_HANDLE;
};

TEST_CASE(
    "deferredOperation-03678: host copies on a deferred operation still running an earlier host copy are "
    "reported; joined first, they stay silent",
    "[integration][host][test-driver][03678]") {
  const OnTestDriver driver;
  // The layer follows deferred operations in its history records: the history family is on too.
  CheckFixture f("host,history", OnTestDriver::HostCommands());
  vkkit::Device& device = f.device();
  HostCommands host(device.handle());
  HostBuilt built(device);
  DeferredOperation operation(device.handle());
  VkCopyAccelerationStructureInfoKHR copy{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_INFO_KHR};
  copy.src = built.source;
  copy.dst = built.clone;
  copy.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_CLONE_KHR;
  // The test driver defers for real: the clone runs when the operation is joined.
  REQUIRE(host.copy(device.handle(), operation.handle, &copy) == VK_OPERATION_DEFERRED_KHR);
  alignas(16) unsigned char bytes[1 << 12] = {};
  SECTION("vkCopyAccelerationStructureKHR") {
    f.monitor().Expect("VUID-vkCopyAccelerationStructureKHR-deferredOperation-03678");
    host.copy(device.handle(), operation.handle, &copy);
  }
  SECTION("vkCopyAccelerationStructureToMemoryKHR") {
    VkCopyAccelerationStructureToMemoryInfoKHR to{VK_STRUCTURE_TYPE_COPY_ACCELERATION_STRUCTURE_TO_MEMORY_INFO_KHR};
    to.src = built.source;
    to.dst.hostAddress = bytes;
    to.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR;
    f.monitor().Expect("VUID-vkCopyAccelerationStructureToMemoryKHR-deferredOperation-03678");
    host.to_memory(device.handle(), operation.handle, &to);
  }
  SECTION("vkCopyMemoryToAccelerationStructureKHR") {
    VkCopyMemoryToAccelerationStructureInfoKHR from{VK_STRUCTURE_TYPE_COPY_MEMORY_TO_ACCELERATION_STRUCTURE_INFO_KHR};
    from.src.hostAddress = bytes;
    from.dst = built.restored;
    from.mode = VK_COPY_ACCELERATION_STRUCTURE_MODE_DESERIALIZE_KHR;
    f.monitor().Expect("VUID-vkCopyMemoryToAccelerationStructureKHR-deferredOperation-03678");
    host.from_memory(device.handle(), operation.handle, &from);
  }
  SECTION("valid twin: joined, then used again") {
    REQUIRE(operation.join(device.handle(), operation.handle) == VK_SUCCESS);
    REQUIRE(host.copy(device.handle(), operation.handle, &copy) == VK_OPERATION_DEFERRED_KHR);
  }
  CHECK(f.monitor().Verify() == "");
  operation.join(device.handle(), operation.handle);  // the deferred clone runs before the structures go
}

TEST_CASE("06731 / 06732 / 06733 / 06734 valid twin on the test driver: host size and bottom-level-pointer "
          "queries with stride 8 and aligned pData stay silent and execute",
          "[integration][copies][test-driver][valid]") {
  const OnTestDriver driver;
  // The two query types of VK_KHR_ray_tracing_maintenance1 (lavapipe has it), with the feature enabled.
  VkPhysicalDeviceRayTracingMaintenance1FeaturesKHR maintenance{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_RAY_TRACING_MAINTENANCE_1_FEATURES_KHR};
  maintenance.rayTracingMaintenance1 = VK_TRUE;
  vkkit::DeviceOptions options = OnTestDriver::HostCommands();
  options.extensions.push_back(VK_KHR_RAY_TRACING_MAINTENANCE_1_EXTENSION_NAME);
  options.features = &maintenance;
  CheckFixture f(nullptr, options);
  vkkit::Device& device = f.device();
  HostCommands host(device.handle());
  HostBuilt built(device);
  alignas(16) VkDeviceSize values[2] = {};
  const VkAccelerationStructureKHR twice[2] = {built.source, built.source};
  CHECK(host.properties(device.handle(), 2, twice, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SIZE_KHR, sizeof(values),
                        values, 8) == VK_SUCCESS);
  CHECK(values[0] != 0);
  CHECK(host.properties(device.handle(), 1, &built.source,
                        VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_BOTTOM_LEVEL_POINTERS_KHR, 8, values, 8) ==
        VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test
