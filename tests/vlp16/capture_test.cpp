// Real third-party captures (../shared/data/velodyne, see its README), replayed through the
// pcap source and the stream decoder; content checked against independent references: the
// data README's counts (made with a separate walker), MRPT's unit test, the GPRMC sentence,
// and nebula's reference cloud.
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <limits>
#include <map>
#include <numbers>
#include <set>
#include <thread>
#include <tuple>

#include "capture_replay.hpp"
#include "test_data.hpp"
#include "trajroi/vlp16/pcap_source.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace trajroi::vlp16 {
namespace {

using capture_test::Replay;
using capture_test::replay;
using capture_test::utc_ns;

TEST(Vlp16Capture, MrptStrongestCaptureMatchesTheReadmeAndMrptsScanCount) {
  TRAJROI_REQUIRE_DATA(path, "velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap");
  const Replay r = replay(path);
  EXPECT_EQ(r.data_datagrams, 293u);
  EXPECT_EQ(r.position_datagrams, 57u);
  EXPECT_EQ(r.counters.decoded_packets, 293u);
  EXPECT_EQ(r.counters.rejected_total(), 0u);
  EXPECT_EQ(r.modes.at(0x37), 293u);
  // README: 73,486 of the 112,512 channel returns are non-zero; range limits are off.
  EXPECT_EQ(r.counters.points, 73'486u);
  EXPECT_EQ(r.counters.points + r.counters.no_return, 293u * 384u);
  EXPECT_EQ(r.counters.lost_packets, 0u);
  EXPECT_EQ(r.counters.out_of_order, 0u);

  // MRPT's unit test counts 4 scans (azimuth wraps): between the first and the last partial
  // sweeps lie wraps − 1 whole ones.
  EXPECT_EQ(r.wraps, 4u);
  EXPECT_EQ(r.counters.frames, r.wraps - 1);
  EXPECT_EQ(r.counters.partial_frames, 2u);
  ASSERT_EQ(r.frames.frames.size(), r.wraps + 1);
  std::size_t points_in_frames = 0;
  for (const Frame& f : r.frames.frames) {
    points_in_frames += f.points.size();
    EXPECT_EQ(f.return_mode, ReturnMode::kStrongest);
    EXPECT_EQ(f.lost_packets, 0u);
  }
  EXPECT_EQ(points_in_frames, r.counters.points);
  for (std::size_t i = 1; i + 1 < r.frames.frames.size(); ++i) {
    const Frame& f = r.frames.frames[i];
    EXPECT_FALSE(f.partial);
    // A whole sweep at ~10 Hz: ~75 packets, ~0.1 s, azimuths from the cut (0°) round to it.
    EXPECT_NEAR(static_cast<double>(f.packets), 75.0, 3.0);
    EXPECT_NEAR(static_cast<double>(f.end_time_ns - f.start_time_ns) * 1e-9, 0.1, 0.005);
    EXPECT_LT(f.points.front().azimuth_deg, 1.0f);
    EXPECT_GT(f.points.back().azimuth_deg, 359.0f);
    EXPECT_EQ(f.points.front().time_offset_ns, 0u);
    ASSERT_TRUE(f.start_utc_ns.has_value());
    // The sweeps lie in 2016-01-21 08:18:02–04 UTC, the GPRMC's second and after.
    EXPECT_GE(*f.start_utc_ns, utc_ns(2016, 1, 21, 8, 18, 2));
    EXPECT_LT(*f.start_utc_ns, utc_ns(2016, 1, 21, 8, 18, 5));
  }
  EXPECT_TRUE(r.frames.frames.front().partial);
  EXPECT_TRUE(r.frames.frames.back().partial);

  // $GPRMC,081802.00,A,3649.7478558,N,00224.4542928,W,0.034,212.5,210116,0.0,E,A*2E
  EXPECT_EQ(r.counters.nmea[static_cast<std::size_t>(NmeaError::kNone)], 57u);
  ASSERT_TRUE(r.first_rmc.has_value());
  EXPECT_EQ(r.first_rmc->pps, PpsStatus::kLocked);
  EXPECT_TRUE(r.first_rmc->rmc.valid);
  EXPECT_EQ(r.first_rmc->rmc.utc_ns, utc_ns(2016, 1, 21, 8, 18, 2));
  EXPECT_DOUBLE_EQ(r.first_rmc->rmc.latitude_deg, 36.0 + 49.7478558 / 60.0);
  EXPECT_DOUBLE_EQ(r.first_rmc->rmc.longitude_deg, -(2.0 + 24.4542928 / 60.0));
  ASSERT_TRUE(r.last_rmc.has_value());
  EXPECT_GE(r.last_rmc->rmc.utc_ns, r.first_rmc->rmc.utc_ns);
}

TEST(Vlp16Capture, EarlyFirmwareProductId0x21WithVlp16TimingDecodesAsVlp16) {
  TRAJROI_REQUIRE_DATA(path, "velodyne/vlp16/rust-lidar-utils_velodyne_vlp16_2014_productid0x21.pcap");
  const Replay r = replay(path);
  EXPECT_EQ(r.data_datagrams, 84u);
  EXPECT_EQ(r.position_datagrams, 16u);
  EXPECT_EQ(r.counters.rejected_total(), 0u) << r.model_rejection;
  EXPECT_EQ(r.counters.decoded_packets, 84u);  // the held first packet included
  // Decided on a VLP-16 single-return period (README: TOH step 1327/1328 µs).
  EXPECT_GE(r.model_period_us, 1327u);
  EXPECT_LE(r.model_period_us, 1328u);
  EXPECT_GT(r.counters.points, 0u);
  EXPECT_EQ(r.counters.lost_packets, 0u);
  EXPECT_EQ(r.wraps, 1u);
  EXPECT_EQ(r.counters.frames, 0u);  // 1 wrap: two partial sweeps
  EXPECT_EQ(r.counters.partial_frames, 2u);
  // Position packets with PPS 0 and no NMEA: no RMC, no UTC.
  EXPECT_EQ(r.counters.nmea[static_cast<std::size_t>(NmeaError::kEmpty)], 16u);
  EXPECT_FALSE(r.first_rmc.has_value());
  EXPECT_FALSE(r.frames.frames.front().start_utc_ns.has_value());
}

TEST(Vlp16Capture, Vlp16Example2018Decodes) {
  TRAJROI_REQUIRE_DATA(path, "velodyne/vlp16/rust-lidar-utils_velodyne_example_2018.pcap");
  const Replay r = replay(path);
  EXPECT_EQ(r.data_datagrams, 84u);
  EXPECT_EQ(r.counters.decoded_packets, 84u);
  EXPECT_EQ(r.counters.lost_packets, 0u);
}

struct RejectedCapture {
  const char* file;
  std::size_t data_packets;
  const char* reason;
};

class Vlp16RejectsOtherModels : public testing::TestWithParam<RejectedCapture> {};

TEST_P(Vlp16RejectsOtherModels, EveryPacketRejectedWithTheReason) {
  TRAJROI_REQUIRE_DATA(path, GetParam().file);
  const Replay r = replay(path);
  EXPECT_EQ(r.data_datagrams, GetParam().data_packets);
  EXPECT_EQ(r.counters.rejected[static_cast<std::size_t>(PacketError::kUnsupportedProduct)], GetParam().data_packets);
  EXPECT_EQ(r.counters.decoded_packets, 0u);
  EXPECT_EQ(r.counters.points, 0u);
  EXPECT_TRUE(r.frames.frames.empty());
  EXPECT_NE(r.model_rejection.find(GetParam().reason), std::string::npos) << r.model_rejection;
}

INSTANTIATE_TEST_SUITE_P(
    Captures, Vlp16RejectsOtherModels,
    testing::Values(RejectedCapture{"velodyne/other_models/mrpt_sample_velodyne_hdl32e.pcap", 500,
                                    "product id 0x21 (HDL-32E) sends HDL-32E packets (told by its timing: 553 µs "
                                    "between packets), but lidar.model is vlp16: dropped (set lidar.model: hdl32e, "
                                    "or auto)"},
                    RejectedCapture{"velodyne/other_models/rust-lidar-utils_velodyne_vlp32_ACTUALLY_HDL-32E.pcap", 91,
                                    "product id 0x21 (HDL-32E) sends HDL-32E packets"},
                    RejectedCapture{"velodyne/other_models/nebula_vlp32c_strongest_1713492677.DERIVED.pcap", 379,
                                    "product id 0x28 (VLP-32C) sends VLP-32C packets, but lidar.model is vlp16"}),
    trajroi::test::FileTestName{});

// The reader thread's early wake-up: every whole frame the decoder completes on a real capture
// is completed by a packet may_complete_frame foresaw, at cuts all round; and it foresees few
// (a packet or two per sweep; a wake-up per packet is what it saves). The strongest-return and
// the dual-return capture (the 2018 example holds less than a sweep).
class Vlp16ForeseesFrameEnds : public testing::TestWithParam<const char*> {};

TEST_P(Vlp16ForeseesFrameEnds, EveryWholeFrameEndsOnAForeseenPacket) {
  TRAJROI_REQUIRE_DATA(path, GetParam());
  struct Ends final : FrameSink {
    std::size_t whole = 0;
    void on_frame(const Frame& frame) override { whole += frame.partial ? 0 : 1; }
  };
  for (const double cut : {0.0, 90.0, 180.5, 271.37, 359.99, -45.0}) {
    PcapSource source(path);
    StreamOptions options;
    options.cut_azimuth_deg = cut;
    StreamDecoder decoder(Calibration::vlp16_default(), options);
    const std::uint16_t cut_cdeg = cut_centidegrees(cut);
    Ends ends;
    std::size_t packets = 0, foreseen = 0;
    Datagram datagram;
    while (source.next(datagram) == PacketSource::Next::kDatagram) {
      if (datagram.destination_port == kPositionPort) continue;
      ++packets;
      const bool may_end = may_complete_frame(datagram.payload, cut_cdeg);
      foreseen += may_end ? 1 : 0;
      const std::size_t before = ends.whole;
      decoder.on_data_packet(datagram.payload, datagram.receive_time_ns, ends);
      if (ends.whole != before) {
        EXPECT_TRUE(may_end) << "cut " << cut << "°, data packet " << packets;
      }
    }
    EXPECT_GE(ends.whole, 2u) << "cut " << cut << "°";
    EXPECT_LE(foreseen, 3 * (ends.whole + 1)) << "cut " << cut << "°, " << packets << " packets";
  }
}

INSTANTIATE_TEST_SUITE_P(Captures, Vlp16ForeseesFrameEnds,
                         testing::Values("velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap",
                                         "velodyne/vlp16/nebula_vlp16_dual_1673400471.DERIVED.pcap"),
                         trajroi::test::FileTestName{});

TEST(Vlp16Stream, CutCentidegreesWrapsAndRounds) {
  EXPECT_EQ(cut_centidegrees(0.0), 0);
  EXPECT_EQ(cut_centidegrees(359.996), 0);
  EXPECT_EQ(cut_centidegrees(-45.0), 31500);
  EXPECT_EQ(cut_centidegrees(720.25), 25);
  EXPECT_EQ(cut_centidegrees(std::numeric_limits<double>::quiet_NaN()), 0);
}

}  // namespace
}  // namespace trajroi::vlp16
