#pragma once
// Callgrind's client requests around the measured calls only: run under
//   valgrind --tool=callgrind --instr-atstart=no PROGRAM
// and the totals are the measured calls' instructions. Without valgrind's headers (a machine without the
// valgrind package) the programs still build and time the calls; run_overhead.py --callgrind then finds no
// instructions and says why.
#if __has_include(<valgrind/callgrind.h>)
#include <valgrind/callgrind.h>
#define OVERHEAD_START_INSTRUMENTATION CALLGRIND_START_INSTRUMENTATION
#define OVERHEAD_STOP_INSTRUMENTATION CALLGRIND_STOP_INSTRUMENTATION
#else
#define OVERHEAD_START_INSTRUMENTATION ((void)0)
#define OVERHEAD_STOP_INSTRUMENTATION ((void)0)
#endif
