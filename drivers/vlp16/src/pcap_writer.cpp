// PcapWriter: a recording's VLP-16 datagrams written as a classic pcap file (Ethernet, IPv4,
// UDP, nanosecond time stamps): the format libpcap's dumper writes, written here (a 24-byte
// file header, a 16-byte header per record, in the host's byte order with the magic number
// that tells it), so that recording needs no libpcap.
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>

#include "trajroi/vlp16/pcap_source.hpp"

namespace trajroi::vlp16 {
namespace {

constexpr std::uint32_t kMagicNanoseconds = 0xA1B23C4D;  // libpcap's for ns time stamps
constexpr std::uint32_t kSnapLength = 65535;
constexpr std::uint32_t kLinkEthernet = 1;  // DLT_EN10MB

bool put(std::FILE* file, const void* data, std::size_t bytes) {
  return std::fwrite(data, 1, bytes, file) == bytes;
}

}  // namespace

struct PcapWriter::Handle {
  std::FILE* file = nullptr;
  bool failed = false;  // a write fell short (said at the next flush or close)
  ~Handle() {
    if (file != nullptr) (void)std::fclose(file);
  }
};

PcapWriter::PcapWriter(const std::filesystem::path& path) : handle_(std::make_unique<Handle>()), path_(path) {
  handle_->file = std::fopen(path.c_str(), "wb");
  if (handle_->file == nullptr) {
    throw std::runtime_error(path.string() + ": cannot create: " + std::strerror(errno));
  }
  struct {
    std::uint32_t magic = kMagicNanoseconds;
    std::uint16_t version_major = 2, version_minor = 4;
    std::int32_t this_zone = 0;
    std::uint32_t sigfigs = 0, snap_length = kSnapLength, link_type = kLinkEthernet;
  } header;
  static_assert(sizeof header == 24);
  if (!put(handle_->file, &header, sizeof header)) {
    throw std::runtime_error(path.string() + ": cannot write: " + std::strerror(errno));
  }
}

PcapWriter::~PcapWriter() = default;

void PcapWriter::write(std::int64_t time_ns, std::uint16_t port, std::span<const std::uint8_t> payload,
                       std::uint64_t sender) {
  const auto address = sender != 0 ? static_cast<std::uint32_t>(sender >> 16) : 0xC0A801C9U;  // 192.168.1.201
  const auto source_port = sender != 0 ? static_cast<std::uint16_t>(sender & 0xFFFF) : port;
  if (handle_->file == nullptr) throw std::runtime_error(path_.string() + ": written after close");
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
  const std::uint32_t record[4] = {static_cast<std::uint32_t>(time_ns / 1'000'000'000),
                                   static_cast<std::uint32_t>(time_ns % 1'000'000'000),  // ns: the file's precision
                                   static_cast<std::uint32_t>(frame_.size()),
                                   static_cast<std::uint32_t>(frame_.size())};
  if (!put(handle_->file, record, sizeof record) || !put(handle_->file, frame_.data(), frame_.size()))
    handle_->failed = true;
}

void PcapWriter::flush() {
  if (handle_->file == nullptr) return;
  if (std::fflush(handle_->file) != 0 || handle_->failed) throw std::runtime_error(path_.string() + ": cannot write");
}

void PcapWriter::close() {
  if (handle_->file == nullptr) return;
  const bool failed = std::fflush(handle_->file) != 0 || handle_->failed;
  const bool closed = std::fclose(handle_->file) == 0;
  handle_->file = nullptr;
  if (failed || !closed) throw std::runtime_error(path_.string() + ": cannot write");
}

}  // namespace trajroi::vlp16
