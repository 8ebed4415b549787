// Family "structure", VkAccelerationStructureBuildGeometryInfoKHR: type, geometry arrays, geometry types and
// counts, flags. These VUIDs name the structure, so all three commands report the same one; indirect and
// host builds are only called with an expected finding (lavapipe has neither).
#include <catch2/catch_test_macros.hpp>

#include "record_checks_helpers.h"

namespace asval_test {
namespace {

constexpr const char* kGeneric = "VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03654";
constexpr const char* kArrays = "VUID-VkAccelerationStructureBuildGeometryInfoKHR-pGeometries-03788";
constexpr const char* kTopInstances = "VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03789";
constexpr const char* kTopOne = "VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03790";
constexpr const char* kBottomNoInstances = "VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03791";
constexpr const char* kBottomSameType = "VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03792";
constexpr const char* kGeometryLimit = "VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03793";
constexpr const char* kAabbLimit = "VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03794";
constexpr const char* kTriangleLimit = "VUID-VkAccelerationStructureBuildGeometryInfoKHR-type-03795";
constexpr const char* kFastBoth = "VUID-VkAccelerationStructureBuildGeometryInfoKHR-flags-03796";
constexpr const char* kMicromapBoth = "VUID-VkAccelerationStructureBuildGeometryInfoKHR-flags-07334";

// Issues `info` through each command, expecting `vuid` once per command.
void ExpectEachCommand(CheckFixture& f, const char* vuid, const VkAccelerationStructureBuildGeometryInfoKHR& info,
                       const VkAccelerationStructureBuildRangeInfoKHR* ranges) {
  for (Command command : kAllCommands) {
    INFO(CommandName(command));
    f.monitor().Expect(vuid);
    IssueOne(f.device(), command, info, ranges);
    CHECK(f.monitor().Verify() == "");
  }
}

TEST_CASE("type-03654: a build of type GENERIC is reported", "[integration][structure][03654]") {
  CheckFixture f("structure");
  Scene scene(f.device());
  VkAccelerationStructureGeometryKHR triangles = scene.Triangles();
  VkAccelerationStructureBuildGeometryInfoKHR info = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {});
  info.geometryCount = 1;
  info.pGeometries = &triangles;
  scene.Prepare(info, {1}, VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR);
  info.type = VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR;
  ExpectEachCommand(f, kGeneric, info, Ranges(1).data());
}

TEST_CASE("pGeometries-03788: neither or both of pGeometries and ppGeometries is reported",
          "[integration][structure][03788]") {
  CheckFixture f("structure");
  Scene scene(f.device());
  VkAccelerationStructureGeometryKHR triangles = scene.Triangles();
  const VkAccelerationStructureGeometryKHR* pointer = &triangles;
  VkAccelerationStructureBuildGeometryInfoKHR info = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {});
  info.geometryCount = 1;
  info.pGeometries = &triangles;
  scene.Prepare(info, {1});
  const auto ranges = Ranges(1);
  info.pGeometries = nullptr;
  ExpectEachCommand(f, kArrays, info, ranges.data());
  info.pGeometries = &triangles;
  info.ppGeometries = &pointer;
  ExpectEachCommand(f, kArrays, info, ranges.data());
}

TEST_CASE("type-03654 and pGeometries-03788 valid twin: bottom- and top-level builds through pGeometries and "
          "ppGeometries stay silent",
          "[integration][structure][03654][03788]") {
  CheckFixture f;
  Scene scene(f.device());
  const auto ranges = Ranges(2);
  VkAccelerationStructureGeometryKHR geometries[2] = {scene.Triangles(), scene.IndexedTriangles(VK_INDEX_TYPE_UINT32)};
  const VkAccelerationStructureGeometryKHR* pointers[2] = {&geometries[0], &geometries[1]};
  VkAccelerationStructureBuildGeometryInfoKHR direct = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {});
  direct.geometryCount = 2;
  direct.pGeometries = geometries;
  scene.Prepare(direct, {1, 1});
  VkAccelerationStructureBuildGeometryInfoKHR indirect = direct;
  indirect.pGeometries = nullptr;
  indirect.ppGeometries = pointers;
  scene.Prepare(indirect, {1, 1});
  VkAccelerationStructureGeometryKHR instances = scene.Instances();
  VkAccelerationStructureBuildGeometryInfoKHR top = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, {});
  top.geometryCount = 1;
  top.pGeometries = &instances;
  scene.Prepare(top, {2});
  const auto two = Ranges(1, 2);
  scene.BuildNow({direct, indirect}, {ranges.data(), ranges.data()});
  scene.BuildNow({top}, {two.data()});
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("type-03789 and type-03790: a top-level build of triangles, or of two geometries, is reported",
          "[integration][structure][03789][03790]") {
  CheckFixture f("structure");
  Scene scene(f.device());
  VkAccelerationStructureGeometryKHR geometries[2] = {scene.Instances(), scene.Triangles()};
  VkAccelerationStructureBuildGeometryInfoKHR info = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, {});
  info.geometryCount = 1;
  info.pGeometries = &geometries[0];
  scene.Prepare(info, {1});
  const auto ranges = Ranges(2);
  info.pGeometries = &geometries[1];
  ExpectEachCommand(f, kTopInstances, info, ranges.data());
  info.pGeometries = geometries;
  info.geometryCount = 2;
  for (Command command : kAllCommands) {
    INFO(CommandName(command));
    f.monitor().Expect(kTopOne);
    f.monitor().Expect(kTopInstances);  // the second geometry is triangles too
    IssueOne(f.device(), command, info, ranges.data());
    CHECK(f.monitor().Verify() == "");
  }
}

TEST_CASE("type-03791 and type-03792: a bottom-level build with instances, or with triangles and AABBs, is reported",
          "[integration][structure][03791][03792]") {
  CheckFixture f("structure");
  Scene scene(f.device());
  VkAccelerationStructureGeometryKHR geometries[2] = {scene.Triangles(), scene.Aabbs()};
  VkAccelerationStructureGeometryKHR instances = scene.Instances();
  VkAccelerationStructureBuildGeometryInfoKHR info = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {});
  info.geometryCount = 1;
  info.pGeometries = geometries;
  scene.Prepare(info, {1});
  const auto ranges = Ranges(2);
  info.pGeometries = &instances;
  ExpectEachCommand(f, kBottomNoInstances, info, ranges.data());
  info.pGeometries = geometries;
  info.geometryCount = 2;
  ExpectEachCommand(f, kBottomSameType, info, ranges.data());
  f.monitor().Expect(kBottomSameType);
  IssueOne(f.device(), Command::kDirect, info, ranges.data());
  std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].text.find("pInfos[0].pGeometries[1].geometryType (VK_GEOMETRY_TYPE_AABBS_KHR)") !=
        std::string::npos);
}

TEST_CASE("type-03791 and type-03792: only the first type a bottom-level build breaks is reported, at its geometry",
          "[integration][structure][03791][03792]") {
  CheckFixture f("structure");
  Scene scene(f.device());
  VkAccelerationStructureGeometryKHR triangles = scene.Triangles();
  VkAccelerationStructureBuildGeometryInfoKHR info = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {});
  info.geometryCount = 1;
  info.pGeometries = &triangles;
  scene.Prepare(info, {1});
  const auto ranges = Ranges(3);
  const auto expect_one = [&](const char* vuid, const char* where) {
    f.monitor().Expect(vuid);
    IssueOne(f.device(), Command::kDirect, info, ranges.data());
    std::vector<Message> messages = f.monitor().Take();
    REQUIRE(messages.size() == 1);
    CHECK(messages[0].text.find(where) != std::string::npos);
  };
  // An instance geometry after triangles breaks 03791 (not 03792, though its type also differs from the first).
  VkAccelerationStructureGeometryKHR later_instances[2] = {scene.Triangles(), scene.Instances()};
  info.geometryCount = 2;
  info.pGeometries = later_instances;
  expect_one(kBottomNoInstances, "pInfos[0].pGeometries[1].geometryType (VK_GEOMETRY_TYPE_INSTANCES_KHR)");
  // A first instance geometry breaks 03791 itself; the triangles after it are not reported (one finding per info).
  VkAccelerationStructureGeometryKHR first_instances[2] = {scene.Instances(), scene.Triangles()};
  info.pGeometries = first_instances;
  expect_one(kBottomNoInstances, "pInfos[0].pGeometries[0].geometryType (VK_GEOMETRY_TYPE_INSTANCES_KHR)");
  // AABBs, then triangles (03792), then instances: only the first finding.
  VkAccelerationStructureGeometryKHR mixed[3] = {scene.Aabbs(), scene.Triangles(), scene.Instances()};
  info.geometryCount = 3;
  info.pGeometries = mixed;
  expect_one(kBottomSameType, "pInfos[0].pGeometries[1].geometryType (VK_GEOMETRY_TYPE_TRIANGLES_KHR)");
}

TEST_CASE("type-03789..03792 valid twin: one instance geometry at the top, several AABB geometries at the bottom, "
          "stay silent",
          "[integration][structure][03789][03790][03791][03792]") {
  CheckFixture f;
  Scene scene(f.device());
  VkAccelerationStructureGeometryKHR boxes[3] = {scene.Aabbs(), scene.Aabbs(), scene.Aabbs()};
  VkAccelerationStructureBuildGeometryInfoKHR bottom = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {});
  bottom.geometryCount = 3;
  bottom.pGeometries = boxes;
  scene.Prepare(bottom, {2, 2, 2});
  VkAccelerationStructureGeometryKHR instances = scene.Instances(/*array_of_pointers=*/true);
  VkAccelerationStructureBuildGeometryInfoKHR top = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, {});
  top.geometryCount = 1;
  top.pGeometries = &instances;
  scene.Prepare(top, {2});
  const auto ranges = Ranges(3, 2);
  scene.BuildNow({bottom}, {ranges.data()});
  scene.BuildNow({top}, {ranges.data()});
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("type-03793, 03794 and 03795: geometry and primitive counts over the device's limits are reported",
          "[integration][structure][03793][03794][03795]") {
  CheckFixture f("structure");
  Scene scene(f.device());
  const VkPhysicalDeviceAccelerationStructurePropertiesKHR& limits = f.device().as_properties();
  REQUIRE(limits.maxGeometryCount < UINT32_MAX);
  REQUIRE(limits.maxPrimitiveCount < UINT32_MAX);
  VkAccelerationStructureGeometryKHR triangles = scene.IndexedTriangles(VK_INDEX_TYPE_UINT32);
  triangles.geometry.triangles.indexData.hostAddress = nullptr;  // host builds then read no index
  VkAccelerationStructureGeometryKHR boxes = scene.Aabbs();
  VkAccelerationStructureBuildGeometryInfoKHR info = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {});
  info.geometryCount = 1;
  info.pGeometries = &triangles;
  scene.Prepare(info, {1});

  // Over maxGeometryCount: the layer judges the count and walks no geometry, so one geometry suffices here.
  info.geometryCount = static_cast<uint32_t>(limits.maxGeometryCount) + 1;
  const auto one = Ranges(1);
  ExpectEachCommand(f, kGeometryLimit, info, one.data());

  info.geometryCount = 1;
  const auto too_many = Ranges(1, static_cast<uint32_t>(limits.maxPrimitiveCount) + 1);
  for (Command command : {Command::kDirect, Command::kHost}) {  // indirect counts live on the device
    INFO(CommandName(command));
    info.pGeometries = &triangles;
    f.monitor().Expect(kTriangleLimit);
    IssueOne(f.device(), command, info, too_many.data());
    CHECK(f.monitor().Verify() == "");
    info.pGeometries = &boxes;
    f.monitor().Expect(kAabbLimit);
    IssueOne(f.device(), command, info, too_many.data());
    CHECK(f.monitor().Verify() == "");
  }
}

TEST_CASE("type-03793..03795 valid twin: counts within the limits, and an indirect build's device-side counts, stay "
          "silent",
          "[integration][structure][03793][03794][03795]") {
  CheckFixture f;
  Scene scene(f.device());
  std::vector<VkAccelerationStructureGeometryKHR> geometries(16, scene.Triangles());
  VkAccelerationStructureBuildGeometryInfoKHR info = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {});
  info.geometryCount = 16;
  info.pGeometries = geometries.data();
  scene.Prepare(info, std::vector<uint32_t>(16, 1));
  const auto ranges = Ranges(16);
  scene.BuildNow({info}, {ranges.data()});
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("flags-03796 and flags-07334: contradictory build flags are reported", "[integration][structure][03796][07334]") {
  CheckFixture f("structure");
  Scene scene(f.device());
  VkAccelerationStructureGeometryKHR triangles = scene.Triangles();
  VkAccelerationStructureBuildGeometryInfoKHR info = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {});
  info.geometryCount = 1;
  info.pGeometries = &triangles;
  scene.Prepare(info, {1});
  const auto ranges = Ranges(1);
  info.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR |
               VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR;
  ExpectEachCommand(f, kFastBoth, info, ranges.data());
  info.flags = VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_OPACITY_MICROMAP_UPDATE_EXT |
               VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_OPACITY_MICROMAP_DATA_UPDATE_EXT;
  ExpectEachCommand(f, kMicromapBoth, info, ranges.data());
}

TEST_CASE("flags-03796 and flags-07334 valid twin: one preference, or none, with update and compaction stays silent",
          "[integration][structure][03796][07334]") {
  CheckFixture f;
  Scene scene(f.device());
  VkAccelerationStructureGeometryKHR triangles = scene.Triangles();
  const auto ranges = Ranges(1);
  for (VkBuildAccelerationStructureFlagsKHR flags :
       {VkBuildAccelerationStructureFlagsKHR{0}, VkBuildAccelerationStructureFlagsKHR{
                                                     VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR |
                                                     VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR},
        VkBuildAccelerationStructureFlagsKHR{VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR |
                                             VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR |
                                             VK_BUILD_ACCELERATION_STRUCTURE_LOW_MEMORY_BIT_KHR}}) {
    VkAccelerationStructureBuildGeometryInfoKHR info = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {});
    info.geometryCount = 1;
    info.pGeometries = &triangles;
    info.flags = flags;
    scene.Prepare(info, {1});
    scene.BuildNow({info}, {ranges.data()});
    INFO("flags 0x" << std::hex << flags);
    CHECK(f.monitor().Verify() == "");
  }
}

}  // namespace
}  // namespace asval_test
