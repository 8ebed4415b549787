// Captures of a run of build commands (issue 27, layer/state/capture_run.h): the build commands recorded one after
// the other are captured once, where the run ends, so N refits in a row cost the device one capture point instead
// of N. What must not change: each update is judged on the bytes it read. A run ends at every command that can
// order a later write of its inputs after the builds' reads (barriers, events, render passes, secondaries, the end
// of a command buffer), so the tests write the inputs right after the run, behind each of those: the updates are
// valid, and a capture taken after the write would see a triangle made inactive (a false 03664). Each test then
// probes that the updates were judged at all. Tagged [capture]: they also run with the Khronos layer's
// synchronization validation below asval, with the capture copied and reduced (CMakeLists.txt).
#include <catch2/catch_test_macros.hpp>

#include <cstring>
#include <functional>
#include <memory>
#include <regex>
#include <string>
#include <vector>

#include "capture_helpers.h"
#include "capture_skipped.h"
#include "history_helpers.h"
#include "temp_report.h"

namespace asval_test {
namespace {

constexpr const char* kBecameInactive = "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03664";

Shape Triangles() {
  Shape s;
  s.triangles = 2;
  return s;
}

// Structures each over inputs of its own, which the device writes; each has its own scratch, so their builds and
// updates need no barrier between them (one call each: a run).
class RunRig {
 public:
  RunRig(HistoryFixture& f, uint32_t count) : device_(f.device()), commands_(device_) {
    for (uint32_t i = 0; i < count; ++i) {
      inputs_.push_back(std::make_unique<Inputs>(device_, VK_BUFFER_USAGE_TRANSFER_DST_BIT));
      structures_.push_back(std::make_unique<Blas>(device_, *inputs_.back()));
    }
  }

  ~RunRig() {
    if (event_ != VK_NULL_HANDLE) vkDestroyEvent(device_.handle(), event_, nullptr);
  }

  vkkit::Device& device() { return device_; }
  Commands& commands() { return commands_; }
  VkEvent event() {
    if (event_ == VK_NULL_HANDLE) {
      VkEventCreateInfo info{VK_STRUCTURE_TYPE_EVENT_CREATE_INFO};
      REQUIRE(vkCreateEvent(device_.handle(), &info, nullptr, &event_) == VK_SUCCESS);
    }
    return event_;
  }
  Blas& structure(uint32_t i) { return *structures_[i]; }

  // Destroys structure i's inputs buffer and frees its memory (the structure must not be built from them again).
  void DropInputs(uint32_t i) { inputs_[i].reset(); }

  void Fill(VkCommandBuffer cb, uint32_t i, VkDeviceSize offset, uint32_t word) {
    vkCmdFillBuffer(cb, inputs_[i]->buffer().buffer, offset, sizeof(uint32_t), word);
  }

  // Every structure's vertices written on the device, then its build: the builds in a run.
  void BuildAll() {
    Run(Record([&](VkCommandBuffer cb) {
      const std::vector<uint32_t> words = Vertices();
      for (const auto& inputs : inputs_) {
        vkCmdUpdateBuffer(cb, inputs->buffer().buffer, Component(0, 0), words.size() * 4, words.data());
      }
      InputsWritten(cb);
      for (const auto& s : structures_) s->Build(cb, Triangles());
    }));
  }
  // Every structure updated in place, one call each, with no barrier between them.
  void UpdateAll(VkCommandBuffer cb) {
    for (const auto& s : structures_) s->Update(cb, Triangles());
  }

  VkCommandBuffer Record(const std::function<void(VkCommandBuffer)>& record) { return RecordWith(commands_, record); }
  void Run(VkCommandBuffer cb) { SubmitAndWait(device_, cb); }

 private:
  vkkit::Device& device_;
  Commands commands_;
  std::vector<std::unique_ptr<Inputs>> inputs_;
  std::vector<std::unique_ptr<Blas>> structures_;
  VkEvent event_ = VK_NULL_HANDLE;
};

// The build stage's reads of the run before the transfer writes after it (a write-after-read dependency).
void ReadsBeforeWrites(VkCommandBuffer cb) {
  vkCmdPipelineBarrier(cb, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 0,
                       nullptr, 0, nullptr, 0, nullptr);
}

// Whether structure 0's updates are judged: an update now, over the NaN the test wrote after its run (vertex 0 of
// triangle 0), must be reported. A valid twin's silence means something only if its updates were judged.
std::string Probe(RunRig& rig, Monitor& monitor) {
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    InputsWritten(cb);
    rig.structure(0).Update(cb, Triangles());
  }));
  return OnlyFinding(monitor, kBecameInactive, ": primitive 0");
}

bool Names(const Message& m, VkAccelerationStructureKHR handle) {
  for (const VkDebugUtilsObjectNameInfoEXT& o : m.objects) {
    if (o.objectHandle == reinterpret_cast<uint64_t>(handle)) return true;
  }
  return false;
}

TEST_CASE("capture run: updates recorded one call each, without a barrier between them, are each judged on their "
          "own inputs (pInfos-03664)",
          "[integration][capture]") {
  HistoryFixture f;
  RunRig rig(f, 3);
  rig.BuildAll();
  REQUIRE(f.monitor().Verify() == "");
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    rig.Fill(cb, 1, Component(4, 0), kNan);  // the middle structure's triangle 1
    InputsWritten(cb);
    rig.UpdateAll(cb);
  }));
  const std::vector<Message> messages = f.monitor().Take();
  REQUIRE(messages.size() == 1);
  CHECK(messages[0].id_name == kBecameInactive);
  CHECK(messages[0].text.find(": primitive 1") != std::string::npos);
  CHECK(Names(messages[0], rig.structure(1).handle()));
  CHECK_FALSE(Names(messages[0], rig.structure(0).handle()));
  CHECK_FALSE(Names(messages[0], rig.structure(2).handle()));
}

// How a test's command buffer ends the run of updates before the app writes their inputs.
struct RunEnd {
  const char* name;
  // Records into cb what follows the run and orders the writes `write` records after the run's reads.
  std::function<void(RunRig&, VkCommandBuffer, const std::function<void(VkCommandBuffer)>& write)> record;
};

std::vector<RunEnd> RunEnds() {
  return {
      {"vkCmdPipelineBarrier",
       [](RunRig&, VkCommandBuffer cb, const std::function<void(VkCommandBuffer)>& write) {
         ReadsBeforeWrites(cb);
         write(cb);
       }},
      {"vkCmdPipelineBarrier2",
       [](RunRig&, VkCommandBuffer cb, const std::function<void(VkCommandBuffer)>& write) {
         VkMemoryBarrier2 barrier{VK_STRUCTURE_TYPE_MEMORY_BARRIER_2};
         barrier.srcStageMask = VK_PIPELINE_STAGE_2_ACCELERATION_STRUCTURE_BUILD_BIT_KHR;
         barrier.dstStageMask = VK_PIPELINE_STAGE_2_CLEAR_BIT;
         VkDependencyInfo dependency{VK_STRUCTURE_TYPE_DEPENDENCY_INFO};
         dependency.memoryBarrierCount = 1;
         dependency.pMemoryBarriers = &barrier;
         vkCmdPipelineBarrier2(cb, &dependency);
         write(cb);
       }},
      {"vkCmdSetEvent and vkCmdWaitEvents",
       [](RunRig& rig, VkCommandBuffer cb, const std::function<void(VkCommandBuffer)>& write) {
         const VkEvent event = rig.event();
         vkCmdSetEvent(cb, event, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR);
         vkCmdWaitEvents(cb, 1, &event, VK_PIPELINE_STAGE_ACCELERATION_STRUCTURE_BUILD_BIT_KHR,
                         VK_PIPELINE_STAGE_TRANSFER_BIT, 0, nullptr, 0, nullptr, 0, nullptr);
         write(cb);
       }},
  };
}

TEST_CASE("capture run valid twin: inputs written right after a run, behind the command that ends it, are not what "
          "the run's updates are judged on",
          "[integration][capture]") {
  VkPhysicalDeviceSynchronization2Features synchronization2{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SYNCHRONIZATION_2_FEATURES};
  synchronization2.synchronization2 = VK_TRUE;
  vkkit::DeviceOptions options;
  options.features = &synchronization2;
  for (const RunEnd& end : RunEnds()) {
    DYNAMIC_SECTION(end.name) {
      HistoryFixture f(nullptr, {}, options);
      RunRig rig(f, 2);
      rig.BuildAll();
      REQUIRE(f.monitor().Verify() == "");
      rig.Run(rig.Record([&](VkCommandBuffer cb) {
        rig.UpdateAll(cb);  // valid: the inputs the builds read
        end.record(rig, cb, [&](VkCommandBuffer w) { rig.Fill(w, 0, Component(0, 0), kNan); });
      }));
      CHECK(f.monitor().Verify() == "");
      CHECK(Probe(rig, f.monitor()) == "");
    }
  }
}

TEST_CASE("capture run valid twin: a run in a secondary command buffer ends with it; the primary's writes after it "
          "are not what its updates are judged on",
          "[integration][capture]") {
  HistoryFixture f;
  RunRig rig(f, 2);
  rig.BuildAll();
  REQUIRE(f.monitor().Verify() == "");
  VkCommandBuffer secondary = rig.commands().BeginSecondary();
  rig.UpdateAll(secondary);
  rig.commands().End(secondary);
  rig.Run(rig.Record([&](VkCommandBuffer cb) {
    vkCmdExecuteCommands(cb, 1, &secondary);
    ReadsBeforeWrites(cb);
    rig.Fill(cb, 0, Component(0, 0), kNan);
  }));
  CHECK(f.monitor().Verify() == "");
  CHECK(Probe(rig, f.monitor()) == "");
}

TEST_CASE("capture run valid twin: a run at the end of a command buffer is captured there; the next command buffer "
          "of the batch writes its inputs",
          "[integration][capture]") {
  HistoryFixture f;
  RunRig rig(f, 2);
  rig.BuildAll();
  REQUIRE(f.monitor().Verify() == "");
  VkCommandBuffer updates = rig.Record([&](VkCommandBuffer cb) { rig.UpdateAll(cb); });
  VkCommandBuffer writes = rig.Record([&](VkCommandBuffer cb) {
    ReadsBeforeWrites(cb);
    rig.Fill(cb, 0, Component(0, 0), kNan);
  });
  CHECK(rig.commands().Submit({updates, writes}) == VK_SUCCESS);
  CHECK(f.monitor().Verify() == "");
  CHECK(Probe(rig, f.monitor()) == "");
}

// The summary's count of capture points, read from the JSON-lines report.
uint64_t CapturePoints(const asval_test_common::TempReport& report) {
  static const std::regex points(R"(The captures were recorded at (\d+) capture points)");
  for (const std::string& line : report.Lines()) {
    std::smatch m;
    if (line.find("ASVAL-History-Summary") != std::string::npos && std::regex_search(line, m, points)) {
      return std::stoull(m[1]);
    }
  }
  return UINT64_MAX;
}

TEST_CASE("capture run: build commands in a row take one capture point; separated by barriers, one each",
          "[integration][capture]") {
  asval_test_common::TempReport report;
  HistoryFixture f(nullptr, {{"report_file", report.path.c_str()}, {"report_flags", "error,warn,info"}});
  {
    RunRig rig(f, 4);
    rig.BuildAll();  // 4 builds in a row: 1 point
    rig.Run(rig.Record([&](VkCommandBuffer cb) {  // 4 updates, a barrier after each of the first 3: 4 points
      for (uint32_t i = 0; i < 4; ++i) {
        rig.structure(i).Update(cb, Triangles());
        if (i < 3) rig.commands().Barrier(cb);
      }
    }));
    rig.Run(rig.Record([&](VkCommandBuffer cb) { rig.UpdateAll(cb); }));  // 4 in a row again: 1 point
    CHECK(f.monitor().Verify() == "");
  }
  f.Close();
  CHECK(CapturePoints(report) == 6);
}

TEST_CASE("capture run: memory freed while the run is open: its copies are left out and counted, no destroyed buffer "
          "is named",
          "[integration][capture][passes-invalid-down]") {
  // An app that goes on recording a command buffer made invalid by the free (invalid itself, and the Khronos layer
  // says so: hence the tag, which keeps the Khronos runs out; such a recording can only be reset or freed) must not
  // make the layer name the buffer that went with the memory. Only the copy method names buffers (the reduced
  // capture reads through addresses; the environment of integration_capture_reduce forces it, though that run
  // leaves this test out).
  asval_test_common::TempReport report;
  HistoryFixture f(nullptr, {{"report_file", report.path.c_str()}, {"report_flags", "error,warn,info"},
                             {"capture_method", "copy"}});
  {
    RunRig rig(f, 1);
    rig.BuildAll();
    VkCommandBuffer cb = rig.commands().Begin();
    rig.structure(0).Update(cb, Triangles());  // its copy reads the layer's buffer over the inputs' memory
    rig.DropInputs(0);                         // that buffer goes with the memory: the recording can never be submitted
    rig.commands().End(cb);                    // the run's capture point
    CHECK(f.monitor().Verify() == "");
  }
  f.Close();
  const std::map<std::string, uint64_t> expected =
      CaptureReducedRun() ? std::map<std::string, uint64_t>{} : std::map<std::string, uint64_t>{{"unknown_address", 1}};
  CHECK(asval_test_common::ReadCaptureSkipped(report.Lines()).NonZero() == expected);
}

}  // namespace
}  // namespace asval_test
