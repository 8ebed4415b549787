#!/usr/bin/env bash
# Installs what is missing (Debian 12 or 13, as root), then builds and runs the tests.
#   scripts/test.sh        the normal build (build/, RelWithDebInfo, GCC) and its full suite: every test. What a
#                          newcomer and every change need (times in docs/reliability.md).
#   scripts/test.sh --all  the same, then three more builds (what CI runs: .ci/run):
#     asan  the `asan` preset (build-asan/: GCC, AddressSanitizer + UndefinedBehaviorSanitizer + LeakSanitizer):
#           every test but the builder's exhaustive sweeps (the preset's
#           ASVAL_BUILDER_TEST_SPEC: the same code runs in the normal build; under ASan they took 430 s of test time);
#     tsan  the `tsan` preset (build-tsan/: GCC, ThreadSanitizer): the layer and the integration tests, the thread
#           tests run (integration_threads), lavapipe's own races suppressed (scripts/sanitizers/tsan.supp);
#     fuzz  the `fuzz` preset (build-fuzz/: Clang, libFuzzer): each fuzz target for ASVAL_FUZZ_SECONDS (20).
#   scripts/test.sh --plan [--all]  prints the builds it would run, one line, and exits (installs nothing).
# Other arguments go to every build's ctest (e.g. `scripts/test.sh -R gate`); --all and --plan may stand anywhere.
# ASVAL_TEST_BUILDS, when set, names the builds exactly (any of "normal asan tsan fuzz", in that order of running),
# with or without --all: it is the more precise of the two. ASVAL_BUILD_DIR moves the normal build.
# Exits non-zero on any failure; 2 on a bad ASVAL_TEST_BUILDS.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
cd "$root"

known="normal asan tsan fuzz"
all=0
plan=0
ctest_args=()
for arg in "$@"; do
  case $arg in
    --all) all=1 ;;
    --plan) plan=1 ;;
    *) ctest_args+=("$arg") ;;
  esac
done
if [[ -n ${ASVAL_TEST_BUILDS:-} ]]; then
  builds=$ASVAL_TEST_BUILDS
elif ((all)); then
  builds=$known
else
  builds=normal
fi
for b in $builds; do
  if [[ " $known " != *" $b "* ]]; then
    echo "scripts/test.sh: ASVAL_TEST_BUILDS names '$b'; the builds are: $known" >&2
    exit 2
  fi
done
# Run in the fixed order, whatever order ASVAL_TEST_BUILDS gives.
chosen=()
for b in $known; do
  if [[ " $builds " == *" $b "* ]]; then chosen+=("$b"); fi
done
if ((${#chosen[@]} == 0)); then
  echo "scripts/test.sh: ASVAL_TEST_BUILDS is set but names no build; the builds are: $known" >&2
  exit 2
fi
if ((plan)); then
  echo "${chosen[*]}"
  exit 0
fi
builds=" ${chosen[*]} "

bash scripts/setup.sh

jobs=$(nproc)
stage() { echo "== scripts/test.sh: $1 build: $2 (started $(date -u +%H:%M:%S))"; }

if [[ $builds == *" normal "* ]]; then
  build=${ASVAL_BUILD_DIR:-$root/build}
  stage normal "$build"
  cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
  cmake --build "$build" -j"$jobs"
  ctest --test-dir "$build" --output-on-failure -j"$jobs" "${ctest_args[@]}"
fi

if [[ $builds == *" asan "* ]]; then
  stage asan "$root/build-asan"
  cmake --preset asan >/dev/null
  cmake --build --preset asan -j"$jobs"
  # Stop at the first finding, with a stack. The one exception to leak checking is in
  # tests/integration/CMakeLists.txt (the Khronos layer's synchronization validation), explained there.
  export ASAN_OPTIONS=${ASAN_OPTIONS:-detect_leaks=1:abort_on_error=1}
  export UBSAN_OPTIONS=${UBSAN_OPTIONS:-halt_on_error=1:print_stacktrace=1}
  ctest --preset asan -j"$jobs" --timeout 1800 "${ctest_args[@]}"
  unset ASAN_OPTIONS UBSAN_OPTIONS
fi

if [[ $builds == *" tsan "* ]]; then
  stage tsan "$root/build-tsan"
  cmake --preset tsan >/dev/null
  cmake --build --preset tsan -j"$jobs"
  TSAN_OPTIONS=${TSAN_OPTIONS:-suppressions=$root/scripts/sanitizers/tsan.supp} \
    ctest --preset tsan -j"$jobs" -R '^integration_threads$' "${ctest_args[@]}"
fi

if [[ $builds == *" fuzz "* ]]; then
  stage fuzz "$root/build-fuzz"
  cmake --preset fuzz >/dev/null
  cmake --build --preset fuzz -j"$jobs"
  ctest --preset fuzz -j"$jobs" "${ctest_args[@]}"
fi
