// What goes down in place of a withheld submission (layer/loader/synchronization_only.h): the same batches without
// command buffers. Pure logic over the app's structures; the hooks' use of it is in protect_unit_test.cpp.
#include <catch2/catch_test_macros.hpp>

#include <vulkan/vulkan.h>

#include "synchronization_only.h"

namespace asval {
namespace {

template <typename T>
T Fake(uint64_t value) {
  return reinterpret_cast<T>(static_cast<uintptr_t>(value));
}

TEST_CASE("emptied submits: command buffers gone, waits, masks, signals and the app's chain kept", "[synchronization]") {
  const VkSemaphore waits[2] = {Fake<VkSemaphore>(1), Fake<VkSemaphore>(2)};
  const VkPipelineStageFlags masks[2] = {VK_PIPELINE_STAGE_TRANSFER_BIT, VK_PIPELINE_STAGE_ALL_COMMANDS_BIT};
  const VkSemaphore signal = Fake<VkSemaphore>(3);
  const VkCommandBuffer cbs[2] = {Fake<VkCommandBuffer>(4), Fake<VkCommandBuffer>(5)};
  VkTimelineSemaphoreSubmitInfo timeline{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
  VkSubmitInfo submits[2] = {{VK_STRUCTURE_TYPE_SUBMIT_INFO}, {VK_STRUCTURE_TYPE_SUBMIT_INFO}};
  submits[0].pNext = &timeline;
  submits[0].waitSemaphoreCount = 2;
  submits[0].pWaitSemaphores = waits;
  submits[0].pWaitDstStageMask = masks;
  submits[0].commandBufferCount = 2;
  submits[0].pCommandBuffers = cbs;
  submits[1].commandBufferCount = 1;
  submits[1].pCommandBuffers = cbs;
  submits[1].signalSemaphoreCount = 1;
  submits[1].pSignalSemaphores = &signal;

  const EmptiedSubmits emptied(2, submits);
  REQUIRE(emptied.count() == 2);
  const VkSubmitInfo* down = emptied.submits();
  CHECK(down[0].pNext == &timeline);
  CHECK(down[0].waitSemaphoreCount == 2);
  CHECK(down[0].pWaitSemaphores == waits);
  CHECK(down[0].pWaitDstStageMask == masks);
  CHECK(down[0].commandBufferCount == 0);
  CHECK(down[0].pCommandBuffers == nullptr);
  CHECK(down[1].commandBufferCount == 0);
  CHECK(down[1].signalSemaphoreCount == 1);
  CHECK(down[1].pSignalSemaphores == &signal);
  // The app's own structures are untouched.
  CHECK(submits[0].commandBufferCount == 2);
  CHECK(submits[1].pCommandBuffers == cbs);

  CHECK(EmptiedSubmits(0, nullptr).count() == 0);
  CHECK(EmptiedSubmits(0, nullptr).submits() == nullptr);
}

TEST_CASE("emptied submits: a device group's command buffer masks go, its semaphore indices and the timeline stay",
          "[synchronization]") {
  const uint32_t wait_indices[1] = {1};
  const uint32_t masks[2] = {3, 3};
  const uint32_t signal_indices[1] = {0};
  const uint64_t values[1] = {9};
  VkTimelineSemaphoreSubmitInfo timeline{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
  timeline.signalSemaphoreValueCount = 1;
  timeline.pSignalSemaphoreValues = values;
  // A structure the layer does not know (newer than its headers): dropped from the rebuilt chain.
  const VkBaseInStructure unknown{static_cast<VkStructureType>(1000999000),
                                  reinterpret_cast<const VkBaseInStructure*>(&timeline)};
  VkDeviceGroupSubmitInfo group{VK_STRUCTURE_TYPE_DEVICE_GROUP_SUBMIT_INFO};
  group.pNext = &unknown;
  group.waitSemaphoreCount = 1;
  group.pWaitSemaphoreDeviceIndices = wait_indices;
  group.commandBufferCount = 2;
  group.pCommandBufferDeviceMasks = masks;
  group.signalSemaphoreCount = 1;
  group.pSignalSemaphoreDeviceIndices = signal_indices;
  const VkCommandBuffer cbs[2] = {Fake<VkCommandBuffer>(4), Fake<VkCommandBuffer>(5)};
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.pNext = &group;
  submit.commandBufferCount = 2;
  submit.pCommandBuffers = cbs;

  const EmptiedSubmits emptied(1, &submit);
  const auto* first = static_cast<const VkDeviceGroupSubmitInfo*>(emptied.submits()[0].pNext);
  REQUIRE(first);
  CHECK(first != &group);  // a copy: the app's structure is const
  CHECK(first->sType == VK_STRUCTURE_TYPE_DEVICE_GROUP_SUBMIT_INFO);
  CHECK(first->commandBufferCount == 0);
  CHECK(first->pCommandBufferDeviceMasks == nullptr);
  CHECK(first->waitSemaphoreCount == 1);
  CHECK(first->pWaitSemaphoreDeviceIndices == wait_indices);
  CHECK(first->signalSemaphoreCount == 1);
  CHECK(first->pSignalSemaphoreDeviceIndices == signal_indices);
  const auto* second = static_cast<const VkTimelineSemaphoreSubmitInfo*>(first->pNext);
  REQUIRE(second);
  CHECK(second->sType == VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO);
  CHECK(second->pSignalSemaphoreValues == values);
  CHECK(second->pNext == nullptr);
  CHECK(group.commandBufferCount == 2);
}

TEST_CASE("emptied submits: a structure chained twice is linked once (no loop)", "[synchronization]") {
  VkTimelineSemaphoreSubmitInfo again{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
  VkTimelineSemaphoreSubmitInfo timeline{VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO};
  timeline.pNext = &again;
  VkDeviceGroupSubmitInfo group{VK_STRUCTURE_TYPE_DEVICE_GROUP_SUBMIT_INFO};
  group.pNext = &timeline;
  VkSubmitInfo submit{VK_STRUCTURE_TYPE_SUBMIT_INFO};
  submit.pNext = &group;
  const EmptiedSubmits emptied(1, &submit);
  int links = 0;
  for (auto s = static_cast<const VkBaseInStructure*>(emptied.submits()[0].pNext); s && links < 10; s = s->pNext) {
    ++links;
  }
  CHECK(links == 2);
}

TEST_CASE("emptied submits2: command buffer infos gone, semaphore infos and chain kept", "[synchronization]") {
  VkSemaphoreSubmitInfo wait{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
  VkSemaphoreSubmitInfo signal{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
  VkCommandBufferSubmitInfo cb{VK_STRUCTURE_TYPE_COMMAND_BUFFER_SUBMIT_INFO};
  VkPerformanceQuerySubmitInfoKHR pass{VK_STRUCTURE_TYPE_PERFORMANCE_QUERY_SUBMIT_INFO_KHR};
  VkSubmitInfo2 submit{VK_STRUCTURE_TYPE_SUBMIT_INFO_2};
  submit.pNext = &pass;
  submit.flags = VK_SUBMIT_PROTECTED_BIT;
  submit.waitSemaphoreInfoCount = 1;
  submit.pWaitSemaphoreInfos = &wait;
  submit.commandBufferInfoCount = 1;
  submit.pCommandBufferInfos = &cb;
  submit.signalSemaphoreInfoCount = 1;
  submit.pSignalSemaphoreInfos = &signal;
  const EmptiedSubmits2 emptied(1, &submit);
  REQUIRE(emptied.count() == 1);
  const VkSubmitInfo2& down = emptied.submits()[0];
  CHECK(down.pNext == &pass);
  CHECK(down.flags == VK_SUBMIT_PROTECTED_BIT);
  CHECK(down.pWaitSemaphoreInfos == &wait);
  CHECK(down.pSignalSemaphoreInfos == &signal);
  CHECK(down.commandBufferInfoCount == 0);
  CHECK(down.pCommandBufferInfos == nullptr);
}

}  // namespace
}  // namespace asval
