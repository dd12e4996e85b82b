#!/usr/bin/env bash
# The README's test command: installs every dependency, checks the formatting (the committed
# .clang-format), builds with warnings as errors with GCC and with clang (tests and benchmarks
# included; the clang build is compiled, its tests are the GCC release's), and runs, each
# through ctest:
#   1. the whole suite, release build;
#   2. the whole suite under AddressSanitizer + UndefinedBehaviorSanitizer (preset asan);
#   3. the threaded tests — the lock-free ring, the daemon end to end and its control — under
#      ThreadSanitizer (preset tsan);
#   4. every fuzz target for TRAJROI_FUZZ_SECONDS (default 60) with ASan + UBSan (preset
#      fuzz, scripts/fuzz.sh), which fails on any crash, leak or timeout.
#   TRAJROI_SKIP_SANITIZERS=1  runs the release suite only (quicker local runs).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)

bash scripts/install-deps.sh

bash scripts/check-format.sh

cmake --preset clang
cmake --build --preset clang -j"$jobs"

cmake --preset release
cmake --build --preset release -j"$jobs"
ctest --preset release -j"$jobs"

if [ "${TRAJROI_SKIP_SANITIZERS:-0}" != "1" ]; then
  cmake --preset asan
  cmake --build --preset asan -j"$jobs"
  ctest --preset asan -j"$jobs"
  cmake --preset tsan
  cmake --build --preset tsan -j"$jobs" --target transport_tests daemon_tests
  # One at a time: two ThreadSanitizer daemons at real-time pace on 2 cores fall behind.
  ctest --preset tsan -j1 -R '^(SpscRing|Pipeline|TrajroidEndToEnd|TrajroidControl)\.'
  bash scripts/fuzz.sh "${TRAJROI_FUZZ_SECONDS:-60}"
fi
