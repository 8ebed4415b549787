#include "check_thread_data.h"

#include "build_aliasing.h"

namespace asval {

CheckThreadData::CheckThreadData() = default;
CheckThreadData::~CheckThreadData() = default;

namespace {

// This thread's data, reached with one thread-local access per call: a constant-initialized pointer has no guard
// (a thread_local object with a constructor costs a second access, to its guard, and a test on every call).
thread_local CheckThreadData* t_data = nullptr;

// Owns the thread's data from its first call to the thread's exit.
struct ThreadDataOwner {
  std::unique_ptr<CheckThreadData> data;
  ~ThreadDataOwner() { t_data = nullptr; }
};

[[gnu::noinline]] CheckThreadData* CreateThreadData() {
  thread_local ThreadDataOwner owner;
  owner.data = std::make_unique<CheckThreadData>();
  t_data = owner.data.get();
  return t_data;
}

}  // namespace

CheckThreadLease::CheckThreadLease() {
  CheckThreadData* data = t_data;
  if (!data) data = CreateThreadData();
  if (!data->in_use) {
    data->in_use = true;
    data_ = data;
    return;
  }
  owned_ = std::make_unique<CheckThreadData>();
  data_ = owned_.get();
}

CheckThreadLease::~CheckThreadLease() {
  if (!owned_) data_->in_use = false;
}

}  // namespace asval
