// Execution-time capture of top-level builds (plain instance records): each instance's
// accelerationStructureReference must be 0 or the address of a structure alive when the build was submitted
// (pInfos-06707), and a top-level update may not make an inactive instance (reference 0) active or an active one
// inactive (pInfos-03663, 03664). The references are judged on the bytes the device read when the build
// executed: the tests write them on the device (vkCmdUpdateBuffer, in the command buffer of the build) or on the
// host before the submission, and assert the findings once the app's wait returned (the layer reports them in
// the wait).
//
// lavapipe reads the bottom-level structures an instance references on the CPU when it builds: a "stale"
// reference here is always the address of a structure whose handle was destroyed while its storage stays
// allocated (Blas::DestroyHandle, as the scene's tlas-destroyed-blas fault does); never an address no memory
// backs. An instance with reference 0 is inactive, and fine for the driver.
#include <catch2/catch_test_macros.hpp>

#include <cstddef>
#include <cstdio>
#include <cstring>
#include <functional>
#include <limits>
#include <string>
#include <vector>

#include "capture_helpers.h"
#include "history_helpers.h"

namespace asval_test {
namespace {

constexpr const char* kStaleReference = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-06707";
constexpr const char* kBecameActive = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03663";
constexpr const char* kBecameInactive = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03664";

constexpr VkDeviceSize kInstanceBytes = sizeof(VkAccelerationStructureInstanceKHR);  // 64
constexpr VkDeviceSize kReferenceOffset = offsetof(VkAccelerationStructureInstanceKHR, accelerationStructureReference);
constexpr uint32_t kMaxInstances = 4;  // the helpers' Tlas is sized for 4

// An instance of `reference` (0: inactive), placed 4 units along X per index `i`, moved by `dx`.
VkAccelerationStructureInstanceKHR Instance(VkDeviceAddress reference, uint32_t i, float dx = 0) {
  VkAccelerationStructureInstanceKHR instance{};
  instance.transform.matrix[0][0] = instance.transform.matrix[1][1] = instance.transform.matrix[2][2] = 1.0f;
  instance.transform.matrix[0][3] = static_cast<float>(i) * 4.0f + dx;
  instance.mask = 0xff;
  instance.accelerationStructureReference = reference;
  return instance;
}

std::string HexAddress(VkDeviceAddress address) {
  char text[32];
  std::snprintf(text, sizeof(text), "0x%llx", static_cast<unsigned long long>(address));
  return text;
}

// What a 06707 message says of one instance (instance_rules.cpp).
std::string Names(uint32_t instance, VkDeviceAddress reference) {
  return "instance " + std::to_string(instance) + " references " + HexAddress(reference);
}


// Bottom-level structures a top-level structure's instances reference, the instance buffer (written on the host
// or on the device) and the command buffers of a test. a and b stay alive; `victim` is built, then its handle
// destroyed by Stale() (its storage stays).
class Rig {
 public:
  explicit Rig(HistoryFixture& f)
      : device_(f.device()), inputs_(device_), a_(device_, inputs_), b_(device_, inputs_), victim_(device_, inputs_),
        tlas_(device_), commands_(device_) {
    instances_ = device_.CreateBuffer(kInstanceBytes * kMaxInstances,
                                      VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                                          VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    std::memset(instances_.mapped, 0, kInstanceBytes * kMaxInstances);
    // The bottom-level structures, built validly from the host-written inputs (each with its own scratch).
    Run(Record([&](VkCommandBuffer cb) {
      a_.Build(cb, Shape{});
      b_.Build(cb, Shape{});
      victim_.Build(cb, Shape{});
    }));
  }
  ~Rig() { device_.Destroy(instances_); }
  Rig(const Rig&) = delete;
  Rig& operator=(const Rig&) = delete;

  Blas& a() { return a_; }
  Blas& b() { return b_; }
  Blas& victim() { return victim_; }
  Inputs& inputs() { return inputs_; }
  Commands& commands() { return commands_; }
  vkkit::Device& device() { return device_; }

  // Destroys the victim's handle (its storage stays: lavapipe can still read it) and returns its old address.
  VkDeviceAddress Stale() {
    victim_.DestroyHandle();
    return victim_.address();
  }

  // Host writes of the instance buffer, seen by the next submission.
  void HostWrite(const std::vector<VkAccelerationStructureInstanceKHR>& instances) {
    std::memcpy(instances_.mapped, instances.data(), instances.size() * kInstanceBytes);
  }

  // Device writes when the command buffer executes: records from instance `first` on, or one instance's
  // reference only.
  void Write(VkCommandBuffer cb, uint32_t first, const std::vector<VkAccelerationStructureInstanceKHR>& instances) {
    vkCmdUpdateBuffer(cb, instances_.buffer, first * kInstanceBytes, instances.size() * kInstanceBytes,
                      instances.data());
  }
  void WriteReference(VkCommandBuffer cb, uint32_t instance, VkDeviceAddress reference) {
    vkCmdUpdateBuffer(cb, instances_.buffer, instance * kInstanceBytes + kReferenceOffset, sizeof(reference),
                      &reference);
  }

  // The writes recorded so far made visible to the build stage's reads, then the top-level build or update (in
  // place) of the first `count` instances.
  void Build(VkCommandBuffer cb, uint32_t count) {
    InputsWritten(cb);
    tlas_.Record(cb, instances_, count, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
  }
  void Update(VkCommandBuffer cb, uint32_t count) {
    InputsWritten(cb);
    tlas_.Record(cb, instances_, count, VK_BUILD_ACCELERATION_STRUCTURE_MODE_UPDATE_KHR);
  }
  void InputsWritten(VkCommandBuffer cb) { asval_test::InputsWritten(cb); }

  VkCommandBuffer Record(const std::function<void(VkCommandBuffer)>& record) { return RecordWith(commands_, record); }

  // Submits cb and waits for it to complete in the way `wait` says (each is a point where the layer reads the
  // captures and reports).
  void Run(VkCommandBuffer cb, Wait wait = Wait::kQueueIdle) { SubmitAndWait(device_, cb, wait); }

 private:
  vkkit::Device& device_;
  Inputs inputs_;
  Blas a_;
  Blas b_;
  Blas victim_;
  Tlas tlas_;
  Commands commands_;
  vkkit::Buffer instances_;
};

// Whether the reference check is live: a build whose instance 0 references the victim's old address (its handle
// destroyed now) must be reported. A valid twin's silence only means something if its references were judged
// (a check skipped for unknown state is silent too).
std::string ProbeReferences(Rig& rig, Monitor& monitor) {
  const VkDeviceAddress stale = rig.Stale();
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    rig.Write(cb, 0, {Instance(stale, 0), Instance(rig.a().address(), 1)});
    rig.Build(cb, 2);
  }));
  return OnlyFinding(monitor, kStaleReference, Names(0, stale));
}

// Whether the top-level updates are compared: an update that now makes instance 0 inactive must be reported.
std::string ProbeActivity(Rig& rig, Monitor& monitor, uint32_t count) {
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    rig.WriteReference(cb, 0, 0);
    rig.Update(cb, count);
  }));
  return OnlyFinding(monitor, kBecameInactive, ": primitive 0");
}

TEST_CASE("capture: a top-level build whose instance references a destroyed structure is reported (pInfos-06707)",
          "[integration][capture]") {
  HistoryFixture f;  // every family, default settings
  Rig rig(f);
  CHECK(f.monitor().Verify() == "");
  const VkDeviceAddress stale = rig.Stale();
  SECTION("the instances written on the device (vkCmdUpdateBuffer) before the build, vkQueueWaitIdle") {
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, 0, {Instance(rig.a().address(), 0), Instance(stale, 1), Instance(rig.b().address(), 2)});
      rig.Build(cb, 3);
    }));
  }
  SECTION("the instances written on the device before the build, vkWaitForFences") {
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, 0, {Instance(rig.a().address(), 0), Instance(stale, 1), Instance(rig.b().address(), 2)});
      rig.Build(cb, 3);
    }),
            Wait::kFence);
  }
  SECTION("the instances written on the host after recording, before the submission") {
    VkCommandBuffer cb = rig.Record([&](VkCommandBuffer c) { rig.Build(c, 3); });
    rig.HostWrite({Instance(rig.a().address(), 0), Instance(stale, 1), Instance(rig.b().address(), 2)});
    rig.Run(cb);
  }
  SECTION("the instances written on the device in a secondary command buffer, executed by the primary") {
    VkCommandBuffer secondary = rig.commands().BeginSecondary();
    rig.Write(secondary, 0, {Instance(rig.a().address(), 0), Instance(stale, 1), Instance(rig.b().address(), 2)});
    rig.Build(secondary, 3);
    rig.commands().End(secondary);
    const Procs procs(rig.device());
    rig.Run(rig.Record([&](VkCommandBuffer cb) { procs.CmdExecuteCommands(cb, 1, &secondary); }));
  }
  CHECK(OnlyFinding(f.monitor(), kStaleReference, Names(1, stale)) == "");
}

TEST_CASE("capture: instance references are judged against the structures alive when the build is submitted",
          "[integration][capture]") {
  // Not when it is recorded: the structure b is alive then, and destroyed (its storage kept) before a submission.
  HistoryFixture f;
  Rig rig(f);
  rig.HostWrite({Instance(rig.a().address(), 0), Instance(rig.b().address(), 1)});
  VkCommandBuffer cb = rig.Record([&](VkCommandBuffer c) { rig.Build(c, 2); });
  SECTION("destroyed after recording, before the only submission") {
    rig.b().DestroyHandle();
    rig.Run(cb);
  }
  SECTION("destroyed between two submissions of the command buffer") {
    rig.Run(cb);
    CHECK(f.monitor().Verify() == "");
    rig.b().DestroyHandle();
    rig.Run(cb, Wait::kFence);
  }
  CHECK(OnlyFinding(f.monitor(), kStaleReference, Names(1, rig.b().address())) == "");
}

TEST_CASE("capture: instance references are judged on the bytes the device built from, not those at recording",
          "[integration][capture]") {
  // The host writes a live address when the command buffer is recorded; the device rewrites it in the same
  // command buffer, before the build. The finding (or its absence) follows what the device wrote.
  HistoryFixture f;
  Rig rig(f);
  const VkDeviceAddress stale = rig.Stale();
  SECTION("a live reference on the host, rewritten to the stale address on the device: reported") {
    rig.HostWrite({Instance(rig.a().address(), 0), Instance(rig.b().address(), 1)});
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.WriteReference(cb, 1, stale);
      rig.Build(cb, 2);
    }));
    CHECK(OnlyFinding(f.monitor(), kStaleReference, Names(1, stale)) == "");
  }
  SECTION("a stale reference on the host, rewritten to a live address on the device: silent") {
    rig.HostWrite({Instance(rig.a().address(), 0), Instance(stale, 1)});
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.WriteReference(cb, 1, rig.b().address());
      rig.Build(cb, 2);
    }));
    CHECK(f.monitor().Verify() == "");
  }
}

TEST_CASE("capture valid twin: top-level builds whose instances reference live structures or 0 stay silent",
          "[integration][capture]") {
  HistoryFixture f;  // every family, default settings (capture=updates captures every top-level build)
  Rig rig(f);
  SECTION("instances of live structures, written on the device") {
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, 0,
                {Instance(rig.a().address(), 0), Instance(rig.b().address(), 1), Instance(rig.a().address(), 2)});
      rig.Build(cb, 3);
    }));
  }
  SECTION("instances of live structures, written on the host") {
    rig.HostWrite({Instance(rig.a().address(), 0), Instance(rig.b().address(), 1)});
    rig.Run(rig.Record([&](VkCommandBuffer cb) { rig.Build(cb, 2); }));
  }
  SECTION("inactive instances (reference 0) among live ones") {
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, 0,
                {Instance(0, 0), Instance(rig.a().address(), 1), Instance(0, 2), Instance(rig.b().address(), 3)});
      rig.Build(cb, 4);
    }));
  }
  SECTION("a stale reference past primitiveCount (in the buffer, not read by the build)") {
    const VkDeviceAddress stale = rig.Stale();
    rig.HostWrite({Instance(rig.a().address(), 0), Instance(rig.b().address(), 1), Instance(stale, 2)});
    rig.Run(rig.Record([&](VkCommandBuffer cb) { rig.Build(cb, 2); }));
  }
  SECTION("the instance buffer rewritten on the device every frame, live addresses each time") {
    for (uint32_t frame = 0; frame < 4; ++frame) {
      const VkDeviceAddress first = frame % 2 ? rig.a().address() : rig.b().address();
      const VkDeviceAddress second = frame % 2 ? rig.b().address() : rig.a().address();
      rig.Run(rig.Record([&](VkCommandBuffer cb) {
        rig.Write(cb, 0, {Instance(first, 0, 0.5f * frame), Instance(frame == 2 ? 0 : second, 1, -0.5f * frame)});
        rig.Build(cb, 2);
      }),
              frame % 2 ? Wait::kFence : Wait::kQueueIdle);
      CHECK(f.monitor().Verify() == "");
    }
  }
  SECTION("the instance buffer rewritten on the host every frame, one command buffer resubmitted") {
    VkCommandBuffer cb = rig.Record([&](VkCommandBuffer c) { rig.Build(c, 2); });
    for (uint32_t frame = 0; frame < 4; ++frame) {
      rig.HostWrite({Instance(frame % 2 ? rig.a().address() : rig.b().address(), 0, 0.5f * frame),
                     Instance(frame == 1 ? 0 : rig.a().address(), 1)});
      rig.Run(cb, frame % 2 ? Wait::kFence : Wait::kQueueIdle);
      CHECK(f.monitor().Verify() == "");
    }
  }
  SECTION("a structure created after the command buffer was recorded, before its submission") {
    VkCommandBuffer cb = rig.Record([&](VkCommandBuffer c) { rig.Build(c, 2); });
    Blas late(rig.device(), rig.inputs());
    rig.Run(rig.Record([&](VkCommandBuffer c) { late.Build(c, Shape{}); }));
    rig.HostWrite({Instance(rig.a().address(), 0), Instance(late.address(), 1)});
    rig.Run(cb);
    CHECK(f.monitor().Verify() == "");
    // The top-level structure no longer references it before it goes.
    rig.HostWrite({Instance(rig.a().address(), 0), Instance(rig.b().address(), 1)});
    rig.Run(cb);
  }
  SECTION("a structure destroyed, a new one created in its memory and referenced by its address") {
    const VkDeviceAddress old_address = rig.a().address();
    rig.a().Recreate();  // destroyed, then created at the same buffer and offset
    INFO("old address " << HexAddress(old_address) << ", new " << HexAddress(rig.a().address()));
    rig.Run(rig.Record([&](VkCommandBuffer cb) { rig.a().Build(cb, Shape{}); }));
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, 0, {Instance(rig.a().address(), 0), Instance(rig.b().address(), 1)});
      rig.Build(cb, 2);
    }));
  }
  SECTION("a structure destroyed after the build that referenced it completed; later frames do not reference it") {
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, 0, {Instance(rig.a().address(), 0), Instance(rig.b().address(), 1)});
      rig.Build(cb, 2);
    }));
    CHECK(f.monitor().Verify() == "");
    rig.b().DestroyHandle();
    for (uint32_t frame = 0; frame < 2; ++frame) {
      rig.Run(rig.Record([&](VkCommandBuffer cb) {
        rig.Write(cb, 0, {Instance(rig.a().address(), 0, 0.25f * frame), Instance(frame ? rig.a().address() : 0, 1)});
        rig.Build(cb, 2);
      }));
      CHECK(f.monitor().Verify() == "");
    }
  }
  CHECK(f.monitor().Verify() == "");
  CHECK(ProbeReferences(rig, f.monitor()) == "");
}

TEST_CASE("capture: a top-level update that makes an inactive instance active is reported (pInfos-03663)",
          "[integration][capture]") {
  HistoryFixture f;
  Rig rig(f);
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    rig.Write(cb, 0, {Instance(rig.a().address(), 0), Instance(0, 1), Instance(rig.b().address(), 2)});
    rig.Build(cb, 3);
  }));
  CHECK(f.monitor().Verify() == "");
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    rig.WriteReference(cb, 1, rig.b().address());
    rig.Update(cb, 3);
  }),
          Wait::kFence);
  CHECK(OnlyFinding(f.monitor(), kBecameActive, ": primitive 1") == "");
}

TEST_CASE("capture: a top-level update that makes an active instance inactive is reported (pInfos-03664)",
          "[integration][capture]") {
  HistoryFixture f;
  Rig rig(f);
  SECTION("written on the device") {
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, 0,
                {Instance(rig.a().address(), 0), Instance(rig.b().address(), 1), Instance(rig.a().address(), 2)});
      rig.Build(cb, 3);
    }));
    CHECK(f.monitor().Verify() == "");
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.WriteReference(cb, 1, 0);
      rig.Update(cb, 3);
    }));
  }
  SECTION("written on the host, one command buffer for the build and another resubmitted for the updates") {
    rig.HostWrite({Instance(rig.a().address(), 0), Instance(rig.b().address(), 1), Instance(rig.a().address(), 2)});
    rig.Run(rig.Record([&](VkCommandBuffer cb) { rig.Build(cb, 3); }));
    VkCommandBuffer update = rig.Record([&](VkCommandBuffer cb) { rig.Update(cb, 3); });
    rig.HostWrite({Instance(rig.a().address(), 0, 1.0f), Instance(rig.b().address(), 1, 1.0f)});
    rig.Run(update);  // moved: silent
    CHECK(f.monitor().Verify() == "");
    rig.HostWrite({Instance(rig.a().address(), 0, 2.0f), Instance(0, 1, 2.0f)});
    rig.Run(update);
  }
  CHECK(OnlyFinding(f.monitor(), kBecameInactive, ": primitive 1") == "");
}

TEST_CASE("capture valid twin: top-level updates that keep each instance's activity stay silent",
          "[integration][capture]") {
  HistoryFixture f;  // every family, default settings
  Rig rig(f);
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    rig.Write(cb, 0, {Instance(rig.a().address(), 0), Instance(rig.b().address(), 1), Instance(0, 2)});
    rig.Build(cb, 3);
  }));
  CHECK(f.monitor().Verify() == "");
  SECTION("transforms, masks and custom indices of the active instances changed") {
    VkAccelerationStructureInstanceKHR first = Instance(rig.a().address(), 0, 1.5f);
    first.transform.matrix[1][1] = 2.0f;
    first.mask = 0x0f;
    first.instanceCustomIndex = 7;
    VkAccelerationStructureInstanceKHR second = Instance(rig.b().address(), 1, -1.0f);
    second.mask = 0x01;
    second.instanceCustomIndex = 0xabcde;
    second.instanceShaderBindingTableRecordOffset = 3;
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, 0, {first, second, Instance(0, 2)});
      rig.Update(cb, 3);
    }));
  }
  SECTION("the inactive instance gets another transform and mask, still reference 0") {
    VkAccelerationStructureInstanceKHR third = Instance(0, 2, 3.0f);
    third.mask = 0x80;
    rig.Run(rig.Record([&](VkCommandBuffer cb) {
      rig.Write(cb, 2, {third});
      rig.Update(cb, 3);
    }));
  }
  SECTION("several updates, one per frame, rewritten on the host") {
    VkCommandBuffer update = rig.Record([&](VkCommandBuffer cb) { rig.Update(cb, 3); });
    for (uint32_t frame = 1; frame <= 3; ++frame) {
      rig.HostWrite({Instance(rig.a().address(), 0, 0.5f * frame), Instance(rig.b().address(), 1, -0.5f * frame),
                     Instance(0, 2, 1.0f * frame)});
      rig.Run(update, frame % 2 ? Wait::kFence : Wait::kQueueIdle);
      CHECK(f.monitor().Verify() == "");
    }
  }
  CHECK(f.monitor().Verify() == "");
  CHECK(ProbeActivity(rig, f.monitor(), 3) == "");
}

TEST_CASE("capture: with capture=off, a top-level build referencing a destroyed structure is not reported",
          "[integration][capture]") {
  HistoryFixture f(nullptr, {{"capture", "off"}});
  Rig rig(f);
  const VkDeviceAddress stale = rig.Stale();
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    rig.Write(cb, 0, {Instance(rig.a().address(), 0), Instance(stale, 1)});
    rig.Build(cb, 2);
  }));
  CHECK(f.monitor().Verify() == "");
}

TEST_CASE("capture: an instance transform with a NaN gets the non-finite-transform warning", "[integration][capture]") {
  // ASVAL-Capture-NonFiniteTransform (a warning of the layer's own): instance 1's translation X is NaN on
  // execution, written on the device; its reference is live, so nothing else is reported. The twin: finite
  // transforms stay silent.
  HistoryFixture f;
  Rig rig(f);
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    rig.Write(cb, 0, {Instance(rig.a().address(), 0), Instance(rig.b().address(), 1)});
    rig.Build(cb, 2);
  }));
  CHECK(f.monitor().Verify() == "");
  VkAccelerationStructureInstanceKHR broken = Instance(rig.b().address(), 1);
  broken.transform.matrix[0][3] = std::numeric_limits<float>::quiet_NaN();
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    rig.Write(cb, 0, {Instance(rig.a().address(), 0), broken});
    rig.Build(cb, 2);
  }));
  CHECK(OnlyFinding(f.monitor(), "ASVAL-Capture-NonFiniteTransform", "first: instance 1, matrix[0][3]") == "");
}

}  // namespace
}  // namespace asval_test
