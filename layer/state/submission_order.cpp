#include "submission_order.h"

#include <algorithm>
#include <new>

#include "vk_struct_chain.h"

namespace asval {

SemaphoreUse BatchSemaphores::Wait(uint32_t i) const {
  if (wait_infos) return {wait_infos[i].semaphore, wait_infos[i].value};
  return {waits[i], wait_values && i < wait_value_count ? wait_values[i] : 0};
}

SemaphoreUse BatchSemaphores::Signal(uint32_t i) const {
  if (signal_infos) return {signal_infos[i].semaphore, signal_infos[i].value};
  return {signals[i], signal_values && i < signal_value_count ? signal_values[i] : 0};
}

namespace {

void AddTimelineValues(const void* chain, BatchSemaphores* out) {
  const auto* values =
      FindInChain<VkTimelineSemaphoreSubmitInfo>(chain, VK_STRUCTURE_TYPE_TIMELINE_SEMAPHORE_SUBMIT_INFO);
  if (!values) return;
  out->wait_values = values->pWaitSemaphoreValues;
  out->wait_value_count = values->waitSemaphoreValueCount;
  out->signal_values = values->pSignalSemaphoreValues;
  out->signal_value_count = values->signalSemaphoreValueCount;
}

}  // namespace

BatchSemaphores SemaphoresOf(const VkSubmitInfo& submit) {
  BatchSemaphores out;
  out.wait_count = submit.waitSemaphoreCount;
  out.waits = submit.pWaitSemaphores;
  out.signal_count = submit.signalSemaphoreCount;
  out.signals = submit.pSignalSemaphores;
  if (out.wait_count != 0 || out.signal_count != 0) AddTimelineValues(submit.pNext, &out);
  return out;
}

BatchSemaphores SemaphoresOf(const VkSubmitInfo2& submit) {
  BatchSemaphores out;
  out.wait_count = submit.waitSemaphoreInfoCount;
  out.wait_infos = submit.pWaitSemaphoreInfos;
  out.signal_count = submit.signalSemaphoreInfoCount;
  out.signal_infos = submit.pSignalSemaphoreInfos;
  return out;
}

BatchSemaphores SemaphoresOf(const VkBindSparseInfo& bind) {
  BatchSemaphores out;
  out.wait_count = bind.waitSemaphoreCount;
  out.waits = bind.pWaitSemaphores;
  out.signal_count = bind.signalSemaphoreCount;
  out.signals = bind.pSignalSemaphores;
  if (out.wait_count != 0 || out.signal_count != 0) AddTimelineValues(bind.pNext, &out);
  return out;
}

void SubmissionOrder::TimelineCreated(VkSemaphore semaphore, uint64_t initial_value, bool external) {
  timeline_values_[semaphore] = Timeline{initial_value, external};
  timelines_.store(timeline_values_.size(), std::memory_order_release);
}

void SubmissionOrder::SemaphoreDestroyed(VkSemaphore semaphore) {
  timeline_values_.erase(semaphore);
  timelines_.store(timeline_values_.size(), std::memory_order_release);
  deferred_binary_.erase(std::remove_if(deferred_binary_.begin(), deferred_binary_.end(),
                                        [&](const auto& entry) { return entry.first == semaphore; }),
                         deferred_binary_.end());
}

void SubmissionOrder::SemaphoreImported(VkSemaphore semaphore) {
  if (Timeline* t = FindTimeline(semaphore)) t->external = true;
}

void SubmissionOrder::Signaled(VkSemaphore semaphore, uint64_t value) {
  if (Timeline* t = FindTimeline(semaphore)) t->known = std::max(t->known, value);
}

SubmissionOrder::Timeline* SubmissionOrder::FindTimeline(VkSemaphore semaphore) {
  if (timeline_values_.empty()) return nullptr;
  const auto it = timeline_values_.find(semaphore);
  return it == timeline_values_.end() ? nullptr : &it->second;
}

bool SubmissionOrder::SignaledByDeferred(VkSemaphore semaphore, uint64_t* id) const {
  for (const auto& [signaled, batch] : deferred_binary_) {
    if (signaled == semaphore) return *id = batch, true;
  }
  return false;
}

bool SubmissionOrder::InBacklog(uint64_t id) const {
  for (const DeferredBatch& b : backlog_) {
    if (b.id == id) return true;
  }
  return false;
}

DeferredBatch SubmissionOrder::MakeBatch(const BatchSemaphores& batch, VkQueue queue, const char* function) {
  DeferredBatch out;
  out.queue = queue;
  out.function = function;
  for (uint32_t i = 0; i < batch.wait_count; ++i) {
    const SemaphoreUse wait = batch.Wait(i);
    uint64_t id = 0;
    if (FindTimeline(wait.semaphore)) {
      out.timeline_waits.push_back(wait);
    } else if (SignaledByDeferred(wait.semaphore, &id)) {
      out.after.push_back(id);
    }
  }
  out.signals.reserve(batch.signal_count);
  for (uint32_t i = 0; i < batch.signal_count; ++i) out.signals.push_back(batch.Signal(i));
  return out;
}

SubmissionOrder::Call::Call(SubmissionOrder& order, VkQueue queue, const char* function)
    : order_(order), queue_(queue), function_(function) {}

SubmissionOrder::Call::~Call() {
  if (!committed_) {
    // The call did not happen: its signals were never made.
    for (auto it = undo_.rbegin(); it != undo_.rend(); ++it) {
      if (Timeline* t = order_.FindTimeline(it->first)) t->known = it->second;
    }
  }
  undo_.clear();
  if (undo_.capacity() > order_.spare_undo_.capacity()) undo_.swap(order_.spare_undo_);
}

Placement SubmissionOrder::Call::Place(const BatchSemaphores& batch) {
  bool defer = deferring_;
  for (std::size_t k = 0; !defer && k < order_.backlog_.size(); ++k) defer = order_.backlog_[k].queue == queue_;
  bool unordered = false;
  for (uint32_t i = 0; !defer && i < batch.wait_count; ++i) {
    const SemaphoreUse wait = batch.Wait(i);
    uint64_t id = 0;
    if (const Timeline* t = order_.FindTimeline(wait.semaphore)) {
      if (wait.value > t->known) (t->external ? unordered : defer) = true;
    } else if (order_.SignaledByDeferred(wait.semaphore, &id)) {
      defer = true;
    }
  }
  if (defer) {
    deferring_ = true;
    try {
      deferred_.push_back(order_.MakeBatch(batch, queue_, function_));
      return Placement::kDeferred;
    } catch (const std::bad_alloc&) {
      // Not kept: applied now, unknown (never a guess); what waits on its signals is ordered as if it had run.
      deferring_ = false;
      unordered = true;
    }
  }
  for (uint32_t i = 0; i < batch.signal_count; ++i) {
    const SemaphoreUse signal = batch.Signal(i);
    Timeline* t = order_.FindTimeline(signal.semaphore);
    if (!t || signal.value <= t->known) continue;
    if (undo_.empty() && undo_.capacity() == 0) undo_.swap(order_.spare_undo_);
    try {
      undo_.emplace_back(signal.semaphore, t->known);
    } catch (const std::bad_alloc&) {
      continue;  // not noted: the value stays unsignaled, so a wait on it is deferred (never applied too early)
    }
    t->known = signal.value;
  }
  return unordered ? Placement::kUnordered : Placement::kNow;
}

void SubmissionOrder::Call::Defer(VkCommandBuffer cb, uint32_t submit_index, uint32_t cb_index,
                                  std::shared_ptr<const RecordedOps> ops, uint64_t submitted_at) {
  DeferredBatch& batch = deferred_.back();
  batch.submitted_at = submitted_at;
  try {
    batch.command_buffers.push_back(DeferredCommandBuffer{cb, submit_index, cb_index, std::move(ops)});
  } catch (const std::bad_alloc&) {
    batch.lost = true;
  }
}

void SubmissionOrder::Call::Commit() {
  committed_ = true;
  for (DeferredBatch& batch : deferred_) {
    batch.id = ++order_.next_id_;
    try {
      for (const SemaphoreUse& signal : batch.signals) {
        if (!order_.FindTimeline(signal.semaphore)) order_.deferred_binary_.emplace_back(signal.semaphore, batch.id);
      }
      order_.backlog_.push_back(std::move(batch));
      order_.counters.batches_deferred.fetch_add(1, std::memory_order_relaxed);
    } catch (const std::bad_alloc&) {
      order_.counters.batches_never_resolved.fetch_add(1, std::memory_order_relaxed);
    }
  }
  order_.backlog_size_.store(order_.backlog_.size(), std::memory_order_release);
}

bool SubmissionOrder::TakeReady(DeferredBatch* out, bool* unordered) {
  if (taking_) return false;
  for (std::size_t k = 0; k < backlog_.size(); ++k) {
    const DeferredBatch& batch = backlog_[k];
    bool ready = true;
    for (std::size_t j = 0; ready && j < k; ++j) ready = backlog_[j].queue != batch.queue;  // first on its queue
    for (std::size_t j = 0; ready && j < batch.after.size(); ++j) ready = !InBacklog(batch.after[j]);
    bool external = batch.lost;
    for (std::size_t j = 0; ready && j < batch.timeline_waits.size(); ++j) {
      const SemaphoreUse& wait = batch.timeline_waits[j];
      const Timeline* t = FindTimeline(wait.semaphore);
      if (!t || wait.value <= t->known) continue;  // met (or the semaphore is gone: its waits were met)
      if (t->external) {
        external = true;
      } else {
        ready = false;
      }
    }
    if (!ready) continue;
    *out = std::move(backlog_[k]);
    backlog_.erase(backlog_.begin() + static_cast<std::ptrdiff_t>(k));
    *unordered = external;
    taking_ = true;
    return true;
  }
  return false;
}

void SubmissionOrder::Applied(const DeferredBatch& batch) {
  for (const SemaphoreUse& signal : batch.signals) {
    if (Timeline* t = FindTimeline(signal.semaphore)) {
      t->known = std::max(t->known, signal.value);
      continue;
    }
    deferred_binary_.erase(std::remove_if(deferred_binary_.begin(), deferred_binary_.end(),
                                          [&](const auto& entry) {
                                            return entry.first == signal.semaphore && entry.second == batch.id;
                                          }),
                           deferred_binary_.end());
  }
  backlog_size_.store(backlog_.size(), std::memory_order_release);
  taking_ = false;
}

void SubmissionOrder::NeverResolved() {
  counters.batches_never_resolved.fetch_add(backlog_.size(), std::memory_order_relaxed);
  backlog_.clear();
  deferred_binary_.clear();
  backlog_size_.store(0, std::memory_order_release);
}

}  // namespace asval
