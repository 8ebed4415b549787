// Peak resident memory of a span of the process (Linux): what the build really occupies, as opposed to
// what it allocated (alloc_counter.h counts every allocated byte, touched or not, released or not).
#pragma once

#include <cstddef>

namespace resident {

// Returns free heap memory to the system and resets the kernel's high-water mark (VmHWM) to the current
// resident size; returns that size in bytes (0 where unsupported).
size_t StartSpan();
// Highest resident size since StartSpan(), in bytes (0 where unsupported).
size_t PeakSinceStart();

}  // namespace resident
