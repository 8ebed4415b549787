#pragma once
// What the execution-time capture tests share: the barrier that makes device writes of build inputs visible to
// the build, a submission waited for in one of the ways the layer reads captures in, and the assertion that
// exactly one finding was reported.
#include <vulkan/vulkan.h>

#include <functional>
#include <string>

#include "history_helpers.h"
#include "monitor.h"
#include "vkkit.h"

namespace asval_test {

// The transfer writes recorded so far (vkCmdUpdateBuffer, vkCmdFillBuffer) made visible to the build stage's reads.
void InputsWritten(VkCommandBuffer cb);

// A new primary command buffer of `commands` holding what `record` records, ended.
VkCommandBuffer RecordWith(Commands& commands, const std::function<void(VkCommandBuffer)>& record);

// How a test learns that its submission completed: each is a point where the layer reads the captures.
enum class Wait { kQueueIdle, kFence, kFenceStatus, kDeviceIdle };

// Submits cb alone and waits for it as `wait` says.
void SubmitAndWait(vkkit::Device& device, VkCommandBuffer cb, Wait wait = Wait::kQueueIdle);

// Whether the environment makes this run reduce the captures on the device (CMakeLists.txt:
// integration_capture_reduce sets VK_ASVAL_AS_VALIDATION_CAPTURE_METHOD=reduce, which wins over a test's
// capture_method=copy): what a recording captures is then counted in other bytes.
bool CaptureReducedRun();

// Empty when the only message since the last check is one `vuid` whose text holds `text`; else what was seen.
std::string OnlyFinding(Monitor& monitor, const char* vuid, const std::string& text);

}  // namespace asval_test
