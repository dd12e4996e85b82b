#!/usr/bin/env bash
# Runs the ROI benchmarks (medians of repeated runs, interleaved in random order so that a
# slow spell of a shared machine falls on all of them alike) and prints the issue's goals as
# ratios measured in the same run. Usage: scripts/bench-roi.sh [build dir]   (default build/release)
set -euo pipefail
cd "$(dirname "$0")/.."
build=${1:-build/release}
out=$(mktemp)
context=$(mktemp)
trap 'rm -f "$out" "$context"' EXIT
"$build/bench/roi_bench" --benchmark_min_time=0.5 --benchmark_repetitions=7 --benchmark_enable_random_interleaving=true \
  --benchmark_report_aggregates_only=true --benchmark_format=console 2>"$context" |
  awk '/_median / { name = $1; sub(/_median$/, "", name); t = $2; if ($3 == "us") t /= 1000; print name, t }
       /^probe\/[a-z]+_(min|max) / { t = $2; if ($3 == "us") t /= 1000; print $1, t }' >"$out"
# Where the figures come from: the CPU and its cores, and the scan the calibration chose for
# each shape (what the fast filter ran, unless TRAJROI_SIMD forced one).
grep -E "^(machine|scan_circular|scan_rectangular):" "$context" || true
echo

awk '
  { ms[$1] = $2 }
  END {
    # Interleaved runs report in random order; print in the order of the issue.
    printf "%-44s %12s\n", "benchmark (median)", "time [ms]"
    split("frame accumulated", wheres, " "); split("circular rectangular", shapes, " ")
    split("25 10", ratios, " "); split("reference fast", methods, " ")
    for (w = 1; w <= 2; ++w) {
      for (r = 1; r <= 2; ++r) for (s = 1; s <= 2; ++s) for (m = 1; m <= 2; ++m) {
        name = "roi/" shapes[s] "/" methods[m] "/" wheres[w] "/" ratios[r]
        if (name in ms) printf "%-44s %12.4f\n", name, ms[name]
      }
      split("read memcpy", limits, " ")
      for (l = 1; l <= 2; ++l) {
        name = "limit/" limits[l] "/" wheres[w]
        if (name in ms) printf "%-44s %12.4f\n", name, ms[name]
      }
    }
    # The core between the others: the clock (x86: 10 M dependent additions, one per cycle) and
    # the scan of one frame in the cache (10 passes over 28 800 points), each as 7 samples.
    if ("probe/scan" in ms) {
      printf "\nthe core over the run (7 samples each, between the others):\n"
      slowed = 0
      if ("probe/clock" in ms) {
        ghz = 10 / ms["probe/clock"]; low = 10 / ms["probe/clock_max"]; high = 10 / ms["probe/clock_min"]
        printf "  clock %.2f GHz (median), %.2f–%.2f\n", ghz, low, high
        slowed = slowed || low < 0.85 * high
      }
      points = 288000  # kProbePasses (10) in roi_bench times the 28 800 points of its frame
      printf "  fast scan in the cache %.2f ns per point (median), %.2f–%.2f\n", ms["probe/scan"] * 1e6 / points,
        ms["probe/scan_min"] * 1e6 / points, ms["probe/scan_max"] * 1e6 / points
      slowed = slowed || ms["probe/scan_max"] > 1.15 * ms["probe/scan_min"]
      if (slowed)
        printf "  the host slowed the core for part of the run: figures taken then are slower for the scans\n  (bound by the core), hardly for the memcpy (bound by memory); see docs/performance.md\n"
    }
    printf "\nGoals on the accumulated cloud (2.88 M points), same run:\n"
    fails = 0
    split("circular rectangular", shapes, " ")
    want["circular", 25] = 3; want["circular", 10] = 7
    want["rectangular", 25] = 6; want["rectangular", 10] = 14
    memcpy = ms["limit/memcpy/accumulated"]
    for (s = 1; s <= 2; ++s) {
      shape = shapes[s]
      for (r = 25; r >= 10; r -= 15) {
        ref = ms["roi/" shape "/reference/accumulated/" r]; fast = ms["roi/" shape "/fast/accumulated/" r]
        ok = ref / fast >= want[shape, r]; fails += !ok
        printf "  %-11s %2d %%: fast %6.1fx faster than reference (goal >= %2dx)   %s\n", shape, r, ref / fast, want[shape, r], ok ? "met" : "MISSED"
        ok = fast / memcpy <= 1.0; fails += !ok
        printf "  %-11s %2d %%: fast = %4.2fx the memcpy of the same points (goal <= 1.0x)  %s\n", shape, r, fast / memcpy, ok ? "met" : "MISSED"
      }
      f10 = ms["roi/" shape "/fast/accumulated/10"]; f25 = ms["roi/" shape "/fast/accumulated/25"]
      ok = f10 / f25 <= 1.25; fails += !ok
      printf "  %-11s fast at 10 %% = %4.2fx fast at 25 %% (goal <= 1.25x)                %s\n", shape, f10 / f25, ok ? "met" : "MISSED"
    }
    exit fails > 0
  }' "$out"
