#pragma once
// When structures and buffers came and went (DeviceState::NextObjectId), so that a submission can tell a command
// recorded while the object it names lived from one recorded with a handle or address that never named one, or one
// whose handle now names a newer object (issue 29: a command buffer whose recorded structure or buffer was destroyed
// since is invalid, VUID-vkQueueSubmit-pCommandBuffers-00070). Handles and addresses are reused: only the serials say
// which object a recording named.
//
// The newest creation and destruction are kept as atomics (the one load a submission pays while nothing happened
// since its recording); destroys are kept in two fixed rings (no allocation): the oldest entries are dropped, and a
// question about a recording older than the newest dropped entry's destruction may have lost its answer: kUnknown
// (counted by the caller, never guessed). Destroys are rare next to recorded commands: one lock for both rings.
#include <vulkan/vulkan.h>

#include <array>
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <mutex>

namespace asval {

class ObjectLifetimes {
 public:
  static constexpr std::size_t kCapacity = 256;

  struct Structure {
    VkAccelerationStructureKHR handle;
    uint64_t created;    // AccelerationStructureState::serial
    uint64_t destroyed;  // NextObjectId() at vkDestroyAccelerationStructureKHR
  };
  struct Buffer {
    VkBuffer handle;
    VkDeviceAddress address;  // BufferState::device_address (buffers without one are not kept)
    VkDeviceSize size;
    uint64_t bound;      // BufferState::bound_serial
    uint64_t destroyed;  // NextObjectId() at vkDestroyBuffer
  };
  enum class Answer : uint8_t { kNo, kYes, kUnknown };

  // A structure was created with this serial (AccelerationStructureState::serial).
  void StructureCreated(uint64_t serial) { RaiseTo(structures_created_, serial); }
  void AddStructure(const Structure& structure);
  void AddBuffer(const Buffer& buffer);

  // The newest creation's serial (0: none yet): a command recorded at or after it names no structure created since
  // (history_apply.cpp: a handle reused after the recording).
  uint64_t last_structure_created() const { return structures_created_.load(std::memory_order_acquire); }
  // The newest destruction's serial (0: none yet). A recording made at or after it named nothing destroyed since.
  uint64_t last_structure_destroyed() const { return structures_last_.load(std::memory_order_acquire); }
  uint64_t last_buffer_destroyed() const { return buffers_last_.load(std::memory_order_acquire); }

  // The ids between a recording and a submission: the id counter when the command was recorded (recorded_at), and an
  // id taken at the submission (submitted_at; destroys with a smaller id came before it).
  struct Between {
    uint64_t recorded_at;
    uint64_t submitted_at;
    bool Holds(uint64_t destroyed) const { return destroyed > recorded_at && destroyed < submitted_at; }
  };
  // Whether `as` named, when recorded, a structure destroyed between: *found is it.
  Answer StructureDestroyedSince(VkAccelerationStructureKHR as, Between between, Structure* found) const;
  // Whether `address` lay, when recorded, in a buffer bound then and destroyed between: *found is it.
  Answer BufferDestroyedSince(VkDeviceAddress address, Between between, Buffer* found) const;

 private:
  template <typename T>
  struct Ring {
    std::array<T, kCapacity> entries{};
    std::size_t next = 0;  // where the next entry goes
    std::size_t size = 0;  // entries held (<= kCapacity)
    uint64_t dropped = 0;  // the newest dropped entry's `destroyed` (0: none dropped)
    void Add(const T& entry) {
      if (size == kCapacity) {
        if (entries[next].destroyed > dropped) dropped = entries[next].destroyed;
      } else {
        ++size;
      }
      entries[next] = entry;
      next = (next + 1) % kCapacity;
    }
    // Every entry is looked at: two threads' destroys may enter in another order than their serials.
    template <typename Match>
    Answer Find(Between between, Match&& match, T* found) const {
      for (std::size_t k = 0; k < size; ++k) {
        const T& e = entries[k];
        if (between.Holds(e.destroyed) && match(e)) {
          *found = e;
          return Answer::kYes;
        }
      }
      return dropped > between.recorded_at ? Answer::kUnknown : Answer::kNo;
    }
  };

  // Threads take serials before they get here: the newest is a maximum, not the last stored.
  static void RaiseTo(std::atomic<uint64_t>& newest, uint64_t serial) {
    for (uint64_t seen = newest.load(std::memory_order_relaxed);
         seen < serial && !newest.compare_exchange_weak(seen, serial, std::memory_order_release);) {
    }
  }

  mutable std::mutex mutex_;
  Ring<Structure> structures_;
  Ring<Buffer> buffers_;
  std::atomic<uint64_t> structures_created_{0};
  std::atomic<uint64_t> structures_last_{0};
  std::atomic<uint64_t> buffers_last_{0};
};

}  // namespace asval
