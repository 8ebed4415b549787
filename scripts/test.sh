#!/usr/bin/env bash
# Installs what is missing (Debian 12 or 13, as root), then builds and runs every test in four builds:
#   normal  RelWithDebInfo (build/): every test;
#   asan    the `asan` preset (build-asan/: GCC, AddressSanitizer + UndefinedBehaviorSanitizer + LeakSanitizer):
#           every test but the builder's exhaustive sweeps (the preset's
#           ASVAL_BUILDER_TEST_SPEC: the same code runs in the normal build; under ASan they took 430 s of test time);
#   tsan    the `tsan` preset (build-tsan/: GCC, ThreadSanitizer): the layer and the integration tests, the thread
#           tests run (integration_threads), lavapipe's own races suppressed (scripts/sanitizers/tsan.supp);
#   fuzz    the `fuzz` preset (build-fuzz/: Clang, libFuzzer): each fuzz target for ASVAL_FUZZ_SECONDS (20).
# Exits non-zero on any failure. Usage: scripts/test.sh [ctest arguments...] (given to every build's ctest).
# ASVAL_TEST_BUILDS picks builds (default "normal asan tsan fuzz"); ASVAL_BUILD_DIR moves the normal build.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

bash scripts/setup.sh

builds=${ASVAL_TEST_BUILDS:-normal asan tsan fuzz}
jobs=$(nproc)
stage() { echo "== scripts/test.sh: $1 build: $2 (started $(date -u +%H:%M:%S))"; }

if [[ " $builds " == *" normal "* ]]; then
  build=${ASVAL_BUILD_DIR:-$root/build}
  stage normal "$build"
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
  cmake --build "$build" -j"$jobs"
  ctest --test-dir "$build" --output-on-failure -j"$jobs" "$@"
fi

if [[ " $builds " == *" asan "* ]]; then
  stage asan "$root/build-asan"
  cmake --preset asan >/dev/null
  cmake --build --preset asan -j"$jobs"
  # Stop at the first finding, with a stack. The one exception to leak checking is in
  # tests/integration/CMakeLists.txt (the Khronos layer's synchronization validation), explained there.
  export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}
  export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
  ctest --preset asan -j"$jobs" --timeout 1800 "$@"
  unset ASAN_OPTIONS UBSAN_OPTIONS
fi

if [[ " $builds " == *" tsan "* ]]; then
  stage tsan "$root/build-tsan"
  cmake --preset tsan >/dev/null
  cmake --build --preset tsan -j"$jobs"
  TSAN_OPTIONS=${TSAN_OPTIONS:-suppressions=$root/scripts/sanitizers/tsan.supp} \
    ctest --preset tsan -j"$jobs" -R '^integration_threads$' "$@"
fi

if [[ " $builds " == *" fuzz "* ]]; then
  stage fuzz "$root/build-fuzz"
  cmake --preset fuzz >/dev/null
  cmake --build --preset fuzz -j"$jobs"
  ctest --preset fuzz -j"$jobs" "$@"
fi
