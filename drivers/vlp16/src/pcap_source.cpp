#include "trajroi/vlp16/pcap_source.hpp"

#include <fcntl.h>
#include <pcap/pcap.h>
#include <setjmp.h>
#include <signal.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <utility>
#include <vector>

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

// A mapped file that another process truncates while it is read: a read of a page past its new
// end raises SIGBUS, which would end the daemon. The records are copied out of the mapping under
// this guard: a SIGBUS in a guarded copy of this thread jumps back to it, which reports a read
// error; any other SIGBUS takes the action it had before (the handler puts it back and the
// faulting instruction runs again).
namespace {
namespace bus_guard {

thread_local sigjmp_buf* active = nullptr;
struct sigaction previous {};

void on_sigbus(int signal, siginfo_t* info, void* context) {
  (void)info;
  (void)context;
  if (active != nullptr) siglongjmp(*active, 1);
  (void)sigaction(signal, &previous, nullptr);
}

void install() {
  static const bool installed = [] {
    struct sigaction action {};
    action.sa_sigaction = on_sigbus;
    action.sa_flags = SA_SIGINFO | SA_NODEFER;  // SIGBUS not blocked after the jump out
    sigemptyset(&action.sa_mask);
    return sigaction(SIGBUS, &action, &previous) == 0;
  }();
  (void)installed;
}

}  // namespace bus_guard
}  // namespace

// A classic pcap file (not pcapng), mapped: its records are read without a read() system call
// or libpcap's copies. The rules are libpcap's (savefile.c, sf-pcap.c): a file header of 24
// bytes, then records of a 16-byte header and the captured bytes; a record cut by the end of the
// file is an error; a captured length over 262 144 bytes is an error; one over the file's snap
// length is cut to it.
struct ClassicPcap {
  const std::uint8_t* data = nullptr;
  std::size_t size = 0;
  std::size_t at = 24;        // the next record
  std::size_t released = 0;   // the mapping's pages before this are given back
  bool swapped = false;       // written on a machine of the other byte order
  bool nanoseconds = false;   // time stamps in ns (magic 0xA1B23C4D), else µs
  std::uint32_t snaplen = 0;  // of the file, as libpcap adjusts it
  int link_type = 0;          // as libpcap reports it (pcap_datalink)

  static constexpr std::uint32_t kMaxSnaplen = 262'144;  // libpcap's MAXIMUM_SNAPLEN
  static constexpr std::size_t kFileHeader = 24;
  static constexpr std::size_t kRecordHeader = 16;

  std::uint32_t u32(std::size_t offset) const noexcept {
    std::uint32_t v = 0;
    std::memcpy(&v, data + offset, sizeof v);
    return swapped ? __builtin_bswap32(v) : v;
  }
  std::uint16_t u16(std::size_t offset) const noexcept {
    std::uint16_t v = 0;
    std::memcpy(&v, data + offset, sizeof v);
    return swapped ? __builtin_bswap16(v) : v;
  }

  // Every 4 MiB read, the pages behind are unmapped (the page cache keeps them): read pages of a
  // mapped file count in the process's RSS, which grew by the capture's size in each lap of a
  // looped replay (the soak's RSS check failed at +26 %).
  void release_behind() noexcept {
    constexpr std::size_t kStep = std::size_t{4} << 20;
    if (at - released < kStep) return;
    static const auto page = static_cast<std::size_t>(sysconf(_SC_PAGESIZE));
    const std::size_t until = at / page * page;
    // The mapping starts on a page; `data` is const only to the parser.
    (void)madvise(const_cast<std::uint8_t*>(data) + released, until - released, MADV_DONTNEED);
    released = until;
  }

  // Reads the file header; false for anything but a classic pcap file of version 2.4 (libpcap
  // then reads it, or says why not; older minors have quirks of their own).
  bool open(const std::uint8_t* bytes, std::size_t length) noexcept {
    if (length < kFileHeader) return false;
    data = bytes;
    size = length;
    std::uint32_t magic = 0;
    std::memcpy(&magic, data, sizeof magic);
    switch (magic) {
      case 0xA1B2C3D4:
        break;
      case 0xA1B23C4D:
        nanoseconds = true;
        break;
      case 0xD4C3B2A1:
        swapped = true;
        break;
      case 0x4D3CB2A1:
        swapped = true;
        nanoseconds = true;
        break;
      default:
        return false;
    }
    if (u16(4) != 2 || u16(6) != 4) return false;
    snaplen = u32(16);
    if (snaplen == 0 || snaplen > kMaxSnaplen) snaplen = kMaxSnaplen;
    const std::uint32_t link = u32(20) & 0x03FFFFFF;  // the upper bits say whether frames end in an FCS
    link_type = link == kLinkRaw ? kLinkRawAlt : static_cast<int>(link);  // LINKTYPE_RAW is DLT_RAW
    return true;
  }

  // The next record's frame, copied into `frame_copy` (the mapping may not be read outside the
  // guard).
  PcapSource::Next next(std::vector<std::uint8_t>& frame_copy, std::size_t& length, std::int64_t& time_ns,
                        std::string& error) noexcept {
    sigjmp_buf jump;
    if (sigsetjmp(jump, 0) != 0) {
      bus_guard::active = nullptr;
      error = "the capture file shrank while it was read (truncated by another program?): read error at byte " +
              std::to_string(at);
      return PcapSource::Next::kError;
    }
    bus_guard::active = &jump;
    const PcapSource::Next got = next_unguarded(frame_copy, length, time_ns, error);
    bus_guard::active = nullptr;
    return got;
  }

  PcapSource::Next next_unguarded(std::vector<std::uint8_t>& frame_copy, std::size_t& length, std::int64_t& time_ns,
                                  std::string& error) noexcept {
    const std::size_t left = size - at;
    if (left == 0) return PcapSource::Next::kEnd;
    if (left < kRecordHeader) {
      error = "truncated dump file; tried to read " + std::to_string(kRecordHeader) + " header bytes, only got " +
              std::to_string(left);
      return PcapSource::Next::kError;
    }
    const std::uint32_t seconds = u32(at);
    const std::uint32_t fraction = u32(at + 4);
    const std::uint32_t captured = u32(at + 8);
    if (captured > kMaxSnaplen) {
      error = "invalid packet capture length " + std::to_string(captured) + ", bigger than maximum of " +
              std::to_string(kMaxSnaplen);
      return PcapSource::Next::kError;
    }
    if (left - kRecordHeader < captured) {
      error = "truncated dump file; tried to read " + std::to_string(captured) + " captured bytes, only got " +
              std::to_string(left - kRecordHeader);
      return PcapSource::Next::kError;
    }
    length = std::min(captured, snaplen);  // the rest of a record longer than the snap length is skipped
    std::memcpy(frame_copy.data(), data + at + kRecordHeader, length);  // sized for kMaxSnaplen
    time_ns = static_cast<std::int64_t>(seconds) * 1'000'000'000 +
              static_cast<std::int64_t>(fraction) * (nanoseconds ? 1 : 1'000);
    at += kRecordHeader + captured;
    release_behind();
    return PcapSource::Next::kDatagram;
  }
};

struct PcapSource::Handle {
  pcap_t* pcap = nullptr;
  std::unique_ptr<char[]> buffer;  // the capture FILE's (glibc ignores a size without one)
  void* mapping = MAP_FAILED;      // the whole capture, when it is a classic pcap file
  std::size_t mapping_bytes = 0;
  bool in_place = false;  // a classic pcap file, mapped: read by `classic`, not by libpcap
  ClassicPcap classic;
  std::vector<std::uint8_t> frame;  // the last record's, copied out of the mapping
  ~Handle() {
    if (pcap != nullptr) pcap_close(pcap);  // closes the FILE, before the buffer or mapping goes
    if (mapping != MAP_FAILED) (void)munmap(mapping, mapping_bytes);
  }
};

namespace {

// A regular file's bytes, mapped, when they are a classic pcap file (the usual capture, and the
// one trajroid records): no read() system call copies every byte into a stdio buffer first, nor
// libpcap from there into its own (on an AMD EPYC, Zen 3, the kernel's copy alone was 9 % of an
// as-fast replay's CPU). Anything else (pcapng, a pipe, an empty file) is read by libpcap as a
// stream.
bool map_classic_capture(int fd, void*& mapping, std::size_t& bytes, ClassicPcap& classic) {
  struct stat status {};
  if (fstat(fd, &status) != 0 || !S_ISREG(status.st_mode) || status.st_size <= 0) return false;
  bytes = static_cast<std::size_t>(status.st_size);
  mapping = mmap(nullptr, bytes, PROT_READ, MAP_PRIVATE, fd, 0);
  if (mapping == MAP_FAILED) return false;
  bus_guard::install();
  volatile bool classic_file = false;  // kept across a jump back from the guard
  {
    sigjmp_buf jump;
    if (sigsetjmp(jump, 0) == 0) {
      bus_guard::active = &jump;
      classic_file = classic.open(static_cast<const std::uint8_t*>(mapping), bytes);
    }
    bus_guard::active = nullptr;
  }
  if (!classic_file) {
    (void)munmap(mapping, bytes);
    mapping = MAP_FAILED;
    return false;
  }
  (void)madvise(mapping, bytes, MADV_SEQUENTIAL);
  return true;
}

}  // namespace

PcapSource::PcapSource(const std::filesystem::path& path, PcapOptions options)
    : handle_(std::make_unique<Handle>()), options_(std::move(options)) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    const int error = errno;
    throw std::runtime_error(path.string() + ": cannot open capture: " + std::strerror(error));
  }
  handle_->in_place = map_classic_capture(fd, handle_->mapping, handle_->mapping_bytes, handle_->classic);
  if (handle_->in_place) {
    (void)::close(fd);  // the mapping keeps the file
    handle_->frame.resize(ClassicPcap::kMaxSnaplen);
    link_type_ = handle_->classic.link_type;
  } else {
    std::FILE* file = fdopen(fd, "rb");
    if (file == nullptr) {
      const int error = errno;
      (void)::close(fd);
      throw std::runtime_error(path.string() + ": cannot open capture: " + std::strerror(error));
    }
    handle_->buffer = std::make_unique_for_overwrite<char[]>(kReadBufferBytes);
    (void)std::setvbuf(file, handle_->buffer.get(), _IOFBF, kReadBufferBytes);  // the default buffer if refused
    char message[PCAP_ERRBUF_SIZE] = {};
    handle_->pcap = pcap_fopen_offline_with_tstamp_precision(file, PCAP_TSTAMP_PRECISION_NANO, message);
    if (handle_->pcap == nullptr) {
      (void)std::fclose(file);  // pcap_close() closes it once the capture is open
      throw std::runtime_error(path.string() + ": cannot open capture: " + message);
    }
    link_type_ = pcap_datalink(handle_->pcap);
  }
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

PcapSource::Next PcapSource::next_record(const std::uint8_t*& frame, std::size_t& length, std::int64_t& time_ns) {
  if (handle_->in_place) {
    frame = handle_->frame.data();
    return handle_->classic.next(handle_->frame, length, time_ns, error_);
  }
  pcap_pkthdr* header = nullptr;
  const int status = pcap_next_ex(handle_->pcap, &header, &frame);
  if (status == PCAP_ERROR_BREAK) return Next::kEnd;
  if (status != 1) {
    error_ = pcap_geterr(handle_->pcap);
    return Next::kError;
  }
  length = header->caplen;
  time_ns = static_cast<std::int64_t>(header->ts.tv_sec) * 1'000'000'000 +
            static_cast<std::int64_t>(header->ts.tv_usec);  // ns precision
  return Next::kDatagram;
}

PcapSource::Next PcapSource::read(Datagram& datagram) {
  while (true) {
    const std::uint8_t* frame = nullptr;
    std::size_t length = 0;
    std::int64_t time_ns = 0;
    if (const Next got = next_record(frame, length, time_ns); got != Next::kDatagram) return got;
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
    // The IPv4 source address and UDP source port, as a live socket reports them.
    datagram.sender = (static_cast<std::uint64_t>(be16(frame + at + 12)) << 32) |
                      (static_cast<std::uint64_t>(be16(frame + at + 14)) << 16) | be16(frame + udp);
    datagram.receive_time_ns = time_ns;
    return Next::kDatagram;
  }
}

}  // namespace trajroi::vlp16
