#pragma once

// Where Velodyne UDP payloads come from: a live socket (UdpSource) or a capture file
// (PcapSource). The consumer cannot tell them apart except by the end of a file.
#include <chrono>
#include <cstdint>
#include <span>
#include <string>

namespace trajroi::vlp16 {

inline constexpr std::uint16_t kDataPort = 2368;
inline constexpr std::uint16_t kPositionPort = 8308;

// One UDP datagram.
struct Datagram {
  std::span<const std::uint8_t> payload;  // valid until the next call to next()
  std::uint16_t destination_port = 0;
  std::int64_t receive_time_ns = 0;  // CLOCK_REALTIME: kernel receive stamp, or pcap record time
  std::uint64_t sender = 0;          // the sender's IPv4 address << 16 | its port (0: unknown)
};

class PacketSource {
 public:
  enum class Next {
    kDatagram,
    kTimeout,  // nothing within the timeout; call again
    kEnd,      // a capture's clean end
    kError,    // error() says why; a capture cut inside a record ends so, after every whole record
  };
  virtual ~PacketSource() = default;
  // The next datagram, waiting at most `timeout` for it.
  virtual Next next(Datagram& datagram, std::chrono::milliseconds timeout) = 0;
  [[nodiscard]] virtual const std::string& error() const noexcept = 0;
};

}  // namespace trajroi::vlp16
