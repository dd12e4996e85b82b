# What the figure scripts (scripts/soak.sh, bench/daemon_figures.sh) say of the machine they
# ran on; sourced, not run.

# The machine as every figure names it (roi::describe_machine: the CPU's model name with x86's
# family and model numbers, the usable cores, the SIMD paths), from trajroi in build dir $1.
machine_name() {
  "$1/tools/trajroi" machine --seconds 0.01 --priority 0 2>/dev/null | sed -n 's/^machine: \([^;]*\);.*/\1/p'
}

# The host's steal so far (/proc/stat, all CPUs, ms): CPU time the hypervisor gave to others
# while this VM's CPUs had work. Differences of two readings time a run or a minute.
steal_ms() { awk -v hz="$(getconf CLK_TCK)" '/^cpu / {printf "%.0f", $9 * 1000 / hz}' /proc/stat; }
