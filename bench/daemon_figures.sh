#!/usr/bin/env bash
# trajroid's performance figures, printed (not a timed test): a dual-return scenario
# (tests/daemon/corridor.yaml, 28.8 s) replayed through the daemon publishing over LCM on
# loopback, (1) at real-time pace: latency from the last packet of a sweep to its LCM
# publication (p50, p99), CPU time per second of data, ring drops; (2) as fast as possible:
# the replay speed as a multiple of real time; (3) four VLP-16 streams (the same data from four
# senders, bench/four_lidars.py, merged) at real-time pace: the pipeline's CPU and latency.
# Each kind is run TRAJROI_FIGURE_RUNS times (5)
# and its medians are the figures. Beside each real-time run, `trajroi machine` says how
# steadily the machine gave a thread its CPU meanwhile (its longest slow spell).
# The LCM group's route is printed with the figures: the publishing thread's CPU depends on it
# (docs/lcm.md, "The group's route on one machine"). TRAJROI_FIGURES_ROUTE=lo measures in a
# network namespace of the script's own whose group goes over lo, as on a robot whose
# subscribers all run on it (needs root, unshare and ip); otherwise the machine's own route.
# Usage: bench/daemon_figures.sh [BUILD_DIR]   (default build/release)
set -euo pipefail
if [ "${TRAJROI_FIGURES_ROUTE:-}" = lo ] && [ -z "${TRAJROI_FIGURES_NETNS:-}" ]; then
  export TRAJROI_FIGURES_NETNS=1
  exec unshare --net bash -c \
    'ip link set lo up && ip link set lo multicast on && ip route add 224.0.0.0/4 dev lo && exec bash "$0" "$@"' "$0" "$@"
fi
export LC_NUMERIC=C  # bash's time and awk agree on the decimal point
cd "$(dirname "$0")/.."
# shellcheck source=scripts/lib/host.sh
. scripts/lib/host.sh  # steal_ms: the host's steal over each run
build=${1:-build/release}
run=$(mktemp -d)/corridor
trap 'rm -rf "$(dirname "$run")"' EXIT
"$build/tools/trajroi" sim --quiet --scenario tests/daemon/corridor.yaml --out "$run" >/dev/null
duration=$(awk '/^duration_s/ {print $2}' "$run/summary.txt")

# A real-time run's witness of the machine (trajroi machine, beside it for the run's length):
# the longest spell a fixed piece of arithmetic ran over twice as slow as at full speed, and how
# slow; a latency tail measured during such a spell is the machine's.
steady="$(dirname "$run")/steady.txt"
figures() {  # rate [run] → "latency_p50 latency_p99 drops wall_s cpu_s pipeline_cpu_s spell_ms spell_factor run_s steal_ms"
  local log witness= steal0 folder=${2:-$run}
  steal0=$(steal_ms)
  if [ "$1" = realtime ]; then
    "$build/tools/trajroi" machine --seconds "$duration" --brief >"$steady" 2>/dev/null &
    witness=$!
  fi
  # The process's wall, user and system time from bash's `time` (to the millisecond), which
  # times the process itself: /usr/bin/time would add its own start (5 ms on a VM) to the wall.
  local TIMEFORMAT='TIME %R %U %S'
  log=$( { time "$build/daemon/trajroid" --config "$folder/trajroid.yaml" --replay "$folder" --rate "$1" 2>&1; } 2>&1 )
  local summary
  summary=$(grep "summary:" <<<"$log")
  local p50 p99 drops run_s
  # The daemon's own run, from its start to its summary (the process's start-up and exit not in it).
  run_s=$(sed -n 's/.*summary: \([0-9.]*\) s .*/\1/p' <<<"$summary")
  p50=$(sed -n 's/.*latency p50 \([0-9.]*\) ms.*/\1/p' <<<"$summary")
  p99=$(sed -n 's/.*p99 \([0-9.]*\) ms over.*/\1/p' <<<"$summary")
  drops=$(sed -n 's/.*ring drops \([0-9]*\).*/\1/p' <<<"$summary")
  local wall user sys
  read -r _ wall user sys < <(grep "^TIME" <<<"$log")
  local pipeline
  pipeline=$(sed -n 's/.*processing \([0-9.]*\) s, publishing \([0-9.]*\) s.*/\1 \2/p' <<<"$log" | awk '{print $1 + $2}')
  local spell="- -"
  if [ -n "$witness" ]; then
    wait "$witness" && spell=$(awk '{print $1, $2}' "$steady")
  fi
  echo "$p50 $p99 $drops $wall $(awk -v u="$user" -v s="$sys" 'BEGIN {print u + s}') $pipeline $spell $run_s $(($(steal_ms) - steal0))"
}

echo "scenario: tests/daemon/corridor.yaml, dual return, ${duration} s of data"
route=$(ip route get 239.255.76.67 2>/dev/null | head -n 1 | sed 's/ *$//' || true)
echo "LCM group udpm://239.255.76.67:7667?ttl=0, its route: ${route:-unknown}${TRAJROI_FIGURES_NETNS:+ (in a network namespace of the script, TRAJROI_FIGURES_ROUTE=lo)}"
# Where these figures come from: the CPU, its cores, and the ROI scan trajroid calibrated.
start=$("$build/daemon/trajroid" --config "$run/trajroid.yaml" --replay "$run" --rate max 2>&1)
scan=$(grep "roi scan for" <<<"$start" || true)
decoder=$(grep "vlp16 decoder:" <<<"$start" || true)
echo "machine and scan: ${scan#*roi scan for }; decoder: ${decoder#*vlp16 decoder: }"
# Five real-time runs: the goals are the medians (one run's tail is one spell of the machine).
runs=${TRAJROI_FIGURE_RUNS:-5}
table=$(for _ in $(seq 1 "$runs"); do figures realtime; done)
median() { sort -g | awk '{v[NR] = $1} END {print (NR % 2) ? v[(NR + 1) / 2] : (v[NR / 2] + v[NR / 2 + 1]) / 2}'; }
p50=$(awk '{print $1}' <<<"$table" | median)
p99=$(awk '{print $2}' <<<"$table" | median)
drops=$(awk '{s += $3} END {print s}' <<<"$table")
cpu=$(awk '{print $5}' <<<"$table" | median)
pipeline=$(awk '{print $6}' <<<"$table" | median)
echo "real-time replay, ${runs} runs: latency last packet → LCM p50 ${p50} ms, p99 ${p99} ms (medians; goal p99 <= 2 ms; each run's p99: $(awk '{printf "%s ", $2}' <<<"$table")); ring drops ${drops} (goal 0)"
echo "the machine meanwhile (trajroi machine, each run): longest spell of arithmetic over 2x slower than at full speed $(awk '{printf "%s ms (%sx) ", $7, $8}' <<<"$table")"
awk -v c="$cpu" -v p="$pipeline" -v d="$duration" 'BEGIN {
  printf "real-time replay: CPU of the pipeline (processing + publishing threads) %.3f s for %.1f s of data = %.2f %% of one core (median; goal <= 2 %%)\n", p, d, 100 * p / d
  printf "real-time replay: CPU of the whole process, the replay reader standing in for the sensors included, %.3f s = %.2f %%\n", c, 100 * c / d}'
# As fast as possible, as many runs: the median wall time (one run's is one spell of the host).
fast=$(for _ in $(seq 1 "$runs"); do figures max; done)
wall=$(awk '{print $4}' <<<"$fast" | median)
drops=$(awk '{s += $3} END {print s}' <<<"$fast")
awk -v w="$wall" -v d="$duration" -v x="$drops" -v n="$runs" -v each="$(awk '{printf "%s ", $4}' <<<"$fast")" \
  'BEGIN {printf "as fast as possible, %d runs: %.1f s of data in %.3f s = %.0fx real time (median; goal >= 200x; each run: %ss); ring drops %d\n", n, d, w, d / w, each, x}'
# Of that wall time, the daemon's own run (its summary: the threads' work) against the process's
# start-up (configuration, the calibrations, the buffers touched) and exit: for where the time goes.
inside=$(awk '{print $9}' <<<"$fast" | median)
awk -v r="$inside" -v w="$wall" -v d="$duration" \
  'BEGIN {printf "as fast as possible: the run inside the daemon (its summary) %.3f s = %.0fx (median), start-up and exit of the process %.3f s\n", r, d / r, w - r}'
# The work against the machine: the whole process's CPU (user + system, every thread) spread
# perfectly over every core is the shortest wall time this build could have here; steal is
# the time the host took the VM's CPUs away meanwhile.
cpu=$(awk '{print $5}' <<<"$fast" | median)
cores=$(nproc)
awk -v c="$cpu" -v n="$cores" -v d="$duration" -v w="$wall" -v st="$(awk '{printf "%s ", $10}' <<<"$fast")" \
  'BEGIN {printf "as fast as possible: CPU of the whole process %.3f s (median) = %.0f %% of %d cores over the wall; spread perfectly over them it needs %.3f s = %.0fx at most; the host'"'"'s steal each run: %sms\n", c, 100 * c / (n * w), n, c / n, d * n / c, st}'
# Four VLP-16 streams at real-time pace, merged into one points_t per window.
run4="$(dirname "$run")/four"
"${PYTHON:-python3}" bench/four_lidars.py "$run" "$run4"
four=$(for _ in $(seq 1 "$runs"); do figures realtime "$run4"; done)
p99=$(awk '{print $2}' <<<"$four" | median)
pipeline=$(awk '{print $6}' <<<"$four" | median)
drops=$(awk '{s += $3} END {print s}' <<<"$four")
awk -v p="$pipeline" -v d="$duration" -v q="$p99" -v x="$drops" -v n="$runs" -v each="$(awk '{printf "%s ", $2}' <<<"$four")" \
  'BEGIN {printf "four VLP-16 streams (dual return, merged), real time, %d runs: CPU of the pipeline %.3f s for %.1f s of data = %.2f %% of one core (median; goal <= 4 %%); latency last packet → LCM p99 %s ms (median; goal <= 2 ms; each run: %s); ring drops %d\n", n, p, d, 100 * p / d, q, each, x}'
