#include "realtime.hpp"

#include <alloca.h>
#include <pthread.h>
#include <sched.h>
#include <sys/mman.h>

#include <cerrno>
#include <cstring>

#include "trajroi/host/memory.hpp"

namespace trajroi::daemon {

std::string apply_thread_config(const char* name, const ThreadConfig& config) {
  pthread_setname_np(pthread_self(), name);
  std::string warning;
  if (!config.cpus.empty()) {
    cpu_set_t set;
    CPU_ZERO(&set);
    for (const int cpu : config.cpus)
      CPU_SET(static_cast<std::size_t>(cpu), &set);
    if (const int rc = pthread_setaffinity_np(pthread_self(), sizeof set, &set); rc != 0) {
      warning += std::string("thread ") + name + ": CPU affinity not set (" + std::strerror(rc) + "); ";
    }
  }
  if (config.policy != SchedPolicy::kOther) {
    const int policy = config.policy == SchedPolicy::kFifo ? SCHED_FIFO : SCHED_RR;
    sched_param param{};
    param.sched_priority = config.priority;
    if (const int rc = pthread_setschedparam(pthread_self(), policy, &param); rc != 0) {
      warning += std::string("thread ") + name + ": " + (policy == SCHED_FIFO ? "SCHED_FIFO" : "SCHED_RR") +
                 " priority " + std::to_string(config.priority) + " refused (" + std::strerror(rc) +
                 "): running SCHED_OTHER; grant CAP_SYS_NICE or LimitRTPRIO";
    }
  }
  return warning;
}

std::string lock_memory() {
  if (mlockall(MCL_CURRENT | MCL_FUTURE) != 0) {
    return std::string("mlockall refused (") + std::strerror(errno) +
           "): memory may be paged; grant CAP_IPC_LOCK or raise LimitMEMLOCK";
  }
  return {};
}

void prefault_stack(std::size_t bytes) {
  // The pages below this frame, `bytes` deep: the thread's calls later stay within them.
  host::populate(alloca(bytes), bytes);
}

}  // namespace trajroi::daemon
