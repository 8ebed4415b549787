// Private: a hint that a large, freshly reserved buffer be backed by transparent huge pages.
// Why: a 1M-primitive LBVH build touches ~100 MB of fresh memory; with 4 KiB pages the page faults (and the
// unmapping on free) were ~20% of its CPU time. Only a hint: no effect on the contents, errors ignored.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#if defined(__linux__)
#include <sys/mman.h>
#endif

namespace asval::builder::detail {

inline void AdviseHugePages(void* p, size_t bytes) {
#if defined(__linux__) && defined(MADV_HUGEPAGE)
    constexpr uintptr_t kHuge = uintptr_t(2) << 20;
    if (bytes < 2 * kHuge) return;  // small buffers: not worth a system call
    const uintptr_t b = (reinterpret_cast<uintptr_t>(p) + kHuge - 1) & ~(kHuge - 1);
    const uintptr_t e = (reinterpret_cast<uintptr_t>(p) + bytes) & ~(kHuge - 1);
    if (e > b) (void)madvise(reinterpret_cast<void*>(b), e - b, MADV_HUGEPAGE);
#else
    (void)p;
    (void)bytes;
#endif
}

// v.reserve(n) plus the hint, before anything is written (the hint only helps pages not yet touched).
template <class T>
void ReserveHuge(std::vector<T>& v, size_t n) {
    v.reserve(n);
    AdviseHugePages(v.data(), v.capacity() * sizeof(T));
}

}  // namespace asval::builder::detail
