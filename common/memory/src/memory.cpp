#include "trajroi/host/memory.hpp"

#include <sys/mman.h>
#include <unistd.h>

#include <atomic>
#include <cerrno>
#include <cstdint>

#ifndef MADV_POPULATE_WRITE
#define MADV_POPULATE_WRITE 23  // Linux 5.14 (uapi/asm-generic/mman-common.h)
#endif

namespace trajroi::host {

void populate(void* data, std::size_t bytes) noexcept {
  if (data == nullptr || bytes == 0) return;
  static const auto page = static_cast<std::uintptr_t>(sysconf(_SC_PAGESIZE));
  const auto first = reinterpret_cast<std::uintptr_t>(data) / page * page;
  const auto last = (reinterpret_cast<std::uintptr_t>(data) + bytes + page - 1) / page * page;
  static std::atomic<bool> supported{true};  // false once the kernel says it has no such advice
  if (supported.load(std::memory_order_relaxed)) {
    if (madvise(reinterpret_cast<void*>(first), last - first, MADV_POPULATE_WRITE) == 0) return;
    if (errno == EINVAL) supported.store(false, std::memory_order_relaxed);
  }
  for (std::uintptr_t at = first; at < last; at += page)
    __atomic_fetch_add(reinterpret_cast<unsigned char*>(at), 0, __ATOMIC_RELAXED);
}

}  // namespace trajroi::host
