// VLP-16 data and position packets: the whole input as one packet of each kind, then as a
// stream of datagrams through the frame-building decoder (ports 2368 / 8308).
#include <cstdint>
#include <vector>

#include "fuzz_input.hpp"
#include "trajroi/vlp16/decoder.hpp"
#include "trajroi/vlp16/packet.hpp"
#include "trajroi/vlp16/position.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace {
struct Discard final : trajroi::vlp16::FrameSink {
  std::size_t points = 0;
  void on_frame(const trajroi::vlp16::Frame& frame) override { points += frame.points.size(); }
};
}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace trajroi::vlp16;
  static const Calibration calibration = Calibration::vlp16_default();
  static const PacketDecoder decoder(calibration, DecodeOptions{0.5, 130.0});
  const std::span<const std::uint8_t> whole(data, size);
  if (validate_data_packet(whole) == PacketError::kNone) {
    std::vector<Point> points;
    (void)decoder.decode(whole, points);
  }
  PositionPacket position;
  (void)parse_position_packet(whole, position);
  Rmc rmc;
  (void)parse_rmc(trajroi::fuzz::as_text(data, size), rmc);

  StreamDecoder stream(calibration, StreamOptions{});
  Discard sink;
  std::int64_t t_ns = 1'000'000'000;
  trajroi::fuzz::for_each_datagram(data, size, [&](bool position_port, std::span<const std::uint8_t> payload) {
    t_ns += 1'326'000;
    if (position_port) {
      stream.on_position_packet(payload);
    } else {
      stream.on_data_packet(payload, t_ns, sink);
    }
  });
  stream.flush(sink);
  return 0;
}
