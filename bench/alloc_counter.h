// Peak heap bytes, counted by replacing the global operator new/delete in the benchmark executables.
#pragma once

#include <cstddef>

namespace alloccount {

void ResetPeak();       // peak := current
size_t PeakBytes();     // highest live heap bytes since the last ResetPeak
size_t CurrentBytes();

}  // namespace alloccount
