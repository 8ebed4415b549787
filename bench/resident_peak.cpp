#include "resident_peak.h"

#include <cstdio>
#include <cstring>

#if defined(__linux__)
#include <malloc.h>
#endif

namespace resident {
namespace {

size_t ReadStatusKb(const char* key) {
    std::FILE* f = std::fopen("/proc/self/status", "r");
    if (!f) return 0;
    char line[256];
    size_t kb = 0;
    const size_t n = std::strlen(key);
    while (std::fgets(line, sizeof line, f)) {
        if (std::strncmp(line, key, n) == 0) {
            std::sscanf(line + n, " %zu", &kb);
            break;
        }
    }
    std::fclose(f);
    return kb * 1024;
}

}  // namespace

size_t StartSpan() {
#if defined(__linux__)
    malloc_trim(0);  // freed heap pages would otherwise be reused without showing in the peak
    if (std::FILE* f = std::fopen("/proc/self/clear_refs", "w")) {
        std::fputs("5", f);  // 5: reset the peak resident size to the current one
        std::fclose(f);
    }
    return ReadStatusKb("VmRSS:");
#else
    return 0;
#endif
}

size_t PeakSinceStart() { return ReadStatusKb("VmHWM:"); }

}  // namespace resident
