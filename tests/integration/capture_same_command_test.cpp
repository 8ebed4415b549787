// Execution-time capture of top-level builds: the rules about the structures a build's instances reference, judged
// on the instances the device read when the build executed.
// - None-03407: no instance references the destination of another info of the same command;
// - dstAccelerationStructure-03706: the bytes the command writes for another info's destination do not overlap
//   the memory of a structure the instances reference;
// - pInfos-03709: the buffer each referenced structure was created on is bound to memory.
// The instances are written on the device (vkCmdUpdateBuffer) in the command buffer of the build, so only the
// capture can know them. These builds reach the driver (the findings come when they completed): lavapipe builds
// the infos of one call in order on the CPU and reads whatever bytes the referenced structures hold, so the
// invalid ones are harmless there; they are tagged [passes-invalid-down] and left out of the runs with the Khronos
// layer below.
#include <catch2/catch_test_macros.hpp>

#include <cstddef>
#include <functional>
#include <string>
#include <vector>

#include "capture_helpers.h"
#include "history_helpers.h"

namespace asval_test {
namespace {

constexpr const char* kReferencedDestination = "VUID-vkCmdBuildAccelerationStructuresKHR-None-03407";
constexpr const char* kReferencedOverlap = "VUID-vkCmdBuildAccelerationStructuresKHR-dstAccelerationStructure-03706";
constexpr const char* kStorageNotBound = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03709";

constexpr VkDeviceSize kInstanceBytes = sizeof(VkAccelerationStructureInstanceKHR);  // 64
constexpr uint32_t kMaxInstances = 4;  // the helpers' Tlas is sized for 4

// Bottom-level structures `a` and `b` (own storage each), `overlap` created in b's storage 256 bytes in (its
// bytes overlap b's, at another address), a top-level structure and its instance buffer. a and b are built validly at the start.
class Rig {
 public:
  explicit Rig(HistoryFixture& f)
      : device_(f.device()), inputs_(device_), a_(device_, inputs_), b_(device_, inputs_),
        overlap_(device_, inputs_, &b_, 256), tlas_(device_), commands_(device_) {
    instances_ = device_.CreateBuffer(kInstanceBytes * kMaxInstances,
                                      VK_BUFFER_USAGE_ACCELERATION_STRUCTURE_BUILD_INPUT_READ_ONLY_BIT_KHR |
                                          VK_BUFFER_USAGE_TRANSFER_DST_BIT);
    Run([&](VkCommandBuffer cb) {
      a_.Build(cb, Shape{});
      b_.Build(cb, Shape{});
    });
  }
  ~Rig() { device_.Destroy(instances_); }
  Rig(const Rig&) = delete;
  Rig& operator=(const Rig&) = delete;

  Blas& a() { return a_; }
  Blas& b() { return b_; }
  Blas& overlap() { return overlap_; }

  // Records `record` into a new command buffer, submits it and waits (where the layer reports).
  void Run(const std::function<void(VkCommandBuffer)>& record) {
    SubmitAndWait(device_, RecordWith(commands_, record));
  }

  // In one command buffer: the instances (references in this order) written on the device, then ONE
  // vkCmdBuildAccelerationStructuresKHR of `blases` (each built again) followed by the top-level build.
  void BuildTogether(const std::vector<const Blas*>& blases, const std::vector<VkDeviceAddress>& references) {
    Run([&](VkCommandBuffer cb) {
      std::vector<VkAccelerationStructureInstanceKHR> instances;
      for (uint32_t i = 0; i < references.size(); ++i) instances.push_back(InstanceRecord(references[i], i));
      vkCmdUpdateBuffer(cb, instances_.buffer, 0, instances.size() * kInstanceBytes, instances.data());
      InputsWritten(cb);
      std::vector<BuildInfo> infos;
      for (const Blas* blas : blases) infos.push_back(blas->Info(Shape{}));
      infos.push_back(tlas_.Info(instances_, static_cast<uint32_t>(references.size()),
                                 VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR));
      std::vector<const BuildInfo*> pointers;
      for (const BuildInfo& info : infos) pointers.push_back(&info);
      RecordBuilds(device_, cb, pointers);
    });
  }

 private:
  vkkit::Device& device_;
  Inputs inputs_;
  Blas a_;
  Blas b_;
  Blas overlap_;
  Tlas tlas_;
  Commands commands_;
  vkkit::Buffer instances_;
};

// The messages since the last check, one line each ("id: text"), for a failure's explanation.
std::string Seen(Monitor& monitor) {
  std::string seen;
  for (const Message& m : monitor.Take()) seen += m.id_name + ": " + m.text + "\n";
  return seen;
}

// How many of `messages` have the id `vuid` and a text holding `text`.
int Count(const std::vector<Message>& messages, const char* vuid, const std::string& text) {
  int n = 0;
  for (const Message& m : messages) n += m.id_name == vuid && m.text.find(text) != std::string::npos;
  return n;
}

}  // namespace

TEST_CASE("capture: an instance referencing another info's destination in the same command is reported "
          "(None-03407, dstAccelerationStructure-03706)",
          "[integration][capture][passes-invalid-down]") {
  HistoryFixture f;
  Rig rig(f);
  // pInfos[0] builds a again; pInfos[1], the top-level build, references b (fine) then a.
  rig.BuildTogether({&rig.a()}, {rig.b().address(), rig.a().address()});
  const std::vector<Message> messages = f.monitor().Take();
  std::string seen;
  for (const Message& m : messages) seen += m.id_name + ": " + m.text + "\n";
  INFO(seen);
  CHECK(messages.size() == 2);
  CHECK(Count(messages, kReferencedDestination, "geometry 0, instance 1 references") == 1);
  CHECK(Count(messages, kReferencedDestination, "which is pInfos[0].dstAccelerationStructure") == 1);
  CHECK(Count(messages, kReferencedOverlap, "for pInfos[0].dstAccelerationStructure") == 1);
}

TEST_CASE("capture: an instance referencing a structure over another info's destination is reported "
          "(dstAccelerationStructure-03706)",
          "[integration][capture][passes-invalid-down]") {
  HistoryFixture f;
  Rig rig(f);
  // pInfos[0] builds `overlap`, which lies in b's storage; the top-level build references b.
  rig.BuildTogether({&rig.overlap()}, {rig.b().address()});
  CHECK(OnlyFinding(f.monitor(), kReferencedOverlap, "geometry 0, instance 0 references") == "");
}

TEST_CASE("capture: an instance referencing a structure whose buffer was destroyed is reported (pInfos-03709)",
          "[integration][capture][passes-invalid-down]") {
  HistoryFixture f;
  Rig rig(f);
  // b's VkBuffer is destroyed; b itself and its memory stay (lavapipe still reads the bytes there).
  rig.b().DestroyStorageBuffer();
  rig.BuildTogether({}, {rig.a().address(), rig.b().address()});
  CHECK(OnlyFinding(f.monitor(), kStorageNotBound, "geometry 0, instance 1 references") == "");
}

TEST_CASE("capture valid twin: top-level and bottom-level builds in one command, instances referencing neither "
          "destination nor its memory, stay silent",
          "[integration][capture]") {
  HistoryFixture f;
  Rig rig(f);
  SECTION("a built again beside a top-level build referencing b") {
    rig.BuildTogether({&rig.a()}, {rig.b().address(), rig.b().address()});
  }
  SECTION("a built again beside a top-level build of inactive instances (reference 0)") {
    rig.BuildTogether({&rig.a()}, {0, 0});
  }
  SECTION("the top-level build first in its own command, then a in the next command referencing it") {
    rig.BuildTogether({}, {rig.a().address(), rig.b().address()});
    rig.Run([&](VkCommandBuffer cb) { rig.a().Build(cb, Shape{}); });
  }
  CHECK(Seen(f.monitor()) == "");
  // The same-command check is live: referencing a now is reported.
  rig.BuildTogether({&rig.a()}, {rig.a().address()});
  CHECK(Count(f.monitor().Take(), kReferencedDestination, "instance 0 references") == 1);
}

}  // namespace asval_test
