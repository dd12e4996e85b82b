// Real third-party captures (../shared/data/velodyne, see its README), read through the pcap
// source and decoded; figures checked against the counts the data README gives.
#include <gtest/gtest.h>

#include <map>

#include "test_data.hpp"
#include "trajroi/vlp16/decoder.hpp"
#include "trajroi/vlp16/pcap_source.hpp"

namespace trajroi::vlp16 {
namespace {

struct CaptureSummary {
  std::size_t data_packets = 0;      // port 2368, 1206 bytes
  std::size_t position_packets = 0;  // port 8308, 512 bytes
  std::map<PacketError, std::size_t> rejected;
  std::map<std::uint8_t, std::size_t> products;
  std::map<std::uint8_t, std::size_t> modes;
  std::size_t points = 0;
  std::size_t no_return = 0;
};

CaptureSummary read_capture(const std::filesystem::path& path) {
  CaptureSummary s;
  PcapSource source(path);
  const PacketDecoder decoder(Calibration::vlp16_default());
  std::vector<Point> points;
  CapturedDatagram datagram{};
  PcapSource::Next next;
  while ((next = source.next(datagram)) == PcapSource::Next::kDatagram) {
    if (datagram.payload.size() == 512) {
      ++s.position_packets;
      continue;
    }
    ++s.data_packets;
    const PacketError error = validate_data_packet(datagram.payload);
    if (error != PacketError::kNone) {
      ++s.rejected[error];
      continue;
    }
    ++s.products[product_id(datagram.payload)];
    ++s.modes[return_mode_byte(datagram.payload)];
    points.clear();
    const PacketDecoder::Result r = decoder.decode(datagram.payload, points);
    s.points += r.points;
    s.no_return += r.no_return;
  }
  EXPECT_EQ(next, PcapSource::Next::kEnd) << source.error();
  return s;
}

TEST(Vlp16Capture, MrptStrongestCaptureCountsMatchTheReadme) {
  TRAJROI_REQUIRE_DATA(path, "velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap");
  const CaptureSummary s = read_capture(path);
  EXPECT_EQ(s.data_packets, 293u);
  EXPECT_EQ(s.position_packets, 57u);
  EXPECT_TRUE(s.rejected.empty());
  EXPECT_EQ(s.products.at(0x22), 293u);
  EXPECT_EQ(s.modes.at(0x37), 293u);
  // README: "73,486 of 112,512 channel returns are non-zero"; range limits are off.
  EXPECT_EQ(s.points, 73'486u);
  EXPECT_EQ(s.points + s.no_return, 112'512u);
}

TEST(Vlp16Capture, NebulaDualCaptureIsDualVlp16) {
  TRAJROI_REQUIRE_DATA(path, "velodyne/vlp16/nebula_vlp16_dual_1673400471.DERIVED.pcap");
  const CaptureSummary s = read_capture(path);
  EXPECT_EQ(s.data_packets, 603u);
  EXPECT_EQ(s.modes.at(0x39), 603u);
  EXPECT_EQ(s.products.at(0x22), 603u);
  EXPECT_GT(s.points, 14'831u);  // nebula's cloud of one scan is a subset of the capture
}

TEST(Vlp16Capture, Vlp32cCaptureIsRejectedByProductId) {
  TRAJROI_REQUIRE_DATA(path, "velodyne/other_models/nebula_vlp32c_strongest_1713492677.DERIVED.pcap");
  const CaptureSummary s = read_capture(path);
  EXPECT_EQ(s.data_packets, 379u);
  EXPECT_EQ(s.rejected.at(PacketError::kUnsupportedProduct), 379u);
  EXPECT_EQ(s.points, 0u);
}

TEST(Vlp16Capture, UnreadableFileIsAClearError) {
  try {
    PcapSource source("/nonexistent/capture.pcap");
    FAIL() << "opened a missing file";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find("/nonexistent/capture.pcap"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace trajroi::vlp16
