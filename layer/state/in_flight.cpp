#include "in_flight.h"

#include <algorithm>
#include <new>

#include "layer_fences.h"

namespace asval {

namespace {

// How long a batch whose fence reads unsignaled is given before it counts as running: a semaphore signal of its
// submission precedes the fence signal, and an app may have learned of completion through it a moment before.
constexpr uint64_t kGraceNs = 2ull * 1000 * 1000;

void Clear(InFlightBatch& b) {
  b.serial = 0;
  b.queue = VK_NULL_HANDLE;
  b.function = nullptr;
  b.submit_index = 0;
  b.fence = VK_NULL_HANDLE;
  b.own_fence = false;
  b.complete = false;
  b.host_may_know = false;
  b.recorded.clear();
  b.traced_tops.clear();
  b.timeline_signals.clear();
  b.binary_signals.clear();
}

}  // namespace

InFlight::~InFlight() {
  for (Deferred& d : deferred_) d.destroy();
  for (const InFlightBatch& b : batches_) {
    if (b.own_fence && b.fence) {
      // Destroyed once: batches of one submission share it.
      const bool first = &b == &*std::find_if(batches_.begin(), batches_.end(),
                                              [&](const InFlightBatch& o) { return o.fence == b.fence; });
      if (first) next_.DestroyFence(device_, b.fence, nullptr);
    }
  }
  for (VkFence f : free_fences_) next_.DestroyFence(device_, f, nullptr);
}

InFlightBatch& InFlight::Stage(std::vector<InFlightBatch>& staging) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!spare_.empty()) {
      staging.push_back(std::move(spare_.back()));
      spare_.pop_back();
      Clear(staging.back());
      return staging.back();
    }
  }
  return staging.emplace_back();
}

void InFlight::Commit(std::vector<InFlightBatch>& staging, VkFence fence, bool own) {
  if (staging.empty()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  for (InFlightBatch& b : staging) {
    b.fence = fence;
    b.own_fence = own;
    batches_.push_back(std::move(b));
  }
  staging.clear();
  count_.store(batches_.size(), std::memory_order_release);
}

void InFlight::Abandon(std::vector<InFlightBatch>& staging) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (InFlightBatch& b : staging) {
    try {
      spare_.push_back(std::move(b));
    } catch (const std::bad_alloc&) {
      break;  // not kept for reuse
    }
  }
  staging.clear();
}

VkFence InFlight::TakeFence() { return TakeLayerFence(device_, next_, mutex_, free_fences_); }

void InFlight::ReturnFence(VkFence fence) {
  if (fence) next_.DestroyFence(device_, fence, nullptr);
}

void InFlight::CompleteUpTo(std::size_t index) {
  const VkQueue queue = batches_[index].queue;
  for (std::size_t k = 0; k <= index; ++k) {
    if (batches_[k].queue == queue) batches_[k].complete = true;
  }
}

void InFlight::QueueIdle(VkQueue queue) {
  if (Empty()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  for (InFlightBatch& b : batches_) {
    if (!queue || b.queue == queue) b.complete = true;
  }
  RetireCompleted();
}

void InFlight::FencesSignaled(uint32_t count, const VkFence* fences) {
  if (Empty() || !fences) return;
  std::lock_guard<std::mutex> lock(mutex_);
  for (std::size_t k = batches_.size(); k-- > 0;) {
    const InFlightBatch& b = batches_[k];
    if (b.own_fence || !b.fence || b.complete) continue;
    for (uint32_t f = 0; f < count; ++f) {
      if (fences[f] == b.fence) {
        CompleteUpTo(k);
        break;
      }
    }
  }
  RetireCompleted();
}

void InFlight::FenceRetired(VkFence fence) {
  if (Empty() || !fence) return;
  std::lock_guard<std::mutex> lock(mutex_);
  for (std::size_t k = batches_.size(); k-- > 0;) {
    InFlightBatch& b = batches_[k];
    if (b.own_fence || b.fence != fence) continue;
    CompleteUpTo(k);
    b.fence = VK_NULL_HANDLE;  // the handle may name another submission from now on
  }
  for (InFlightBatch& b : batches_) {
    if (!b.own_fence && b.fence == fence) b.fence = VK_NULL_HANDLE;
  }
  RetireCompleted();
}

void InFlight::SemaphoreDestroyed(VkSemaphore semaphore) {
  if (Empty()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  for (std::size_t k = batches_.size(); k-- > 0;) {
    InFlightBatch& b = batches_[k];
    const auto named = [&](const SemaphoreUse& s) { return s.semaphore == semaphore; };
    const bool timeline =
        std::find_if(b.timeline_signals.begin(), b.timeline_signals.end(), named) != b.timeline_signals.end();
    const bool binary =
        std::find(b.binary_signals.begin(), b.binary_signals.end(), semaphore) != b.binary_signals.end();
    if (!timeline && !binary) continue;
    if (!b.complete) CompleteUpTo(k);
    b.timeline_signals.erase(std::remove_if(b.timeline_signals.begin(), b.timeline_signals.end(), named),
                             b.timeline_signals.end());
    b.binary_signals.erase(std::remove(b.binary_signals.begin(), b.binary_signals.end(), semaphore),
                           b.binary_signals.end());
  }
  RetireCompleted();
}

void InFlight::BinaryWaited(VkQueue queue, VkSemaphore semaphore) {
  if (Empty()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  for (InFlightBatch& b : batches_) {
    if (b.complete || b.queue == queue) continue;
    if (std::find(b.binary_signals.begin(), b.binary_signals.end(), semaphore) != b.binary_signals.end()) {
      b.host_may_know = true;
    }
  }
}

void InFlight::HostReadDeviceProgress() {
  if (Empty()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  for (InFlightBatch& b : batches_) b.host_may_know = true;
}

bool InFlight::StillRunning(InFlightBatch& b) {
  const std::size_t index = static_cast<std::size_t>(&b - &batches_[0]);
  for (const SemaphoreUse& s : b.timeline_signals) {
    uint64_t value = 0;
    if (next_.GetSemaphoreCounterValue && next_.GetSemaphoreCounterValue(device_, s.semaphore, &value) == VK_SUCCESS &&
        value >= s.value) {
      CompleteUpTo(index);
      return false;
    }
  }
  VkResult status = next_.GetFenceStatus(device_, b.fence);
  if (status == VK_NOT_READY) status = next_.WaitForFences(device_, 1, &b.fence, VK_TRUE, kGraceNs);
  if (status == VK_SUCCESS) {
    CompleteUpTo(index);
    return false;
  }
  // VK_TIMEOUT: running. A lost device: nothing will run any more, not reported.
  return status == VK_TIMEOUT || status == VK_NOT_READY;
}

void InFlight::Poll() {
  if (Empty()) return;
  std::lock_guard<std::mutex> lock(mutex_);
  for (std::size_t k = batches_.size(); k-- > 0;) {
    const InFlightBatch& b = batches_[k];
    if (b.complete || !b.fence) continue;
    if (next_.GetFenceStatus(device_, b.fence) == VK_SUCCESS) {
      CompleteUpTo(k);
      break;  // every earlier batch of its queue is complete too; other queues' are polled next time
    }
  }
  RetireCompleted();
}

void InFlight::RetireCompleted() {
  while (!batches_.empty()) {
    InFlightBatch& b = batches_.front();
    // Not known complete (without a fence: until a wait of its queue or the device; its uses are skipped).
    if (!b.complete) break;
    if (b.own_fence && b.fence) {
      // Reused only once it reads signaled (a fence may be reset only when its submission completed); the
      // batches of one submission share it: the last of them gives it back.
      if (next_.GetFenceStatus(device_, b.fence) != VK_SUCCESS) break;
      const bool shared = batches_.size() > 1 && batches_[1].fence == b.fence && batches_[1].own_fence;
      if (!shared) {
        if (recycled_) recycled_(recycled_context_, b.fence);
        try {
          free_fences_.push_back(b.fence);
          next_.ResetFences(device_, 1, &b.fence);
        } catch (const std::bad_alloc&) {
          next_.DestroyFence(device_, b.fence, nullptr);
        }
      }
    }
    try {
      Clear(b);
      spare_.push_back(std::move(b));
    } catch (const std::bad_alloc&) {
    }
    batches_.pop_front();
  }
  count_.store(batches_.size(), std::memory_order_release);
  if (deferred_.empty()) return;
  uint64_t oldest = ~uint64_t{0};
  for (const InFlightBatch& b : batches_) {
    if (!b.complete) oldest = std::min(oldest, b.serial);
  }
  for (std::size_t k = 0; k < deferred_.size();) {
    if (deferred_[k].serial <= oldest) {
      deferred_[k].destroy();
      deferred_.erase(deferred_.begin() + static_cast<std::ptrdiff_t>(k));
    } else {
      ++k;
    }
  }
}

void InFlight::Defer(uint64_t serial, std::function<void()> destroy, VkBuffer buffer, VkDeviceMemory memory) {
  std::lock_guard<std::mutex> lock(mutex_);
  deferred_.push_back({serial, std::move(destroy), buffer, memory});
}

VkBuffer InFlight::DeferredBufferOn(VkDeviceMemory memory) const {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const Deferred& d : deferred_) {
    if (d.memory == memory && d.buffer) return d.buffer;
  }
  return VK_NULL_HANDLE;
}

}  // namespace asval
