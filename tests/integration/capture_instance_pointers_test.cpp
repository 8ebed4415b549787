// Execution-time capture of top-level builds whose instances are given as an array of pointers
// (geometry.instances.arrayOfPointers): the layer copies the pointers the device reads when the build executes and
// holds each to 16-byte alignment (pInfos-03717). The records they point to cannot be located when the copies are
// recorded: their references and activity are unknown, skipped and counted, never guessed. The pointers are written
// on the device (vkCmdUpdateBuffer) in the command buffer of the build, so only the capture can know them.
#include <catch2/catch_test_macros.hpp>

#include <cstring>
#include <functional>
#include <string>
#include <vector>

#include "capture_helpers.h"
#include "history_helpers.h"

namespace asval_test {
namespace {

constexpr const char* kMisalignedPointer = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03717";
constexpr VkDeviceSize kInstanceBytes = sizeof(VkAccelerationStructureInstanceKHR);  // 64
constexpr uint32_t kInstances = 2;
// Room for the records at 16-aligned offsets and at offsets 8 past them.
constexpr VkDeviceSize kRecordsBytes = kInstanceBytes * kInstances * 2 + 16;

// Bottom-level structure `a`, a top-level structure, a buffer of instance records of a (written on the host) and
// a buffer of pointers to them (written on the device, in the command buffer of the build).
class Rig {
 public:
  explicit Rig(HistoryFixture& f)
      : device_(f.device()), inputs_(device_), a_(device_, inputs_), tlas_(device_), commands_(device_) {
    records_ = device_.CreateBuffer(kRecordsBytes, VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR);
    pointers_ = device_.CreateBuffer(sizeof(VkDeviceAddress) * kInstances,
                                     VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                                         VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    std::memset(records_.mapped, 0, kRecordsBytes);
    Run([&](VkCommandBuffer cb) { a_.Build(cb, Shape{}); });
  }
  ~Rig() {
    device_.Destroy(pointers_);
    device_.Destroy(records_);
  }
  Rig(const Rig&) = delete;
  Rig& operator=(const Rig&) = delete;

  // The address of a record of `a` written at byte `offset` of the records buffer (instance i: 4 units along X).
  VkDeviceAddress Record(VkDeviceSize offset, uint32_t i) {
    VkAccelerationStructureInstanceKHR instance{};
    instance.transform.matrix[0][0] = instance.transform.matrix[1][1] = instance.transform.matrix[2][2] = 1.0f;
    instance.transform.matrix[0][3] = static_cast<float>(i) * 4.0f;
    instance.mask = 0xff;
    instance.accelerationStructureReference = a_.address();
    std::memcpy(static_cast<unsigned char*>(records_.mapped) + offset, &instance, sizeof(instance));
    return records_.address + offset;
  }

  void Run(const std::function<void(VkCommandBuffer)>& record) { SubmitAndWait(device_, RecordWith(commands_, record)); }

  // The pointers written on the device, then the top-level build (or update in place) from them.
  void Build(const std::vector<VkDeviceAddress>& pointers, VkBuildAccelerationStructureModeKHR mode) {
    Run([&](VkCommandBuffer cb) {
      vkCmdUpdateBuffer(cb, pointers_.buffer, 0, pointers.size() * sizeof(VkDeviceAddress), pointers.data());
      InputsWritten(cb);
      BuildInfo b = tlas_.Info(pointers_, static_cast<uint32_t>(pointers.size()), mode);
      b.geometries[0].geometry.instances.arrayOfPointers = VK_TRUE;
      RecordBuilds(device_, cb, {&b});
    });
  }

 private:
  vkkit::Device& device_;
  Inputs inputs_;
  Blas a_;
  Tlas tlas_;
  Commands commands_;
  vkkit::Buffer records_;
  vkkit::Buffer pointers_;
};

}  // namespace

TEST_CASE("capture: an array of instance pointers holding a pointer not aligned to 16 bytes is reported (pInfos-03717)",
          "[integration][capture][passes-invalid-down]") {
  HistoryFixture f;
  Rig rig(f);
  // Instance 1's record 8 bytes past a 16-byte boundary (still aligned for the record's own members).
  rig.Build({rig.Record(0, 0), rig.Record(kInstanceBytes * 2 + 8, 1)}, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
  CHECK(OnlyFinding(f.monitor(), kMisalignedPointer, "1 pointer(s) are not aligned to 16 bytes: instance 1 at") == "");
}

TEST_CASE("capture valid twin: arrays of instance pointers aligned to 16 bytes stay silent, their records unjudged",
          "[integration][capture]") {
  HistoryFixture f;
  Rig rig(f);
  const VkDeviceAddress first = rig.Record(0, 0);
  const VkDeviceAddress second = rig.Record(kInstanceBytes * 2, 1);
  SECTION("a build") { rig.Build({first, second}, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR); }
  SECTION("a build, then updates that swap the pointers (their records' activity is not known: not compared)") {
    rig.Build({first, second}, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
    rig.Build({second, first}, VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);
    rig.Build({first, second}, VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);
  }
  // No probe of a misaligned pointer here: this twin also runs on the GPU machine, which must not get one (the
  // firing test above, kept off it, shows the check is live).
  CHECK(f.monitor().Verify() == "");
}

}  // namespace asval_test
