// Family "addresses": the bytes a build reads and writes lie in one bound buffer with the right usage, and the
// destination and scratch are as large as the driver says; with the valid twins that real programs use.
// Negative tests narrow enabled_checks to the family; lavapipe has no indirect or host builds, so those
// commands only go through the layer when it skips them (an expected finding).
#include <catch2/catch_test_macros.hpp>
#include <cstring>

#include "memory_placement_helpers.h"
#include "record_checks_helpers.h"

namespace asval_test {
namespace {

constexpr VkBufferUsageFlags kInput = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR;
constexpr VkDeviceAddress kNowhere = 0x100;  // 16-aligned, below every buffer lavapipe hands out

constexpr PerCommand kVertex = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03804",
                                "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03804", nullptr};
constexpr PerCommand kIndex = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03806",
                               "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03806", nullptr};
constexpr PerCommand kTransform = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03808",
                                   "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03808", nullptr};
constexpr PerCommand kAabb = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03811",
                              "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03811", nullptr};
constexpr PerCommand kInstance = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03813",
                                  "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03813", nullptr};
constexpr PerCommand kInputUsage = {"VUID-vkCmdBuildAccelerationStructuresKHR-geometry-03673",
                                    "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-geometry-03673", nullptr};
constexpr PerCommand kDestinationSize = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-10126",
                                         "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03652",
                                         "VUID-vkBuildAccelerationStructuresKHR-pInfos-10126"};
constexpr PerCommand kInstanceLimit = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03801",
                                       "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03801",
                                       "VUID-vkBuildAccelerationStructuresKHR-pInfos-03801"};

// Records one info with one geometry and `range`: directly, or indirectly with the range in a valid
// INDIRECT_BUFFER (max count = the range's count), or as a host build.
class Recorder {
 public:
  explicit Recorder(vkkit::Device& device) : device_(device) {
    indirect_ = device.CreateBuffer(256, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  }
  ~Recorder() { device_.Destroy(indirect_); }

  void Record(Command command, const VkAccelerationStructureBuildGeometryInfoKHR& info,
              const VkAccelerationStructureBuildRangeInfoKHR& range) {
    switch (command) {
      case Command::kIndirect:
        std::memcpy(indirect_.mapped, &range, sizeof(range));
        RecordIndirect(device_, {info}, {indirect_.address}, {16}, {{range.primitiveCount}});
        return;
      case Command::kHost:
        CallHostBuild(device_, {info}, {&range});
        return;
      case Command::kDirect:
        IssueOne(device_, Command::kDirect, info, &range);
        return;
    }
  }
  const vkkit::Buffer& indirect() const { return indirect_; }

 private:
  vkkit::Device& device_;
  vkkit::Buffer indirect_;
};

// A bottom-level info over one geometry, its destination and scratch prepared by the scene.
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

TEST_CASE("03804: vertex reads past the end of their buffer are reported", "[integration][addresses][03804]") {
  CheckFixture f("addresses");
  vkkit::Device& device = f.device();
  Scene scene(device);
  vkkit::Buffer vertices = device.CreateBuffer(36, kInput);  // exactly three R32G32B32_SFLOAT vertices
  VkAccelerationStructureGeometryKHR g = scene.Triangles();
  g.geometry.triangles.vertexData.deviceAddress = vertices.address;
  OneGeometry one(scene, g);
  // primitiveOffset 12: the build reads [12, 48) of a 36-byte buffer.
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 12, 0, 0};
  f.monitor().Expect(kVertex.direct);
  IssueOne(device, Command::kDirect, one.info, &range);
  const std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].text.find("pInfos[0].pGeometries[0].geometry.triangles.vertexData.deviceAddress") !=
        std::string::npos);
  CHECK(messages[0].text.find("48 bytes") != std::string::npos);
  device.Destroy(vertices);
}

TEST_CASE("03806 / 03808 / 03811 / 03813: index, transform, AABB and instance reads past their buffer are reported",
          "[integration][addresses][03806][03808][03811][03813]") {
  CheckFixture f("addresses");
  vkkit::Device& device = f.device();
  Scene scene(device);
  vkkit::Buffer small = device.CreateBuffer(256, kInput);
  VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  const char* expected = nullptr;
  VkAccelerationStructureGeometryKHR g{};
  uint32_t count = 1;
  SECTION("indices: 3 uint32 at primitiveOffset 248 of 256 bytes") {
    g = scene.IndexedTriangles(VK_INDEX_TYPE_UINT32);
    g.geometry.triangles.indexData.deviceAddress = small.address;
    range.primitiveOffset = 248;
    expected = kIndex.direct;
  }
  SECTION("transform: one matrix at transformOffset 224 of 256 bytes") {
    g = scene.Triangles();
    g.geometry.triangles.transformData.deviceAddress = small.address;
    range.transformOffset = 224;
    expected = kTransform.direct;
  }
  SECTION("AABBs: 11 boxes of stride 24 in 256 bytes") {
    g = scene.Aabbs();
    g.geometry.aabbs.data.deviceAddress = small.address;
    count = range.primitiveCount = 11;
    expected = kAabb.direct;
  }
  SECTION("instances: 5 records of 64 bytes in 256 bytes") {
    g = scene.Instances();
    g.geometry.instances.data.deviceAddress = small.address;
    count = range.primitiveCount = 5;
    expected = kInstance.direct;
  }
  OneGeometry one(scene, g, count);
  f.monitor().Expect(expected);
  IssueOne(device, Command::kDirect, one.info, &range);
  CHECK(f.monitor().Verify() == "");
  device.Destroy(small);
}

TEST_CASE("03804 / 03806 / 03808 / 03811 / 03813: input addresses that no buffer holds are reported, direct and "
          "indirect",
          "[integration][addresses][03804][03806][03808][03811][03813]") {
  CheckFixture f("addresses");
  vkkit::Device& device = f.device();
  Scene scene(device);
  Recorder recorder(device);
  for (Command command : {Command::kDirect, Command::kIndirect}) {
    INFO(CommandName(command));
    struct Case {
      VkAccelerationStructureGeometryKHR geometry;
      const char* vuid;
    };
    std::vector<Case> cases;
    VkAccelerationStructureGeometryKHR g = scene.Triangles();
    g.geometry.triangles.vertexData.deviceAddress = kNowhere;
    cases.push_back({g, kVertex.For(command)});
    g = scene.IndexedTriangles(VK_INDEX_TYPE_UINT16);
    g.geometry.triangles.indexData.deviceAddress = kNowhere;
    cases.push_back({g, kIndex.For(command)});
    g = scene.Triangles();
    g.geometry.triangles.transformData.deviceAddress = kNowhere;
    cases.push_back({g, kTransform.For(command)});
    g = scene.Aabbs();
    g.geometry.aabbs.data.deviceAddress = kNowhere;
    cases.push_back({g, kAabb.For(command)});
    g = scene.Instances();
    g.geometry.instances.data.deviceAddress = kNowhere;
    cases.push_back({g, kInstance.For(command)});
    for (const Case& c : cases) {
      INFO(c.vuid);
      OneGeometry one(scene, c.geometry);
      f.monitor().Expect(c.vuid);
      recorder.Record(command, one.info, VkAccelerationStructureBuildRangeInfoKHR{1, 0, 0, 0});
      CHECK(f.monitor().Verify() == "");
    }
  }
}

TEST_CASE("geometry-03673: inputs from a buffer without BUILD_INPUT_READ_ONLY usage are reported",
          "[integration][addresses][03673]") {
  CheckFixture f("addresses");
  vkkit::Device& device = f.device();
  Scene scene(device);
  Recorder recorder(device);
  vkkit::Buffer storage = device.CreateBuffer(256, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  VkAccelerationStructureGeometryKHR g = scene.Triangles();
  g.geometry.triangles.vertexData.deviceAddress = storage.address;
  OneGeometry one(scene, g);
  for (Command command : {Command::kDirect, Command::kIndirect}) {
    INFO(CommandName(command));
    f.monitor().Expect(kInputUsage.For(command));
    recorder.Record(command, one.info, VkAccelerationStructureBuildRangeInfoKHR{1, 0, 0, 0});
    CHECK(f.monitor().Verify() == "");
  }
  device.Destroy(storage);
}

TEST_CASE("03802 / 03674 / 03671 / 03672: scratch that is no address, lacks STORAGE usage or is too small",
          "[integration][addresses][03802][03674][03671][03672]") {
  CheckFixture f("addresses");
  vkkit::Device& device = f.device();
  Scene scene(device);
  OneGeometry one(scene, scene.Triangles());
  const VkAccelerationStructureBuildSizesInfoKHR sizes = DriverSizes(device, one.info, {1});
  REQUIRE(sizes.buildScratchSize > 0);
  REQUIRE(sizes.updateScratchSize > 0);
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  VkAccelerationStructureBuildGeometryInfoKHR info = one.info;
  info.pGeometries = &one.geometry;
  vkkit::Buffer exact = device.CreateBuffer(sizes.buildScratchSize, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  vkkit::Buffer exact_update = device.CreateBuffer(sizes.updateScratchSize, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  vkkit::Buffer input_only = device.CreateBuffer(sizes.buildScratchSize, kInput);
  SECTION("03802: no buffer holds the scratch address") {
    info.scratchData.deviceAddress = kNowhere;
    f.monitor().Expect("VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03802");
  }
  SECTION("03674: the scratch buffer lacks STORAGE_BUFFER usage") {
    info.scratchData.deviceAddress = input_only.address;
    f.monitor().Expect("VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03674");
  }
  SECTION("03671: buildScratchSize bytes from the scratch address pass the end of its buffer") {
    info.scratchData.deviceAddress = exact.address + 8;
    f.monitor().Expect("VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03671");
  }
  SECTION("03672: an update's updateScratchSize bytes pass the end of its buffer") {
    info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
    info.srcAccelerationStructure = info.dstAccelerationStructure;
    info.scratchData.deviceAddress = exact_update.address + 8;
    f.monitor().Expect("VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03672");
  }
  IssueOne(device, Command::kDirect, info, &range);
  CHECK(f.monitor().Verify() == "");
  device.Destroy(exact);
  device.Destroy(exact_update);
  device.Destroy(input_only);
}

TEST_CASE("12258 / 12259 / 12260 / 12261: indirect scratch that lacks STORAGE usage, is no address or is too small",
          "[integration][addresses][12258][12259][12260][12261]") {
  CheckFixture f("addresses");
  vkkit::Device& device = f.device();
  Scene scene(device);
  Recorder recorder(device);
  OneGeometry one(scene, scene.Triangles());
  const VkAccelerationStructureBuildSizesInfoKHR sizes = DriverSizes(device, one.info, {1});
  VkAccelerationStructureBuildGeometryInfoKHR info = one.info;
  info.pGeometries = &one.geometry;
  vkkit::Buffer exact = device.CreateBuffer(sizes.buildScratchSize, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  vkkit::Buffer exact_update = device.CreateBuffer(sizes.updateScratchSize, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  vkkit::Buffer input_only = device.CreateBuffer(sizes.buildScratchSize, kInput);
  SECTION("12258: build scratch too small") {
    info.scratchData.deviceAddress = exact.address + 8;
    f.monitor().Expect("VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-12258");
  }
  SECTION("12259: update scratch too small") {
    info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
    info.srcAccelerationStructure = info.dstAccelerationStructure;
    info.scratchData.deviceAddress = exact_update.address + 8;
    f.monitor().Expect("VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-12259");
  }
  SECTION("12260: update scratch without STORAGE usage") {
    info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
    info.srcAccelerationStructure = info.dstAccelerationStructure;
    info.scratchData.deviceAddress = input_only.address;
    f.monitor().Expect("VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-12260");
  }
  SECTION("12261: build scratch at an address no buffer holds") {
    info.scratchData.deviceAddress = kNowhere;
    f.monitor().Expect("VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-12261");
  }
  recorder.Record(Command::kIndirect, info, VkAccelerationStructureBuildRangeInfoKHR{1, 0, 0, 0});
  CHECK(f.monitor().Verify() == "");
  device.Destroy(exact);
  device.Destroy(exact_update);
  device.Destroy(input_only);
}

TEST_CASE("10126 / 03652: a destination smaller than the driver's accelerationStructureSize is reported",
          "[integration][addresses][10126][03652]") {
  CheckFixture f("addresses");
  vkkit::Device& device = f.device();
  Scene scene(device);
  Recorder recorder(device);
  OneGeometry one(scene, scene.Triangles());
  const VkAccelerationStructureBuildSizesInfoKHR sizes = DriverSizes(device, one.info, {1});
  VkAccelerationStructureBuildGeometryInfoKHR info = one.info;
  info.pGeometries = &one.geometry;
  info.dstAccelerationStructure =
      scene.NewStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, sizes.accelerationStructureSize - 16);
  for (Command command : kAllCommands) {
    INFO(CommandName(command));
    f.monitor().Expect(kDestinationSize.For(command));
    recorder.Record(command, info, VkAccelerationStructureBuildRangeInfoKHR{1, 0, 0, 0});
    const std::vector<Message> messages = f.monitor().Take();
    REQUIRE(messages.size() == 1);
    CHECK(messages[0].id_name == kDestinationSize.For(command));
    CHECK(messages[0].text.find("16 bytes short") != std::string::npos);
  }
}

TEST_CASE("03801: an instance count above maxInstanceCount is reported", "[integration][addresses][03801]") {
  CheckFixture f("addresses");
  vkkit::Device& device = f.device();
  Scene scene(device);
  Recorder recorder(device);
  const uint32_t limit = static_cast<uint32_t>(device.as_properties().maxInstanceCount);
  REQUIRE(limit < UINT32_MAX);
  OneGeometry one(scene, scene.Instances());  // a destination for 1 instance: never built
  for (Command command : kAllCommands) {
    INFO(CommandName(command));
    f.monitor().Expect(kInstanceLimit.For(command));
    // Direct builds also read limit + 1 instance records, far past the scene's buffer.
    if (command == Command::kDirect) f.monitor().Expect(kInstance.direct);
    recorder.Record(command, one.info, VkAccelerationStructureBuildRangeInfoKHR{limit + 1, 0, 0, 0});
    CHECK(f.monitor().Verify() == "");
  }
}

TEST_CASE("pIndirectDeviceAddresses-03646 / 03647: build ranges outside one buffer or without INDIRECT_BUFFER usage",
          "[integration][addresses][03646][03647]") {
  CheckFixture f("addresses");
  vkkit::Device& device = f.device();
  Scene scene(device);
  VkAccelerationStructureGeometryKHR geometries[2] = {scene.Triangles(), scene.Triangles()};
  VkAccelerationStructureBuildGeometryInfoKHR info =
      Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {geometries[0], geometries[1]});
  info.pGeometries = geometries;
  scene.Prepare(info, {1, 1});
  vkkit::Buffer ranges = device.CreateBuffer(48, VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT);
  vkkit::Buffer storage = device.CreateBuffer(64, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  SECTION("03646: 2 geometries x stride 32 = 64 bytes from a 48-byte buffer") {
    f.monitor().Expect("VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pIndirectDeviceAddresses-03646");
    RecordIndirect(device, {info}, {ranges.address}, {32}, {{1, 1}});
  }
  SECTION("03647: the ranges' buffer lacks INDIRECT_BUFFER usage") {
    f.monitor().Expect("VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pIndirectDeviceAddresses-03647");
    RecordIndirect(device, {info}, {storage.address}, {16}, {{1, 1}});
  }
  CHECK(f.monitor().Verify() == "");
  device.Destroy(ranges);
  device.Destroy(storage);
}

// ---- valid twins: every family on, built for real on lavapipe

TEST_CASE("addresses valid twin: every input kind from exact-size buffers, strides 12 and 44, ppGeometries",
          "[integration][addresses][valid]") {
  CheckFixture f;
  vkkit::Device& device = f.device();
  Scene scene(device);
  SharedMemory memory(device, 1 << 16);
  // Inputs in buffers of exactly the bytes the builds read, sub-allocated from one memory.
  vkkit::Buffer vertices = memory.Bind(0, 36, kInput);
  vkkit::Buffer wide = memory.Bind(256, 2 * 44 + 12, kInput);  // 3 vertices in 44-byte records
  vkkit::Buffer indices = memory.Bind(512, 6, kInput);         // 3 uint16
  vkkit::Buffer transforms = memory.Bind(768, 96, kInput);     // the second matrix is used
  vkkit::Buffer aabbs = memory.Bind(1024, 24 + 24, kInput);    // 2 boxes, stride 24
  vkkit::Buffer instances = memory.Bind(1280, 128, kInput);    // 2 instances
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
  VkAccelerationStructureGeometryKHR instance_geometry = scene.Instances();
  instance_geometry.geometry.instances.data.deviceAddress = instances.address;

  // Two triangle geometries through ppGeometries; one AABB BLAS; then a TLAS of two instances.
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
  CHECK(f.monitor().Verify() == "");

  OneGeometry tlas(scene, instance_geometry, 2);
  const VkAccelerationStructureBuildRangeInfoKHR instance_range{2, 0, 0, 0};
  scene.BuildNow({tlas.info}, {&instance_range});
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("addresses valid twin: scratch and destination of exactly the driver's sizes; update scratch of "
          "updateScratchSize",
          "[integration][addresses][valid]") {
  CheckFixture f;
  vkkit::Device& device = f.device();
  Scene scene(device);
  VkAccelerationStructureGeometryKHR g = scene.Triangles();
  VkAccelerationStructureBuildGeometryInfoKHR info = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {g});
  info.pGeometries = &g;
  const VkAccelerationStructureBuildSizesInfoKHR sizes = DriverSizes(device, info, {1});
  info.dstAccelerationStructure =
      scene.NewStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, sizes.accelerationStructureSize);
  vkkit::Buffer build_scratch = device.CreateBuffer(sizes.buildScratchSize, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  vkkit::Buffer update_scratch = device.CreateBuffer(sizes.updateScratchSize, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
  VkAccelerationStructureBuildGeometryInfoKHR update = info;
  update.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  update.srcAccelerationStructure = info.dstAccelerationStructure;
  info.scratchData.deviceAddress = build_scratch.address;
  update.scratchData.deviceAddress = update_scratch.address;
  device.OneShot([&](VkCommandBuffer cb) {
    device.CmdBuildAccelerationStructuresKHR(cb, 1, &info, &ranges);
    BuildBarrier(cb);
    device.CmdBuildAccelerationStructuresKHR(cb, 1, &update, &ranges);
  });
  CHECK(f.monitor().Verify() == "");
  device.Destroy(build_scratch);
  device.Destroy(update_scratch);
}

TEST_CASE("addresses valid twin: sub-allocated buffers destroyed and re-created every frame, addresses reused",
          "[integration][addresses][valid]") {
  CheckFixture f;
  vkkit::Device& device = f.device();
  Scene scene(device);
  SharedMemory memory(device, 1 << 16);
  VkAccelerationStructureGeometryKHR g = scene.Triangles();
  VkAccelerationStructureBuildGeometryInfoKHR info = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {g});
  info.pGeometries = &g;
  const VkAccelerationStructureBuildSizesInfoKHR sizes = DriverSizes(device, info, {1});
  info.dstAccelerationStructure =
      scene.NewStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, sizes.accelerationStructureSize);
  const float positions[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
  for (int frame = 0; frame < 4; ++frame) {
    INFO("frame " << frame);
    // Each frame binds its buffers at other offsets of the same memory; the last frame's were destroyed.
    const VkDeviceSize base = 4096 * (frame % 2);
    vkkit::Buffer vertices = memory.Bind(base, 36, kInput);
    vkkit::Buffer scratch = memory.Bind(base + 1024, sizes.buildScratchSize, VK_BUFFER_USAGE_STORAGE_BUFFER_BIT);
    std::memcpy(vertices.mapped, positions, sizeof(positions));
    g.geometry.triangles.vertexData.deviceAddress = vertices.address;
    info.scratchData.deviceAddress = scratch.address;
    scene.BuildNow({info}, {&range});
    CHECK(f.monitor().Verify() == "");
    memory.DestroyBuffer(vertices);
    memory.DestroyBuffer(scratch);
  }
}

}  // namespace
}  // namespace asval_test
