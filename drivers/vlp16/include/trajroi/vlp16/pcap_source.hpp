#pragma once

// Reading Velodyne UDP payloads from a pcap capture (libpcap). An I/O adapter: kept out of
// the pure decoder's target.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>

namespace trajroi::vlp16 {

// One UDP datagram from the capture.
struct CapturedDatagram {
  std::span<const std::uint8_t> payload;  // valid until the next call to next()
  std::uint16_t destination_port;
  std::int64_t capture_time_ns;           // the pcap record's timestamp
};

// Link types understood: Ethernet (with or without 802.1Q / 802.1ad tags), Linux cooked
// capture SLL and SLL2, and raw IPv4. IPv4 fragments other than the first, non-UDP packets
// and truncated records are skipped and counted.
class PcapSource {
 public:
  // Throws std::runtime_error naming the file when it cannot be opened or its link type is
  // not one of the above.
  explicit PcapSource(const std::filesystem::path& path);
  ~PcapSource();
  PcapSource(const PcapSource&) = delete;
  PcapSource& operator=(const PcapSource&) = delete;

  enum class Next { kDatagram, kEnd, kError };
  // The next UDP datagram. kEnd at a clean end of file; kError when the file is cut inside
  // a record (every complete record before the cut has been delivered) — error() says why.
  Next next(CapturedDatagram& datagram);

  [[nodiscard]] std::uint64_t skipped_records() const noexcept { return skipped_; }
  [[nodiscard]] const std::string& error() const noexcept { return error_; }
  [[nodiscard]] int link_type() const noexcept { return link_type_; }

 private:
  struct Handle;
  std::unique_ptr<Handle> handle_;
  int link_type_ = 0;
  std::uint64_t skipped_ = 0;
  std::string error_;
};

}  // namespace trajroi::vlp16
