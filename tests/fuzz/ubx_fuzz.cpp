// u-blox UBX: framing a byte stream cut into pieces, every decoder on every frame, and the
// pose input that turns NAV messages into fixes.
#include <cstdint>

#include "fuzz_input.hpp"
#include "trajroi/pose_input/pose_input.hpp"
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
  static const trajroi::pose::GlobalFrame frame =
      trajroi::pose::GlobalFrame::local_cartesian(trajroi::pose::Geodetic{48.1351, 11.5820, 520.0});
  trajroi::ublox::Framer framer;
  trajroi::pose::PoseBuffer buffer(trajroi::pose::PoseGate{}, Eigen::Vector3d::Zero(), 16);
  trajroi::pose_input::PoseInput input(frame, trajroi::pose_input::PoseInputConfig{}, buffer);
  std::int64_t t_ns = 1'000'000'000;
  trajroi::fuzz::for_each_piece(data, size, [&](std::span<const std::uint8_t> piece) {
    framer.feed(piece, decode_all);
    input.gnss_bytes(piece, t_ns += 10'000'000);
  });
  framer.finish(decode_all);
  (void)buffer.pose_at(t_ns);
  return 0;
}
