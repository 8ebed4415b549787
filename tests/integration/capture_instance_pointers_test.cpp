// Execution-time capture of top-level builds whose instances are given as an array of pointers
// (geometry.instances.arrayOfPointers), in two stages: the pointers the device reads when the build executes, each
// held to 16-byte alignment (pInfos-03717), then the records they point to, gathered by the layer's dispatch right
// before the build, and judged exactly as a plain array of the same records: references (pInfos-06707, 03709) and,
// for updates, activity (pInfos-03663, 03664), whichever layout the update's source used. The pointers are written on
// the device (vkCmdUpdateBuffer) in the command buffer of the build, so only the capture can know them.
//
// The gathering dispatch runs where the capture reduces, and where it copies on a device that is not a CPU
// (CaptureGathers): these tests ask for capture_method=reduce, which lavapipe runs; with `copy` on lavapipe the
// records are not gathered (lavapipe loses the app's compute state when the layer binds its pipeline, capture.md),
// skipped and counted, never guessed.
//
// As in capture_instances_test.cpp, a "stale" reference is the address of a structure whose handle was destroyed
// while its storage stays allocated (lavapipe reads the structures instances reference on the CPU).
#include <catch2/catch_test_macros.hpp>

#include <cstdio>
#include <cstring>
#include <functional>
#include <string>
#include <utility>
#include <vector>

#include "capture_helpers.h"
#include "history_helpers.h"

namespace asval_test {
namespace {

constexpr const char* kMisalignedPointer = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03717";
constexpr const char* kStaleReference = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-06707";
constexpr const char* kStorageNotBound = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03709";
constexpr const char* kBecameActive = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03663";
constexpr const char* kBecameInactive = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03664";
constexpr VkDeviceSize kInstanceBytes = sizeof(VkAccelerationStructureInstanceKHR);  // 64
constexpr uint32_t kMaxInstances = 4;                                                // the helpers' Tlas
constexpr uint32_t kRecordSlots = 8;
// Room for kRecordSlots records at 16-aligned offsets, and one 8 bytes past the last of them.
constexpr VkDeviceSize kRecordsBytes = kInstanceBytes * kRecordSlots + 16;

// The layer's dispatch gathers the records (lavapipe's default, copy, does not: CaptureGathers).
std::vector<std::pair<const char*, const char*>> Gathering() { return {{"capture_method", "reduce"}}; }

std::string HexAddress(VkDeviceAddress address) {
  char text[32];
  std::snprintf(text, sizeof(text), "0x%llx", static_cast<unsigned long long>(address));
  return text;
}

// Bottom-level structures a and b (alive) and `victim` (its handle destroyed by Stale(), its storage kept), a
// top-level structure, a buffer of instance records (written on the host) and a buffer of pointers to them (written
// on the device, in the command buffer of the build).
class Rig {
 public:
  explicit Rig(HistoryFixture& f)
      : device_(f.device()), inputs_(device_), a_(device_, inputs_), b_(device_, inputs_), victim_(device_, inputs_),
        tlas_(device_), commands_(device_) {
    records_ =
        device_.CreateBuffer(kRecordsBytes, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
    pointers_ = device_.CreateBuffer(sizeof(VkDeviceAddress) * kMaxInstances,
                                     VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                                         VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    std::memset(records_.mapped, 0, kRecordsBytes);
    Run([&](VkCommandBuffer cb) {
      a_.Build(cb, Shape{});
      b_.Build(cb, Shape{});
      victim_.Build(cb, Shape{});
    });
  }
  ~Rig() {
    device_.Destroy(pointers_);
    device_.Destroy(records_);
  }
  Rig(const Rig&) = delete;
  Rig& operator=(const Rig&) = delete;

  Blas& a() { return a_; }
  Blas& b() { return b_; }
  // Destroys the victim's handle (its storage stays) and returns its old address.
  VkDeviceAddress Stale() {
    victim_.DestroyHandle();
    return victim_.address();
  }

  // Writes, on the host, a record referencing `reference` (0: inactive) at byte `offset` of the records buffer
  // (instance i: 4 units along X); returns its address.
  VkDeviceAddress Record(VkDeviceSize offset, uint32_t i, VkDeviceAddress reference) {
    VkAccelerationStructureInstanceKHR instance{};
    instance.transform.matrix[0][0] = instance.transform.matrix[1][1] = instance.transform.matrix[2][2] = 1.0f;
    instance.transform.matrix[0][3] = static_cast<float>(i) * 4.0f;
    instance.mask = 0xff;
    instance.accelerationStructureReference = reference;
    std::memcpy(static_cast<unsigned char*>(records_.mapped) + offset, &instance, sizeof(instance));
    return records_.address + offset;
  }
  // Record slot s (a 16-aligned place), as Record.
  VkDeviceAddress Slot(uint32_t s, uint32_t i, VkDeviceAddress reference) {
    return Record(kInstanceBytes * s, i, reference);
  }

  void Run(const std::function<void(VkCommandBuffer)>& record) {
    SubmitAndWait(device_, RecordWith(commands_, record));
  }

  // The pointers written on the device, then the top-level build (or update in place) from them.
  void Build(const std::vector<VkDeviceAddress>& pointers,
             VkBuildAccelerationStructureModeKHR mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR) {
    Run([&](VkCommandBuffer cb) {
      vkCmdUpdateBuffer(cb, pointers_.buffer, 0, pointers.size() * sizeof(VkDeviceAddress), pointers.data());
      InputsWritten(cb);
      BuildInfo b = tlas_.Info(pointers_, static_cast<uint32_t>(pointers.size()), mode);
      b.geometries[0].geometry.instances.arrayOfPointers = VK_TRUE;
      RecordBuilds(device_, cb, {&b});
    });
  }
  void Update(const std::vector<VkDeviceAddress>& pointers) {
    Build(pointers, VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);
  }
  // The top-level build (or update) from the first `count` record slots as a plain array (arrayOfPointers false).
  void BuildPlain(uint32_t count,
                  VkBuildAccelerationStructureModeKHR mode = VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR) {
    Run([&](VkCommandBuffer cb) {
      InputsWritten(cb);
      tlas_.Record(cb, records_, count, mode);
    });
  }

 private:
  vkkit::Device& device_;
  Inputs inputs_;
  Blas a_;
  Blas b_;
  Blas victim_;
  Tlas tlas_;
  Commands commands_;
  vkkit::Buffer records_;
  vkkit::Buffer pointers_;
};

}  // namespace

TEST_CASE("capture: an array of instance pointers holding a pointer not aligned to 16 bytes is reported (pInfos-03717)",
          "[integration][capture][passes-invalid-down]") {
  SECTION("capture_method as the run has it") {
    HistoryFixture f;
    Rig rig(f);
    // Instance 1's record 8 bytes past a 16-byte boundary (still aligned for the record's own members).
    rig.Build({rig.Slot(0, 0, rig.a().address()), rig.Record(kInstanceBytes * kRecordSlots + 8, 1, rig.a().address())});
    CHECK(OnlyFinding(f.monitor(), kMisalignedPointer, "1 pointer(s) are not aligned to 16 bytes: instance 1 at") ==
          "");
  }
  SECTION("gathered: the misaligned pointer is not followed, the aligned one's record is judged") {
    HistoryFixture f(nullptr, Gathering());
    Rig rig(f);
    const VkDeviceAddress stale = rig.Stale();
    rig.Build({rig.Slot(0, 0, stale), rig.Record(kInstanceBytes * kRecordSlots + 8, 1, rig.a().address())});
    const std::vector<Message> messages = f.monitor().Take();
    std::string seen;
    for (const Message& m : messages) seen += m.id_name + ": " + m.text + "\n";
    INFO(seen);
    REQUIRE(messages.size() == 2);
    int misaligned = 0, stale_named = 0;
    for (const Message& m : messages) {
      misaligned += m.id_name == kMisalignedPointer && m.text.find("instance 1 at") != std::string::npos;
      stale_named += m.id_name == kStaleReference &&
                     m.text.find("instance 0 references " + HexAddress(stale)) != std::string::npos;
    }
    CHECK(misaligned == 1);
    CHECK(stale_named == 1);
  }
}

TEST_CASE("capture: a record named by an array of instance pointers referencing a destroyed structure is reported "
          "(pInfos-06707)",
          "[integration][capture]") {
  HistoryFixture f(nullptr, Gathering());
  Rig rig(f);
  const VkDeviceAddress stale = rig.Stale();
  // Records out of order: the message names the instance (the pointer's index), not where its record lies.
  SECTION("a build") {
    rig.Build({rig.Slot(3, 0, rig.a().address()), rig.Slot(1, 1, stale), rig.Slot(5, 2, rig.b().address())});
  }
  SECTION("the pointers rewritten between recording and execution: the records the device read are judged") {
    rig.Build({rig.Slot(3, 0, rig.a().address()), rig.Slot(5, 1, rig.b().address())});
    CHECK(f.monitor().Verify() == "");
    rig.Build({rig.Slot(3, 0, rig.a().address()), rig.Slot(1, 1, stale), rig.Slot(5, 2, rig.b().address())});
  }
  CHECK(OnlyFinding(f.monitor(), kStaleReference,
                    "geometry 0: 1 instance(s) reference no acceleration structure that was alive when the build was "
                    "submitted (not 0 and not an address vkGetAccelerationStructureDeviceAddressKHR returned for a "
                    "live structure): instance 1 references " +
                        HexAddress(stale)) == "");
}

TEST_CASE("capture: a record named by an array of instance pointers referencing a structure whose buffer was "
          "destroyed is reported (pInfos-03709)",
          "[integration][capture][passes-invalid-down]") {
  HistoryFixture f(nullptr, Gathering());
  Rig rig(f);
  // b's VkBuffer is destroyed; b itself and its memory stay (lavapipe still reads the bytes there).
  rig.b().DestroyStorageBuffer();
  rig.Build({rig.Slot(2, 0, rig.a().address()), rig.Slot(0, 1, rig.b().address())});
  CHECK(OnlyFinding(f.monitor(), kStorageNotBound, "geometry 0, instance 1 references") == "");
}

TEST_CASE("capture: a top-level update through an array of instance pointers that changes an instance's activity is "
          "reported (pInfos-03663, 03664), whichever layout its source used",
          "[integration][capture]") {
  HistoryFixture f(nullptr, Gathering());
  Rig rig(f);
  const VkDeviceAddress a = rig.a().address();
  const VkDeviceAddress b = rig.b().address();
  SECTION("active to inactive: the update's pointer names an inactive record") {
    rig.Build({rig.Slot(0, 0, a), rig.Slot(1, 1, b)});
    CHECK(f.monitor().Verify() == "");
    rig.Update({rig.Slot(0, 0, a), rig.Slot(4, 1, 0)});
    CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 1") == "");
  }
  SECTION("inactive to active") {
    rig.Build({rig.Slot(0, 0, 0), rig.Slot(1, 1, b)});
    CHECK(f.monitor().Verify() == "");
    rig.Update({rig.Slot(4, 0, a), rig.Slot(1, 1, b)});
    CHECK(OnlyFinding(f.monitor(), kBecameActive, ": primitive 0") == "");
  }
  SECTION("a source built from a plain array, updated through pointers") {
    rig.Slot(0, 0, a);
    rig.Slot(1, 1, b);
    rig.BuildPlain(2);
    CHECK(f.monitor().Verify() == "");
    rig.Update({rig.Slot(0, 0, a), rig.Slot(4, 1, 0)});
    CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 1") == "");
  }
  SECTION("a source built through pointers, updated from a plain array") {
    rig.Build({rig.Slot(4, 0, a), rig.Slot(5, 1, b)});
    CHECK(f.monitor().Verify() == "");
    rig.Slot(0, 0, 0);
    rig.Slot(1, 1, b);
    rig.BuildPlain(2, VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);
    CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 0") == "");
  }
}

TEST_CASE("capture valid twin: arrays of instance pointers naming live records, and updates keeping each instance's "
          "activity, stay silent",
          "[integration][capture]") {
  HistoryFixture f(nullptr, Gathering());
  Rig rig(f);
  const VkDeviceAddress a = rig.a().address();
  const VkDeviceAddress b = rig.b().address();
  SECTION("a build, inactive records among them") {
    rig.Build({rig.Slot(3, 0, a), rig.Slot(1, 1, 0), rig.Slot(5, 2, b)});
  }
  SECTION("a build, then updates that swap the pointers or move to other records of the same activity") {
    const VkDeviceAddress first = rig.Slot(0, 0, a);
    const VkDeviceAddress second = rig.Slot(1, 1, b);
    rig.Build({first, second});
    rig.Update({second, first});
    rig.Update({rig.Slot(6, 0, b), rig.Slot(7, 1, a)});
  }
  SECTION("a plain array's source updated through pointers to the same records, and back") {
    const VkDeviceAddress first = rig.Slot(0, 0, a);
    const VkDeviceAddress second = rig.Slot(1, 1, 0);
    rig.BuildPlain(2);
    rig.Update({first, second});
    rig.BuildPlain(2, VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);
  }
  // No probe of a misaligned pointer here: this twin also runs on the GPU machine, which must not get one.
  CHECK(f.monitor().Verify() == "");
  // The checks are live on this device: an update whose second record is now inactive is reported.
  rig.Build({rig.Slot(2, 0, a), rig.Slot(3, 1, b)});
  rig.Update({rig.Slot(2, 0, a), rig.Slot(4, 1, 0)});
  CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 1") == "");
}

TEST_CASE("capture: where the layer does not gather (capture_method=copy on a CPU device), the records of arrays of "
          "instance pointers are not judged, never guessed",
          "[integration][capture]") {
  HistoryFixture f(nullptr, {{"capture_method", "copy"}});
  Rig rig(f);
  VkPhysicalDeviceProperties properties{};
  vkGetPhysicalDeviceProperties(f.instance().FindRayTracingGpu(), &properties);
  // integration_capture_reduce forces reduce; a device that is not a CPU gathers where the capture copies.
  const bool gathers = CaptureReducedRun() || properties.deviceType != VK_PHYSICAL_DEVICE_TYPE_CPU;
  const VkDeviceAddress stale = rig.Stale();
  rig.Build({rig.Slot(0, 0, rig.a().address()), rig.Slot(1, 1, stale)});
  if (gathers) {
    CHECK(OnlyFinding(f.monitor(), kStaleReference, "instance 1 references " + HexAddress(stale)) == "");
  } else {
    CHECK(f.monitor().Verify() == "");
  }
}

}  // namespace asval_test
