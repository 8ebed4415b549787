// Family "handles": live source and destination structures of the right type, distinct within one command,
// on buffers bound to memory. Indirect and host builds are only recorded or called with an expected finding
// (lavapipe has neither); their valid twins are unit tests (tests/unit/record_checks_unit_test.cpp).
#include <catch2/catch_test_macros.hpp>

#include "record_checks_helpers.h"

namespace asval_test {
namespace {

constexpr PerCommand kDstValid = {"VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03800",
                                  "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-dstAccelerationStructure-03800",
                                  "VUID-vkBuildAccelerationStructuresKHR-dstAccelerationStructure-03800"};
constexpr PerCommand kSrcValid = {"VUID-vkCmdBuildAccelerationStructuresKHR-srcAccelerationStructure-04629",
                                  "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-srcAccelerationStructure-04629",
                                  "VUID-vkBuildAccelerationStructuresKHR-srcAccelerationStructure-04629"};
constexpr PerCommand kTopType = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03699",
                                 "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03699",
                                 "VUID-vkBuildAccelerationStructuresKHR-pInfos-03699"};
constexpr PerCommand kBottomType = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03700",
                                    "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03700",
                                    "VUID-vkBuildAccelerationStructuresKHR-pInfos-03700"};
constexpr PerCommand kSharedDst = {"VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03698",
                                   "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-dstAccelerationStructure-03698",
                                   "VUID-vkBuildAccelerationStructuresKHR-dstAccelerationStructure-03698"};
constexpr PerCommand kSrcIsOtherDst = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03403",
                                       "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03403",
                                       "VUID-vkBuildAccelerationStructuresKHR-pInfos-03403"};
constexpr PerCommand kDstBound = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03707",
                                  "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03707", nullptr};
constexpr PerCommand kSrcBound = {"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03708",
                                  "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-pInfos-03708", nullptr};

constexpr Command kDeviceCommands[] = {Command::kDirect, Command::kIndirect};

// A bottom-level build of one triangle with its own destination and scratch.
struct TriangleInfo {
  explicit TriangleInfo(Scene& scene) : geometry(scene.Triangles()) {
    info = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {geometry});
    info.pGeometries = &geometry;
    scene.Prepare(info, {1});
  }
  TriangleInfo(const TriangleInfo& other) : geometry(other.geometry), info(other.info) { info.pGeometries = &geometry; }
  VkAccelerationStructureGeometryKHR geometry;
  VkAccelerationStructureBuildGeometryInfoKHR info;
};

// A structure over a buffer that has no memory (created, never bound); destroyed with the object.
struct UnboundStructure {
  UnboundStructure(vkkit::Device& d, VkAccelerationStructureTypeKHR type) : device(d) {
    VkBufferCreateInfo buffer_info{VK_STRUCTURE_TYPE_BUFFER_CREATE_INFO};
    buffer_info.size = 1 << 16;
    buffer_info.usage = VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_STORAGE_BIT_KHR | VK_BUFFER_USAGE_SHADER_DEVICE_ADDRESS_BIT;
    vkkit::Check(vkCreateBuffer(device.handle(), &buffer_info, nullptr, &buffer), "vkCreateBuffer");
    VkAccelerationStructureCreateInfoKHR info{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_CREATE_INFO_KHR};
    info.buffer = buffer;
    info.size = buffer_info.size;
    info.type = type;
    vkkit::Check(device.CreateAccelerationStructureKHR(device.handle(), &info, nullptr, &handle),
                 "vkCreateAccelerationStructureKHR");
  }
  // Gives the buffer memory (after the structure's creation, which the spec allows).
  void Bind() {
    VkMemoryRequirements req;
    vkGetBufferMemoryRequirements(device.handle(), buffer, &req);
    VkPhysicalDeviceMemoryProperties props;
    vkGetPhysicalDeviceMemoryProperties(gpu, &props);
    uint32_t type = 0;
    while (!(req.memoryTypeBits & (1u << type))) ++type;
    VkMemoryAllocateFlagsInfo flags{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_FLAGS_INFO};
    flags.flags = VK_MEMORY_ALLOCATE_DEVICE_ADDRESS_BIT;
    VkMemoryAllocateInfo alloc{VK_STRUCTURE_TYPE_MEMORY_ALLOCATE_INFO, &flags};
    alloc.allocationSize = req.size;
    alloc.memoryTypeIndex = type;
    vkkit::Check(vkAllocateMemory(device.handle(), &alloc, nullptr, &memory), "vkAllocateMemory");
    vkkit::Check(vkBindBufferMemory(device.handle(), buffer, memory, 0), "vkBindBufferMemory");
  }
  ~UnboundStructure() {
    device.DestroyAccelerationStructureKHR(device.handle(), handle, nullptr);
    vkDestroyBuffer(device.handle(), buffer, nullptr);
    if (memory) vkFreeMemory(device.handle(), memory, nullptr);
  }
  vkkit::Device& device;
  VkPhysicalDevice gpu = VK_NULL_HANDLE;
  VkBuffer buffer = VK_NULL_HANDLE;
  VkDeviceMemory memory = VK_NULL_HANDLE;
  VkAccelerationStructureKHR handle = VK_NULL_HANDLE;
};

// The handle of a structure that was live once, destroyed (with its buffer) before the build.
VkAccelerationStructureKHR DestroyedStructure(vkkit::Device& device) {
  vkkit::AccelerationStructure as = device.CreateAccelerationStructure(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, 4096);
  const VkAccelerationStructureKHR handle = as.handle;
  device.Destroy(as);
  return handle;
}

TEST_CASE("03800: a destination that is not a live structure is reported by all three commands",
          "[integration][handles][03800]") {
  CheckFixture f("handles");
  Scene scene(f.device());
  TriangleInfo t(scene);
  const VkAccelerationStructureKHR destroyed = DestroyedStructure(f.device());
  const auto ranges = Ranges(1);
  for (VkAccelerationStructureKHR dst : {destroyed, VkAccelerationStructureKHR(VK_NULL_HANDLE)}) {
    t.info.dstAccelerationStructure = dst;
    for (Command command : kAllCommands) {
      INFO(CommandName(command) << " dst " << dst);
      f.monitor().Expect(kDstValid.For(command));
      IssueOne(f.device(), command, t.info, ranges.data());
      CHECK(f.monitor().Verify() == "");
    }
  }
}

TEST_CASE("04629: a source that is not a live structure is reported by all three commands",
          "[integration][handles][04629]") {
  CheckFixture f("handles");
  Scene scene(f.device());
  TriangleInfo t(scene);
  const VkAccelerationStructureKHR destroyed = DestroyedStructure(f.device());
  t.info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  t.info.srcAccelerationStructure = destroyed;
  const auto ranges = Ranges(1);
  for (Command command : kAllCommands) {
    INFO(CommandName(command));
    f.monitor().Expect(kSrcValid.For(command));
    IssueOne(f.device(), command, t.info, ranges.data());
    CHECK(f.monitor().Verify() == "");
  }
}

TEST_CASE("03800 and 04629 valid twin: live destinations and sources stay silent", "[integration][handles][03800][04629]") {
  CheckFixture f;
  Scene scene(f.device());
  TriangleInfo t(scene);
  const auto ranges = Ranges(1);
  scene.BuildNow({t.info}, {ranges.data()});
  t.info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  t.info.srcAccelerationStructure = t.info.dstAccelerationStructure;
  scene.BuildNow({t.info}, {ranges.data()});
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("03699 and 03700: a build into a structure created with the other level is reported by all three commands",
          "[integration][handles][03699][03700]") {
  CheckFixture f("handles");
  Scene scene(f.device());
  const auto ranges = Ranges(1);
  VkAccelerationStructureGeometryKHR instances = scene.Instances();
  VkAccelerationStructureBuildGeometryInfoKHR top = Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, {instances});
  top.pGeometries = &instances;
  scene.Prepare(top, {1}, VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  TriangleInfo bottom(scene);
  bottom.info.dstAccelerationStructure = scene.NewStructure(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, 1 << 16);
  for (Command command : kAllCommands) {
    INFO(CommandName(command));
    f.monitor().Expect(kTopType.For(command));
    IssueOne(f.device(), command, top, ranges.data());
    std::vector<Message> messages = f.monitor().Take();
    REQUIRE(messages.size() == 1);
    CHECK(messages[0].id_name == kTopType.For(command));
    CHECK(messages[0].text.find("VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR") != std::string::npos);
    f.monitor().Expect(kBottomType.For(command));
    IssueOne(f.device(), command, bottom.info, ranges.data());
    CHECK(f.monitor().Verify() == "");
  }
}

TEST_CASE("03699 and 03700 valid twin: structures created as generic or with the build's level stay silent",
          "[integration][handles][03699][03700]") {
  CheckFixture f;
  Scene scene(f.device());
  const auto ranges = Ranges(1);
  for (VkAccelerationStructureTypeKHR created :
       {VK_ACCELERATION_STRUCTURE_TYPE_GENERIC_KHR, VK_ACCELERATION_STRUCTURE_TYPE_MAX_ENUM_KHR /* the build's */}) {
    VkAccelerationStructureGeometryKHR triangles = scene.Triangles();
    VkAccelerationStructureBuildGeometryInfoKHR bottom =
        Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR, {triangles});
    bottom.pGeometries = &triangles;
    scene.Prepare(bottom, {1}, created);
    VkAccelerationStructureGeometryKHR instances = scene.Instances();
    VkAccelerationStructureBuildGeometryInfoKHR top =
        Scene::Info(VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR, {instances});
    top.pGeometries = &instances;
    scene.Prepare(top, {1}, created);
    scene.BuildNow({bottom}, {ranges.data()});
    scene.BuildNow({top}, {ranges.data()});
    CHECK(f.monitor().Verify() == "");
  }
}

TEST_CASE("03698 and 03403: one structure written twice, or read by one info and written by another, is reported "
          "by all three commands",
          "[integration][handles][03698][03403]") {
  CheckFixture f("handles");
  Scene scene(f.device());
  TriangleInfo a(scene), b(scene), c(scene);
  const auto ranges = Ranges(1);
  const std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> three(3, ranges.data());
  for (Command command : kAllCommands) {
    INFO(CommandName(command));
    // c writes a's destination.
    TriangleInfo c_into_a = c;
    c_into_a.info.dstAccelerationStructure = a.info.dstAccelerationStructure;
    f.monitor().Expect(kSharedDst.For(command));
    Issue(f.device(), command, {a.info, b.info, c_into_a.info}, three);
    std::vector<Message> messages = f.monitor().Take();
    REQUIRE(messages.size() == 1);
    CHECK(messages[0].text.find("pInfos[2].dstAccelerationStructure") != std::string::npos);
    CHECK(messages[0].text.find("of pInfos[0]") != std::string::npos);
    // b updates from a's destination while a builds it.
    TriangleInfo b_reads_a = b;
    b_reads_a.info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
    b_reads_a.info.srcAccelerationStructure = a.info.dstAccelerationStructure;
    f.monitor().Expect(kSrcIsOtherDst.For(command));
    Issue(f.device(), command, {a.info, b_reads_a.info}, {ranges.data(), ranges.data()});
    CHECK(f.monitor().Verify() == "");
  }
}

TEST_CASE("03698 and 03403 valid twin: 64 builds, then 64 in-place updates, in one call each, stay silent",
          "[integration][handles][03698][03403]") {
  CheckFixture f;
  Scene scene(f.device());
  std::vector<TriangleInfo> builds;
  builds.reserve(64);
  for (int k = 0; k < 64; ++k) builds.emplace_back(scene);
  std::vector<VkAccelerationStructureBuildGeometryInfoKHR> infos;
  for (TriangleInfo& t : builds) infos.push_back(t.info);
  const auto ranges = Ranges(1);
  const std::vector<const VkAccelerationStructureBuildRangeInfoKHR*> range_pointers(64, ranges.data());
  scene.BuildNow(infos, range_pointers);
  CHECK(f.monitor().Verify() == "");
  for (VkAccelerationStructureBuildGeometryInfoKHR& info : infos) {
    info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
    info.srcAccelerationStructure = info.dstAccelerationStructure;
  }
  scene.BuildNow(infos, range_pointers);
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("03707 and 03708: a destination, or an update's source, on a buffer without memory is reported",
          "[integration][handles][03707][03708]") {
  CheckFixture f("handles");
  Scene scene(f.device());
  TriangleInfo t(scene);
  UnboundStructure unbound(f.device(), VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  const auto ranges = Ranges(1);
  for (Command command : kDeviceCommands) {
    INFO(CommandName(command));
    TriangleInfo into_unbound = t;
    into_unbound.info.dstAccelerationStructure = unbound.handle;
    f.monitor().Expect(kDstBound.For(command));
    IssueOne(f.device(), command, into_unbound.info, ranges.data());
    std::vector<Message> messages = f.monitor().Take();
    REQUIRE(messages.size() == 1);
    CHECK(messages[0].text.find("not bound to device memory") != std::string::npos);

    TriangleInfo from_unbound = t;
    from_unbound.info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
    from_unbound.info.srcAccelerationStructure = unbound.handle;
    f.monitor().Expect(kSrcBound.For(command));
    IssueOne(f.device(), command, from_unbound.info, ranges.data());
    CHECK(f.monitor().Verify() == "");
  }
}

TEST_CASE("03707 and 03708 valid twin: a structure whose buffer got memory after its creation stays silent",
          "[integration][handles][03707][03708]") {
  CheckFixture f;
  Scene scene(f.device());
  TriangleInfo t(scene);
  UnboundStructure late(f.device(), VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR);
  late.gpu = f.instance().FindRayTracingGpu();
  late.Bind();
  t.info.dstAccelerationStructure = late.handle;
  const auto ranges = Ranges(1);
  scene.BuildNow({t.info}, {ranges.data()});
  t.info.mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR;
  t.info.srcAccelerationStructure = late.handle;
  scene.BuildNow({t.info}, {ranges.data()});
  CHECK(f.monitor().Verify() == "");
}

}  // namespace
}  // namespace asval_test
