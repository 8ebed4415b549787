#pragma once
// Per-instance and per-device data is keyed by the loader's dispatch-table pointer, the first word of every
// dispatchable handle: a VkDevice, its VkQueues and its VkCommandBuffers share one key, so one lookup serves
// all of them and no handle is wrapped (loader docs, "Hash Maps").
#include <atomic>
#include <array>
#include <memory>
#include <mutex>
#include <unordered_map>

namespace asval {

using DispatchKey = void*;

template <typename Handle>
DispatchKey GetDispatchKey(Handle handle) {
  return *reinterpret_cast<void* const*>(handle);
}

// Maps dispatch keys to layer data. Lookups are lock-free over a small array of slots (applications hold a
// handful of instances and devices); only creation and destruction take the mutex. The Vulkan rules on
// object lifetime (no call on a device after vkDestroyDevice returns) make a raw pointer safe for the
// duration of a call. Beyond kSlots live entries the overflow map is used, under the mutex.
template <typename T>
class DispatchRegistry {
 public:
  T* Find(DispatchKey key) const {
    for (const Slot& slot : slots_) {
      if (slot.key.load(std::memory_order_acquire) == key) return slot.value.load(std::memory_order_relaxed);
    }
    if (overflow_used_.load(std::memory_order_acquire)) {
      std::lock_guard lock(mutex_);
      auto it = overflow_.find(key);
      if (it != overflow_.end()) return it->second.get();
    }
    return nullptr;
  }

  T* Insert(DispatchKey key, std::unique_ptr<T> data) {
    std::lock_guard lock(mutex_);
    T* raw = data.get();
    owned_[key] = std::move(data);
    for (Slot& slot : slots_) {
      if (slot.key.load(std::memory_order_relaxed) == nullptr) {
        slot.value.store(raw, std::memory_order_relaxed);
        slot.key.store(key, std::memory_order_release);
        return raw;
      }
    }
    overflow_[key] = std::move(owned_[key]);
    owned_.erase(key);
    overflow_used_.store(true, std::memory_order_release);
    return raw;
  }

  // Removes and returns the data so that the caller can finish with it after the map no longer lists it.
  std::unique_ptr<T> Remove(DispatchKey key) {
    std::lock_guard lock(mutex_);
    for (Slot& slot : slots_) {
      if (slot.key.load(std::memory_order_relaxed) == key) {
        slot.key.store(nullptr, std::memory_order_release);
        slot.value.store(nullptr, std::memory_order_relaxed);
        auto node = owned_.extract(key);
        return node ? std::move(node.mapped()) : nullptr;
      }
    }
    auto node = overflow_.extract(key);
    return node ? std::move(node.mapped()) : nullptr;
  }

 private:
  static constexpr size_t kSlots = 32;
  struct Slot {
    std::atomic<DispatchKey> key{nullptr};
    std::atomic<T*> value{nullptr};
  };
  std::array<Slot, kSlots> slots_{};
  mutable std::mutex mutex_;
  std::unordered_map<DispatchKey, std::unique_ptr<T>> owned_;     // entries that live in slots_
  std::unordered_map<DispatchKey, std::unique_ptr<T>> overflow_;  // entries beyond kSlots
  std::atomic<bool> overflow_used_{false};
};

}  // namespace asval
