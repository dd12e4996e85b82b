// The pcap reader: the input as a capture file (a memfd: mapped, so a classic pcap file goes
// through trajroi's own record parsing and anything else through libpcap's), then ours of the
// link, IP and UDP headers, fragments and ports.
#include <sys/mman.h>
#include <unistd.h>

#include <cstdint>
#include <string>

#include "trajroi/vlp16/pcap_source.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const int fd = memfd_create("capture", MFD_CLOEXEC);
  if (fd < 0) return 0;
  std::size_t written = 0;
  while (written < size) {
    const ssize_t n = write(fd, data + written, size - written);
    if (n <= 0) break;
    written += static_cast<std::size_t>(n);
  }
  try {
    trajroi::vlp16::PcapSource source("/proc/self/fd/" + std::to_string(fd));
    trajroi::vlp16::Datagram datagram;
    for (int k = 0; k < 100'000 && source.next(datagram) == trajroi::vlp16::PacketSource::Next::kDatagram; ++k) {
    }
  } catch (const std::exception&) {
    // Not a capture that can be opened: the documented error.
  }
  close(fd);
  return 0;
}
