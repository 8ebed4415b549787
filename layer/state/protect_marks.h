#pragma once
// Protect mode's state (setting `protect`; layer/report/protect_scope.h): what a command buffer's recording lost
// because the layer kept a command of it from the driver, and how many calls the layer withheld on a device.
// A command buffer with such a command must never execute: what it records after that command may depend on it
// (a trace of a structure that was never built), so its submissions are withheld whole until it is recorded again.
#include <vulkan/vulkan.h>

#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <string_view>

namespace asval {

// The first command withheld from a recording (or from a secondary the recording executes), named in the notice
// of each submission withheld because of it.
struct WithheldCommand {
  std::string function;  // e.g. "vkCmdBuildAccelerationStructuresKHR"
  std::string vuid;      // the error that withheld it (newest spelling)
  std::string where;     // where that error was found, e.g. "vkCmdBuildAccelerationStructuresKHR(): pInfos[0].mode"
};

// An error judged when a submission completed (execution-time capture): the work that broke the rule already ran,
// and what it built may be corrupt, so every later submission on the device is withheld (a trace of such a
// structure is what hangs a GPU). Set once; the first such finding is kept and named.
class SubmissionHalt {
 public:
  void Set(std::shared_ptr<const WithheldCommand> cause) {
    std::lock_guard<std::mutex> lock(mutex_);
    if (cause_) return;
    cause_ = std::move(cause);
    halted_.store(true, std::memory_order_release);
  }
  // The finding that halted submissions, or null: a single load while none did.
  std::shared_ptr<const WithheldCommand> Cause() const {
    if (!halted_.load(std::memory_order_acquire)) return nullptr;
    std::lock_guard<std::mutex> lock(mutex_);
    return cause_;
  }

 private:
  std::atomic<bool> halted_{false};
  mutable std::mutex mutex_;
  std::shared_ptr<const WithheldCommand> cause_;
};

// Counted in ASVAL-History-Summary at vkDestroyDevice (layer/checks/protect_notices.h).
struct ProtectCounters {
  std::atomic<uint64_t> commands_withheld{0};       // recorded commands not passed down (their buffers marked)
  std::atomic<uint64_t> submissions_withheld{0};    // queue submissions not passed down
  std::atomic<uint64_t> host_commands_withheld{0};  // host builds, copies and property writes not run
  // Withheld submissions whose emptied batches (layer/loader/synchronization_only.h) the layer could not make (its
  // allocation failed): nothing of them went down, so their fence and semaphores were not signaled.
  std::atomic<uint64_t> synchronizations_lost{0};
};

class DeviceState;

// Protect mode withheld a command recorded into cb (the hook did not pass it down): cb is marked so that its
// submissions are withheld too, and the command counted. False when cb could not be marked (the layer never saw it
// allocated). An allocation failure marks it with an unnamed command.
bool RecordWithheldCommand(DeviceState& state, VkCommandBuffer cb, std::string_view function, std::string_view vuid,
                           std::string_view where);
// Protect mode: an error was judged at completion (`function` names the command whose completion showed it, e.g.
// "vkCmdBuildAccelerationStructuresKHR"); every later submission on the device is withheld.
void RecordSubmissionHalt(DeviceState& state, std::string_view function, std::string_view vuid,
                          std::string_view where);
// A queue submission, or a host command, protect mode kept from the driver.
void RecordWithheldSubmission(DeviceState& state);
void RecordWithheldHostCommand(DeviceState& state);
// A withheld submission's emptied batches could not be made: nothing of it went down.
void RecordSynchronizationLost(DeviceState& state);

}  // namespace asval
