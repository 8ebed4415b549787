#include "submission_hold.h"

#include "driver_dispatch.h"

namespace asval_test_driver {

namespace {

const VkTimelineSemaphoreSubmitInfo* TimelineInfoOf(const void* next) {
  for (auto* s = static_cast<const VkBaseInStructure*>(next); s != nullptr; s = s->pNext) {
    if (s->sType == VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO) {
      return reinterpret_cast<const VkTimelineSemaphoreSubmitInfo*>(s);
    }
  }
  return nullptr;
}

}  // namespace

VkResult SubmissionHold::Hold(DeviceData& device, bool hold) {
  if (hold == held_) return VK_SUCCESS;
  if (semaphore_ == VK_NULL_HANDLE) {
    VkSemaphoreTypeCreateInfo type{VK_STRUCTURE_TYPE_SEMAPHORE_TYPE_CREATE_INFO};
    type.semaphoreType = VK_SEMAPHORE_TYPE_TIMELINE;
    VkSemaphoreCreateInfo info{VK_STRUCTURE_TYPE_SEMAPHORE_CREATE_INFO, &type};
    const VkResult created = device.vk.CreateSemaphore(device.device, &info, nullptr, &semaphore_);
    if (created != VK_SUCCESS) return created;
  }
  if (hold) {
    ++value_;
    held_ = true;
    return VK_SUCCESS;
  }
  held_ = false;
  VkSemaphoreSignalInfo signal{VK_STRUCTURE_TYPE_SEMAPHORE_SIGNAL_INFO};
  signal.semaphore = semaphore_;
  signal.value = value_;
  return device.vk.SignalSemaphore(device.device, &signal);
}

const VkSubmitInfo* SubmissionHold::Submits(uint32_t count, const VkSubmitInfo* submits) {
  if (!held_ || count == 0) return submits;
  submits_.assign(submits, submits + count);
  VkSubmitInfo& first = submits_[0];
  const VkTimelineSemaphoreSubmitInfo* timeline = TimelineInfoOf(first.pNext);
  waits_.assign(first.pWaitSemaphores, first.pWaitSemaphores + first.waitSemaphoreCount);
  stages_.assign(first.pWaitDstStageMask, first.pWaitDstStageMask + first.waitSemaphoreCount);
  values_.assign(first.waitSemaphoreCount, 0);
  if (timeline != nullptr && timeline->pWaitSemaphoreValues != nullptr) {
    for (uint32_t w = 0; w < timeline->waitSemaphoreValueCount && w < first.waitSemaphoreCount; ++w) {
      values_[w] = timeline->pWaitSemaphoreValues[w];
    }
  }
  waits_.push_back(semaphore_);
  stages_.push_back(VK_PIPELINE_STAGE_ALL_COMMANDS_BIT);
  values_.push_back(value_);
  first.waitSemaphoreCount = static_cast<uint32_t>(waits_.size());
  first.pWaitSemaphores = waits_.data();
  first.pWaitDstStageMask = stages_.data();
  // The batch's own timeline info, if any, is taken over: its signal values stay, its wait values gain ours.
  timeline_ = timeline != nullptr ? *timeline : VkTimelineSemaphoreSubmitInfo{};
  timeline_.sType = VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO;
  timeline_.waitSemaphoreValueCount = static_cast<uint32_t>(values_.size());
  timeline_.pWaitSemaphoreValues = values_.data();
  if (timeline == nullptr) {
    timeline_.pNext = first.pNext;
    first.pNext = &timeline_;
  } else if (first.pNext == timeline) {
    timeline_.pNext = timeline->pNext;
    first.pNext = &timeline_;
  }  // else: a timeline info deeper in the app's const chain is not rewritten (no test holds such a batch)
  return submits_.data();
}

const VkSubmitInfo2* SubmissionHold::Submits2(uint32_t count, const VkSubmitInfo2* submits) {
  if (!held_ || count == 0) return submits;
  submits2_.assign(submits, submits + count);
  VkSubmitInfo2& first = submits2_[0];
  waits2_.assign(first.pWaitSemaphoreInfos, first.pWaitSemaphoreInfos + first.waitSemaphoreInfoCount);
  VkSemaphoreSubmitInfo held{VK_STRUCTURE_TYPE_SEMAPHORE_SUBMIT_INFO};
  held.semaphore = semaphore_;
  held.value = value_;
  held.stageMask = VK_PIPELINE_STAGE_2_ALL_COMMANDS_BIT;
  waits2_.push_back(held);
  first.waitSemaphoreInfoCount = static_cast<uint32_t>(waits2_.size());
  first.pWaitSemaphoreInfos = waits2_.data();
  return submits2_.data();
}

void SubmissionHold::Destroy(DeviceData& device) {
  if (semaphore_ != VK_NULL_HANDLE) device.vk.DestroySemaphore(device.device, semaphore_, nullptr);
  semaphore_ = VK_NULL_HANDLE;
}

}  // namespace asval_test_driver
