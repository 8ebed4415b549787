#pragma once
// Everything the build commands' hot path keeps per thread from one call to the next, in one place: the buffer
// and structure memos, the per-info records of calls of many infos, the aliasing sweep's buffers, the size
// cache's table of recent hits, and the recorder's last command buffer (post-record, layer/state). One
// thread_local, reached once per call by the hook (each thread_local of a shared library costs a __tls_get_addr
// call per access). A call made from inside an app callback during another call on the
// same thread (a report's callback that records a build) gets data of its own, so the outer call's records
// stay as they were.
#include <cstdint>
#include <memory>
#include <vector>

#include "buffer_memo.h"
#include "build_size_cache.h"
#include "history_recorder.h"
#include "resolved_build.h"
#include "structure_memo.h"

namespace asval {

struct AliasingWorkspace;  // build_aliasing.cpp

struct CheckThreadData {
  CheckThreadData();
  ~CheckThreadData();

  BufferMemo buffers;
  StructureMemo structures;
  BuildSizeCache::ThreadTable sizes;
  std::vector<ResolvedInfo> infos;  // the per-info records of calls of more infos than ResolvedBuild keeps inline
  std::unique_ptr<AliasingWorkspace> aliasing;  // made on the thread's first sweep
  LastRecordedBuild last_recorded;  // RecordCmdBuild's memo
  std::vector<uint32_t> captured_infos;  // the capture's per-info answer for the call (build_hooks.cpp)
  // Per info index (the first kHintedInfos), the buffer-memo entries that answered its scratch and its
  // destination's buffer last call (BufferMemo::HoldingHinted, FindOfStructureHinted): a frame records the same
  // builds call after call.
  static constexpr uint32_t kHintedInfos = 64;
  uint8_t scratch_hints[kHintedInfos] = {};
  uint8_t dst_buffer_hints[kHintedInfos] = {};
  uint8_t spare_hint = 0;  // for infos beyond kHintedInfos (a hint of no use, never wrong)
  bool in_use = false;
};

// This thread's data for the duration of one call (or fresh data for a call nested in another on this thread).
class CheckThreadLease {
 public:
  CheckThreadLease();
  ~CheckThreadLease();
  CheckThreadLease(const CheckThreadLease&) = delete;
  CheckThreadLease& operator=(const CheckThreadLease&) = delete;
  CheckThreadData& data() const { return *data_; }

 private:
  CheckThreadData* data_;
  std::unique_ptr<CheckThreadData> owned_;  // only for a nested call
};

}  // namespace asval
