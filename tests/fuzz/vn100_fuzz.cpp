// VectorNav VN-100 binary output: framing a byte stream cut into pieces, the layout and
// decoder on every frame, and the pose input that turns samples into attitude.
#include <cstdint>

#include "fuzz_input.hpp"
#include "pose_input_harness.hpp"
#include "trajroi/vn100/decoder.hpp"
#include "trajroi/vn100/framer.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  trajroi::vn100::Framer framer{trajroi::vn100::Protocol{}};
  const auto on_frame = [](std::span<const std::uint8_t> f) {
    (void)trajroi::vn100::parse_layout(f);
    trajroi::vn100::Sample sample;
    (void)trajroi::vn100::decode(f, sample);
  };
  trajroi::fuzz::PoseInputHarness pose;
  trajroi::fuzz::for_each_piece(data, size, [&](std::span<const std::uint8_t> piece) {
    framer.feed(piece, on_frame);
    pose.input.imu_bytes(piece, pose.next_time());
  });
  framer.finish(on_frame);
  return 0;
}
