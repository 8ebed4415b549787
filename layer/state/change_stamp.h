#pragma once
// How many times a container has changed, and which container it is. A reader that copied Read() and later
// reads an equal stamp knows that nothing was added, replaced or removed in between, and that it is looking
// at the same container (ids are never reused, so a container created later at the same address, for a later
// device, never matches). Lets a per-thread memo of lookups (checks/buffer_memo.h) survive from one recorded
// command to the next without ever serving a stale answer.
//
// Thread safety: Bump is called by a writer after its change, while it still holds the container's lock
// (release); Read may run on any thread (acquire): a reader that sees the new count sees the change.
#include <atomic>
#include <cstdint>

namespace asval {

struct StampValue {
  uint64_t id = 0;  // 0: no container
  uint64_t count = 0;
  friend bool operator==(const StampValue& a, const StampValue& b) { return a.id == b.id && a.count == b.count; }
  friend bool operator!=(const StampValue& a, const StampValue& b) { return !(a == b); }
};

class ChangeStamp {
 public:
  ChangeStamp() : id_(NextId()) {}
  ChangeStamp(const ChangeStamp&) = delete;
  ChangeStamp& operator=(const ChangeStamp&) = delete;

  StampValue Read() const { return StampValue{id_, count_.load(std::memory_order_acquire)}; }
  void Bump() { count_.fetch_add(1, std::memory_order_release); }

 private:
  static uint64_t NextId() {
    static std::atomic<uint64_t> next{1};
    return next.fetch_add(1, std::memory_order_relaxed);
  }
  const uint64_t id_;
  std::atomic<uint64_t> count_{0};
};

}  // namespace asval
