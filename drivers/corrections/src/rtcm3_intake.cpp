#include "trajroi/corrections/rtcm3_intake.hpp"

namespace trajroi::corrections {

void Rtcm3Intake::restart() noexcept {
  seen_.checksum_errors += framer_.counters().checksum_errors;
  seen_.skipped_bytes += framer_.counters().skipped_bytes + framer_.pending_bytes();
  framer_ = framing::Rtcm3Framer();
  counters_.crc_errors = seen_.checksum_errors;
  counters_.other_bytes = seen_.skipped_bytes;
}

}  // namespace trajroi::corrections
