#pragma once
// Applies the operations of submitted command buffers to the structures' histories, in submission order
// (batches in order, command buffers in order, operations in recording order), checking each against the
// history that the operations before it left. Findings are reported after the history lock is released.
//
//   SubmitHistory submit(data->state, reporter, enabled, "vkQueueSubmit");
//   for each batch i, command buffer j: submit.Apply(cb, Location("vkQueueSubmit").Field("pSubmits", i)...);
//   if (submit.Finish()) return VK_ERROR_VALIDATION_FAILED_EXT;  // the app asked to skip: changes undone
//   result = downcall; if (result != VK_SUCCESS) submit.Undo();
#include <vulkan/vulkan.h>

#include <mutex>

#include "device_state.h"
#include "history_findings.h"

namespace asval {

// True when the settings enable a family that needs the history (history, or copies for dst-03561).
bool HistoryTracked(uint32_t enabled_checks);

class SubmitHistory {
 public:
  SubmitHistory(DeviceState& state, Reporter& reporter, uint32_t enabled_checks);
  SubmitHistory(const SubmitHistory&) = delete;
  SubmitHistory& operator=(const SubmitHistory&) = delete;

  // One submitted command buffer; loc names it in the submit call's parameters.
  void Apply(VkCommandBuffer cb, const Location& loc);
  // Releases the lock and reports. Returns true when a callback asked to skip the submission; its changes are
  // then undone.
  bool Finish();
  // The driver rejected the submission: it did not happen.
  void Undo();

  uint64_t ops_applied() const { return ops_applied_; }

 private:
  DeviceState& state_;
  Reporter& reporter_;
  const uint32_t enabled_;
  std::unique_lock<std::mutex> lock_;  // taken at the first command buffer with operations
  Transaction txn_;
  HistoryFindings findings_;
  uint64_t ops_applied_ = 0;
};

}  // namespace asval
