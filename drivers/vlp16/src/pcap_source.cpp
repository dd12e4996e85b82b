#include "trajroi/vlp16/pcap_source.hpp"

#include <fcntl.h>
#include <pcap/pcap.h>
#include <sys/stat.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <stdexcept>
#include <utility>
#include <vector>

#include "libpcap.hpp"
#include "trajroi/host/memory.hpp"

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

// A classic pcap file (not pcapng), read by the process itself: pread() in large pieces into
// one buffer, the records parsed where they lie (no stdio buffer, no libpcap copy). The rules
// are libpcap's (savefile.c, sf-pcap.c): a file header of 24 bytes, then records of a 16-byte
// header and the captured bytes; a record cut by the end of the file is an error; a captured
// length over 262 144 bytes is an error; one over the file's snap length is cut to it.
//
// Not mapped: a mapped capture's every page is a page fault (a 54 MB capture, 13 000 pages; on
// a paravirtualised AMD EPYC, Zen 5, about 40 ms of the replay thread's CPU against 12–16 ms for
// the kernel's copy into this buffer), its pages count in the process's RSS, and a file truncated
// meanwhile raises SIGBUS. The buffer stays in the core's cache: the record is read from there.
struct ClassicPcap {
  int fd = -1;
  std::unique_ptr<std::uint8_t[]> buffer;  // kBufferBytes
  std::size_t begin = 0;                   // the unparsed bytes are buffer[begin, end)
  std::size_t end = 0;
  std::uint64_t read_to = 0;  // the file's offset of buffer[end]
  bool swapped = false;       // written on a machine of the other byte order
  bool nanoseconds = false;   // time stamps in ns (magic 0xA1B23C4D), else µs
  std::uint32_t snaplen = 0;  // of the file, as libpcap adjusts it
  int link_type = 0;          // as libpcap reports it (pcap_datalink)

  static constexpr std::uint32_t kMaxSnaplen = 262'144;  // libpcap's MAXIMUM_SNAPLEN
  static constexpr std::size_t kFileHeader = 24;
  static constexpr std::size_t kRecordHeader = 16;
  // Room for the largest record twice over: each refill reads at least 256 KiB.
  static constexpr std::size_t kBufferBytes = 2 * (kMaxSnaplen + kRecordHeader);

  ClassicPcap() = default;
  ClassicPcap(const ClassicPcap&) = delete;
  ClassicPcap& operator=(const ClassicPcap&) = delete;
  ~ClassicPcap() {
    if (fd >= 0) (void)::close(fd);
  }

  [[nodiscard]] std::uint64_t offset() const noexcept { return read_to - (end - begin); }

  std::uint32_t u32(const std::uint8_t* p) const noexcept {
    std::uint32_t v = 0;
    std::memcpy(&v, p, sizeof v);
    return swapped ? __builtin_bswap32(v) : v;
  }
  std::uint16_t u16(const std::uint8_t* p) const noexcept {
    std::uint16_t v = 0;
    std::memcpy(&v, p, sizeof v);
    return swapped ? __builtin_bswap16(v) : v;
  }

  // At least `bytes` (≤ kBufferBytes) unparsed, reading more as needed: kYes; kEnd when the file
  // ends first (fewer are there); kError on a read error, which `error` says.
  enum class Have { kYes, kEnd, kError };
  Have have(std::size_t bytes, std::string& error) {
    if (end - begin >= bytes) return Have::kYes;
    std::memmove(buffer.get(), buffer.get() + begin, end - begin);
    end -= begin;
    begin = 0;
    while (end < bytes) {
      const ssize_t got = ::pread(fd, buffer.get() + end, kBufferBytes - end, static_cast<off_t>(read_to));
      if (got < 0) {
        if (errno == EINTR) continue;
        error = std::string("read error at byte ") + std::to_string(read_to) + ": " + std::strerror(errno);
        return Have::kError;
      }
      if (got == 0) return Have::kEnd;
      end += static_cast<std::size_t>(got);
      read_to += static_cast<std::uint64_t>(got);
    }
    return Have::kYes;
  }

  // Reads the header of `file`, which it then owns; false for anything but a classic pcap file of
  // version 2.4, `file` left to the caller (libpcap then reads it: pread() did not move its
  // offset; older minors have quirks of their own).
  bool open(int file) {
    fd = file;
    buffer = std::make_unique_for_overwrite<std::uint8_t[]>(kBufferBytes);
    host::populate(buffer.get(), kBufferBytes);
    if (!classic_header()) {
      fd = -1;
      buffer.reset();
      begin = end = 0;
      read_to = 0;
      return false;
    }
    return true;
  }

  bool classic_header() {
    std::string ignored;
    if (have(kFileHeader, ignored) != Have::kYes) return false;
    const std::uint8_t* header = buffer.get();
    std::uint32_t magic = 0;
    std::memcpy(&magic, header, sizeof magic);
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
    if (u16(header + 4) != 2 || u16(header + 6) != 4) return false;
    snaplen = u32(header + 16);
    if (snaplen == 0 || snaplen > kMaxSnaplen) snaplen = kMaxSnaplen;
    const std::uint32_t link = u32(header + 20) & 0x03FFFFFF;  // the upper bits say whether frames end in an FCS
    link_type = link == kLinkRaw ? kLinkRawAlt : static_cast<int>(link);  // LINKTYPE_RAW is DLT_RAW
    begin = kFileHeader;
    return true;
  }

  // The file ended before a record did (`truncated`: libpcap's words for it; empty between
  // records). A file shorter now than what was read of it was truncated by another program:
  // said so (what was read before it is delivered).
  PcapSource::Next ended(std::string truncated, std::string& error) const {
    struct stat status {};
    if (fstat(fd, &status) == 0 && static_cast<std::uint64_t>(status.st_size) < read_to) {
      error = "the capture file shrank while it was read (truncated by another program?): read error at byte " +
              std::to_string(offset());
      return PcapSource::Next::kError;
    }
    if (truncated.empty()) return PcapSource::Next::kEnd;
    error = std::move(truncated);
    return PcapSource::Next::kError;
  }

  // The next record's frame, in the buffer until the next call.
  PcapSource::Next next(const std::uint8_t*& frame, std::size_t& length, std::int64_t& time_ns, std::string& error) {
    if (const Have h = have(kRecordHeader, error); h != Have::kYes) {
      if (h == Have::kError) return PcapSource::Next::kError;
      const std::size_t left = end - begin;
      return ended(left == 0 ? std::string()
                             : "truncated dump file; tried to read " + std::to_string(kRecordHeader) +
                                   " header bytes, only got " + std::to_string(left),
                   error);
    }
    const std::uint8_t* header = buffer.get() + begin;
    const std::uint32_t seconds = u32(header);
    const std::uint32_t fraction = u32(header + 4);
    const std::uint32_t captured = u32(header + 8);
    if (captured > kMaxSnaplen) {
      error = "invalid packet capture length " + std::to_string(captured) + ", bigger than maximum of " +
              std::to_string(kMaxSnaplen);
      return PcapSource::Next::kError;
    }
    if (const Have h = have(kRecordHeader + captured, error); h != Have::kYes) {
      if (h == Have::kError) return PcapSource::Next::kError;
      return ended("truncated dump file; tried to read " + std::to_string(captured) + " captured bytes, only got " +
                       std::to_string(end - begin - kRecordHeader),
                   error);
    }
    frame = buffer.get() + begin + kRecordHeader;
    length = std::min(captured, snaplen);  // the rest of a record longer than the snap length is skipped
    time_ns = static_cast<std::int64_t>(seconds) * 1'000'000'000 +
              static_cast<std::int64_t>(fraction) * (nanoseconds ? 1 : 1'000);
    begin += kRecordHeader + captured;
    return PcapSource::Next::kDatagram;
  }
};

struct PcapSource::Handle {
  pcap_t* pcap = nullptr;          // opened through libpcap() (loaded at the first stream)
  std::unique_ptr<char[]> buffer;  // the capture FILE's (glibc ignores a size without one)
  bool in_place = false;           // a classic pcap file: read by `classic`, not by libpcap
  ClassicPcap classic;
  ~Handle() {
    if (pcap != nullptr) libpcap().close(pcap);  // closes the FILE before its buffer goes
  }
};

PcapSource::PcapSource(const std::filesystem::path& path, PcapOptions options)
    : handle_(std::make_unique<Handle>()), options_(std::move(options)) {
  int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) {
    const int error = errno;
    throw std::runtime_error(path.string() + ": cannot open capture: " + std::strerror(error));
  }
  // A regular file that is a classic pcap file (the usual capture, and the one trajroid
  // records) is read by ClassicPcap; anything else (pcapng, a pipe, an empty file) by libpcap as
  // a stream, from the start.
  struct stat status {};
  if (fstat(fd, &status) == 0 && S_ISREG(status.st_mode) && handle_->classic.open(fd)) {
    handle_->in_place = true;
    link_type_ = handle_->classic.link_type;
  }
  if (!handle_->in_place) {
    const Libpcap& pcap = libpcap();
    if (!pcap.error.empty()) {
      (void)::close(fd);
      throw std::runtime_error(path.string() + ": cannot open capture: " + pcap.error);
    }
    std::FILE* file = fdopen(fd, "rb");
    if (file == nullptr) {
      const int error = errno;
      (void)::close(fd);
      throw std::runtime_error(path.string() + ": cannot open capture: " + std::strerror(error));
    }
    handle_->buffer = std::make_unique_for_overwrite<char[]>(kReadBufferBytes);
    (void)std::setvbuf(file, handle_->buffer.get(), _IOFBF, kReadBufferBytes);  // the default buffer if refused
    char message[PCAP_ERRBUF_SIZE] = {};
    handle_->pcap = pcap.fopen_offline_with_tstamp_precision(file, PCAP_TSTAMP_PRECISION_NANO, message);
    if (handle_->pcap == nullptr) {
      (void)std::fclose(file);  // pcap_close() closes it once the capture is open
      throw std::runtime_error(path.string() + ": cannot open capture: " + message);
    }
    link_type_ = pcap.datalink(handle_->pcap);
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
  if (handle_->in_place) return handle_->classic.next(frame, length, time_ns, error_);
  pcap_pkthdr* header = nullptr;
  const int status = libpcap().next_ex(handle_->pcap, &header, &frame);
  if (status == PCAP_ERROR_BREAK) return Next::kEnd;
  if (status != 1) {
    error_ = libpcap().geterr(handle_->pcap);
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
