#pragma once
// What the execution-time capture tests share: the barrier that makes device writes of build inputs visible to
// the build, a submission waited for in one of the ways the layer reads captures in, and the assertion that
// exactly one finding was reported.
#include <vulkan/vulkan.h>

#include <cstring>
#include <functional>
#include <string>
#include <vector>

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

// The inputs the capture tests write on the device (history_helpers.h's Inputs): R32G32B32_SFLOAT vertices.
inline constexpr uint32_t kNan = 0x7fc00000u;  // the quiet NaN
inline constexpr VkDeviceSize kVertexBytes = 12;  // R32G32B32_SFLOAT, tightly packed (the helpers' vertexStride)

inline uint32_t Bits(float value) {
  uint32_t bits;
  std::memcpy(&bits, &value, sizeof(bits));
  return bits;
}

// Where component c (0: X) of vertex v lies in the inputs buffer.
inline VkDeviceSize Component(uint32_t v, uint32_t c) { return Inputs::kVerticesOffset + kVertexBytes * v + 4 * c; }

// Six vertices: triangles (0, 1, 2) and (3, 4, 5), unit right triangles at z = 0 and z = 1, moved by dx along X.
inline std::vector<uint32_t> Vertices(float dx = 0) {
  const float corner[3][2] = {{0, 0}, {1, 0}, {0, 1}};
  std::vector<uint32_t> words;
  for (uint32_t v = 0; v < 6; ++v) {
    words.push_back(Bits(corner[v % 3][0] + dx));
    words.push_back(Bits(corner[v % 3][1]));
    words.push_back(Bits(static_cast<float>(v / 3)));
  }
  return words;
}

// Empty when the only message since the last check is one `vuid` whose text holds `text`; else what was seen.
std::string OnlyFinding(Monitor& monitor, const char* vuid, const std::string& text);

}  // namespace asval_test
