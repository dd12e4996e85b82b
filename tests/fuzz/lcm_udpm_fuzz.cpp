// LCM datagrams as trajroid's UdpmOutlet receives them from the group: any sequence, from two
// senders (the datagram's port bit), is a message, a pending fragment, another channel's, or a
// counted malformed datagram; a whole message's payload lies within what was received.
#include <cstdint>
#include <cstdlib>

#include "fuzz_input.hpp"
#include "trajroi/transport/lcm_udpm.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  namespace udpm = trajroi::transport::udpm;
  udpm::Reassembler reassembler({"TRAJROI_TRAJECTORY", "T"}, 1u << 20);
  std::uint64_t messages = 0;
  trajroi::fuzz::for_each_datagram(data, size, [&](bool second, std::span<const std::uint8_t> datagram) {
    udpm::Reassembler::Message m;
    if (reassembler.accept(second ? 2 : 1, datagram, m) == udpm::Reassembler::Verdict::kMessage) {
      ++messages;
      if (m.channel != "TRAJROI_TRAJECTORY" && m.channel != "T") std::abort();
      if (m.payload.size() > (1u << 20)) std::abort();
    }
  });
  if (messages != reassembler.counters().messages) std::abort();
  return 0;
}
