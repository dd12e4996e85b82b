// trajroi machine: how steadily this machine gives a thread its CPU (see
// trajroi/eval/steadiness.hpp). One timing thread per usable core, pinned to it and, where
// allowed, SCHED_FIFO above every other thread of the machine, times a fixed piece of
// arithmetic every few milliseconds; the slow spells found are the machine's own. The soak
// and bench/daemon_figures.sh run it beside the daemon to say what the machine did meanwhile.
#include <pthread.h>
#include <sched.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include "commands.hpp"
#include "trajroi/eval/steadiness.hpp"
#include "trajroi/host/clock.hpp"
#include "trajroi/inputs/input_source.hpp"
#include "trajroi/inputs/pacer.hpp"
#include "trajroi/roi/cpu.hpp"

namespace trajroi::cli {
namespace {

struct MachineOptions {
  double seconds = 10.0;
  double every_ms = 5.0;
  double piece_us = 50.0;
  int priority = 80;
  bool brief = false;
};

// A dependent chain of multiply-adds: no memory traffic, no branch to mispredict; its time
// is the core's speed alone.
double arithmetic(long steps, double x) noexcept {
  for (long i = 0; i < steps; ++i)
    x = x * 1.0000001 + 1e-9;
  return x;
}

// Steps for a piece of about `piece_us` at full speed: the fastest of a few timings.
long calibrate_steps(double piece_us) {
  constexpr long kProbe = 20'000;
  double fastest_us = 1e30;
  double sink = 1.0;
  for (int i = 0; i < 50; ++i) {
    const std::int64_t start = host::monotonic_ns();
    sink = arithmetic(kProbe, sink);
    fastest_us = std::min(fastest_us, static_cast<double>(host::monotonic_ns() - start) * 1e-3);
  }
  if (sink == 0.0) std::puts("");  // keeps the chain
  return std::max(1L, static_cast<long>(static_cast<double>(kProbe) * piece_us / std::max(fastest_us, 1e-3)));
}

struct Timer {
  std::size_t cpu = 0;
  bool pinned = false;
  bool fifo = false;
  std::vector<eval::PieceTiming> pieces;
};

void time_pieces(Timer& timer, const MachineOptions& o, long steps, std::int64_t start_ns) {
  cpu_set_t set;
  CPU_ZERO(&set);
  CPU_SET(timer.cpu, &set);
  timer.pinned = pthread_setaffinity_np(pthread_self(), sizeof set, &set) == 0;
  sched_param param{};
  param.sched_priority = o.priority;
  timer.fifo = o.priority > 0 && pthread_setschedparam(pthread_self(), SCHED_FIFO, &param) == 0;
  const std::int64_t every_ns = std::llround(o.every_ms * 1e6);
  const std::int64_t end_ns = start_ns + std::llround(o.seconds * 1e9);
  std::int64_t next_ns = host::monotonic_ns();
  double x = 1.0;
  timer.pieces.reserve(static_cast<std::size_t>(o.seconds * 1e3 / o.every_ms) + 16);
  for (;;) {
    const std::int64_t t = host::monotonic_ns();
    if (t >= end_ns) break;
    x = arithmetic(steps, x);
    const std::int64_t done = host::monotonic_ns();
    timer.pieces.push_back({static_cast<double>(t - start_ns) * 1e-9, static_cast<double>(done - t) * 1e-3});
    // The next piece one interval on; after a slow spell, one interval from now (catching up
    // would run pieces back to back, above every other thread).
    next_ns = std::max(next_ns, done) + every_ns;
    (void)inputs::Pacer::sleep_until(next_ns);
  }
  if (x == 0.0) std::puts("");
}

int run_machine(const MachineOptions& o) {
  if (!(o.seconds > 0.0) || !(o.every_ms > 0.0) || !(o.piece_us > 0.0) || o.piece_us >= o.every_ms * 1e3) {
    std::fprintf(stderr,
                 "trajroi machine: --seconds, --every-ms and --piece-us must be positive, the piece shorter "
                 "than the interval\n");
    return 2;
  }
  cpu_set_t allowed;
  CPU_ZERO(&allowed);
  (void)sched_getaffinity(0, sizeof allowed, &allowed);
  std::vector<Timer> timers;
  for (std::size_t cpu = 0; cpu < CPU_SETSIZE; ++cpu) {
    if (CPU_ISSET(cpu, &allowed)) timers.push_back({cpu, false, false, {}});
  }
  const long steps = calibrate_steps(o.piece_us);
  const std::int64_t start_ns = host::monotonic_ns();
  std::vector<std::thread> threads;
  threads.reserve(timers.size());
  for (Timer& t : timers)
    threads.emplace_back(time_pieces, std::ref(t), std::cref(o), steps, start_ns);
  for (std::thread& t : threads)
    t.join();

  std::vector<eval::Steadiness> found;
  for (const Timer& t : timers)
    found.push_back(eval::find_slow_spells(t.pieces));
  double longest = 0.0;
  double worst = 0.0;
  double slow = 0.0;
  for (const eval::Steadiness& s : found) {
    longest = std::max(longest, s.longest_ms());
    worst = std::max(worst, s.worst_factor());
    slow = std::max(slow, s.slow_ms());
  }
  if (o.brief) {  // for scripts: the longest spell (ms), the worst factor, the most slow time of a core (ms);
    // the factor to 0.01, so that a spell just over 2x does not read as 2x
    std::printf("%.1f %.2f %.1f\n", longest, worst, slow);
    return 0;
  }
  const bool fifo = std::all_of(timers.begin(), timers.end(), [](const Timer& t) { return t.fifo; });
  std::printf(
      "machine: %s; %zu timing threads (one per core, %s), a %.0f µs piece of arithmetic every %.1f ms for "
      "%g s\n",
      roi::describe_machine().c_str(), timers.size(),
      fifo              ? ("SCHED_FIFO " + std::to_string(o.priority)).c_str()
      : o.priority <= 0 ? "SCHED_OTHER as asked: this machine's own threads count too"
                        : "SCHED_OTHER: could not raise the priority, so this machine's own threads count too",
      o.piece_us, o.every_ms, o.seconds);
  for (std::size_t i = 0; i < timers.size(); ++i) {
    const eval::Steadiness& s = found[i];
    std::printf(
        "cpu %zu: %zu pieces, full speed %.1f µs, median %.1f µs; %zu slow spells (over 2x full speed), longest "
        "%.1f ms, worst %.1fx, %.1f ms slow in all%s\n",
        timers[i].cpu, s.pieces, s.full_speed_us, s.median_us, s.spells.size(), s.longest_ms(), s.worst_factor(),
        s.slow_ms(), timers[i].pinned ? "" : " (not pinned: it may have moved between cores)");
    int shown = 0;
    for (const eval::SlowSpell& spell : s.spells) {
      if (spell.end_s - spell.start_s < 0.005 || ++shown > 10) continue;
      std::printf("  %.3f–%.3f s: %.1f ms, up to %.1fx\n", spell.start_s, spell.end_s,
                  (spell.end_s - spell.start_s) * 1e3, spell.worst_factor);
    }
  }
  std::printf("machine: longest slow spell %.1f ms, worst %.1fx full speed\n", longest, worst);
  return 0;
}

}  // namespace

void add_machine_command(CLI::App& app) {
  auto opts = std::make_shared<MachineOptions>();
  CLI::App* cmd = app.add_subcommand(
      "machine",
      "How steadily this machine gives a thread its CPU: the slow spells of a fixed piece of arithmetic "
      "timed on every core (what a real-time figure measured meanwhile also measures)");
  cmd->add_option("--seconds", opts->seconds, "How long to time (default 10)");
  cmd->add_option("--every-ms", opts->every_ms, "One piece every this many milliseconds on each core (default 5)");
  cmd->add_option("--piece-us", opts->piece_us, "The piece's length at full speed in µs (default 50)");
  cmd->add_option("--priority", opts->priority,
                  "SCHED_FIFO priority of the timing threads, 0 for SCHED_OTHER (default 80; needs CAP_SYS_NICE)");
  cmd->add_flag("--brief", opts->brief, "One line: longest spell ms, worst factor, slow ms of the slowest core");
  cmd->callback([opts] {
    if (const int rc = run_machine(*opts); rc != 0) throw CLI::RuntimeError(rc);
  });
}

}  // namespace trajroi::cli
