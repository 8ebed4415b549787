// Private: runs fn(chunk) for chunk = 0 .. chunks-1 on up to `threads` threads (the caller is one of them).
// Chunks are claimed dynamically, so each fn must write only its own chunk's slots; the caller combines
// the slots in chunk order afterwards, which makes the result independent of the thread count.
#pragma once

#include <algorithm>
#include <atomic>
#include <cstdint>
#include <thread>
#include <vector>

#include "float_mode.h"

namespace asval::builder::detail {

template <class Fn>
void ForEachChunk(uint32_t threads, size_t chunks, Fn&& fn) {
    std::atomic<size_t> next{0};
    auto work = [&] {
        const FloatModeGuard mode;  // a new thread's mode is not the caller's guarded one everywhere
        for (size_t c; (c = next.fetch_add(1, std::memory_order_relaxed)) < chunks;) fn(c);
    };
    const size_t helpers = std::min<size_t>(std::max<uint32_t>(threads, 1) - 1, chunks > 0 ? chunks - 1 : 0);
    std::vector<std::thread> pool;
    pool.reserve(helpers);
    for (size_t i = 0; i < helpers; ++i) pool.emplace_back(work);
    work();
    for (std::thread& t : pool) t.join();
}

}  // namespace asval::builder::detail
