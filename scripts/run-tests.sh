#!/usr/bin/env bash
# The README's test command: installs every dependency, builds with warnings as errors, and
# runs the whole test suite twice through ctest — a release build, then an AddressSanitizer +
# UndefinedBehaviorSanitizer build (the parsers, the vector scans and the daemon run under
# both) — and the lock-free ring's tests under ThreadSanitizer.
#   TRAJROI_SKIP_SANITIZERS=1  skips the sanitizer pass (quicker local runs).
set -euo pipefail
cd "$(dirname "$0")/.."
jobs=$(nproc)

bash scripts/install-deps.sh

cmake --preset release
cmake --build --preset release -j"$jobs"
ctest --preset release -j"$jobs"

if [ "${TRAJROI_SKIP_SANITIZERS:-0}" != "1" ]; then
  cmake --preset asan
  cmake --build --preset asan -j"$jobs"
  ctest --preset asan -j"$jobs"
  cmake --preset tsan
  cmake --build --preset tsan -j"$jobs" --target transport_tests
  ctest --preset tsan -j"$jobs" -R '^SpscRing\.'
fi
