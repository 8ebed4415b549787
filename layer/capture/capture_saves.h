#pragma once
// vkCmdExecuteCommands of a secondary whose captures the primary's recording already reads (a SIMULTANEOUS_USE
// secondary executed twice; issue 25): the recorder (history_recorder.h, RecordExecuteCommands) asks for the bytes
// the executions so far wrote to be saved before the next execution writes them again. This records that into the
// primary, through the next element of the chain: the app's secondaries before it (vkCmdExecuteCommands of that
// part of the app's array: executing them in two calls is executing them in one), a barrier that makes the
// captures' writes visible to a transfer read, one vkCmdCopyBuffer per slab of the log into the slab of the same
// index of its copy, and a barrier that makes the copies visible to the host and orders later writes (the next
// execution's captures, which overwrite what was just read) after them.
//
// Only outside a render pass instance: a secondary holding captures holds builds or serializations, which a valid
// app records outside one, and executes outside one (a secondary executed inside one must continue it, and then may
// not hold such commands). The layer's own slabs are the only buffers named.
#include <vulkan/vulkan.h>

#include "history_recorder.h"
#include "vk_dispatch_table.h"

namespace asval {

class ExecuteCommandsSaver final : public CaptureSaver {
 public:
  ExecuteCommandsSaver(const DeviceDispatchTable& next, VkCommandBuffer primary, const VkCommandBuffer* secondaries)
      : next_(next), primary_(primary), secondaries_(secondaries) {}
  void PassDown(uint32_t next) override {
    if (next > passed_) next_.CmdExecuteCommands(primary_, next - passed_, secondaries_ + passed_);
    if (next > passed_) passed_ = next;
  }
  bool RecordCopy(const CaptureLog& from, const CaptureLog& to) override;

 private:
  const DeviceDispatchTable& next_;
  const VkCommandBuffer primary_;
  const VkCommandBuffer* const secondaries_;
  uint32_t passed_ = 0;  // the app's secondaries before this index went down
};

}  // namespace asval
