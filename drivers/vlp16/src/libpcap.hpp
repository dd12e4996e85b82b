#pragma once

// libpcap, loaded at the first capture that needs it: one that is not a classic pcap file
// (pcapng, a pipe), which PcapSource reads through libpcap as a stream. Not linked: Debian's
// libpcap is built with D-Bus, whose library brings libsystemd and six more, and every program
// that replays or records classic captures (trajroid among them) would load all ten at start
// (about 2 ms on a virtual machine) without calling one of them.
#include <pcap/pcap.h>

#include <string>

namespace trajroi::vlp16 {

struct Libpcap {
  decltype(&pcap_fopen_offline_with_tstamp_precision) fopen_offline_with_tstamp_precision = nullptr;
  decltype(&pcap_datalink) datalink = nullptr;
  decltype(&pcap_next_ex) next_ex = nullptr;
  decltype(&pcap_geterr) geterr = nullptr;
  decltype(&pcap_close) close = nullptr;
  std::string error;  // why it cannot be used ("" when every function above is there)
};

// The process's libpcap, loaded at the first call (thread-safe).
const Libpcap& libpcap();

}  // namespace trajroi::vlp16
