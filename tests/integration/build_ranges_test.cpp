// Family "structure", VkAccelerationStructureBuildRangeInfoKHR: offsets and vertex counts of the ranges the
// app passes on the host, for the direct and the host build (an indirect build's ranges are device memory,
// judged on their capture: tests/unit/indirect_capture_unit_test.cpp).
// Host builds get host addresses into the scene's mapped buffer, since maxVertex-10774 reads their indices.
#include <catch2/catch_test_macros.hpp>

#include "record_checks_helpers.h"

namespace asval_test {
namespace {

constexpr const char* kIndexOffset = "VUID-VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03656";
constexpr const char* kVertexOffset = "VUID-VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03657";
constexpr const char* kTransformOffset = "VUID-VkAccelerationStructureBuildRangeInfoKHR-transformOffset-03658";
constexpr const char* kAabbOffset = "VUID-VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03659";
constexpr const char* kInstanceOffset = "VUID-VkAccelerationStructureBuildRangeInfoKHR-primitiveOffset-03660";
constexpr const char* kVertexCount = "VUID-VkAccelerationStructureBuildRangeInfoKHR-vertexData-10418";
constexpr const char* kLastVertex = "VUID-VkAccelerationStructureBuildRangeInfoKHR-None-10775";
constexpr const char* kLargestIndex = "VUID-VkAccelerationStructureBuildRangeInfoKHR-maxVertex-10774";

constexpr Command kHostRangeCommands[] = {Command::kDirect, Command::kHost};

// One geometry of `type` (bottom or top level), its info prepared for one primitive.
struct OneRange {
  OneRange(Scene& s, const VkAccelerationStructureGeometryKHR& g,
           VkAccelerationStructureTypeKHR type = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR)
      : scene(s), geometry(g) {
    info = Scene::Info(type, {});
    info.geometryCount = 1;
    info.pGeometries = &geometry;
    scene.Prepare(info, {1});
  }
  // Issues the build through `command` with `range`; host builds read host addresses.
  void Issue(CheckFixture& f, Command command, const VkAccelerationStructureBuildRangeInfoKHR& range) {
    VkAccelerationStructureGeometryKHR host = scene.OnHost(geometry);
    VkAccelerationStructureBuildGeometryInfoKHR issued = info;
    if (command == Command::kHost) issued.pGeometries = &host;
    IssueOne(f.device(), command, issued, &range);
  }
  Scene& scene;
  VkAccelerationStructureGeometryKHR geometry;
  VkAccelerationStructureBuildGeometryInfoKHR info;
};

void ExpectEachCommand(CheckFixture& f, std::initializer_list<const char*> vuids, OneRange& build,
                       const VkAccelerationStructureBuildRangeInfoKHR& range) {
  for (Command command : kHostRangeCommands) {
    INFO(CommandName(command));
    for (const char* vuid : vuids) f.monitor().Expect(vuid);
    build.Issue(f, command, range);
    CHECK(f.monitor().Verify() == "");
  }
}

TEST_CASE("primitiveOffset-03656 and 03657: triangle offsets off the index or component size are reported",
          "[integration][structure][03656][03657]") {
  CheckFixture f("structure");
  Scene scene(f.device());
  OneRange indexed(scene, scene.IndexedTriangles(VK_INDEX_TYPE_UINT32));
  ExpectEachCommand(f, {kIndexOffset}, indexed, {1, 2, 0, 0});
  OneRange plain(scene, scene.Triangles());
  ExpectEachCommand(f, {kVertexOffset}, plain, {1, 6, 0, 0});
}

TEST_CASE("transformOffset-03658, primitiveOffset-03659 and 03660: transform, AABB and instance offsets are checked",
          "[integration][structure][03658][03659][03660]") {
  CheckFixture f("structure");
  Scene scene(f.device());
  VkAccelerationStructureGeometryKHR transformed = scene.Triangles();
  transformed.geometry.triangles.transformData.deviceAddress = scene.Address(Scene::kTransforms);
  OneRange triangles(scene, transformed);
  ExpectEachCommand(f, {kTransformOffset}, triangles, {1, 0, 0, 24});
  OneRange boxes(scene, scene.Aabbs());
  ExpectEachCommand(f, {kAabbOffset}, boxes, {1, 4, 0, 0});
  OneRange instances(scene, scene.Instances(), VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR);
  ExpectEachCommand(f, {kInstanceOffset}, instances, {1, 8, 0, 0});
  std::vector<Message> none = f.monitor().Take();
  CHECK(none.empty());
  f.monitor().Expect(kInstanceOffset);
  instances.Issue(f, Command::kDirect, {1, 8, 0, 0});
  std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].text.find("ppBuildRangeInfos[0][0].primitiveOffset (8)") != std::string::npos);
}

TEST_CASE("range offsets valid twin: aligned offsets into the data stay silent",
          "[integration][structure][03656][03657][03658][03659][03660]") {
  CheckFixture f;
  Scene scene(f.device());
  VkAccelerationStructureGeometryKHR transformed = scene.Triangles();
  transformed.geometry.triangles.transformData.deviceAddress = scene.Address(Scene::kTransforms);
  OneRange indexed16(scene, scene.IndexedTriangles(VK_INDEX_TYPE_UINT16));
  OneRange second_transform(scene, transformed);
  OneRange one_vertex_in(scene, scene.Triangles());  // reads vertices 1..3 of the zero-padded buffer
  one_vertex_in.geometry.geometry.triangles.maxVertex = 3;
  OneRange second_box(scene, scene.Aabbs());
  OneRange second_instance(scene, scene.Instances(), VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR);
  const VkAccelerationStructureBuildRangeInfoKHR at_zero{1, 0, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR transform_48{1, 0, 0, 48};
  const VkAccelerationStructureBuildRangeInfoKHR vertex_12{1, 12, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR box_24{1, 24, 0, 0};
  const VkAccelerationStructureBuildRangeInfoKHR instance_64{1, 64, 0, 0};
  scene.BuildNow({indexed16.info}, {&at_zero});
  scene.BuildNow({second_transform.info}, {&transform_48});
  scene.BuildNow({one_vertex_in.info}, {&vertex_12});
  scene.BuildNow({second_box.info}, {&box_24});
  scene.BuildNow({second_instance.info}, {&instance_64});
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("vertexData-10418 and None-10775: non-indexed triangles past maxVertex are reported",
          "[integration][structure][10418][10775]") {
  CheckFixture f("structure");
  Scene scene(f.device());
  OneRange plain(scene, scene.Triangles());
  // Three vertices from firstVertex 1: the count fits maxVertex + 1 = 3, the last index 3 does not.
  ExpectEachCommand(f, {kLastVertex}, plain, {1, 0, 1, 0});
  // maxVertex 1: three vertices never fit, wherever they start.
  plain.geometry.geometry.triangles.maxVertex = 1;
  ExpectEachCommand(f, {kVertexCount, kLastVertex}, plain, {1, 0, 0, 0});
}

TEST_CASE("maxVertex-10774: a host build whose indices pass maxVertex is reported", "[integration][structure][10774]") {
  CheckFixture f("structure");
  Scene scene(f.device());
  for (VkIndexType type : {VK_INDEX_TYPE_UINT16, VK_INDEX_TYPE_UINT32}) {
    OneRange indexed(scene, scene.IndexedTriangles(type));
    indexed.geometry.geometry.triangles.maxVertex = 1;  // the indices are 0, 1, 2
    f.monitor().Expect(kLargestIndex);
    indexed.Issue(f, Command::kHost, {1, 0, 0, 0});
    std::vector<Message> messages = f.monitor().Take();
    REQUIRE(messages.size() == 1);
    CHECK(messages[0].text.find("largest index the build reads (2") != std::string::npos);
    // firstVertex moves every index: 0 + 1 .. 2 + 1 against maxVertex 2.
    indexed.geometry.geometry.triangles.maxVertex = 2;
    f.monitor().Expect(kLargestIndex);
    indexed.Issue(f, Command::kHost, {1, 0, 1, 0});
    CHECK(f.monitor().Verify() == "");
  }
}

TEST_CASE("vertex counts valid twin: maxVertex that covers firstVertex and the largest index stays silent",
          "[integration][structure][10418][10775][10774]") {
  CheckFixture f;
  Scene scene(f.device());
  OneRange plain(scene, scene.Triangles());
  plain.geometry.geometry.triangles.maxVertex = 3;  // vertices 1..3 (the fourth is zero padding)
  OneRange indexed(scene, scene.IndexedTriangles(VK_INDEX_TYPE_UINT32));
  indexed.geometry.geometry.triangles.maxVertex = 3;  // indices 0..2 from firstVertex 1
  const VkAccelerationStructureBuildRangeInfoKHR from_one{1, 0, 1, 0};
  scene.BuildNow({plain.info, indexed.info}, {&from_one, &from_one});
  // No triangles at all: firstVertex names no vertex that is read.
  const VkAccelerationStructureBuildRangeInfoKHR empty{0, 0, 100, 0};
  scene.BuildNow({plain.info}, {&empty});
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test

namespace asval_test {
namespace {

constexpr const char* k03676Direct = "VUID-vkCmdBuildAccelerationStructuresKHR-ppBuildRangeInfos-03676";

TEST_CASE("ppBuildRangeInfos-03676: a NULL element of ppBuildRangeInfos for an info with geometries is reported",
          "[integration][structure][03676]") {
  CheckFixture f("structure");
  Scene scene(f.device());
  OneRange plain(scene, scene.Triangles());
  f.monitor().Expect(k03676Direct);
  IssueOne(f.device(), Command::kDirect, plain.info, nullptr);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("ppBuildRangeInfos-03676 valid twin: range infos for every info with geometries, none for one without",
          "[integration][structure][valid]") {
  CheckFixture f;
  Scene scene(f.device());
  OneRange plain(scene, scene.Triangles());
  plain.Issue(f, Command::kDirect, {1, 0, 0, 0});
  VkAccelerationStructureBuildGeometryInfoKHR empty = plain.info;
  empty.geometryCount = 0;  // a structure of no geometry: nothing to point to
  empty.pGeometries = nullptr;
  IssueOne(f.device(), Command::kDirect, empty, nullptr);
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test
