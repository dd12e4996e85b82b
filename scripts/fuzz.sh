#!/usr/bin/env bash
# Builds the libFuzzer targets (preset `fuzz`: clang, ASan + UBSan), seeds them from the shared
# captures, the project's own files and a simulated run, and runs each for SECONDS (default
# 60). Prints executions per second and in total per target (also written to
# build/fuzz/report.md). Any crash, leak or timeout fails the script; its input is left in
# build/fuzz/artifacts/<target>/ — fix the bug and keep the input in tests/fuzz/corpus/<target>/
# so the ordinary test suite replays it from then on.
#
# Usage: scripts/fuzz.sh [SECONDS] [TARGET...]    (dependencies: scripts/install-deps.sh)
set -euo pipefail
cd "$(dirname "$0")/.."
seconds=${1:-60}
shift || true
targets=("$@")
if [ ${#targets[@]} -eq 0 ]; then
  targets=(vlp16_packets pcap_source ubx vn100 daemon_config trajectory_csv trajectory_message scenario vlp16_calibration
    lcm_udpm view_protocol ntrip_answer)
fi
data=${TRAJROI_DATA_DIR:-$(pwd)/../shared/data}
if [ ! -d "$data" ]; then
  if [ "${CI:-}" = "true" ]; then
    echo "fuzz.sh: the shared captures ($data) are missing; CI needs them for the seed corpora" >&2
    exit 1
  fi
  echo "fuzz.sh: $data absent: seeding from the project's files and a simulated run only" >&2
fi

cmake --preset fuzz >/dev/null
cmake --build --preset fuzz -j"$(nproc)" >/dev/null
# The simulator for the seed run comes from the ordinary build.
cmake --preset release >/dev/null
cmake --build build/release -j"$(nproc)" --target trajroi >/dev/null
build=build/fuzz
seeds=$build/seeds
rm -rf "$seeds" "$build/artifacts"
mkdir -p "$seeds"

# A short simulated run: its pcap, GNSS and IMU recordings, trajectory and configuration.
run=$build/seed-run
if [ ! -f "$run/lidar.pcap" ]; then
  rm -rf "$run"
  build/release/tools/trajroi sim --quiet --scenario tests/daemon/corridor.yaml --out "$run" >/dev/null
fi

# Byte streams: the start of each log and 2 KiB slices of it (at most 24 per file).
slices() {  # out_dir file...
  local out=$1 f
  shift
  mkdir -p "$out"
  for f in "$@"; do
    [ -f "$f" ] || continue
    split -b 2048 -d -a 3 <(head -c 49152 "$f") "$out/$(basename "$f")."
  done
}

pcaps=("$run/lidar.pcap")
if [ -d "$data" ]; then
  while IFS= read -r f; do pcaps+=("$f"); done < <(find "$data/velodyne" -name '*.pcap' | sort)
fi
"$build/tests/fuzz/fuzz_seeds" "$seeds" "${pcaps[@]}" >/dev/null
mkdir -p "$seeds/pcap_source"
for f in "${pcaps[@]}"; do head -c 32768 "$f" >"$seeds/pcap_source/$(basename "$f")"; done
slices "$seeds/ubx" "$run/gnss.trjb" ${data:+$(find "$data/ublox" -name '*.log' 2>/dev/null | sort)}
slices "$seeds/vn100" "$run/imu.trjb" ${data:+$(find "$data/vectornav" \( -name '*.raw' -o -name '*.bin' \) 2>/dev/null | sort)}
mkdir -p "$seeds"/{daemon_config,trajectory_csv,scenario,vlp16_calibration}
cp config/trajroid.yaml "$seeds/daemon_config/example.yaml"
cp "$run/trajroid.yaml" "$seeds/daemon_config/simulated.yaml"
cp config/trajectory.csv "$seeds/trajectory_csv/example.csv"
cp "$run/trajectory.csv" "$seeds/trajectory_csv/simulated.csv"
cp config/scenarios/*.yaml tests/daemon/corridor.yaml "$seeds/scenario/"
if [ -f "$data/velodyne/vlp16/nebula_VLP16_calibration.yaml" ]; then
  cp "$data/velodyne/vlp16/nebula_VLP16_calibration.yaml" "$seeds/vlp16_calibration/"
fi

max_len() {
  case $1 in
    vlp16_packets | pcap_source) echo 65536 ;;
    lcm_udpm) echo 262144 ;;
    ubx | vn100 | view_protocol | ntrip_answer) echo 16384 ;;
    *) echo 8192 ;;
  esac
}

report=$build/report.md
{
  echo "| target | seconds | executions | executions/s | corpus | peak RSS MB | result |"
  echo "|---|---|---|---|---|---|---|"
} >"$report"
failed=0
for t in "${targets[@]}"; do
  work=$build/work/$t
  artifacts=$build/artifacts/$t
  mkdir -p "$work" "$artifacts" "$seeds/$t"
  log=$build/logs/$t.log
  mkdir -p "$(dirname "$log")"
  set +e
  ASAN_OPTIONS=detect_leaks=1:abort_on_error=1 UBSAN_OPTIONS=print_stacktrace=1 \
    "$build/tests/fuzz/fuzz_$t" -max_total_time="$seconds" -max_len="$(max_len "$t")" -rss_limit_mb=2048 \
    -timeout=10 -print_final_stats=1 -artifact_prefix="$artifacts/" \
    "$work" "$seeds/$t" "tests/fuzz/corpus/$t" >"$log" 2>&1
  rc=$?
  set -e
  execs=$(sed -n 's/^stat::number_of_executed_units: *//p' "$log" | tail -1)
  rate=$(sed -n 's/^stat::average_exec_per_sec: *//p' "$log" | tail -1)
  rss=$(sed -n 's/^stat::peak_rss_mb: *//p' "$log" | tail -1)
  corpus=$(find "$work" -type f | wc -l)
  result=ok
  if [ $rc -ne 0 ]; then
    result="FAILED (exit $rc, see $log; input in $artifacts)"
    failed=1
  fi
  echo "| $t | $seconds | ${execs:-?} | ${rate:-?} | $corpus | ${rss:-?} | $result |" >>"$report"
  echo "fuzz $t: ${execs:-?} executions, ${rate:-?}/s, corpus $corpus, peak RSS ${rss:-?} MB: $result"
done
echo
cat "$report"
exit $failed
