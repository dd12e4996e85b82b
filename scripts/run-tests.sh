#!/usr/bin/env bash
# The README's test command: installs every dependency, checks the formatting (the committed
# .clang-format), builds with warnings as errors with GCC (preset release) and with clang (preset
# asan: every target, tests and benchmarks included), and runs, each through ctest:
#   1. the whole suite, release build (GCC);
#   2. the whole suite under AddressSanitizer + UndefinedBehaviorSanitizer (preset asan, clang);
#   3. the threaded tests — the lock-free ring, the daemon end to end and its control — under
#      ThreadSanitizer (preset tsan, clang);
#   4. every fuzz target for TRAJROI_FUZZ_SECONDS (default 30) with ASan + UBSan (preset
#      fuzz, scripts/fuzz.sh), which fails on any crash, leak or timeout.
#   TRAJROI_SKIP_SANITIZERS=1  runs the release suite only (quicker local runs).
# The sanitizer builds use clang: on 2 cores GCC took 29 minutes to build the ASan tree alone,
# clang takes 12, and the TSan tests ran 2–3 times as long under GCC's TSan as under clang's.
# The clang release tree (preset clang) is no longer built here: the asan tree compiles every
# target with clang and -Werror.
# Each stage prints its wall time.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)
started=$SECONDS
stage() {  # name command...
  local name=$1 t0=$SECONDS
  shift
  "$@"
  echo "run-tests: $name took $((SECONDS - t0)) s (total $((SECONDS - started)) s)"
}

stage "installing" bash scripts/install-deps.sh
stage "the format check" bash scripts/check-format.sh

stage "configuring release" cmake --preset release
stage "the release build" cmake --build --preset release -j"$jobs"
stage "the release suite" ctest --preset release -j"$jobs"

if [ "${TRAJROI_SKIP_SANITIZERS:-0}" != "1" ]; then
  stage "configuring asan" cmake --preset asan
  stage "the asan build" cmake --build --preset asan -j"$jobs"
  stage "the asan suite" ctest --preset asan -j"$jobs"
  stage "configuring tsan" cmake --preset tsan
  stage "the tsan build" cmake --build --preset tsan -j"$jobs" --target transport_tests daemon_tests
  # One at a time: two ThreadSanitizer daemons at real-time pace on 2 cores fall behind.
  stage "the tsan suite" ctest --preset tsan -j1 -R '^(SpscRing|Pipeline|TrajroidEndToEnd|TrajroidControl)\.'
  stage "fuzzing" bash scripts/fuzz.sh "${TRAJROI_FUZZ_SECONDS:-30}"
fi
