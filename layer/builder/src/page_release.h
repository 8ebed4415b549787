// Private: handing the physical pages of a consumed part of a buffer back to the system while the buffer
// itself stays allocated. The expansion reads the references once, front to back, and then frees them:
// releasing the part already read keeps the resident peak near tree + ids instead of references + tree +
// ids. Only whole pages strictly inside [begin, end) are released (never a page the allocator may still
// use for its own bookkeeping); they read back as zeros and are never read again. Linux only; elsewhere a
// no-op (the build is the same, its peak is higher).
#pragma once

#include <cstddef>
#include <cstdint>

#if defined(__linux__)
#include <sys/mman.h>
#include <unistd.h>
#endif

namespace asval::builder::detail {

class PageReleaser {
public:
    // `base` .. `base + bytes`: the buffer; nothing is released for buffers below kMinBytes.
    PageReleaser(const void* base, size_t bytes)
        : begin_(reinterpret_cast<uintptr_t>(base)), end_(begin_ + bytes), released_(begin_) {
#if defined(__linux__)
        const long page = sysconf(_SC_PAGESIZE);
        page_ = page > 0 ? uintptr_t(page) : 4096;
        enabled_ = bytes >= kMinBytes;
#endif
    }

    // Everything before `consumedBytes` has been read for the last time.
    void Consumed(size_t consumedBytes) {
        if (!enabled_ || begin_ + consumedBytes < released_ + kChunkBytes) return;
#if defined(__linux__) && defined(MADV_DONTNEED)
        const uintptr_t from = (released_ + page_ - 1) & ~(page_ - 1);
        const uintptr_t to = (begin_ + consumedBytes) & ~(page_ - 1);
        if (to > from && to <= end_) {
            (void)madvise(reinterpret_cast<void*>(from), to - from, MADV_DONTNEED);
            released_ = to;  // the partly read page after `to` is released next time
        }
#endif
    }

private:
    static constexpr size_t kMinBytes = size_t(2) << 20;    // 2 MiB (64K references)
    static constexpr size_t kChunkBytes = size_t(1) << 20;  // one system call per MiB read
    uintptr_t begin_, end_, released_;
    uintptr_t page_ = 4096;
    bool enabled_ = false;
};

}  // namespace asval::builder::detail
