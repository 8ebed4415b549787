// Global operator new/delete that keep a byte count (a 16-byte header holds each block's size).
#include "alloc_counter.h"

#include <atomic>
#include <cstdlib>
#include <new>

namespace {
std::atomic<size_t> g_current{0};
std::atomic<size_t> g_peak{0};

void* Allocate(size_t n) {
    auto* p = static_cast<unsigned char*>(std::malloc(n + 16));
    if (!p) throw std::bad_alloc();
    *reinterpret_cast<size_t*>(p) = n;
    const size_t now = g_current.fetch_add(n) + n;
    size_t peak = g_peak.load();
    while (now > peak && !g_peak.compare_exchange_weak(peak, now)) {}
    return p + 16;
}

void Release(void* q) {
    if (!q) return;
    auto* p = static_cast<unsigned char*>(q) - 16;
    g_current.fetch_sub(*reinterpret_cast<size_t*>(p));
    std::free(p);
}
}  // namespace

void* operator new(size_t n) { return Allocate(n); }
void* operator new[](size_t n) { return Allocate(n); }
void operator delete(void* p) noexcept { Release(p); }
void operator delete[](void* p) noexcept { Release(p); }
void operator delete(void* p, size_t) noexcept { Release(p); }
void operator delete[](void* p, size_t) noexcept { Release(p); }

namespace alloccount {
void ResetPeak() { g_peak.store(g_current.load()); }
size_t PeakBytes() { return g_peak.load(); }
size_t CurrentBytes() { return g_current.load(); }
}  // namespace alloccount
