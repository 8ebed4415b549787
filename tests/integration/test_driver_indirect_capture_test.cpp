// Execution-time capture of indirect builds on asval's test driver (issue 28, docs/capture.md "Indirect builds"):
// the range infos of vkCmdBuildAccelerationStructuresIndirectKHR are on the device, so the geometry they select is
// read by the layer's dispatch, which reads each range info first. The rules judged on those bytes are the direct
// command's: an update may not change a primitive's activity (pInfos-03663, 03664) nor the index values (03768),
// and a top-level build's instances reference 0 or a live bottom-level structure (pInfos-12281). The tests write
// the inputs on the device in the command buffer of the build or update, as capture_activity_test.cpp does, so that
// only the capture can know them, and wait for each submission (the layer reports in the wait). They ask for
// capture_method=reduce: the test driver sits over lavapipe, a CPU device, where the layer's dispatch is not made
// unless asked (the last test: there the geometry is not judged, never guessed).
#include <catch2/catch_test_macros.hpp>
#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "capture_helpers.h"
#include "history_helpers.h"
#include "indirect_helpers.h"
#include "on_test_driver.h"
#include "scoped_env.h"

namespace asval_test {
namespace {

constexpr const char* kBecameActive = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03663";
constexpr const char* kBecameInactive = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03664";
constexpr const char* kIndicesChanged = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03768";
constexpr const char* kStaleReference = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-12281";
constexpr const char* kStorageNotBound = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03709";
constexpr const char* kMisalignedPointer = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03717";
constexpr const char* kReferencedDestination = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-None-03407";
constexpr const char* kReferencedOverlap =
    "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-dstAccelerationStructure-03706";

// How many of `messages` have the id `vuid` and a text holding `text`.
int Count(const std::vector<Message>& messages, const char* vuid, const std::string& text) {
  int n = 0;
  for (const Message& m : messages) n += m.id_name == vuid && m.text.find(text) != std::string::npos;
  return n;
}

std::vector<std::pair<const char*, const char*>> Reduced() { return {{"capture_method", "reduce"}}; }

// Whether the structure's indirect updates are judged: one that now makes primitive `primitive` inactive (a NaN X
// over `vertex`) must be reported. A valid twin's silence means something only if its updates were judged.
std::string Probe(IndirectRig& rig, Monitor& monitor, const Shape& shape, uint32_t vertex = 0, uint32_t primitive = 0) {
  rig.SetRanges({IndirectRig::ShapeRange(shape)});
  rig.Run([&](VkCommandBuffer cb) {
    rig.Fill(cb, Component(vertex, 0), kNan);
    rig.Record(cb, shape, VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);
  });
  return OnlyFinding(monitor, kBecameInactive, ": primitive " + std::to_string(primitive));
}

TEST_CASE(
    "capture on the test driver: an indirect update that makes an active triangle inactive is reported "
    "(pInfos-03664)",
    "[integration][capture][test-driver][03664]") {
  const OnTestDriver driver;
  HistoryFixture f(nullptr, Reduced(), IndirectBuild());
  IndirectRig rig(f.device());
  rig.Build(Triangles());
  REQUIRE(f.monitor().Verify() == "");
  CHECK(Probe(rig, f.monitor(), Triangles()) == "");
}

TEST_CASE(
    "capture on the test driver: an indirect update that makes an inactive triangle active is reported "
    "(pInfos-03663)",
    "[integration][capture][test-driver][03663]") {
  const OnTestDriver driver;
  HistoryFixture f(nullptr, Reduced(), IndirectBuild());
  IndirectRig rig(f.device());
  std::vector<uint32_t> vertices = Vertices();
  vertices[0] = kNan;  // triangle 0 inactive
  rig.Build(Triangles(), vertices);
  REQUIRE(f.monitor().Verify() == "");
  rig.SetRanges({IndirectRig::ShapeRange(Triangles())});
  rig.Run([&](VkCommandBuffer cb) {
    rig.Write(cb, Component(0, 0), Vertices(0.5f));
    rig.Record(cb, Triangles(), VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);
  });
  CHECK(OnlyFinding(f.monitor(), kBecameActive, ": primitive 0") == "");
}

TEST_CASE("capture on the test driver: an indirect update with other index values is reported (pInfos-03768)",
          "[integration][capture][test-driver][03768]") {
  const OnTestDriver driver;
  HistoryFixture f(nullptr, Reduced(), IndirectBuild());
  IndirectRig rig(f.device());
  Shape shape = Triangles();
  shape.index_type = VK_INDEX_TYPE_UINT32;
  const std::vector<uint32_t> indices = {0, 1, 2, 3, 4, 5};
  rig.SetRanges({IndirectRig::ShapeRange(shape)});
  rig.Run([&](VkCommandBuffer cb) {
    rig.Write(cb, Component(0, 0), Vertices());
    rig.Write(cb, Inputs::kIndicesOffset, indices);
    rig.Record(cb, shape, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
  });
  REQUIRE(f.monitor().Verify() == "");
  rig.Run([&](VkCommandBuffer cb) {
    rig.Write(cb, Inputs::kIndicesOffset, {0, 2, 1, 3, 4, 5});  // triangle 0's winding turned
    rig.Record(cb, shape, VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);
  });
  CHECK(OnlyFinding(f.monitor(), kIndicesChanged, "") == "");
}

TEST_CASE(
    "capture valid twin on the test driver: indirect updates that keep each triangle's activity and the "
    "index values stay silent, and are judged",
    "[integration][capture][test-driver][valid]") {
  const OnTestDriver driver;
  HistoryFixture f(nullptr, Reduced(), IndirectBuild());
  IndirectRig rig(f.device());
  SECTION("not indexed") {
    rig.Build(Triangles());
    for (float dx : {0.25f, 0.5f}) {
      rig.Run([&](VkCommandBuffer cb) {
        rig.Write(cb, Component(0, 0), Vertices(dx));
        rig.Record(cb, Triangles(), VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);
      });
    }
    CHECK(f.monitor().Verify() == "");
    CHECK(Probe(rig, f.monitor(), Triangles()) == "");
  }
  SECTION("indexed, ppMaxPrimitiveCounts above the range's count") {
    Shape shape = Triangles();
    shape.index_type = VK_INDEX_TYPE_UINT16;
    rig.SetRanges({IndirectRig::ShapeRange(shape)});
    rig.Run([&](VkCommandBuffer cb) {
      rig.Write(cb, Component(0, 0), Vertices());
      rig.Write(cb, Inputs::kIndicesOffset, {0u | 1u << 16, 2u | 3u << 16, 4u | 5u << 16});
      rig.Record(cb, shape, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR, 2);
    });
    rig.Run([&](VkCommandBuffer cb) {
      rig.Write(cb, Component(0, 0), Vertices(0.5f));
      rig.Record(cb, shape, VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR, 2);
    });
    CHECK(f.monitor().Verify() == "");
    CHECK(Probe(rig, f.monitor(), shape) == "");
  }
}

TEST_CASE("capture on the test driver: an indirect update that makes an AABB inactive is reported (pInfos-03664)",
          "[integration][capture][test-driver][03664]") {
  const OnTestDriver driver;
  HistoryFixture f(nullptr, Reduced(), IndirectBuild());
  IndirectRig rig(f.device());
  Shape boxes = Triangles();
  boxes.geometry_type = VK_GEOMETRY_TYPE_AABBS_KHR;
  constexpr VkDeviceSize kAabbBytes = 24;
  const auto write_boxes = [&](VkCommandBuffer cb, float dx) {  // two unit boxes side by side, moved by dx
    std::vector<uint32_t> words;
    for (float x : {0.0f, 2.0f}) {
      for (float value : {x + dx, 0.0f, 0.0f, x + dx + 1, 1.0f, 1.0f}) words.push_back(Bits(value));
    }
    rig.Write(cb, Inputs::kAabbsOffset, words);
  };
  rig.SetRanges({IndirectRig::ShapeRange(boxes)});
  rig.Run([&](VkCommandBuffer cb) {
    write_boxes(cb, 0);
    rig.Record(cb, boxes, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
  });
  rig.Run([&](VkCommandBuffer cb) {  // moved: silent
    write_boxes(cb, 0.5f);
    rig.Record(cb, boxes, VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);
  });
  REQUIRE(f.monitor().Verify() == "");
  rig.Run([&](VkCommandBuffer cb) {
    rig.Fill(cb, Inputs::kAabbsOffset + kAabbBytes, kNan);  // box 1's minX
    rig.Record(cb, boxes, VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);
  });
  CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 1") == "");
}

TEST_CASE(
    "capture on the test driver: an indirect top-level update that makes an active instance inactive is "
    "reported (pInfos-03664)",
    "[integration][capture][test-driver][03664]") {
  const OnTestDriver driver;
  HistoryFixture f(nullptr, Reduced(), IndirectBuild());
  TopLevelRig made(f.device());
  auto& [rig, other, top] = made;
  vkkit::Buffer instances = top.tlas().MakeInstances({&rig.blas(), &other});
  top.Build(instances, 2);
  top.Build(instances, 2, false, VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);  // the same instances: silent
  REQUIRE(f.monitor().Verify() == "");
  const VkAccelerationStructureInstanceKHR inactive = InstanceRecord(0, 1);  // instance 1 now references nothing
  std::memcpy(static_cast<unsigned char*>(instances.mapped) + sizeof(inactive), &inactive, sizeof(inactive));
  top.Build(instances, 2, false, VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);
  CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 1") == "");
  rig.device().Destroy(instances);
}

TEST_CASE(
    "capture on the test driver: an indirect build's primitives are counted from the range info's "
    "primitiveOffset and firstVertex the device read",
    "[integration][capture][test-driver][03664]") {
  const OnTestDriver driver;
  HistoryFixture f(nullptr, Reduced(), IndirectBuild());
  IndirectRig rig(f.device());
  // One triangle: the second of the inputs' two, selected by the range info only (the recorded info cannot say).
  Shape shape = Triangles(1);
  SECTION("primitiveOffset") { shape.primitive_offset = 3 * kVertexBytes; }
  SECTION("firstVertex") {
    shape.first_vertex = 3;
    shape.max_vertex = 5;  // firstVertex + 3 * primitiveCount - 1 (VkAccelerationStructureBuildRangeInfoKHR-None-10775)
  }
  rig.Build(shape);
  // Vertex 0 is outside the range: a NaN there changes nothing the build reads.
  rig.SetRanges({IndirectRig::ShapeRange(shape)});
  rig.Run([&](VkCommandBuffer cb) {
    rig.Fill(cb, Component(0, 0), kNan);
    rig.Record(cb, shape, VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);
  });
  CHECK(f.monitor().Verify() == "");
  // Vertex 3 is the range's first: its triangle, primitive 0 of the geometry, becomes inactive.
  CHECK(Probe(rig, f.monitor(), shape, 3, 0) == "");
}

TEST_CASE(
    "capture on the test driver: an indirect top-level build whose instance references a destroyed "
    "structure is reported (pInfos-12281)",
    "[integration][capture][test-driver][12281][passes-invalid-down]") {
  const OnTestDriver driver;
  HistoryFixture f(nullptr, Reduced(), IndirectBuild());
  TopLevelRig made(f.device());
  auto& [rig, gone, top] = made;
  vkkit::Buffer instances = top.tlas().MakeInstances({&rig.blas(), &gone});
  gone.DestroyHandle();
  top.Build(instances, 2);
  CHECK(OnlyFinding(f.monitor(), kStaleReference, "instance(s) reference no acceleration structure") == "");
  rig.device().Destroy(instances);
}

TEST_CASE(
    "capture on the test driver: an indirect top-level build whose instance references a structure whose "
    "buffer was destroyed is reported (pInfos-03709)",
    "[integration][capture][test-driver][03709][passes-invalid-down]") {
  const OnTestDriver driver;
  HistoryFixture f(nullptr, Reduced(), IndirectBuild());
  TopLevelRig made(f.device());
  auto& [rig, lost, top] = made;
  vkkit::Buffer instances = top.tlas().MakeInstances({&rig.blas(), &lost});
  lost.DestroyStorageBuffer();  // the structure and its memory stay (the driver still reads the bytes there)
  top.Build(instances, 2);
  CHECK(OnlyFinding(f.monitor(), kStorageNotBound, "geometry 0, instance 1 references") == "");
  rig.device().Destroy(instances);
}

TEST_CASE(
    "capture valid twin on the test driver: indirect top-level builds whose instances reference live "
    "structures stay silent; only the range info's count of instances is read",
    "[integration][capture][test-driver][valid]") {
  const OnTestDriver driver;
  HistoryFixture f(nullptr, Reduced(), IndirectBuild());
  TopLevelRig made(f.device());
  auto& [rig, gone, top] = made;
  vkkit::Buffer instances = top.tlas().MakeInstances({&rig.blas(), &gone});
  top.Build(instances, 2);
  CHECK(f.monitor().Verify() == "");
  // The stale instance lies past the range info's count: the build does not read it, neither does the capture.
  gone.DestroyHandle();
  top.Build(instances, 1);
  CHECK(f.monitor().Verify() == "");
  rig.device().Destroy(instances);
}

TEST_CASE(
    "capture on the test driver: an indirect top-level build whose instance references another info's "
    "destination in the same command is reported (None-03407, dstAccelerationStructure-03706)",
    "[integration][capture][test-driver][03407][03706][passes-invalid-down]") {
  const OnTestDriver driver;
  HistoryFixture f(nullptr, Reduced(), IndirectBuild());
  TopLevelRig made(f.device());
  auto& [rig, other, top] = made;
  vkkit::Buffer instances = top.tlas().MakeInstances({&rig.blas(), &other});
  top.BuildTogether(other, instances, 2);  // pInfos[0] builds `other` again; instance 1 references it
  // Its address is another destination's (03407), and its memory the bytes pInfos[0] writes (03706: the range info's
  // count is the recorded maximum, so those bytes are known).
  const std::vector<Message> messages = f.monitor().Take();
  std::string seen;
  for (const Message& m : messages) seen += m.id_name + ": " + m.text + "\n";
  INFO(seen);
  CHECK(messages.size() == 2);
  CHECK(Count(messages, kReferencedDestination, "geometry 0, instance 1 references VkAccelerationStructureKHR") == 1);
  CHECK(Count(messages, kReferencedOverlap, "for pInfos[0].dstAccelerationStructure") == 1);
  rig.device().Destroy(instances);
}

TEST_CASE(
    "capture on the test driver: an indirect top-level build whose instance references a structure over the bytes "
    "the same command writes for another destination is reported (dstAccelerationStructure-03706)",
    "[integration][capture][test-driver][03706][passes-invalid-down]") {
  const OnTestDriver driver;
  HistoryFixture f(nullptr, Reduced(), IndirectBuild());
  TopLevelRig made(f.device());
  auto& [rig, other, top] = made;
  Blas over(rig.device(), rig.inputs(), &other, 256);  // in other's storage, 256 bytes in
  vkkit::Buffer instances = top.tlas().MakeInstances({&other});
  top.BuildTogether(over, instances, 1);  // pInfos[0] builds `over`, its count the recorded maximum
  CHECK(OnlyFinding(f.monitor(), kReferencedOverlap, "geometry 0, instance 0 references") == "");
  rig.device().Destroy(instances);
}

TEST_CASE(
    "capture on the test driver: the bytes an indirect build writes for other counts than its recorded maximum are "
    "not known: an instance over its destination is skipped and counted, never guessed",
    "[integration][capture][test-driver][03706][passes-invalid-down]") {
  const OnTestDriver driver;
  HistoryFixture f(nullptr, Reduced(), IndirectBuild());
  TopLevelRig made(f.device());
  auto& [rig, other, top] = made;
  Blas over(rig.device(), rig.inputs(), &other, 256);
  vkkit::Buffer instances = top.tlas().MakeInstances({&other});
  top.BuildTogether(over, instances, 1, 2);  // pInfos[0]: one triangle of at most two
  CHECK(f.monitor().Verify() == "");
  rig.device().Destroy(instances);
}

TEST_CASE(
    "capture valid twin on the test driver: an indirect command of a bottom-level and a top-level build "
    "whose instances do not reference the other destination stays silent",
    "[integration][capture][test-driver][valid]") {
  const OnTestDriver driver;
  HistoryFixture f(nullptr, Reduced(), IndirectBuild());
  TopLevelRig made(f.device());
  auto& [rig, other, top] = made;
  vkkit::Buffer instances = top.tlas().MakeInstances({&rig.blas(), &other});
  top.BuildTogether(other, instances, 1);  // only instance 0 (rig's structure) is read
  CHECK(f.monitor().Verify() == "");
  rig.device().Destroy(instances);
}

// Instance records, each referencing one of `blases`, at the byte offsets given (16-aligned or not), in a buffer of
// build inputs, and a buffer of pointers to them (in that order).
struct PointedRecords {
  PointedRecords(vkkit::Device& device, const std::vector<const Blas*>& blases,
                 const std::vector<VkDeviceSize>& offsets)
      : device_(device),
        records(device.CreateBuffer(1024, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR)),
        pointers(device.CreateBuffer(sizeof(VkDeviceAddress) * 4,
                                     VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR)) {
    std::memset(records.mapped, 0, 1024);
    std::memset(pointers.mapped, 0, sizeof(VkDeviceAddress) * 4);
    for (size_t i = 0; i < blases.size(); ++i) {
      const VkAccelerationStructureInstanceKHR instance =
          InstanceRecord(blases[i]->address(), static_cast<uint32_t>(i));
      std::memcpy(static_cast<unsigned char*>(records.mapped) + offsets[i], &instance, sizeof(instance));
      const VkDeviceAddress pointer = records.address + offsets[i];
      std::memcpy(static_cast<unsigned char*>(pointers.mapped) + i * sizeof(pointer), &pointer, sizeof(pointer));
    }
  }
  ~PointedRecords() {
    device_.Destroy(pointers);
    device_.Destroy(records);
  }
  vkkit::Device& device_;
  vkkit::Buffer records;
  vkkit::Buffer pointers;
};

TEST_CASE(
    "capture on the test driver: an indirect top-level build from an array of instance pointers holding a "
    "pointer not aligned to 16 bytes is reported (pInfos-03717)",
    "[integration][capture][test-driver][03717][passes-invalid-down]") {
  const OnTestDriver driver;
  HistoryFixture f(nullptr, Reduced(), IndirectBuild());
  IndirectRig rig(f.device());
  rig.Build(Triangles());
  IndirectTlas top(rig.device());
  // Instance 1's record 8 bytes past a 16-byte boundary (still aligned for the record's own members).
  const PointedRecords pointed(rig.device(), {&rig.blas(), &rig.blas()}, {0, 128 + 8});
  top.Build(pointed.pointers, 2, true);
  CHECK(OnlyFinding(f.monitor(), kMisalignedPointer, "1 pointer(s) are not aligned to 16 bytes: instance 1 at") == "");
}

TEST_CASE(
    "capture valid twin on the test driver: indirect top-level builds from arrays of instance pointers naming "
    "live records stay silent; only the range info's count of pointers is read",
    "[integration][capture][test-driver][valid]") {
  const OnTestDriver driver;
  HistoryFixture f(nullptr, Reduced(), IndirectBuild());
  TopLevelRig made(f.device());
  auto& [rig, gone, top] = made;
  const PointedRecords pointed(rig.device(), {&rig.blas(), &rig.blas(), &gone}, {0, 128, 256 + 8});
  top.Build(pointed.pointers, 2, true);
  CHECK(f.monitor().Verify() == "");
  // The misaligned pointer and the stale record lie past the range info's count.
  gone.DestroyHandle();
  top.Build(pointed.pointers, 2, true);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "capture on the test driver: where the capture copies on a GPU, an indirect update's geometry is read by the "
    "layer's dispatch (pInfos-03664)",
    "[integration][capture][test-driver][03664]") {
  const OnTestDriver driver;
  // The test driver says it is a GPU: asval's capture then copies the direct builds' inputs (capture_method=copy)
  // and still reads what the indirect builds' range infos select with its dispatch.
  const ScopedEnvironment gpu("ASVAL_TEST_DRIVER_DEVICE_TYPE", "integrated-gpu");
  HistoryFixture f(nullptr, {{"capture_method", "copy"}}, IndirectBuild());
  IndirectRig rig(f.device());
  rig.Build(Triangles());
  REQUIRE(f.monitor().Verify() == "");
  CHECK(Probe(rig, f.monitor(), Triangles()) == "");
}

TEST_CASE(
    "capture on the test driver: where the layer has no dispatch (capture_method=copy on a CPU device), an "
    "indirect update's geometry is not judged, never guessed",
    "[integration][capture][test-driver]") {
  if (CaptureReducedRun()) SKIP("capture_method=reduce: the layer's dispatch reads the geometry");
  const OnTestDriver driver;
  HistoryFixture f(nullptr, {{"capture_method", "copy"}}, IndirectBuild());
  IndirectRig rig(f.device());
  rig.Build(Triangles());
  rig.SetRanges({IndirectRig::ShapeRange(Triangles())});
  rig.Run([&](VkCommandBuffer cb) {
    rig.Fill(cb, Component(0, 0), kNan);
    rig.Record(cb, Triangles(), VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);
  });
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test
