#include "capture_saves.h"

namespace asval {

bool ExecuteCommandsSaver::RecordCopy(const CaptureLog& from, const CaptureLog& to) {
  if (!next_.CmdCopyBuffer || !next_.CmdPipelineBarrier || from.slabs.size() != to.slabs.size()) return false;
  // The executions' captures (copies, the reducing dispatch's writes) visible to the transfer read.
  VkMemoryBarrier before{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  before.srcAccessMask = VK_ACCESS_MEMORY_WRITE_BIT;
  before.dstAccessMask = VK_ACCESS_TRANSFER_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  next_.CmdPipelineBarrier(primary_, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, VK_PIPELINE_STAGE_TRANSFER_BIT, 0, 1, &before,
                           0, nullptr, 0, nullptr);
  for (uint32_t k = 0; k < from.slabs.size(); ++k) {
    const VkDeviceSize used = from.UsedBytes(k);
    if (used == 0) continue;
    const VkBufferCopy region{0, 0, used};
    next_.CmdCopyBuffer(primary_, from.slabs[k].buffer, to.slabs[k].buffer, 1, &region);
  }
  // The copies visible to the host once the submission completes; the next execution's captures (and a later
  // execution of the primary, which writes `to` again) wait for them: the same barrier as after a capture.
  VkMemoryBarrier after{VK_STRUCTURE_TYPE_MEMORY_BARRIER};
  after.srcAccessMask = VK_ACCESS_TRANSFER_WRITE_BIT;
  after.dstAccessMask = VK_ACCESS_HOST_READ_BIT | VK_ACCESS_TRANSFER_WRITE_BIT;
  next_.CmdPipelineBarrier(primary_, VK_PIPELINE_STAGE_TRANSFER_BIT,
                           VK_PIPELINE_STAGE_HOST_BIT | VK_PIPELINE_STAGE_ALL_COMMANDS_BIT, 0, 1, &after, 0, nullptr,
                           0, nullptr);
  return true;
}

}  // namespace asval
