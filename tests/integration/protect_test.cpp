// Protect mode (setting `protect`, issue 16) through the real loader on lavapipe, every submission waited for. With
// protect on and an app messenger that returns VK_FALSE (it never asks for a skip), a command asval reports an error
// for at record time is not recorded and its command buffer is marked; a submission of a marked command buffer, or one
// asval reports an error for in execution order, returns VK_ERROR_VALIDATION_FAILED_EXT; a host command with an error
// returns it without running. Each is named once by an ASVAL-Protect-Withheld information message, and the app goes
// on: a later valid submission on the same queue runs and signals its fence. Valid programs give the same results
// with protect on and off; the JSON report holds every finding and notice even when the app aborts right after; the
// Khronos validation layer below asval never sees a protected command.
//
// Record-time cases: one per family with record-time rules (features, handles, structure, alignment, addresses,
// aliasing, copies). Submit-time cases: the submission of each of those marked command buffers, and the two families
// with rules judged in execution order (history: an update's flags; copies: serialization room). Host cases: a host
// build (features) and a host property query (history); lavapipe has no host commands, so only withheld host calls
// are made (none reaches the driver).
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <catch2/catch_test_macros.hpp>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <memory>
#include <mutex>
#include <nlohmann/json.hpp>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "history_helpers.h"
#include "record_checks_helpers.h"
#include "temp_report.h"
#include "scoped_env.h"

extern char** environ;

namespace asval_test {
namespace {

constexpr const char* kNotice = "ASVAL-Protect-Withheld";
constexpr const char* kLayerName = "VK_LAYER_ASVAL_as_validation";
constexpr VkAccelerationStructureTypeKHR kBottom = VK_ACCELERATION_STRUCTURE_TYPE_BOTTOM_LEVEL_KHR;

// The run's settings through VkLayerSettingsCreateInfoEXT: `protect` as VK_LAYER_SETTING_TYPE_BOOL32_EXT (the way an
// app written against VK_EXT_layer_settings turns it on), enabled_checks and report_file as strings when given.
class RunSettings {
 public:
  RunSettings(bool protect, const char* families, std::string report_file, const char* duplicate_limit = nullptr)
      : protect_(protect ? VK_TRUE : VK_FALSE), families_(families), report_(std::move(report_file)),
        duplicate_limit_(duplicate_limit) {
    report_ptr_ = report_.c_str();
    if (duplicate_limit_) {
      settings_.push_back(
          {kLayerName, "duplicate_message_limit", VK_LAYER_SETTING_TYPE_STRING_EXT, 1, &duplicate_limit_});
    }
    settings_.push_back({kLayerName, "protect", VK_LAYER_SETTING_TYPE_BOOL32_EXT, 1, &protect_});
    if (families_) settings_.push_back({kLayerName, "enabled_checks", VK_LAYER_SETTING_TYPE_STRING_EXT, 1, &families_});
    if (!report_.empty()) {
      settings_.push_back({kLayerName, "report_file", VK_LAYER_SETTING_TYPE_STRING_EXT, 1, &report_ptr_});
    }
    info_ = {VK_STRUCTURE_TYPE_LAYER_SETTINGS_CREATE_INFO_EXT, nullptr, static_cast<uint32_t>(settings_.size()),
             settings_.data()};
  }
  RunSettings(const RunSettings&) = delete;
  RunSettings& operator=(const RunSettings&) = delete;
  const void* Chain() const { return &info_; }

 private:
  VkBool32 protect_;
  const char* families_;
  std::string report_;
  const char* duplicate_limit_;
  const char* report_ptr_ = nullptr;
  std::vector<VkLayerSettingEXT> settings_;
  VkLayerSettingsCreateInfoEXT info_{};
};

// A second messenger, for information messages: it keeps asval's ASVAL-Protect-Withheld notices (the Monitor hears
// errors and warnings only). Returns VK_FALSE.
class NoticeListener {
 public:
  explicit NoticeListener(VkInstance instance) : instance_(instance) {
    VkDebugUtilsMessengerCreateInfoEXT info{VK_STRUCTURE_TYPE_DEBUG_UTILS_MESSENGER_CREATE_INFO_EXT};
    info.messageSeverity = VK_DEBUG_UTILS_MESSAGE_SEVERITY_INFO_BIT_EXT;
    info.messageType = VK_DEBUG_UTILS_MESSAGE_TYPE_VALIDATION_BIT_EXT;
    info.pfnUserCallback = &NoticeListener::Callback;
    info.pUserData = this;
    auto create = reinterpret_cast<PFN_vkCreateDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance, "vkCreateDebugUtilsMessengerEXT"));
    vkkit::Check(create(instance, &info, nullptr, &messenger_), "vkCreateDebugUtilsMessengerEXT");
  }
  ~NoticeListener() {
    auto destroy = reinterpret_cast<PFN_vkDestroyDebugUtilsMessengerEXT>(
        vkGetInstanceProcAddr(instance_, "vkDestroyDebugUtilsMessengerEXT"));
    destroy(instance_, messenger_, nullptr);
  }
  NoticeListener(const NoticeListener&) = delete;
  NoticeListener& operator=(const NoticeListener&) = delete;

  std::vector<std::string> Take() {
    std::lock_guard lock(mutex_);
    return std::move(notices_);
  }

 private:
  static VKAPI_ATTR VkBool32 VKAPI_CALL Callback(VkDebugUtilsMessageSeverityFlagBitsEXT,
                                                 VkDebugUtilsMessageTypeFlagsEXT,
                                                 const VkDebugUtilsMessengerCallbackDataEXT* data, void* user) {
    auto* self = static_cast<NoticeListener*>(user);
    if (data->pMessageIdName && std::strcmp(data->pMessageIdName, kNotice) == 0) {
      std::lock_guard lock(self->mutex_);
      self->notices_.emplace_back(data->pMessage ? data->pMessage : "");
    }
    return VK_FALSE;
  }

  VkInstance instance_;
  VkDebugUtilsMessengerEXT messenger_ = VK_NULL_HANDLE;
  std::mutex mutex_;
  std::vector<std::string> notices_;
};

// An instance and device under asval with protect on (or off), enabled_checks narrowed to `families` (null: all), the
// Monitor for errors and warnings (nothing is Expect()ed, so it returns VK_FALSE for every message) and a
// NoticeListener. `settings_chain` false: nothing chained (protect then comes from the environment).
class ProtectRun {
 public:
  explicit ProtectRun(const char* families = nullptr, bool protect = true, const std::string& report = "",
                      bool settings_chain = true, const char* duplicate_limit = nullptr,
                      const vkkit::DeviceOptions& device = {})
      : settings_(protect, families, report, duplicate_limit),
        fixture_(std::make_unique<Fixture>(settings_chain ? settings_.Chain() : nullptr, device)),
        notices_(std::make_unique<NoticeListener>(fixture_->instance().handle())) {}
  ~ProtectRun() { Close(); }
  // Destroys the device and the instance now (vkDestroyDevice writes the protect summary).
  void Close() {
    notices_.reset();
    fixture_.reset();
  }
  vkkit::Device& device() { return fixture_->device(); }
  VkInstance instance() { return fixture_->instance().handle(); }

  // Every error and warning since the last call, as "VUID" (errors) or "warning VUID".
  std::vector<std::string> TakeFindings() {
    std::vector<std::string> out;
    for (const Message& m : fixture_->monitor().Take()) {
      out.push_back(m.severity == VK_DEBUG_UTILS_MESSAGE_SEVERITY_ERROR_BIT_EXT ? m.id_name : "warning " + m.id_name);
    }
    return out;
  }
  std::vector<std::string> TakeNotices() { return notices_->Take(); }

 private:
  RunSettings settings_;
  std::unique_ptr<Fixture> fixture_;
  std::unique_ptr<NoticeListener> notices_;
};

using Strings = std::vector<std::string>;

bool Contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

template <typename Fn>
Fn LoadDevice(vkkit::Device& device, const char* name) {
  auto fn = reinterpret_cast<Fn>(vkGetDeviceProcAddr(device.handle(), name));
  if (!fn) throw std::runtime_error(std::string("no ") + name);
  return fn;
}

struct Outcome {
  VkResult result = VK_SUCCESS;
  bool signaled = false;
};

// One submission of `cb` with a fence (vkQueueSubmit, or vkQueueSubmit2 when `submit2`), waited for (10 s at most)
// whatever it returned, as an app that ignores the result does: the result and whether the fence signaled. A withheld
// submission must signal it too (its batches go down emptied: layer/loader/synchronization_only.h).
Outcome SubmitWithFence(vkkit::Device& device, const std::vector<VkCommandBuffer>& cbs, bool submit2 = false) {
  VkFenceCreateInfo fence_info{VK_STRUCTURE_TYPE_FENCE_CREATE_INFO};
  VkFence fence = VK_NULL_HANDLE;
  vkkit::Check(vkCreateFence(device.handle(), &fence_info, nullptr, &fence), "vkCreateFence");
  Outcome out;
  if (submit2) {
    std::vector<VkCommandBufferSubmitInfo> cb_infos;
    for (VkCommandBuffer cb : cbs) {
      cb_infos.push_back({VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO});
      cb_infos.back().commandBuffer = cb;
    }
    VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
    submit.commandBufferInfoCount = static_cast<uint32_t>(cb_infos.size());
    submit.pCommandBufferInfos = cb_infos.data();
    out.result = LoadDevice<PFN_vkQueueSubmit2>(device, "vkQueueSubmit2")(device.queue(), 1, &submit, fence);
  } else {
    VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    submit.commandBufferCount = static_cast<uint32_t>(cbs.size());
    submit.pCommandBuffers = cbs.data();
    out.result = vkQueueSubmit(device.queue(), 1, &submit, fence);
  }
  out.signaled = vkWaitForFences(device.handle(), 1, &fence, VK_TRUE, 10'000'000'000ull) == VK_SUCCESS;
  vkkit::Check(vkQueueWaitIdle(device.queue()), "vkQueueWaitIdle");
  vkDestroyFence(device.handle(), fence, nullptr);
  return out;
}
Outcome SubmitWithFence(vkkit::Device& device, VkCommandBuffer cb, bool submit2 = false) {
  return SubmitWithFence(device, std::vector<VkCommandBuffer>{cb}, submit2);
}

// One bottom-level triangle build over the scene's inputs, with its destination and scratch (Scene::Prepare).
struct TriangleInfo {
  explicit TriangleInfo(Scene& scene) : geometry(scene.Triangles()) {
    info = Scene::Info(kBottom, {geometry});
    info.pGeometries = &geometry;
    scene.Prepare(info, {1});
  }
  TriangleInfo(const TriangleInfo&) = delete;
  TriangleInfo& operator=(const TriangleInfo&) = delete;
  void Record(vkkit::Device& device, VkCommandBuffer cb) const {
    const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
    device.CmdBuildAccelerationStructuresKHR(cb, 1, &info, &ranges);
  }
  VkAccelerationStructureGeometryKHR geometry;
  VkAccelerationStructureBuildGeometryInfoKHR info{};
  VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
};

// The app goes on after a withheld call: a valid build, submitted on the same queue, runs and signals its fence, and
// asval says nothing about it.
void CheckValidSubmissionRuns(ProtectRun& run, Scene& scene) {
  vkkit::Device& device = run.device();
  TriangleInfo valid(scene);
  Commands commands(device);
  VkCommandBuffer cb = commands.Begin();
  valid.Record(device, cb);
  commands.End(cb);
  const Outcome outcome = SubmitWithFence(device, cb);
  CHECK(outcome.result == VK_SUCCESS);
  CHECK(outcome.signaled);
  CHECK(run.TakeFindings() == Strings{});
  CHECK(run.TakeNotices() == Strings{});
}

// A record-time violation: the family it belongs to, its exact VUID, the command that breaks it, and how to record it.
struct RecordCase {
  const char* family;
  const char* vuid;
  const char* function;
  std::function<void(vkkit::Device&, Scene&, VkCommandBuffer)> record;
};

std::vector<RecordCase> RecordCases() {
  return {
      {"features", "VUID-vkCmdBuildAccelerationStructuresIndirectKHR-accelerationStructureIndirectBuild-03650",
       "vkCmdBuildAccelerationStructuresIndirectKHR",
       [](vkkit::Device& device, Scene& scene, VkCommandBuffer cb) {
         // Lavapipe has no indirectBuild feature: any indirect build breaks 03650.
         TriangleInfo t(scene);
         const VkDeviceAddress ranges = scene.Address(Scene::kSize - 64);
         const uint32_t stride = 16, max_count = 1;
         const uint32_t* max_counts = &max_count;
         const auto indirect = LoadDevice<PFN_vkCmdBuildAccelerationStructuresIndirectKHR>(
             device, "vkCmdBuildAccelerationStructuresIndirectKHR");
         indirect(cb, 1, &t.info, &ranges, &stride, &max_counts);
       }},
      {"handles", "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03700", "vkCmdBuildAccelerationStructuresKHR",
       [](vkkit::Device& device, Scene& scene, VkCommandBuffer cb) {
         VkAccelerationStructureGeometryKHR triangles = scene.Triangles();
         VkAccelerationStructureBuildGeometryInfoKHR info = Scene::Info(kBottom, {triangles});
         info.pGeometries = &triangles;
         scene.Prepare(info, {1}, VK_ACCELERATION_STRUCTURE_TYPE_TOP_LEVEL_KHR);  // created as the other level
         const VkAccelerationStructureBuildRangeInfoKHR range{1, 0, 0, 0};
         const VkAccelerationStructureBuildRangeInfoKHR* ranges = &range;
         device.CmdBuildAccelerationStructuresKHR(cb, 1, &info, &ranges);
       }},
      {"structure", "VUID-VkAccelerationStructureBuildGeometryInfoKHR-flags-03796",
       "vkCmdBuildAccelerationStructuresKHR",
       [](vkkit::Device& device, Scene& scene, VkCommandBuffer cb) {
         TriangleInfo t(scene);
         t.info.flags = VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_TRACE_BIT_KHR |
                        VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR;
         t.Record(device, cb);
       }},
      {"alignment", "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710", "vkCmdBuildAccelerationStructuresKHR",
       [](vkkit::Device& device, Scene& scene, VkCommandBuffer cb) {
         TriangleInfo t(scene);
         t.info.scratchData.deviceAddress += device.as_properties().minAccelerationStructureScratchOffsetAlignment / 2;
         t.Record(device, cb);
       }},
      {"addresses", "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-10126", "vkCmdBuildAccelerationStructuresKHR",
       [](vkkit::Device& device, Scene& scene, VkCommandBuffer cb) {
         TriangleInfo t(scene);
         VkAccelerationStructureBuildSizesInfoKHR sizes{VK_STRUCTURE_TYPE_ACCELERATION_STRUCTURE_BUILD_SIZES_INFO_KHR};
         const uint32_t count = 1;
         device.GetAccelerationStructureBuildSizesKHR(device.handle(), VK_ACCELERATION_STRUCTURE_BUILD_TYPE_DEVICE_KHR,
                                                      &t.info, &count, &sizes);
         t.info.dstAccelerationStructure = scene.NewStructure(kBottom, sizes.accelerationStructureSize - 16);
         t.Record(device, cb);
       }},
      {"aliasing", "VUID-vkCmdBuildAccelerationStructuresKHR-scratchData-03704", "vkCmdBuildAccelerationStructuresKHR",
       [](vkkit::Device& device, Scene& scene, VkCommandBuffer cb) {
         TriangleInfo a(scene), b(scene);
         b.info.scratchData = a.info.scratchData;  // two builds of one command share their scratch
         const VkAccelerationStructureBuildGeometryInfoKHR infos[] = {a.info, b.info};
         const VkAccelerationStructureBuildRangeInfoKHR* ranges[] = {&a.range, &b.range};
         device.CmdBuildAccelerationStructuresKHR(cb, 2, infos, ranges);
       }},
      {"copies", "VUID-VkCopyAccelerationStructureInfoKHR-mode-03410", "vkCmdCopyAccelerationStructureKHR",
       [](vkkit::Device& device, Scene& scene, VkCommandBuffer cb) {
         CmdCopy(device, cb, scene.blas(), scene.NewStructure(kBottom, 1 << 16),
                 VK_COPY_ACCELERATION_STRUCTURE_MODE_SERIALIZE_KHR);
       }},
  };
}

// The notice of a withheld submission of a marked command buffer names where it was and the finding behind it.
void CheckMarkedSubmissionNotice(const Strings& notices, const std::string& where, const RecordCase& c) {
  REQUIRE(notices.size() == 1);
  CHECK(Contains(notices[0], where));
  CHECK(Contains(notices[0], c.function));
  CHECK(Contains(notices[0], c.vuid));
  CHECK(Contains(notices[0], "VK_ERROR_VALIDATION_FAILED_EXT"));
}

TEST_CASE("protect: a record-time error of each family withholds the command and every submission of its command "
          "buffer; the queue goes on",
          "[integration][protect]") {
  for (const RecordCase& c : RecordCases()) {
    DYNAMIC_SECTION(c.family << ": " << c.vuid) {
      ProtectRun run(c.family);
      vkkit::Device& device = run.device();
      Scene scene(device);
      Commands commands(device);
      VkCommandBuffer cb = commands.Begin();
      c.record(device, scene, cb);
      commands.End(cb);
      CHECK(run.TakeFindings() == Strings{c.vuid});
      const Strings recorded = run.TakeNotices();
      REQUIRE(recorded.size() == 1);
      CHECK(Contains(recorded[0], c.function));
      CHECK(Contains(recorded[0], "not passed down"));
      CHECK(Contains(recorded[0], c.vuid));

      const Outcome outcome = SubmitWithFence(device, cb);
      CHECK(outcome.result == VK_ERROR_VALIDATION_FAILED_EXT);
      CHECK(outcome.signaled);  // its fence still signals
      CHECK(run.TakeFindings() == Strings{});
      CheckMarkedSubmissionNotice(run.TakeNotices(), "pSubmits[0].pCommandBuffers[0]", c);
      // Marked until reset: a second submission is withheld again.
      CHECK(SubmitWithFence(device, cb).result == VK_ERROR_VALIDATION_FAILED_EXT);
      CHECK(run.TakeNotices().size() == 1);
      CheckValidSubmissionRuns(run, scene);
    }
  }
}

TEST_CASE("protect: vkQueueSubmit2 and a primary executing a marked secondary are withheld too",
          "[integration][protect]") {
  const RecordCase c = RecordCases()[3];  // alignment
  // vkQueueSubmit2 needs synchronization2 (03866): the withheld submission's emptied batch reaches the driver.
  VkPhysicalDeviceSynchronization2Features synchronization2{
      VK_STRUCTURE_TYPE_PHYSICAL_DEVICE_SYNCHRONIZATION_2_FEATURES};
  synchronization2.synchronization2 = VK_TRUE;
  vkkit::DeviceOptions options;
  options.features = &synchronization2;
  ProtectRun run(c.family, true, "", true, nullptr, options);
  vkkit::Device& device = run.device();
  Scene scene(device);
  Commands commands(device);
  VkCommandBuffer cb = commands.Begin();
  c.record(device, scene, cb);
  commands.End(cb);
  CHECK(run.TakeFindings() == Strings{c.vuid});
  CHECK(run.TakeNotices().size() == 1);
  const Outcome outcome = SubmitWithFence(device, cb, /*submit2=*/true);
  CHECK(outcome.result == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(outcome.signaled);  // its fence still signals
  CheckMarkedSubmissionNotice(run.TakeNotices(), "pSubmits[0].pCommandBufferInfos[0]", c);

  VkCommandBuffer secondary = commands.BeginSecondary();
  c.record(device, scene, secondary);
  commands.End(secondary);
  CHECK(run.TakeFindings() == Strings{c.vuid});
  CHECK(run.TakeNotices().size() == 1);
  VkCommandBuffer primary = commands.Begin();
  Procs(device).CmdExecuteCommands(primary, 1, &secondary);
  commands.End(primary);
  const Outcome executed = SubmitWithFence(device, primary);
  CHECK(executed.result == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(executed.signaled);
  CheckMarkedSubmissionNotice(run.TakeNotices(), "pSubmits[0].pCommandBuffers[0]", c);
  // Begun again, the primary holds only what it records now.
  vkkit::Check(vkResetCommandBuffer(primary, 0), "vkResetCommandBuffer");
  VkCommandBufferBeginInfo begin{VK_STRUCTURE_TYPE_COMMAND_BUFFER_BEGIN_INFO};
  vkkit::Check(vkBeginCommandBuffer(primary, &begin), "vkBeginCommandBuffer");
  TriangleInfo valid(scene);
  valid.Record(device, primary);
  commands.End(primary);
  const Outcome again = SubmitWithFence(device, primary);
  CHECK(again.result == VK_SUCCESS);
  CHECK(again.signaled);
  CHECK(run.TakeFindings() == Strings{});
  CHECK(run.TakeNotices() == Strings{});
}

TEST_CASE("protect: past the duplicate message limit an error is no longer reported, but its command is still "
          "withheld and named",
          "[integration][protect]") {
  const RecordCase c = RecordCases()[3];  // alignment
  ProtectRun run(c.family, true, "", true, /*duplicate_limit=*/"1");
  vkkit::Device& device = run.device();
  Scene scene(device);
  Commands commands(device);
  VkCommandBuffer first = commands.Begin();
  c.record(device, scene, first);
  commands.End(first);
  CHECK(run.TakeFindings() == Strings{c.vuid});
  CHECK(run.TakeNotices().size() == 1);
  VkCommandBuffer second = commands.Begin();
  c.record(device, scene, second);
  commands.End(second);
  CHECK(run.TakeFindings() == Strings{});  // over the limit: not reported again
  const Strings notices = run.TakeNotices();
  REQUIRE(notices.size() == 1);
  CHECK(Contains(notices[0], c.vuid));
  const Outcome outcome = SubmitWithFence(device, second);
  CHECK(outcome.result == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(outcome.signaled);  // its fence still signals
  CheckMarkedSubmissionNotice(run.TakeNotices(), "pSubmits[0].pCommandBuffers[0]", c);
  CheckValidSubmissionRuns(run, scene);
}

// A submission asval finds invalid in execution order: withheld with VK_ERROR_VALIDATION_FAILED_EXT, its fence still
// signaled, one notice; what was recorded reached the command buffer (it was valid when recorded), hence the tag.
void CheckWithheldSubmission(ProtectRun& run, const std::vector<VkCommandBuffer>& cbs, const char* vuid) {
  CHECK(run.TakeFindings() == Strings{});  // nothing at record time
  CHECK(run.TakeNotices() == Strings{});
  const Outcome outcome = SubmitWithFence(run.device(), cbs);
  CHECK(outcome.result == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(outcome.signaled);  // its fence still signals
  CHECK(run.TakeFindings() == Strings{vuid});
  const Strings notices = run.TakeNotices();
  REQUIRE(notices.size() == 1);
  CHECK(Contains(notices[0], "vkQueueSubmit"));
  CHECK(Contains(notices[0], vuid));
  CHECK(Contains(notices[0], "in execution order"));
}

void SubmitValid(ProtectRun& run, VkCommandBuffer cb) {
  const Outcome outcome = SubmitWithFence(run.device(), cb);
  CHECK(outcome.result == VK_SUCCESS);
  CHECK(outcome.signaled);
}

TEST_CASE("protect: an update that breaks the history in execution order is withheld at submission (history)",
          "[integration][protect][passes-invalid-down]") {
  ProtectRun run("history");
  vkkit::Device& device = run.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  Commands commands(device);
  VkCommandBuffer build = commands.Begin();
  blas.Build(build, Shape{});
  commands.End(build);
  SubmitValid(run, build);
  // One submission: a rebuild with other flags (valid), then an update with the old ones (03759 after that rebuild).
  Shape other_flags;
  other_flags.flags =
      VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR | VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR;
  VkCommandBuffer rebuild = commands.Begin();
  blas.Build(rebuild, other_flags);
  commands.End(rebuild);
  VkCommandBuffer update = commands.Begin();
  blas.Update(update, Shape{});
  commands.End(update);
  CheckWithheldSubmission(run, {rebuild, update}, "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03759");
  // The history is as before the withheld submission (its rebuild undone): an update with the first build's flags
  // is valid, runs and signals its fence.
  VkCommandBuffer valid = commands.Begin();
  blas.Update(valid, Shape{});
  commands.End(valid);
  SubmitValid(run, valid);
  CHECK(run.TakeFindings() == Strings{});
  CHECK(run.TakeNotices() == Strings{});
}

TEST_CASE("protect: serializing into less than the serialization size read back is withheld at submission (copies)",
          "[integration][protect][passes-invalid-down]") {
  ProtectRun run("copies");
  vkkit::Device& device = run.device();
  Inputs inputs(device);
  Blas blas(device, inputs);
  QueryPool pool(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR, 1);
  Commands commands(device);
  VkCommandBuffer build = commands.Begin();
  pool.Reset(build);
  blas.Build(build, Shape{});
  commands.Barrier(build);
  CmdWriteProperties(device, build, {blas.handle()}, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR,
                     pool.handle(), 0);
  commands.End(build);
  SubmitValid(run, build);
  const uint64_t size = pool.Results()[0];
  REQUIRE(size > 256);
  vkkit::Buffer small = device.CreateBuffer(size - 256, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  vkkit::Buffer room = device.CreateBuffer(size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  VkCommandBuffer serialize = commands.Begin();
  CmdSerialize(device, serialize, blas.handle(), small.address);
  commands.End(serialize);
  CheckWithheldSubmission(run, {serialize}, "VUID-VkCopyAccelerationStructureToMemoryInfoKHR-dst-03561");
  VkCommandBuffer valid = commands.Begin();
  CmdSerialize(device, valid, blas.handle(), room.address);
  commands.End(valid);
  SubmitValid(run, valid);
  CHECK(run.TakeFindings() == Strings{});
  CHECK(run.TakeNotices() == Strings{});
  device.Destroy(small);
  device.Destroy(room);
}

TEST_CASE("protect: host commands with an error return VK_ERROR_VALIDATION_FAILED_EXT without running (features, "
          "history)",
          "[integration][protect]") {
  SECTION("features: a host build without accelerationStructureHostCommands") {
    ProtectRun run("features");
    vkkit::Device& device = run.device();
    Scene scene(device);
    TriangleInfo t(scene);
    const VkAccelerationStructureBuildRangeInfoKHR* ranges = &t.range;
    const VkResult result = Procs(device).HostBuild(device.handle(), VK_NULL_HANDLE, 1, &t.info, &ranges);
    CHECK(result == VK_ERROR_VALIDATION_FAILED_EXT);
    CHECK(run.TakeFindings() ==
          Strings{"VUID-vkBuildAccelerationStructuresKHR-accelerationStructureHostCommands-03581"});
    const Strings notices = run.TakeNotices();
    REQUIRE(notices.size() == 1);
    CHECK(Contains(notices[0], "vkBuildAccelerationStructuresKHR"));
    CHECK(Contains(notices[0], "accelerationStructureHostCommands-03581"));
    CheckValidSubmissionRuns(run, scene);
  }
  SECTION("history: a host property query of a structure never built") {
    ProtectRun run("history");
    vkkit::Device& device = run.device();
    Scene scene(device);
    const VkAccelerationStructureKHR never_built = scene.NewStructure(kBottom, 1 << 16);
    uint64_t value = 0;
    const VkResult result = Procs(device).HostWriteProperties(
        device.handle(), 1, &never_built, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR, sizeof(value),
        &value, sizeof(value));
    CHECK(result == VK_ERROR_VALIDATION_FAILED_EXT);
    CHECK(run.TakeFindings() ==
          Strings{"VUID-vkWriteAccelerationStructuresPropertiesKHR-pAccelerationStructures-04964"});
    const Strings notices = run.TakeNotices();
    REQUIRE(notices.size() == 1);
    CHECK(Contains(notices[0], "vkWriteAccelerationStructuresPropertiesKHR"));
    CheckValidSubmissionRuns(run, scene);
  }
}

// What a valid program computes: a bottom-level build, its update, a top-level build over it, the compacted and
// serialization sizes queried, a compaction and the serialized bytes.
struct ValidResults {
  uint64_t compacted_size = 0;
  uint64_t serialization_size = 0;
  std::vector<unsigned char> serialized;
};

ValidResults RunValidProgram(bool protect) {
  ProtectRun run(nullptr, protect);
  vkkit::Device& device = run.device();
  Inputs inputs(device);
  Blas blas(device, inputs), compacted(device, inputs);
  Tlas tlas(device);
  vkkit::Buffer instances = tlas.MakeInstances({&blas});
  QueryPool compacted_size(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR, 1);
  QueryPool serialization_size(device, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR, 1);
  Shape shape;
  shape.flags |= VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_COMPACTION_BIT_KHR;
  Commands commands(device);
  VkCommandBuffer cb = commands.Begin();
  compacted_size.Reset(cb);
  serialization_size.Reset(cb);
  blas.Build(cb, shape);
  commands.Barrier(cb);
  blas.Update(cb, shape);
  commands.Barrier(cb);
  tlas.Record(cb, instances, 1, VK_BUILD_ACCELERATION_STRUCTURE_MODE_BUILD_KHR);
  CmdWriteProperties(device, cb, {blas.handle()}, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_COMPACTED_SIZE_KHR,
                     compacted_size.handle(), 0);
  CmdWriteProperties(device, cb, {blas.handle()}, VK_QUERY_TYPE_ACCELERATION_STRUCTURE_SERIALIZATION_SIZE_KHR,
                     serialization_size.handle(), 0);
  commands.End(cb);
  Outcome first = SubmitWithFence(device, cb);
  CHECK(first.result == VK_SUCCESS);
  CHECK(first.signaled);
  ValidResults r;
  r.compacted_size = compacted_size.Results()[0];
  r.serialization_size = serialization_size.Results()[0];
  REQUIRE(r.serialization_size > 0);
  vkkit::Buffer bytes = device.CreateBuffer(r.serialization_size, VK_BUFFER_USAGE_TRANSFER_SRC_BIT);
  VkCommandBuffer copies = commands.Begin();
  CmdCopy(device, copies, blas.handle(), compacted.handle(), VK_COPY_ACCELERATION_STRUCTURE_MODE_COMPACT_KHR);
  CmdSerialize(device, copies, blas.handle(), bytes.address);
  commands.End(copies);
  Outcome second = SubmitWithFence(device, copies);
  CHECK(second.result == VK_SUCCESS);
  CHECK(second.signaled);
  const auto* data = static_cast<const unsigned char*>(bytes.mapped);
  r.serialized.assign(data, data + r.serialization_size);
  CHECK(run.TakeFindings() == Strings{});
  CHECK(run.TakeNotices() == Strings{});
  device.Destroy(bytes);
  device.Destroy(instances);
  return r;
}

TEST_CASE("protect valid twin: build, update, TLAS, compaction query, compaction and serialization give the same "
          "results with protect on and off, silently",
          "[integration][protect]") {
  const ValidResults off = RunValidProgram(false);
  const ValidResults on = RunValidProgram(true);
  CHECK(on.compacted_size > 0);
  CHECK(on.compacted_size == off.compacted_size);
  CHECK(on.serialization_size == off.serialization_size);
  CHECK(on.serialized == off.serialized);
  CHECK(std::count(on.serialized.begin(), on.serialized.end(), 0) < static_cast<long>(on.serialized.size()));
}

using ScopedEnv = ScopedEnvironment;  // scoped_env.h

bool KhronosLayerPresent() {
  uint32_t count = 0;
  vkEnumerateInstanceLayerProperties(&count, nullptr);
  std::vector<VkLayerProperties> layers(count);
  vkEnumerateInstanceLayerProperties(&count, layers.data());
  for (const VkLayerProperties& l : layers) {
    if (std::strcmp(l.layerName, "VK_LAYER_KHRONOS_validation") == 0) return true;
  }
  return false;
}

TEST_CASE("protect: the Khronos validation layer below asval never sees a protected command or submission",
          "[integration][protect]") {
  const char* path = std::getenv("VK_LAYER_PATH");
  const ScopedEnv layer_path("VK_LAYER_PATH", std::string(path ? path : "") + ":/usr/share/vulkan/explicit_layer.d");
  const ScopedEnv layers("ASVAL_TEST_LAYERS", "VK_LAYER_ASVAL_as_validation:VK_LAYER_KHRONOS_validation");
  // protect from the environment: the Khronos layer 1.3.239 would report a VkLayerSettingsCreateInfoEXT in pNext.
  const ScopedEnv protect("VK_ASVAL_AS_VALIDATION_PROTECT", "true");
  REQUIRE(KhronosLayerPresent());
  ProtectRun run(nullptr, false, "", /*settings_chain=*/false);
  vkkit::Device& device = run.device();
  Scene scene(device);
  Commands commands(device);
  // Record time: the Khronos layer checks 03710 as well; only asval's report arrives (one message).
  VkCommandBuffer misaligned = commands.Begin();
  TriangleInfo t(scene);
  t.info.scratchData.deviceAddress += device.as_properties().minAccelerationStructureScratchOffsetAlignment / 2;
  t.Record(device, misaligned);
  commands.End(misaligned);
  CHECK(run.TakeFindings() == Strings{"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710"});
  CHECK(run.TakeNotices().size() == 1);
  CHECK(SubmitWithFence(device, misaligned).result == VK_ERROR_VALIDATION_FAILED_EXT);
  CHECK(run.TakeFindings() == Strings{});
  CHECK(run.TakeNotices().size() == 1);
  // The withheld submission's emptied batch signals a semaphore that the next submission waits for: the Khronos
  // layer finds both valid (an unsignaled wait, or a signal left pending, would be reported).
  {
    const VkSemaphoreCreateInfo semaphore_info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO};
    VkSemaphore semaphore = VK_NULL_HANDLE;
    vkkit::Check(vkCreateSemaphore(device.handle(), &semaphore_info, nullptr, &semaphore), "vkCreateSemaphore");
    VkSubmitInfo signal{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    signal.commandBufferCount = 1;
    signal.pCommandBuffers = &misaligned;
    signal.signalSemaphoreCount = 1;
    signal.pSignalSemaphores = &semaphore;
    CHECK(vkQueueSubmit(device.queue(), 1, &signal, VK_NULL_HANDLE) == VK_ERROR_VALIDATION_FAILED_EXT);
    const VkPipelineStageFlags stage = VK_PIPELINE_STAGE_ALL_COMMANDS_BIT;
    VkSubmitInfo wait{VK_STRUCTURE_TYPE_SUBMIT_INFO};
    wait.waitSemaphoreCount = 1;
    wait.pWaitSemaphores = &semaphore;
    wait.pWaitDstStageMask = &stage;
    CHECK(vkQueueSubmit(device.queue(), 1, &wait, VK_NULL_HANDLE) == VK_SUCCESS);
    vkkit::Check(vkQueueWaitIdle(device.queue()), "vkQueueWaitIdle");
    vkDestroySemaphore(device.handle(), semaphore, nullptr);
    CHECK(run.TakeFindings() == Strings{});
    CHECK(run.TakeNotices().size() == 1);
  }
  // Submission: an update recorded before a rebuild with other flags, submitted after it. Valid when recorded (the
  // Khronos layer, which judges updates by the build recorded last, agrees), invalid in execution order.
  Inputs inputs(device);
  Blas blas(device, inputs);
  VkCommandBuffer build = commands.Begin();
  blas.Build(build, Shape{});
  commands.End(build);
  SubmitValid(run, build);
  VkCommandBuffer update = commands.Begin();
  blas.Update(update, Shape{});
  commands.End(update);
  Shape other_flags;
  other_flags.flags =
      VK_BUILD_ACCELERATION_STRUCTURE_ALLOW_UPDATE_BIT_KHR | VK_BUILD_ACCELERATION_STRUCTURE_PREFER_FAST_BUILD_BIT_KHR;
  VkCommandBuffer rebuild = commands.Begin();
  blas.Build(rebuild, other_flags);
  commands.End(rebuild);
  SubmitValid(run, rebuild);
  CheckWithheldSubmission(run, {update}, "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03759");
  CheckValidSubmissionRuns(run, scene);
}

TEST_CASE("protect off control: the Khronos validation layer below asval reports the command asval lets through",
          "[integration][protect][passes-invalid-down]") {
  const char* path = std::getenv("VK_LAYER_PATH");
  const ScopedEnv layer_path("VK_LAYER_PATH", std::string(path ? path : "") + ":/usr/share/vulkan/explicit_layer.d");
  const ScopedEnv layers("ASVAL_TEST_LAYERS", "VK_LAYER_ASVAL_as_validation:VK_LAYER_KHRONOS_validation");
  const ScopedEnv protect("VK_ASVAL_AS_VALIDATION_PROTECT", "false");
  REQUIRE(KhronosLayerPresent());
  ProtectRun run(nullptr, false, "", /*settings_chain=*/false);
  vkkit::Device& device = run.device();
  Scene scene(device);
  Commands commands(device);
  // Recorded, never submitted: the misaligned build reaches the Khronos layer, which reports it too.
  VkCommandBuffer misaligned = commands.Begin();
  TriangleInfo t(scene);
  t.info.scratchData.deviceAddress += device.as_properties().minAccelerationStructureScratchOffsetAlignment / 2;
  t.Record(device, misaligned);
  commands.End(misaligned);
  CHECK(run.TakeFindings() == Strings{"VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710",
                                      "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710"});
  CHECK(run.TakeNotices() == Strings{});
}

// The JSON report's lines as "severity vuid function".
Strings ReportSummary(const asval_test_common::TempReport& report) {
  Strings out;
  for (const std::string& line : report.Lines()) {
    const nlohmann::json j = nlohmann::json::parse(line);
    out.push_back(j.value("severity", "") + " " + j.value("vuid", "") + " " + j.value("function", ""));
  }
  return out;
}

constexpr const char* kChildReportEnv = "ASVAL_PROTECT_CHILD_REPORT";

// Run only by the test below, in a child process: protected calls, then an abort with everything still alive.
TEST_CASE("protect child: withheld calls, then abort()", "[.][protect-report-child]") {
  const char* path = std::getenv(kChildReportEnv);
  REQUIRE(path);
  ProtectRun run(nullptr, true, path);
  vkkit::Device& device = run.device();
  Scene scene(device);
  Commands commands(device);
  VkCommandBuffer cb = commands.Begin();
  RecordCases()[3].record(device, scene, cb);  // alignment: 03710
  commands.End(cb);
  REQUIRE(SubmitWithFence(device, cb).result == VK_ERROR_VALIDATION_FAILED_EXT);
  TriangleInfo host(scene);
  const VkAccelerationStructureBuildRangeInfoKHR* ranges = &host.range;
  REQUIRE(Procs(device).HostBuild(device.handle(), VK_NULL_HANDLE, 1, &host.info, &ranges) ==
          VK_ERROR_VALIDATION_FAILED_EXT);
  signal(SIGABRT, SIG_DFL);  // no handler of the test framework's: the app dies here
  std::abort();
}

TEST_CASE("protect: the JSON report holds every finding and every notice, one line each, when the app aborts right "
          "after",
          "[integration][protect]") {
  asval_test_common::TempReport report;
  std::vector<std::string> env;
  for (char** e = environ; *e; ++e) env.emplace_back(*e);
  env.push_back(std::string(kChildReportEnv) + "=" + report.path);
  std::vector<char*> envp;
  for (std::string& e : env) envp.push_back(e.data());
  envp.push_back(nullptr);
  char self[] = "/proc/self/exe";
  char filter[] = "[protect-report-child]";
  char* argv[] = {self, filter, nullptr};
  pid_t pid = 0;
  REQUIRE(posix_spawn(&pid, self, nullptr, nullptr, argv, envp.data()) == 0);
  int status = 0;
  REQUIRE(waitpid(pid, &status, 0) == pid);
  REQUIRE(WIFSIGNALED(status));
  CHECK(WTERMSIG(status) == SIGABRT);
  CHECK(ReportSummary(report) ==
        Strings{"error VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710 vkCmdBuildAccelerationStructuresKHR",
                "info ASVAL-Protect-Withheld vkCmdBuildAccelerationStructuresKHR",
                "info ASVAL-Protect-Withheld vkQueueSubmit",
                "error VUID-vkBuildAccelerationStructuresKHR-accelerationStructureHostCommands-03581 "
                "vkBuildAccelerationStructuresKHR",
                "info ASVAL-Protect-Withheld vkBuildAccelerationStructuresKHR"});
}

// Threads: four threads record at once (a pool each), some commands withheld, and submit under the app's queue lock
// (vkQueueSubmit's queue is externally synchronized): each submission gets its own verdict, marks never leak to
// another thread's command buffers, and every withheld call is named once. The tsan build runs it ([threads]).
TEST_CASE("protect: threads recording withheld and valid commands at once each get their own verdicts",
          "[integration][protect][threads]") {
  constexpr int kThreads = 4, kJobs = 24;
  ProtectRun run("alignment", /*protect=*/true, "", /*settings_chain=*/true, /*duplicate_limit=*/"0");
  vkkit::Device& device = run.device();
  Scene scene(device);
  std::vector<std::unique_ptr<TriangleInfo>> builds;  // one destination and scratch per thread
  for (int t = 0; t < kThreads; ++t) builds.push_back(std::make_unique<TriangleInfo>(scene));
  const VkDeviceSize misalign = device.as_properties().minAccelerationStructureScratchOffsetAlignment / 2;
  REQUIRE(misalign > 0);
  std::mutex queue_mutex;
  std::vector<std::string> problems(kThreads);
  auto work = [&](int t) {
    Commands commands(device);
    const TriangleInfo& valid = *builds[t];
    VkAccelerationStructureBuildGeometryInfoKHR invalid = valid.info;
    invalid.scratchData.deviceAddress += misalign;  // pInfos-03710
    const VkAccelerationStructureBuildRangeInfoKHR* ranges = &valid.range;
    for (int j = 0; j < kJobs; ++j) {
      const bool withheld = (j + t) % 3 == 0;
      VkCommandBuffer cb = commands.Begin();
      device.CmdBuildAccelerationStructuresKHR(cb, 1, withheld ? &invalid : &valid.info, &ranges);
      commands.End(cb);
      VkResult result;
      {
        std::lock_guard lock(queue_mutex);
        result = commands.Submit(cb);
      }
      const VkResult expected = withheld ? VK_ERROR_VALIDATION_FAILED_EXT : VK_SUCCESS;
      if (result != expected && problems[t].empty()) {
        problems[t] = "thread " + std::to_string(t) + " job " + std::to_string(j) + ": VkResult " +
                      std::to_string(result);
      }
    }
  };
  std::vector<std::thread> threads;
  for (int t = 0; t < kThreads; ++t) threads.emplace_back(work, t);
  for (std::thread& thread : threads) thread.join();
  CHECK(problems == Strings(kThreads));
  int withheld_jobs = 0;
  for (int t = 0; t < kThreads; ++t) {
    for (int j = 0; j < kJobs; ++j) withheld_jobs += (j + t) % 3 == 0;
  }
  CHECK(run.TakeFindings() ==
        Strings(static_cast<size_t>(withheld_jobs), "VUID-vkCmdBuildAccelerationStructuresKHR-pInfos-03710"));
  const Strings notices = run.TakeNotices();
  CHECK(notices.size() == static_cast<size_t>(2 * withheld_jobs));  // the command, then its submission
  CHECK(std::count_if(notices.begin(), notices.end(), [](const std::string& n) {
          return Contains(n, "lacks a command asval withheld");
        }) == withheld_jobs);
}


TEST_CASE("protect: a buffer destroyed while a pending build reads it is kept until the build completed, named by a "
          "notice (buffer-00922)",
          "[integration][protect][lifetime]") {
  ProtectRun run("lifetime", true, "", true, nullptr, TimelineDevice());
  vkkit::Device& device = run.device();
  auto inputs = std::make_unique<Inputs>(device);
  Blas blas(device, *inputs);
  Commands commands(device);
  Timeline gate(device);
  const VkCommandBuffer cb = Recorded(commands, [&](VkCommandBuffer c) { blas.Build(c, Shape{}); });
  REQUIRE(SubmitOn(device.queue(), cb, gate, 1, 2) == VK_SUCCESS);  // runs once the host signals 1
  const vkkit::Buffer held = inputs->buffer();
  vkDestroyBuffer(device.handle(), held.buffer, nullptr);  // kept back: the build still reads it
  vkFreeMemory(device.handle(), held.memory, nullptr);     // kept back too: the kept buffer is bound to it
  inputs->Forget();
  CHECK(run.TakeFindings() == Strings{"VUID-vkDestroyBuffer-buffer-00922", "VUID-vkFreeMemory-memory-00677"});
  const Strings notices = run.TakeNotices();
  REQUIRE(notices.size() == 2);
  CHECK(Contains(notices[0], "makes it once the work that uses the object completed"));
  // The build runs on the bytes it was given (nothing was freed under it), and the layer then makes both calls.
  CHECK(gate.HostSignal(1) == VK_SUCCESS);
  CHECK(vkQueueWaitIdle(device.queue()) == VK_SUCCESS);
  CHECK(run.TakeFindings().empty());
}

}  // namespace
}  // namespace asval_test
