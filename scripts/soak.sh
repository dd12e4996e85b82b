#!/usr/bin/env bash
# Soak: trajroid replays a simulated run (tests/daemon/corridor.yaml, dual return) in a loop at
# RATE × real time for MINUTES, publishing over LCM on loopback. Each minute it prints the
# daemon's resident memory (from /proc), the sweeps, the latency percentiles (last packet of a
# sweep → LCM publication), ring and kernel drops, as the daemon's own once-a-minute line
# reports them, and the CPU time the hypervisor took from this machine (steal). Passes when
# memory stays within 5 % of the first minute's and nothing is dropped; says how many minutes
# had a maximum latency above 5 ms. Beside the daemon run witnesses of the machine itself, whose
# figures no process of this machine can have caused (nothing runs above them): `trajroi
# machine` (a fixed piece of arithmetic timed every 5 ms on each core: the longest spell it ran
# over twice as slow as at full speed) and, with cyclictest installed (Debian's rt-tests), a
# SCHED_FIFO thread per CPU waking every millisecond (its longest delay); each minute's are
# printed next to the daemon's maximum.
# Usage: scripts/soak.sh [MINUTES=10] [RATE=10] [BUILD_DIR=build/release]
set -euo pipefail
cd "$(dirname "$0")/.."
# shellcheck source=scripts/lib/host.sh
. scripts/lib/host.sh
minutes=${1:-10}
rate=${2:-10}
build=${3:-build/release}
if [ ! -x "$build/daemon/trajroid" ] || [ ! -x "$build/tools/trajroi" ]; then
  cmake --preset release >/dev/null
  cmake --build "$build" --target trajroid trajroi
fi
work=$(mktemp -d)
daemon_pid=
probe_pid=
steady_pid=
cleanup() {
  if [ -n "$daemon_pid" ]; then kill "$daemon_pid" 2>/dev/null || true; fi
  if [ -n "$steady_pid" ]; then
    local -a timers
    mapfile -t timers < <(pgrep -P "$steady_pid" || true)
    kill "$steady_pid" "${timers[@]}" 2>/dev/null || true
  fi
  if [ -n "$probe_pid" ]; then
    local -a children
    mapfile -t children < <(pgrep -P "$probe_pid" || true)
    kill "$probe_pid" "${children[@]}" 2>/dev/null || true
  fi
  rm -rf "$work"
}
trap cleanup EXIT
"$build/tools/trajroi" sim --quiet --scenario tests/daemon/corridor.yaml --out "$work/run" >/dev/null
lap_s=$(awk '/^duration_s/ {print $2}' "$work/run/summary.txt")
# Own channel names: nothing else listening on this machine is disturbed.
cp "$work/run/trajroid.yaml" "$work/run/soak.yaml"
printf 'lcm:\n  channels: {points: SOAK_POINTS, pose: SOAK_POSE, roi: SOAK_ROI, status: SOAK_STATUS, trajectory: SOAK_TRAJECTORY}\n' \
  >>"$work/run/soak.yaml"

"$build/daemon/trajroid" --config "$work/run/soak.yaml" --replay "$work/run" --loop --rate "$rate" \
  --lcm-url 'udpm://239.255.76.67:7667?ttl=0' 2>"$work/trajroid.log" &
daemon_pid=$!
# The second witness: how steadily the machine gave a thread its CPU each minute (trajroi
# machine: a fixed piece of arithmetic timed every 5 ms on each core, SCHED_FIFO): the longest
# spell it ran over twice as slow as at full speed, and how slow. A hypervisor that takes the
# CPUs away in slices delays a wake-up by a millisecond or two (cyclictest) but stretches a few
# milliseconds of work ten-fold.
for ((m = 1; m <= minutes; ++m)); do
  "$build/tools/trajroi" machine --seconds 60 --brief 2>/dev/null || echo "- - -"
done >"$work/steady.txt" &
steady_pid=$!
probe=$(command -v cyclictest || true)
if [ -n "$probe" ]; then
  # One run a minute, started with the daemon: its m-th line is the daemon's m-th minute (ms).
  for ((m = 1; m <= minutes; ++m)); do
    "$probe" -q -m -S -p 90 -i 1000 -D 60 2>/dev/null |
      awk '/Max:/ {v = $NF + 0; if (v > max) max = v} END {printf "%.2f\n", max / 1000}'
  done >"$work/probe.txt" &
  probe_pid=$!
else
  echo "soak: cyclictest not installed (apt-get install rt-tests): no witness of the machine's own wake-up delays"
fi
echo "soak: corridor run (${lap_s} s of dual-return data a lap) looped at ${rate}x real time for ${minutes} min"
echo "soak: machine: $(machine_name "$build")"
printf '%-6s %9s %8s %9s %10s %10s %10s %10s %10s %10s\n' minute "RSS MiB" sweeps published "p50 ms" "p99 ms" "max ms" \
  "ring drop" "kern drop" "steal ms"
# Steal: CPU time the hypervisor gave to others while this machine's CPUs wanted it (all CPUs,
# /proc/stat), during that minute; a virtual machine's tail latency follows it.
steal_before=$(steal_ms)
maxima=()
rss_mib() { awk '/^VmRSS:/ {printf "%.1f", $2 / 1024}' "/proc/$daemon_pid/status"; }
rss=()
seen=0
for ((m = 1; m <= minutes; ++m)); do
  # The daemon logs its minute line once a minute of status; wait for the m-th.
  until [ "$(grep -c ' minute: ' "$work/trajroid.log" || true)" -ge "$m" ]; do
    if ! kill -0 "$daemon_pid" 2>/dev/null; then
      echo "soak: trajroid ended early:" >&2
      tail -20 "$work/trajroid.log" >&2
      exit 1
    fi
    sleep 1
  done
  r=$(rss_mib)
  rss+=("$r")
  steal_now=$(steal_ms)
  stolen=$((steal_now - steal_before))
  steal_before=$steal_now
  line=$(grep ' minute: ' "$work/trajroid.log" | sed -n "${m}p")
  seen=$m
  maxima+=("$(awk '{for (i = 1; i <= NF; ++i) if ($i == "max") print $(i + 1)}' <<<"$line")")
  awk -v m="$m" -v r="$r" -v stolen="$stolen" '{
      for (i = 1; i <= NF; ++i) {
        if ($i == "sweeps") sweeps = $(i + 1)
        if ($i == "published") published = $(i + 1)
        if ($i == "p50") p50 = $(i + 1)
        if ($i == "p99") p99 = $(i + 1)
        if ($i == "max") max = $(i + 1)
        if ($i == "ring") ring = $(i + 2)
        if ($i == "kernel") kern = $(i + 2)
      }
      printf "%-6s %9s %8s %9s %10s %10s %10s %10s %10s %10s\n", m, r, sweeps, published, p50, p99, max, ring, kern, stolen
    }' <<<"$line"
done
kill -TERM "$daemon_pid"
wait "$daemon_pid" || true
daemon_pid=
summary=$(grep 'summary:' "$work/trajroid.log" || true)
echo "soak: ${summary#*summary: }"
laps=$(grep -c 'replay: lap' "$work/trajroid.log" || true)
echo "soak: $((laps + 1)) laps; lidar restarts at each lap boundary are the replay looping, not a fault"
awk -v all="${maxima[*]}" 'BEGIN {
  n = split(all, v, " "); over = 0; hi = 0
  for (i = 1; i <= n; ++i) { if (v[i] > 5) ++over; if (v[i] > hi) hi = v[i] }
  printf "soak: per-minute maximum latency up to %.2f ms; %d of %d minutes above 5 ms (goal 0)\n", hi, over, n
}'
# Where each late minute's slowest sweep spent its time (the daemon names it on the minute's line).
grep ' minute: ' "$work/trajroid.log" | head -n "$seen" |
  awk -F ' [|] slowest: ' 'NF > 1 {printf "soak: minute %d, slowest: %s\n", NR, $2}'
if [ -n "$probe_pid" ]; then
  wait "$probe_pid" || true
  probe_pid=
else
  for ((m = 1; m <= seen; ++m)); do echo "-"; done >"$work/probe.txt"
fi
wait "$steady_pid" || true
steady_pid=
# A minute the machine itself held a thread off (cyclictest) or ran it over twice as slow
# (trajroi machine) for more than 5 ms cannot judge a daemon's maximum above 5 ms: such a
# minute is named apart. A maximum within 5 ms is met whatever the machine did.
echo "soak: per-minute maximum, daemon's latency / the machine's wake-up delay (cyclictest, SCHED_FIFO, every CPU each ms) / its longest slow spell (trajroi machine: arithmetic over 2x slower than at full speed, every core):"
paste -d ' ' <(printf '%s\n' "${maxima[@]}") <(head -n "$seen" "$work/probe.txt") <(head -n "$seen" "$work/steady.txt") |
  awk '{printf "  minute %d: %s / %s ms / %s ms, up to %sx\n", NR, $1, ($2 == "" ? "-" : $2), $3, $4}
    ($2 != "-" && $2 > 5) || ($3 != "-" && $3 > 5) {++slow; if ($1 > 5) ++unjudged}
    END {
      if (slow == 0) exit
      printf "soak: the machine itself held a thread off or slowed it for over 5 ms in %d of %d minutes", slow, NR
      if (unjudged > 0) printf "; %d of the daemon'"'"'s minutes above 5 ms fell in them and cannot be judged here\n", unjudged
      else printf "; the daemon stayed within 5 ms in all of them\n"
    }'
drops=$(grep ' minute: ' "$work/trajroid.log" | head -n "$seen" |
  awk '{for (i = 1; i <= NF; ++i) {if ($i == "ring") r += $(i + 2); if ($i == "kernel") k += $(i + 2)}} END {print r + k}')
awk -v first="${rss[0]}" -v last="${rss[${#rss[@]} - 1]}" -v drops="$drops" -v all="${rss[*]}" 'BEGIN {
  n = split(all, v, " "); lo = v[1]; hi = v[1]
  for (i = 2; i <= n; ++i) { if (v[i] < lo) lo = v[i]; if (v[i] > hi) hi = v[i] }
  growth = 100 * (hi - first) / first
  printf "soak: RSS first minute %.1f MiB, last %.1f MiB, range %.1f … %.1f MiB (%+.1f %% of the first; goal within 5 %%); drops %d (goal 0)\n", first, last, lo, hi, growth, drops
  ok = (growth <= 5 && (first - lo) / first * 100 <= 5 && drops == 0)
  print ok ? "soak: PASS" : "soak: FAIL"
  exit !ok
}'
