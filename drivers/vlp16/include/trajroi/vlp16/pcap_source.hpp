#pragma once

// Reading Velodyne UDP payloads from a pcap capture. An I/O adapter: kept out of the pure
// decoder's target. A classic pcap file (version 2.4, either byte order, µs or ns time stamps)
// is read in large pieces into one buffer and its records parsed there by libpcap's rules,
// without libpcap's copies; a file truncated by another program while it is read gives a read
// error that says so. Anything else (pcapng, a pipe) is read by libpcap as a stream.
#include <chrono>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "trajroi/vlp16/packet_source.hpp"

namespace trajroi::vlp16 {

struct PcapOptions {
  // UDP datagrams to these destination ports are delivered; others are skipped and counted.
  std::vector<std::uint16_t> ports{kDataPort, kPositionPort};
};

// Link types understood: Ethernet (with or without 802.1Q / 802.1ad tags), Linux cooked
// capture SLL and SLL2, and raw IPv4. IPv4 fragments other than the first, non-UDP packets,
// other ports and records cut by the snap length are skipped and counted.
class PcapSource final : public PacketSource {
 public:
  // Throws std::runtime_error naming the file when it cannot be opened or its link type is
  // not one of the above.
  explicit PcapSource(const std::filesystem::path& path, PcapOptions options = {});
  ~PcapSource() override;
  PcapSource(const PcapSource&) = delete;
  PcapSource& operator=(const PcapSource&) = delete;

  Next next(Datagram& datagram, std::chrono::milliseconds timeout) override;
  // The next datagram (a capture is read as fast as asked: pacing is inputs::Pacer's).
  Next next(Datagram& datagram) { return next(datagram, std::chrono::milliseconds::max()); }

  [[nodiscard]] const std::string& error() const noexcept override { return error_; }
  [[nodiscard]] std::uint64_t skipped_records() const noexcept { return skipped_; }
  [[nodiscard]] int link_type() const noexcept { return link_type_; }

 private:
  Next read(Datagram& datagram);
  // The next record's frame, its captured length and time stamp (ns).
  Next next_record(const std::uint8_t*& frame, std::size_t& length, std::int64_t& time_ns);

  struct Handle;
  std::unique_ptr<Handle> handle_;
  PcapOptions options_;
  int link_type_ = 0;
  std::uint64_t skipped_ = 0;
  std::string error_;
};

// Writes UDP payloads to a pcap file (nanosecond timestamps), wrapped in Ethernet + IPv4 +
// UDP headers as the sensor sends them: broadcast from the factory address 192.168.1.201 (or
// the datagram's own sender), Velodyne's OUI 60:76:88, UDP checksum 0 (allowed on IPv4). Throws std::runtime_error
// naming the file when it cannot be created or written.
class PcapWriter {
 public:
  explicit PcapWriter(const std::filesystem::path& path);
  ~PcapWriter();
  PcapWriter(const PcapWriter&) = delete;
  PcapWriter& operator=(const PcapWriter&) = delete;

  // `sender`: IPv4 address << 16 | source port, as Datagram::sender (0: 192.168.1.201 from `port`).
  void write(std::int64_t time_ns, std::uint16_t port, std::span<const std::uint8_t> payload, std::uint64_t sender = 0);
  void flush();
  // Flushes and closes; throws when the data could not be written.
  void close();

 private:
  struct Handle;
  std::unique_ptr<Handle> handle_;
  std::filesystem::path path_;
  std::vector<std::uint8_t> frame_;
  std::uint16_t id_ = 0;
};

}  // namespace trajroi::vlp16
