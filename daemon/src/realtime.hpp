#pragma once

// Real-time set-up of the calling thread and of the process: scheduling policy and priority,
// CPU affinity, locked memory. Each returns a message to log when it could not do what was
// configured (permission, no such CPU), and the daemon carries on with what it got.
#include <cstddef>
#include <string>

#include "trajroi/daemon/config.hpp"

namespace trajroi::daemon {

// Applies `config` to the calling thread and names it (visible in top -H, ps -L).
// Returns an empty string on success, else a warning.
std::string apply_thread_config(const char* name, const ThreadConfig& config);

// mlockall(MCL_CURRENT | MCL_FUTURE). Empty on success, else a warning.
std::string lock_memory();

// Makes `bytes` of stack below the caller resident (host::populate) before the steady state.
void prefault_stack(std::size_t bytes = 256 * 1024);

}  // namespace trajroi::daemon
