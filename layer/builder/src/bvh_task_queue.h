// Private: the work queue of the binned SAH builder's subtree tasks. Which thread runs a task never
// changes what the task records, so the queue's order does not matter for the output.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <deque>
#include <mutex>

#include "bvh_code.h"

namespace asval::builder::detail {

class TaskQueue {
public:
    void Push(Task* t) {
        { std::lock_guard<std::mutex> l(mutex_); queue_.push_back(t); ++pending_; }
        cv_.notify_one();
    }
    // Runs tasks until every pushed task (and those they push) has finished.
    template <typename Fn>
    void Work(Fn&& run) {
        std::unique_lock<std::mutex> l(mutex_);
        for (;;) {
            if (!queue_.empty()) {
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

private:
    std::mutex mutex_;
    std::condition_variable cv_;
    std::deque<Task*> queue_;
    uint32_t pending_ = 0;
};

}  // namespace asval::builder::detail
