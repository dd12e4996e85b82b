#include "trajroi/vlp16/pcap_source.hpp"

#include <fcntl.h>
#include <pcap/pcap.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <utility>

namespace trajroi::vlp16 {
namespace {

constexpr int kLinkEthernet = 1;  // DLT_EN10MB
constexpr int kLinkRaw = 101;     // LINKTYPE_RAW (DLT_RAW differs per platform)
constexpr int kLinkRawAlt = 12;   // DLT_RAW on Linux
constexpr int kLinkIpv4 = 228;    // LINKTYPE_IPV4
constexpr int kLinkSll = 113;     // LINKTYPE_LINUX_SLL
constexpr int kLinkSll2 = 276;    // LINKTYPE_LINUX_SLL2
constexpr std::uint16_t kEtherIpv4 = 0x0800;
constexpr std::uint16_t kEtherVlan = 0x8100;
constexpr std::uint16_t kEtherQinQ = 0x88A8;
constexpr std::uint8_t kIpProtoUdp = 17;
// The capture is read through a stdio buffer this large: with stdio's default 4 KiB, an
// as-fast-as-possible replay of a 54 MB capture made 13 000 read() calls.
constexpr std::size_t kReadBufferBytes = std::size_t{1} << 20;

std::uint16_t be16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>((p[0] << 8) | p[1]);
}

// Offset of the IPv4 header in a frame of this link type, or −1 when the frame is not IPv4.
long ipv4_offset(int link, const std::uint8_t* frame, std::size_t length) {
  switch (link) {
    case kLinkEthernet: {
      std::size_t at = 12;
      if (length < at + 2) return -1;
      std::uint16_t type = be16(frame + at);
      while ((type == kEtherVlan || type == kEtherQinQ) && length >= at + 6) {
        at += 4;
        type = be16(frame + at);
      }
      return type == kEtherIpv4 ? static_cast<long>(at + 2) : -1;
    }
    case kLinkSll:  // 16-byte header, protocol at 14
      return length >= 16 && be16(frame + 14) == kEtherIpv4 ? 16 : -1;
    case kLinkSll2:  // 20-byte header, protocol at 0
      return length >= 20 && be16(frame) == kEtherIpv4 ? 20 : -1;
    case kLinkRaw:
    case kLinkRawAlt:
    case kLinkIpv4:
      return length >= 1 && (frame[0] >> 4) == 4 ? 0 : -1;
    default:
      return -1;
  }
}

}  // namespace

struct PcapSource::Handle {
  pcap_t* pcap = nullptr;
  std::unique_ptr<char[]> buffer;  // the capture FILE's (glibc ignores a size without one)
  void* mapping = MAP_FAILED;      // the whole capture, when it is a regular file
  std::size_t mapping_bytes = 0;
  ~Handle() {
    if (pcap != nullptr) pcap_close(pcap);  // closes the FILE, before the buffer or mapping goes
    if (mapping != MAP_FAILED) (void)munmap(mapping, mapping_bytes);
  }
};

namespace {

// A regular file's bytes, mapped and read through a memory FILE: libpcap's reads become copies
// from the page cache's pages, without a read() system call copying every byte into a stdio
// buffer first (on an AMD EPYC, Zen 3, the kernel's copy was 9 % of an as-fast replay's CPU).
// Null when the file cannot be mapped (a pipe, an empty file): it is read as a stream then.
std::FILE* open_mapped(int fd, void*& mapping, std::size_t& bytes) {
  struct stat status {};
  if (fstat(fd, &status) != 0 || !S_ISREG(status.st_mode) || status.st_size <= 0) return nullptr;
  bytes = static_cast<std::size_t>(status.st_size);
  mapping = mmap(nullptr, bytes, PROT_READ, MAP_PRIVATE, fd, 0);
  if (mapping == MAP_FAILED) return nullptr;
  (void)madvise(mapping, bytes, MADV_SEQUENTIAL);
  std::FILE* file = fmemopen(mapping, bytes, "rb");
  if (file == nullptr) {
    (void)munmap(mapping, bytes);
    mapping = MAP_FAILED;
    return nullptr;
  }
  return file;
}

}  // namespace

PcapSource::PcapSource(const std::filesystem::path& path, PcapOptions options)
    : handle_(std::make_unique<Handle>()), options_(std::move(options)) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    const int error = errno;
    throw std::runtime_error(path.string() + ": cannot open capture: " + std::strerror(error));
  }
  std::FILE* file = open_mapped(fd, handle_->mapping, handle_->mapping_bytes);
  if (file != nullptr) {
    (void)::close(fd);  // the mapping keeps the file
  } else {
    file = fdopen(fd, "rb");
    if (file == nullptr) {
      const int error = errno;
      (void)::close(fd);
      throw std::runtime_error(path.string() + ": cannot open capture: " + std::strerror(error));
    }
    handle_->buffer = std::make_unique_for_overwrite<char[]>(kReadBufferBytes);
    (void)std::setvbuf(file, handle_->buffer.get(), _IOFBF, kReadBufferBytes);  // the default buffer if refused
  }
  char message[PCAP_ERRBUF_SIZE] = {};
  handle_->pcap = pcap_fopen_offline_with_tstamp_precision(file, PCAP_TSTAMP_PRECISION_NANO, message);
  if (handle_->pcap == nullptr) {
    (void)std::fclose(file);  // pcap_close() closes it once the capture is open
    throw std::runtime_error(path.string() + ": cannot open capture: " + message);
  }
  link_type_ = pcap_datalink(handle_->pcap);
  if (link_type_ != kLinkEthernet && link_type_ != kLinkSll && link_type_ != kLinkSll2 && link_type_ != kLinkRaw &&
      link_type_ != kLinkRawAlt && link_type_ != kLinkIpv4) {
    throw std::runtime_error(path.string() + ": unsupported link type " + std::to_string(link_type_));
  }
}

PcapSource::~PcapSource() = default;

// A capture is read as fast as asked; pacing is the caller's (inputs::Pacer, the one pacer).
PcapSource::Next PcapSource::next(Datagram& datagram, std::chrono::milliseconds /*timeout*/) {
  return read(datagram);
}

PcapSource::Next PcapSource::read(Datagram& datagram) {
  while (true) {
    pcap_pkthdr* header = nullptr;
    const std::uint8_t* frame = nullptr;
    const int status = pcap_next_ex(handle_->pcap, &header, &frame);
    if (status == PCAP_ERROR_BREAK) return Next::kEnd;
    if (status != 1) {
      error_ = pcap_geterr(handle_->pcap);
      return Next::kError;
    }
    const std::size_t length = header->caplen;
    const long ip = ipv4_offset(link_type_, frame, length);
    if (ip < 0) {
      ++skipped_;
      continue;
    }
    const auto at = static_cast<std::size_t>(ip);
    if (length < at + 20) {
      ++skipped_;
      continue;
    }
    const std::size_t ihl = static_cast<std::size_t>(frame[at] & 0x0F) * 4;
    const std::uint16_t fragment = be16(frame + at + 6) & 0x1FFF;
    if (ihl < 20 || frame[at + 9] != kIpProtoUdp || fragment != 0 || length < at + ihl + 8) {
      ++skipped_;
      continue;
    }
    const std::size_t udp = at + ihl;
    const std::size_t udp_length = be16(frame + udp + 4);
    if (udp_length < 8 || length < udp + udp_length) {  // truncated by the snap length
      ++skipped_;
      continue;
    }
    const std::uint16_t port = be16(frame + udp + 2);
    if (std::find(options_.ports.begin(), options_.ports.end(), port) == options_.ports.end()) {
      ++skipped_;
      continue;
    }
    datagram.payload = std::span<const std::uint8_t>(frame + udp + 8, udp_length - 8);
    datagram.destination_port = port;
    datagram.receive_time_ns = static_cast<std::int64_t>(header->ts.tv_sec) * 1'000'000'000 +
                               static_cast<std::int64_t>(header->ts.tv_usec);  // ns precision
    return Next::kDatagram;
  }
}

}  // namespace trajroi::vlp16

// ---- PcapWriter -----------------------------------------------------------------------------

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

void PcapWriter::write(std::int64_t time_ns, std::uint16_t port, std::span<const std::uint8_t> payload) {
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
                               192,
                               168,
                               1,
                               201,
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
  const std::uint8_t udp[8] = {static_cast<std::uint8_t>(port >> 8),
                               static_cast<std::uint8_t>(port),
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
