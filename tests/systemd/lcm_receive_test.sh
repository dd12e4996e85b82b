#!/usr/bin/env bash
# A plain lcm-logger (its default URL, no receive-buffer option) records every point cloud of a
# real-time dual-return replay once the package's sysctl drop-in is applied. The replay and the
# logger share a network namespace of their own (LCM on its loopback); the receive-buffer
# settings are the machine's (the kernel keeps net.core.rmem_* global), applied here and put
# back as they were at the end. First the same run with the machine's settings, for the record.
# Usage: lcm_receive_test.sh TRAJROI TRAJROID SCENARIO DROP_IN PYTHONPATH WORK
set -euo pipefail
trajroi=$1 trajroid=$2 scenario=$3 drop_in=$4 python_path=$5 work=$6
here=$(cd "$(dirname "$0")" && pwd)
# shellcheck source=../lib/skip.sh
source "$here/../lib/skip.sh"
require_netns lcm_receive_test
rm -rf "$work"
mkdir -p "$work"
"$trajroi" sim --quiet --scenario "$scenario" --out "$work/run" >/dev/null

old_default=$(sysctl -n net.core.rmem_default)
old_max=$(sysctl -n net.core.rmem_max)
trap 'sysctl -q -w net.core.rmem_max="$old_max" net.core.rmem_default="$old_default"' EXIT

# One real-time replay with lcm-logger listening; prints "published RECEIVED".
run() {
  local label=$1
  bash "$(dirname "$0")/../systemd/own_network.sh" /bin/bash -c '
    set -euo pipefail
    lcm-logger --quiet "$1/$2.lcmlog" >"$1/$2.logger.txt" 2>&1 &
    logger=$!
    sleep 1
    "$3" --config "$1/run/trajroid.yaml" --replay "$1/run" --rate realtime 2>"$1/$2.trajroid.log"
    sleep 1
    kill -INT "$logger"
    wait "$logger" || true' _ "$work" "$label" "$trajroid"
  local published received
  published=$(sed -n 's/.*summary: .* published \([0-9]*\) withheld.*/\1/p' "$work/$label.trajroid.log")
  received=$(PYTHONPATH="$python_path" "${PYTHON:-python3}" "$here/log_summary.py" "$work/$label.lcmlog" |
    awk '$2 == "points_t" {n += $3} END {print n + 0}')
  echo "$published $received"
}

read -r published received < <(run machine)
echo "machine settings (rmem_default $old_default, rmem_max $old_max): lcm-logger recorded $received of $published point clouds"
grep -h "buffer" "$work/machine.logger.txt" || true

sysctl -q -p "$drop_in"
read -r published received < <(run drop_in)
echo "after $(basename "$drop_in") (rmem_default $(sysctl -n net.core.rmem_default), rmem_max $(sysctl -n net.core.rmem_max)): lcm-logger recorded $received of $published point clouds"
grep -h "buffer" "$work/drop_in.logger.txt" || true
[ "$published" -gt 200 ] || { echo "FAIL: only $published clouds published" >&2; exit 1; }
# At least 99.9 %: with fewer than 1 000 clouds, every one.
awk -v r="$received" -v p="$published" 'BEGIN { exit !(r * 1000 >= p * 999) }' ||
  { echo "FAIL: $received of $published clouds recorded, fewer than 99.9 %" >&2; exit 1; }
echo "PASS: $(awk -v r="$received" -v p="$published" 'BEGIN { printf "%.2f", 100 * r / p }') % of the clouds recorded"
