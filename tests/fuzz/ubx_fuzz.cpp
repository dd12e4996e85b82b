// u-blox UBX: framing a byte stream cut into pieces, every decoder on every frame, and the
// pose input that turns NAV messages into fixes.
#include <cstdint>

#include "fuzz_input.hpp"
#include "pose_input_harness.hpp"
#include "trajroi/ublox/framer.hpp"
#include "trajroi/ublox/messages.hpp"

namespace {
void decode_all(const trajroi::ublox::Message& m) {
  using namespace trajroi::ublox;
  if (const auto pvt = decode_nav_pvt(m.payload); pvt.ok() && pvt.value.utc_valid()) (void)pvt.value.utc_ns();
  (void)decode_nav_hpposllh(m.payload);
  (void)decode_nav_relposned(m.payload);
  (void)decode_nav_cov(m.payload);
  (void)decode_nav_status(m.payload);
  (void)decode_ack(m.msg_id, m.payload);
}
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  trajroi::ublox::Framer framer;
  trajroi::fuzz::PoseInputHarness pose;
  trajroi::fuzz::for_each_piece(data, size, [&](std::span<const std::uint8_t> piece) {
    framer.feed(piece, decode_all);
    pose.input.gnss_bytes(piece, pose.next_time());
  });
  framer.finish(decode_all);
  (void)pose.buffer.pose_at(pose.t_ns);
  return 0;
}
