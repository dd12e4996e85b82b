// PcapWriter: a recording's VLP-16 datagrams written as a pcap file (Ethernet, IPv4, UDP,
// nanosecond timestamps) through libpcap's dumper.
#include <pcap/pcap.h>

#include <cstring>
#include <stdexcept>

#include "trajroi/vlp16/pcap_source.hpp"

namespace trajroi::vlp16 {

struct PcapWriter::Handle {
  pcap_t* pcap = nullptr;
  pcap_dumper_t* dumper = nullptr;
  ~Handle() {
    if (dumper != nullptr) pcap_dump_close(dumper);
    if (pcap != nullptr) pcap_close(pcap);
  }
};

PcapWriter::PcapWriter(const std::filesystem::path& path) : handle_(std::make_unique<Handle>()), path_(path) {
  handle_->pcap = pcap_open_dead_with_tstamp_precision(DLT_EN10MB, 65535, PCAP_TSTAMP_PRECISION_NANO);
  if (handle_->pcap == nullptr) throw std::runtime_error(path.string() + ": libpcap cannot open a writer");
  handle_->dumper = pcap_dump_open(handle_->pcap, path.c_str());
  if (handle_->dumper == nullptr) {
    throw std::runtime_error(path.string() + ": cannot create: " + pcap_geterr(handle_->pcap));
  }
}

PcapWriter::~PcapWriter() = default;

void PcapWriter::write(std::int64_t time_ns, std::uint16_t port, std::span<const std::uint8_t> payload,
                       std::uint64_t sender) {
  const auto address = sender != 0 ? static_cast<std::uint32_t>(sender >> 16) : 0xC0A801C9U;  // 192.168.1.201
  const auto source_port = sender != 0 ? static_cast<std::uint16_t>(sender & 0xFFFF) : port;
  if (handle_->dumper == nullptr) throw std::runtime_error(path_.string() + ": written after close");
  frame_.assign({0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0xFF, 0x60, 0x76, 0x88, 0x00, 0x00, 0x01, 0x08, 0x00});
  const std::size_t ip_start = frame_.size();
  const auto ip_length = static_cast<std::uint16_t>(20 + 8 + payload.size());
  const std::uint8_t ip[20] = {0x45,
                               0,
                               static_cast<std::uint8_t>(ip_length >> 8),
                               static_cast<std::uint8_t>(ip_length),
                               static_cast<std::uint8_t>(id_ >> 8),
                               static_cast<std::uint8_t>(id_),
                               0x40,
                               0,
                               64,
                               17,
                               0,
                               0,
                               static_cast<std::uint8_t>(address >> 24),
                               static_cast<std::uint8_t>(address >> 16),
                               static_cast<std::uint8_t>(address >> 8),
                               static_cast<std::uint8_t>(address),
                               255,
                               255,
                               255,
                               255};
  ++id_;
  frame_.insert(frame_.end(), std::begin(ip), std::end(ip));
  std::uint32_t sum = 0;
  for (std::size_t i = 0; i < 20; i += 2)
    sum += static_cast<std::uint32_t>(frame_[ip_start + i] << 8 | frame_[ip_start + i + 1]);
  while (sum > 0xFFFF)
    sum = (sum & 0xFFFF) + (sum >> 16);
  const auto checksum = static_cast<std::uint16_t>(~sum);
  frame_[ip_start + 10] = static_cast<std::uint8_t>(checksum >> 8);
  frame_[ip_start + 11] = static_cast<std::uint8_t>(checksum);
  const auto udp_length = static_cast<std::uint16_t>(8 + payload.size());
  const std::uint8_t udp[8] = {static_cast<std::uint8_t>(source_port >> 8),
                               static_cast<std::uint8_t>(source_port),
                               static_cast<std::uint8_t>(port >> 8),
                               static_cast<std::uint8_t>(port),
                               static_cast<std::uint8_t>(udp_length >> 8),
                               static_cast<std::uint8_t>(udp_length),
                               0,
                               0};
  frame_.insert(frame_.end(), std::begin(udp), std::end(udp));
  frame_.insert(frame_.end(), payload.begin(), payload.end());
  pcap_pkthdr header{};
  header.ts.tv_sec = static_cast<time_t>(time_ns / 1'000'000'000);
  header.ts.tv_usec = static_cast<suseconds_t>(time_ns % 1'000'000'000);  // ns: the file's precision
  header.caplen = header.len = static_cast<bpf_u_int32>(frame_.size());
  pcap_dump(reinterpret_cast<u_char*>(handle_->dumper), &header, frame_.data());
}

void PcapWriter::flush() {
  if (handle_->dumper != nullptr && pcap_dump_flush(handle_->dumper) != 0) {
    throw std::runtime_error(path_.string() + ": cannot write");
  }
}

void PcapWriter::close() {
  if (handle_->dumper == nullptr) return;
  const bool failed = pcap_dump_flush(handle_->dumper) != 0;
  pcap_dump_close(handle_->dumper);
  handle_->dumper = nullptr;
  if (failed) throw std::runtime_error(path_.string() + ": cannot write");
}

}  // namespace trajroi::vlp16
