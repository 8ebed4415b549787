#include "check_thread_data.h"

#include "build_aliasing.h"

namespace asval {

CheckThreadData::CheckThreadData() = default;
CheckThreadData::~CheckThreadData() = default;

CheckThreadLease::CheckThreadLease() {
  thread_local CheckThreadData data;
  if (!data.in_use) {
    data.in_use = true;
    data_ = &data;
    return;
  }
  owned_ = std::make_unique<CheckThreadData>();
  data_ = owned_.get();
}

CheckThreadLease::~CheckThreadLease() {
  if (!owned_) data_->in_use = false;
}

}  // namespace asval
