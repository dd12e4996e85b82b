#pragma once

// One interface for every serial byte stream (GNSS, IMU), live or replayed, so the daemon
// cannot tell a recorded run from a live one except by configuration.
#include <chrono>
#include <cstdint>
#include <span>
#include <string>

namespace trajroi::serial {

// Bytes as they arrived, stamped with the host's monotonic clock (ns) when the read
// returned. `bytes` stays valid until the next read().
struct Chunk {
  std::span<const std::uint8_t> bytes;
  std::int64_t receive_time_ns = 0;
};

enum class ReadStatus : std::uint8_t {
  kData,          // `chunk` holds at least one byte
  kTimeout,       // nothing within the timeout (a live port waiting, or reconnecting)
  kDisconnected,  // the device went away; the source keeps trying to reopen it
  kEnd,           // a replay reached its end
};

struct SourceCounters {
  std::uint64_t chunks = 0;
  std::uint64_t bytes = 0;
  std::uint64_t disconnects = 0;    // a port that was open and failed
  std::uint64_t open_failures = 0;  // attempts to (re)open that failed
  std::uint64_t opens = 0;          // successful opens
};

class ByteSource {
 public:
  virtual ~ByteSource() = default;
  // Waits at most `timeout` for bytes. Never throws once constructed.
  virtual ReadStatus read(Chunk& chunk, std::chrono::milliseconds timeout) = 0;
  [[nodiscard]] virtual const SourceCounters& counters() const noexcept = 0;
  // What the source is reading, for logs ("/dev/ttyACM0 @ 115200", "gnss.trjb").
  [[nodiscard]] virtual std::string describe() const = 0;
};

}  // namespace trajroi::serial
