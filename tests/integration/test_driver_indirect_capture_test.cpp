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
#include "on_test_driver.h"

namespace asval_test {
namespace {

constexpr const char* kBecameActive = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03663";
constexpr const char* kBecameInactive = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03664";
constexpr const char* kIndicesChanged = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03768";
constexpr const char* kStaleReference = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-12281";
constexpr const char* kStorageNotBound = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03709";
constexpr const char* kMisalignedPointer = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03717";
constexpr const char* kReferencedDestination = "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-None-03407";

constexpr uint32_t kNan = 0x7fc00000u;
constexpr VkDeviceSize kVertexBytes = 12;  // R32G32B32_SFLOAT, tightly packed (the helpers' vertexStride)

uint32_t Bits(float value) {
  uint32_t bits;
  std::memcpy(&bits, &value, sizeof(bits));
  return bits;
}

// Where component c (0: X) of vertex v lies in the inputs buffer.
VkDeviceSize Component(uint32_t v, uint32_t c) { return Inputs::kVerticesOffset + kVertexBytes * v + 4 * c; }

// Six vertices: triangles (0, 1, 2) and (3, 4, 5), unit right triangles at z = 0 and z = 1, moved by dx along X.
std::vector<uint32_t> Vertices(float dx = 0) {
  const float corner[3][2] = {{0, 0}, {1, 0}, {0, 1}};
  std::vector<uint32_t> words;
  for (uint32_t v = 0; v < 6; ++v) {
    words.push_back(Bits(corner[v % 3][0] + dx));
    words.push_back(Bits(corner[v % 3][1]));
    words.push_back(Bits(static_cast<float>(v / 3)));
  }
  return words;
}

Shape Triangles(uint32_t count = 2) {
  Shape s;
  s.triangles = count;
  return s;
}

std::vector<std::pair<const char*, const char*>> Reduced() { return {{"capture_method", "reduce"}}; }

vkkit::DeviceOptions IndirectBuild() {
  vkkit::DeviceOptions options;
  options.indirect_build = true;
  return options;
}

// A structure over inputs the device writes, built and updated by indirect builds whose range infos (one per
// geometry of the shape) lie in an INDIRECT_BUFFER the test writes from the host before each submission.
class IndirectRig {
 public:
  explicit IndirectRig(HistoryFixture& f)
      : device_(f.device()),
        inputs_(device_, VK_BUFFER_USAGE_TRANSFER_DST_BIT),
        blas_(device_, inputs_),
        commands_(device_),
        ranges_(device_.CreateBuffer(16 * sizeof(VkAccelerationStructureBuildRangeInfoKHR),
                                     VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT)),
        indirect_(reinterpret_cast<PFN_vkCmdBuildAccelerationStructuresIndirectKHR>(
            vkGetDeviceProcAddr(device_.handle(), "vkCmdBuildAccelerationStructuresIndirectKHR"))) {}
  ~IndirectRig() { device_.Destroy(ranges_); }

  vkkit::Device& device() { return device_; }
  Blas& blas() { return blas_; }
  const Inputs& inputs() const { return inputs_; }

  void Write(VkCommandBuffer cb, VkDeviceSize offset, const std::vector<uint32_t>& words) {
    vkCmdUpdateBuffer(cb, inputs_.buffer().buffer, offset, words.size() * sizeof(uint32_t), words.data());
  }
  void Fill(VkCommandBuffer cb, VkDeviceSize offset, uint32_t word) {
    vkCmdFillBuffer(cb, inputs_.buffer().buffer, offset, sizeof(uint32_t), word);
  }

  // The range infos the next indirect build reads, geometry j's at j * 16 (written now: the submission comes later).
  void SetRanges(const std::vector<VkAccelerationStructureBuildRangeInfoKHR>& ranges) {
    std::memcpy(ranges_.mapped, ranges.data(), ranges.size() * sizeof(ranges[0]));
  }

  // One indirect build (or update in place) of the shape's info, the writes recorded before it made visible;
  // `max_count` is every geometry's ppMaxPrimitiveCounts (0: the shape's triangles).
  void Record(VkCommandBuffer cb, const Shape& shape, VkBuildAccelerationStructureModeKHR mode,
              uint32_t max_count = 0) {
    InputsWritten(cb);
    const BuildInfo built = blas_.Info(shape, mode);
    const std::vector<uint32_t> max_counts(built.info.geometryCount, max_count != 0 ? max_count : shape.triangles);
    const uint32_t* counts = max_counts.data();
    const uint32_t stride = sizeof(VkAccelerationStructureBuildRangeInfoKHR);
    indirect_(cb, 1, &built.info, &ranges_.address, &stride, &counts);
  }

  // Records `record` into a new command buffer, submits it and waits for it.
  void Run(const std::function<void(VkCommandBuffer)>& record) {
    SubmitAndWait(device_, RecordWith(commands_, record));
  }

  // A build of the shape with `vertices` written first, its ranges the shape's own.
  void Build(const Shape& shape, const std::vector<uint32_t>& vertices = Vertices()) {
    SetRanges({ShapeRange(shape)});
    Run([&](VkCommandBuffer cb) {
      Write(cb, Component(0, 0), vertices);
      Record(cb, shape, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
    });
  }

  static VkAccelerationStructureBuildRangeInfoKHR ShapeRange(const Shape& shape) {
    return VkAccelerationStructureBuildRangeInfoKHR{shape.triangles, shape.primitive_offset, shape.first_vertex, 0};
  }

 private:
  vkkit::Device& device_;
  Inputs inputs_;
  Blas blas_;
  Commands commands_;
  vkkit::Buffer ranges_;
  PFN_vkCmdBuildAccelerationStructuresIndirectKHR indirect_;
};

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
  IndirectRig rig(f);
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
  IndirectRig rig(f);
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
  IndirectRig rig(f);
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
  IndirectRig rig(f);
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

TEST_CASE(
    "capture on the test driver: an indirect build's primitives are counted from the range info's "
    "primitiveOffset and firstVertex the device read",
    "[integration][capture][test-driver][03664]") {
  const OnTestDriver driver;
  HistoryFixture f(nullptr, Reduced(), IndirectBuild());
  IndirectRig rig(f);
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

// A top-level structure built by indirect builds over instances the test writes from the host.
class IndirectTlas {
 public:
  explicit IndirectTlas(vkkit::Device& device)
      : device_(device),
        tlas_(device),
        commands_(device),
        ranges_(device.CreateBuffer(2 * sizeof(VkAccelerationStructureBuildRangeInfoKHR),
                                    VK_BUFFER_USAGE_INDIRECT_BUFFER_BIT)),
        indirect_(reinterpret_cast<PFN_vkCmdBuildAccelerationStructuresIndirectKHR>(
            vkGetDeviceProcAddr(device.handle(), "vkCmdBuildAccelerationStructuresIndirectKHR"))) {}
  ~IndirectTlas() { device_.Destroy(ranges_); }

  // Builds the top level over `count` of the instances (the range info's count; the recorded maximum is 4), given
  // as records or (`pointers`) as an array of pointers to them.
  void Build(const vkkit::Buffer& instances, uint32_t count, bool pointers = false) {
    const VkAccelerationStructureBuildRangeInfoKHR range{count, 0, 0, 0};
    std::memcpy(ranges_.mapped, &range, sizeof(range));
    BuildInfo built = tlas_.Info(instances, 4, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
    built.geometries[0].geometry.instances.arrayOfPointers = pointers ? VK_TRUE : VK_FALSE;
    const uint32_t max_count = 4;
    const uint32_t* counts = &max_count;
    const uint32_t stride = sizeof(range);
    SubmitAndWait(device_, RecordWith(commands_, [&](VkCommandBuffer cb) {
                    indirect_(cb, 1, &built.info, &ranges_.address, &stride, &counts);
                  }));
  }
  Tlas& tlas() { return tlas_; }

  // One indirect command of two infos: pInfos[0] builds `blas` (one triangle), pInfos[1] the top level over `count`
  // of the instances.
  void BuildTogether(const Blas& blas, const vkkit::Buffer& instances, uint32_t count) {
    const VkAccelerationStructureBuildRangeInfoKHR ranges[2] = {{1, 0, 0, 0}, {count, 0, 0, 0}};
    std::memcpy(ranges_.mapped, ranges, sizeof(ranges));
    const BuildInfo bottom = blas.Info(Shape{});
    const BuildInfo top = tlas_.Info(instances, 4, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
    const VkAccelerationStructureBuildGeometryInfoKHR infos[2] = {bottom.info, top.info};
    const VkDeviceAddress addresses[2] = {ranges_.address, ranges_.address + sizeof(ranges[0])};
    const uint32_t strides[2] = {sizeof(ranges[0]), sizeof(ranges[0])};
    const uint32_t bottom_max = 1, top_max = 4;
    const uint32_t* counts[2] = {&bottom_max, &top_max};
    SubmitAndWait(device_, RecordWith(commands_, [&](VkCommandBuffer cb) {
                    indirect_(cb, 2, infos, addresses, strides, counts);
                  }));
  }

 private:
  vkkit::Device& device_;
  Tlas tlas_;
  Commands commands_;
  vkkit::Buffer ranges_;
  PFN_vkCmdBuildAccelerationStructuresIndirectKHR indirect_;
};

TEST_CASE(
    "capture on the test driver: an indirect top-level build whose instance references a destroyed "
    "structure is reported (pInfos-12281)",
    "[integration][capture][test-driver][12281][passes-invalid-down]") {
  const OnTestDriver driver;
  HistoryFixture f(nullptr, Reduced(), IndirectBuild());
  IndirectRig rig(f);
  rig.Build(Triangles());
  Blas gone(rig.device(), rig.inputs());
  rig.Run([&](VkCommandBuffer cb) { gone.Build(cb, Shape{}); });
  IndirectTlas top(rig.device());
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
  IndirectRig rig(f);
  rig.Build(Triangles());
  Blas lost(rig.device(), rig.inputs());
  rig.Run([&](VkCommandBuffer cb) { lost.Build(cb, Shape{}); });
  IndirectTlas top(rig.device());
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
  IndirectRig rig(f);
  rig.Build(Triangles());
  Blas gone(rig.device(), rig.inputs());
  rig.Run([&](VkCommandBuffer cb) { gone.Build(cb, Shape{}); });
  IndirectTlas top(rig.device());
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
    "destination in the same command is reported (None-03407)",
    "[integration][capture][test-driver][03407][passes-invalid-down]") {
  const OnTestDriver driver;
  HistoryFixture f(nullptr, Reduced(), IndirectBuild());
  IndirectRig rig(f);
  rig.Build(Triangles());
  Blas other(rig.device(), rig.inputs());
  rig.Run([&](VkCommandBuffer cb) { other.Build(cb, Shape{}); });
  IndirectTlas top(rig.device());
  vkkit::Buffer instances = top.tlas().MakeInstances({&rig.blas(), &other});
  top.BuildTogether(other, instances, 2);  // pInfos[0] builds `other` again; instance 1 references it
  CHECK(OnlyFinding(f.monitor(), kReferencedDestination,
                    "geometry 0, instance 1 references VkAccelerationStructureKHR") == "");
  rig.device().Destroy(instances);
}

TEST_CASE(
    "capture valid twin on the test driver: an indirect command of a bottom-level and a top-level build "
    "whose instances do not reference the other destination stays silent",
    "[integration][capture][test-driver][valid]") {
  const OnTestDriver driver;
  HistoryFixture f(nullptr, Reduced(), IndirectBuild());
  IndirectRig rig(f);
  rig.Build(Triangles());
  Blas other(rig.device(), rig.inputs());
  rig.Run([&](VkCommandBuffer cb) { other.Build(cb, Shape{}); });
  IndirectTlas top(rig.device());
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
      VkAccelerationStructureInstanceKHR instance{};
      instance.transform.matrix[0][0] = instance.transform.matrix[1][1] = instance.transform.matrix[2][2] = 1.0f;
      instance.transform.matrix[0][3] = static_cast<float>(i) * 4.0f;
      instance.mask = 0xff;
      instance.accelerationStructureReference = blases[i]->address();
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
  IndirectRig rig(f);
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
  IndirectRig rig(f);
  rig.Build(Triangles());
  Blas gone(rig.device(), rig.inputs());
  rig.Run([&](VkCommandBuffer cb) { gone.Build(cb, Shape{}); });
  IndirectTlas top(rig.device());
  const PointedRecords pointed(rig.device(), {&rig.blas(), &rig.blas(), &gone}, {0, 128, 256 + 8});
  top.Build(pointed.pointers, 2, true);
  CHECK(f.monitor().Verify() == "");
  // The misaligned pointer and the stale record lie past the range info's count.
  gone.DestroyHandle();
  top.Build(pointed.pointers, 2, true);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE(
    "capture on the test driver: where the layer has no dispatch (capture_method=copy on a CPU device), an "
    "indirect update's geometry is not judged, never guessed",
    "[integration][capture][test-driver]") {
  if (CaptureReducedRun()) SKIP("capture_method=reduce: the layer's dispatch reads the geometry");
  const OnTestDriver driver;
  HistoryFixture f(nullptr, {{"capture_method", "copy"}}, IndirectBuild());
  IndirectRig rig(f);
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
