// VectorNav VN-100 binary output: framing a byte stream cut into pieces, the layout and
// decoder on every frame, and the pose input that turns samples into attitude.
#include <cstdint>

#include "fuzz_input.hpp"
#include "trajroi/pose_input/pose_input.hpp"
#include "trajroi/vn100/decoder.hpp"
#include "trajroi/vn100/framer.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static const trajroi::pose::GlobalFrame frame =
      trajroi::pose::GlobalFrame::local_cartesian(trajroi::pose::Geodetic{48.1351, 11.5820, 520.0});
  trajroi::vn100::Framer framer{trajroi::vn100::Protocol{}};
  const auto on_frame = [](std::span<const std::uint8_t> f) {
    (void)trajroi::vn100::parse_layout(f);
    trajroi::vn100::Sample sample;
    (void)trajroi::vn100::decode(f, sample);
  };
  trajroi::pose::PoseBuffer buffer(trajroi::pose::PoseGate{}, Eigen::Vector3d::Zero(), 16);
  trajroi::pose_input::PoseInput input(frame, trajroi::pose_input::PoseInputConfig{}, buffer);
  std::int64_t t_ns = 1'000'000'000;
  trajroi::fuzz::for_each_piece(data, size, [&](std::span<const std::uint8_t> piece) {
    framer.feed(piece, on_frame);
    input.imu_bytes(piece, t_ns += 10'000'000);
  });
  framer.finish(on_frame);
  return 0;
}
