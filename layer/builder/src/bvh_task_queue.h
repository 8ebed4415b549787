// Private: the binned SAH builder's thread pool. It runs subtree tasks (Task) and, for the few nodes
// too large to leave to one thread, batches of chunk jobs (ParallelFor) that idle threads help with.
// Which thread runs what never changes the output: tasks record their own subtrees, and chunk jobs write
// disjoint, fixed parts of the result.
#pragma once

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <deque>
#include <functional>
#include <mutex>
#include <vector>

#include "bvh_code.h"

namespace asval::builder::detail {

class TaskQueue {
public:
    void Push(Task* t) {
        { std::lock_guard<std::mutex> l(mutex_); queue_.push_back(t); ++pending_; }
        cv_.notify_one();
    }

    // Runs tasks (and helps with batches) until every pushed task, and those they push, has finished.
    template <typename Fn>
    void Work(Fn&& run) {
        std::unique_lock<std::mutex> l(mutex_);
        for (;;) {
            if (Batch* b = OpenBatch()) {
                ++b->helpers;
                l.unlock();
                RunItems(*b);
                l.lock();
                if (--b->helpers == 0) batchDone_.notify_all();
            } else if (!queue_.empty()) {
                Task* t = queue_.front();
                queue_.pop_front();
                l.unlock();
                run(t);
                l.lock();
                if (--pending_ == 0) cv_.notify_all();
            } else if (pending_ == 0) {
                return;
            } else {
                cv_.wait(l);
            }
        }
    }

    // Runs fn(0) .. fn(count - 1) on this thread and any idle one; returns when all have run.
    void ParallelFor(uint32_t count, const std::function<void(uint32_t)>& fn) {
        Batch b{&fn, count};
        {
            std::lock_guard<std::mutex> l(mutex_);
            batches_.push_back(&b);
        }
        cv_.notify_all();
        RunItems(b);
        std::unique_lock<std::mutex> l(mutex_);
        batches_.erase(std::find(batches_.begin(), batches_.end(), &b));
        batchDone_.wait(l, [&b] { return b.helpers == 0; });  // every item taken has finished
    }

private:
    struct Batch {
        const std::function<void(uint32_t)>* fn;
        uint32_t count;
        std::atomic<uint32_t> next{0};
        uint32_t helpers = 0;  // threads inside RunItems besides the owner (guarded by mutex_)
    };

    // A batch with items left (under the lock).
    Batch* OpenBatch() {
        for (Batch* b : batches_)
            if (b->next.load(std::memory_order_relaxed) < b->count) return b;
        return nullptr;
    }

    static void RunItems(Batch& b) {
        for (uint32_t i = b.next.fetch_add(1); i < b.count; i = b.next.fetch_add(1)) (*b.fn)(i);
    }

    std::mutex mutex_;
    std::condition_variable cv_;          // idle workers: a task or a batch item is available, or all done
    std::condition_variable batchDone_;   // batch owners: their batch's helpers have finished
    std::deque<Task*> queue_;
    std::vector<Batch*> batches_;
    uint32_t pending_ = 0;
};

}  // namespace asval::builder::detail
