// Where and when a frame ends, on real captures (../shared/data/velodyne): each whole frame ends
// at the wrap of its points' firing azimuths past the cut, with nothing lost between frames, and
// a frame whose cut falls between two packets is delivered with the first of them, not a
// packet later. The reference is the captures' own points, decoded packet by packet here with
// the packet decoder alone (no stream), and their block azimuths read from the bytes.
#include <gtest/gtest.h>

#include <cstdint>
#include <vector>

#include "test_data.hpp"
#include "trajroi/vlp16/packet.hpp"
#include "trajroi/vlp16/pcap_source.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace trajroi::vlp16 {
namespace {

struct Capture {
  const char* file;
  Model model;
  // Cuts between packets with the next one's first block 6 hundredths of a degree or more
  // past the cut, over the 240 cuts: an HDL-32E's gap after its last firing is narrower (a
  // block step is 0.17° at 10 Hz, its last firing ends at four fifths of it).
  std::size_t min_between;
};

// Each data packet's bytes, receive time and points (decoded alone).
struct Packets {
  std::vector<std::vector<std::uint8_t>> bytes;
  std::vector<std::int64_t> receive_ns;
  std::vector<std::vector<Point>> points;
};

Packets read_packets(const std::filesystem::path& path, Model model) {
  Packets p;
  const PacketDecoder decoder(Calibration::for_model(model), {}, model);
  PcapSource source(path);
  Datagram datagram;
  while (source.next(datagram) == PacketSource::Next::kDatagram) {
    if (datagram.destination_port == kPositionPort) continue;
    p.points.emplace_back();
    (void)decoder.decode(datagram.payload, p.points.back());
    p.bytes.emplace_back(datagram.payload.begin(), datagram.payload.end());
    p.receive_ns.push_back(datagram.receive_time_ns);
  }
  return p;
}

double phase_of(const Point& p, double cut_deg) {
  const double phase = static_cast<double>(p.azimuth_deg) - cut_deg;
  return phase < 0.0 ? phase + 360.0 : phase;
}

// A frame delivered: its points, whether whole, and the data packet (0, 1, …) being handed over
// when it came (the capture's length: at the flush).
struct Delivered {
  std::size_t points;
  bool whole;
  std::size_t during_packet;
};

struct Deliveries final : FrameSink {
  std::size_t packet = 0;
  std::vector<Delivered> frames;
  void on_frame(const Frame& frame) override { frames.push_back({frame.points.size(), !frame.partial, packet}); }
};

class Vlp16FrameEnds : public testing::TestWithParam<Capture> {};

TEST_P(Vlp16FrameEnds, AFrameEndsAtTheCutAndComesWithItsLastPacket) {
  TRAJROI_REQUIRE_DATA(path, GetParam().file);
  const Model model = GetParam().model;
  const Packets packets = read_packets(path, model);
  ASSERT_GT(packets.bytes.size(), 80u);
  // Every point in stream order, with the packet it came in.
  std::vector<std::size_t> packet_of;
  std::vector<Point> all;
  for (std::size_t k = 0; k < packets.points.size(); ++k) {
    packet_of.insert(packet_of.end(), packets.points[k].size(), k);
    all.insert(all.end(), packets.points[k].begin(), packets.points[k].end());
  }
  std::size_t whole = 0, between = 0, with_last_packet = 0;
  for (int step = 0; step < 240; ++step) {
    const double cut = 1.5 * step + 0.37;
    StreamOptions options;
    options.model = model;
    options.cut_azimuth_deg = cut;
    StreamDecoder stream(Calibration::for_model(model), options);
    Deliveries sink;
    for (; sink.packet < packets.bytes.size(); ++sink.packet)
      stream.on_data_packet(packets.bytes[sink.packet], packets.receive_ns[sink.packet], sink);
    stream.flush(sink);
    ASSERT_EQ(stream.counters().lost_packets, 0u) << "a capture without loss: frames end at the cut only";
    std::size_t at = 0;  // the frame's first point
    for (const Delivered& f : sink.frames) {
      const std::size_t end = at + f.points;  // one past its last point
      ASSERT_LE(end, all.size()) << "cut " << cut << "°";
      // Every frame but the last (flushed) ends at the wrap past the cut: its last point
      // before the cut, the next one past it; it comes no later than the packet of that next
      // point (a packet without points, all before the cut, may come between).
      if (end == all.size()) break;
      EXPECT_TRUE(f.whole || at == 0) << "cut " << cut << "°: only the first frame is partial";
      ASSERT_GT(f.points, 0u);
      EXPECT_GT(phase_of(all[end - 1], cut), 180.0) << "cut " << cut << "°, point " << end - 1;
      EXPECT_LT(phase_of(all[end], cut), 180.0) << "cut " << cut << "°, point " << end;
      const std::size_t last_packet = packet_of[end - 1];
      // (The first frame may wait for the model check: 0x21 packets are held until it decides.)
      if (at != 0) {
        EXPECT_LE(f.during_packet, packet_of[end]) << "cut " << cut << "°";
      }
      if (f.whole) ++whole;
      if (packet_of[end] == last_packet + 1) {
        // The cut between two packets, the next one's first block well past it (6 hundredths of
        // a degree or more, twice the margin): the frame comes with its last packet.
        const std::uint16_t next_first = block_azimuth(packets.bytes[last_packet + 1], 0) % kAzimuthLimit;
        const std::uint32_t past_cut = azimuth_gap(cut_centidegrees(cut), next_first);
        if (past_cut >= 6 && past_cut < 18000) {
          ++between;
          with_last_packet += f.during_packet == last_packet ? 1 : 0;
          EXPECT_EQ(f.during_packet, last_packet)
              << "cut " << cut << "°: the next packet's first block is " << past_cut << " cdeg past the cut";
        }
      }
      at = end;
    }
  }
  // Each capture has such cuts: the gap after a packet's last firing is about a fifth of a
  // block step, and a packet covers 2.4° to 4.8°.
  EXPECT_GT(whole, 240u);
  EXPECT_GE(between, GetParam().min_between);
  EXPECT_EQ(with_last_packet, between);
}

INSTANTIATE_TEST_SUITE_P(
    Captures, Vlp16FrameEnds,
    testing::Values(Capture{"velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap", Model::kVlp16, 10},
                    Capture{"velodyne/vlp16/nebula_vlp16_dual_1673400471.DERIVED.pcap", Model::kVlp16, 10},
                    Capture{"velodyne/other_models/mrpt_sample_velodyne_hdl32e.pcap", Model::kHdl32e, 0}),
    trajroi::test::FileTestName{});

}  // namespace
}  // namespace trajroi::vlp16
