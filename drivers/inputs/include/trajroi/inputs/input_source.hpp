#pragma once

// What every input of trajroid is: a stream of items {stream, bytes, receive time}, the time
// always the host's CLOCK_MONOTONIC in ns (a live source converts at the edge; a recorded
// source hands back what was recorded). The daemon's input thread, `trajroi feed` and the
// evaluations read through this interface and cannot tell a live sensor from a recording
// except by the end of the latter.
#include <chrono>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

namespace trajroi::inputs {

enum class Stream : std::uint8_t {
  kLidarData,      // a VLP-16 data packet (UDP 2368)
  kLidarPosition,  // a VLP-16 position packet (UDP 8308)
  kGnss,           // bytes from the GNSS receiver (u-blox UBX)
  kImu,            // bytes from the IMU (VN-100 binary)
  kPose,           // a pose from the robot's localization (pose_input_t, with its clock offset)
};
inline constexpr std::size_t kStreamCount = 5;
[[nodiscard]] constexpr bool is_lidar(Stream s) noexcept {
  return s == Stream::kLidarData || s == Stream::kLidarPosition;
}

// The longest LiDAR datagram an input hands out (the Ethernet MTU; a VLP-16 packet is 1206
// bytes): longer ones are dropped and counted by the source (InputCounters::oversize).
inline constexpr std::size_t kMaxDatagramBytes = 1500;

struct InputItem {
  Stream stream = Stream::kLidarData;
  std::span<const std::uint8_t> bytes;  // valid until the next call to next()
  std::int64_t receive_ns = 0;          // CLOCK_MONOTONIC (or as recorded)
  std::uint64_t sender = 0;             // a datagram's sender: IPv4 address << 16 | port (0: unknown)
  std::uint16_t port = 0;               // a datagram's destination port (0: unknown)
};

// Something the source wants said in the log (a port opened, a device unplugged, a lap).
struct Notice {
  enum class Level : std::uint8_t { kInfo, kWarning } level = Level::kInfo;
  std::string text;
};

// Counted by the source, read by its one reader thread (copied to the status from there).
struct InputCounters {
  std::uint64_t items = 0;
  std::uint64_t oversize = 0;          // datagrams too long for a Velodyne packet (dropped)
  std::uint64_t errors = 0;            // socket or file errors
  std::uint64_t disconnects = 0;       // serial devices that went away
  std::uint64_t rejected_sources = 0;  // datagrams from an address other than the sensor's
  std::uint64_t kernel_drops = 0;      // datagrams the kernel dropped (full receive buffer)
  std::uint8_t closed_streams = 0;     // bit 1 << stream: a serial device not open now (retried)
};

class InputSource {
 public:
  enum class Next : std::uint8_t {
    kItem,     // `item` is filled
    kTimeout,  // nothing within the timeout; call again
    kNotice,   // notice() has something to log; call again
    kError,    // error() says what failed; the source goes on (live) or ends (a cut file)
    kEnd,      // a recording's end: nothing more will come
  };
  virtual ~InputSource() = default;
  // Waits at most `timeout` for the next item. Never throws once constructed.
  virtual Next next(InputItem& item, std::chrono::milliseconds timeout) = 0;
  // True when next() would return an item now without waiting (a paced recording's next item
  // is due): the reader does not let an item wait for company then. A live source says false.
  [[nodiscard]] virtual bool ready() const noexcept { return false; }
  [[nodiscard]] virtual const Notice& notice() const noexcept = 0;
  [[nodiscard]] virtual const std::string& error() const noexcept = 0;
  [[nodiscard]] virtual InputCounters counters() const noexcept = 0;
  // What is read, for logs ("UDP 0.0.0.0:2368/8308", "/dev/gnss at 115200 baud", a folder).
  [[nodiscard]] virtual std::string describe() const = 0;
};

}  // namespace trajroi::inputs
