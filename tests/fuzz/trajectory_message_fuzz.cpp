// The trajectory LCM channel: any datagram payload is a checked trajectory or a counted reason.
#include <cstdint>

#include "trajroi/daemon/messages.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const trajroi::pose::GlobalFrame frame =
      trajroi::pose::GlobalFrame::local_cartesian(trajroi::pose::Geodetic{48.1351, 11.5820, 520.0});
  (void)trajroi::daemon::decode_trajectory(data, size, frame);
  return 0;
}
