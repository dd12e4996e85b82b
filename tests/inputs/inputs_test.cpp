// The one input path: the merger's order and its loop shift, the pacer, and the live inputs'
// time base (UDP datagrams stamped by the kernel in CLOCK_REALTIME come out in CLOCK_MONOTONIC;
// a serial port says when it opens, then hands its bytes).
#include <arpa/inet.h>
#include <fcntl.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <pty.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <filesystem>
#include <string>
#include <vector>

#include "test_data.hpp"
#include "trajroi/host/clock.hpp"
#include "trajroi/inputs/live_input.hpp"
#include "trajroi/inputs/pacer.hpp"
#include "trajroi/inputs/recorded_input.hpp"
#include "trajroi/inputs/run_merger.hpp"
#include "trajroi/serial/byte_log.hpp"
#include "trajroi/vlp16/pcap_source.hpp"

namespace {

namespace fs = std::filesystem;
using namespace trajroi::inputs;
using namespace std::chrono_literals;

struct TempRun {
  fs::path dir = fs::temp_directory_path() / ("trajroi_inputs_" + std::to_string(::getpid()));
  TempRun() { fs::create_directories(dir); }
  ~TempRun() {
    std::error_code ignored;
    fs::remove_all(dir, ignored);
  }
};

std::vector<std::uint8_t> bytes(std::uint8_t tag, std::size_t n) {
  return std::vector<std::uint8_t>(n, tag);
}

// lidar data at 10 and 50 ms, position at 30; GNSS at 20 and 50; IMU at 40 and 50 (ms).
void write_run(const fs::path& dir, bool with_imu = true) {
  {
    trajroi::vlp16::PcapWriter pcap(dir / kLidarFile);
    pcap.write(10'000'000, trajroi::vlp16::kDataPort, bytes(1, 1206));
    pcap.write(30'000'000, trajroi::vlp16::kPositionPort, bytes(2, 512));
    pcap.write(50'000'000, trajroi::vlp16::kDataPort, bytes(3, 1206));
    pcap.close();
  }
  trajroi::serial::RecordingWriter gnss((dir / kGnssFile).string());
  gnss.write({bytes(4, 100), 20'000'000});
  gnss.write({bytes(5, 100), 50'000'000});
  gnss.flush();
  if (with_imu) {
    trajroi::serial::RecordingWriter imu((dir / kImuFile).string());
    imu.write({bytes(6, 40), 40'000'000});
    imu.write({bytes(7, 40), 50'000'000});
    imu.flush();
  }
}

struct Seen {
  Stream stream;
  std::int64_t t_ms;
  std::uint8_t tag;
};

TEST(RunMerger, GivesEveryItemInReceiveTimeOrderGnssThenImuThenLidarOnATie) {
  TempRun run;
  write_run(run.dir);
  RunMerger merger(run.dir);
  std::vector<Seen> seen;
  InputItem item;
  while (merger.next(item))
    seen.push_back({item.stream, item.receive_ns / 1'000'000, item.bytes.front()});
  const std::vector<Seen> expected{{Stream::kLidarData, 10, 1}, {Stream::kGnss, 20, 4}, {Stream::kLidarPosition, 30, 2},
                                   {Stream::kImu, 40, 6},       {Stream::kGnss, 50, 5}, {Stream::kImu, 50, 7},
                                   {Stream::kLidarData, 50, 3}};
  ASSERT_EQ(seen.size(), expected.size());
  for (std::size_t i = 0; i < seen.size(); ++i) {
    EXPECT_EQ(seen[i].stream, expected[i].stream) << i;
    EXPECT_EQ(seen[i].t_ms, expected[i].t_ms) << i;
    EXPECT_EQ(seen[i].tag, expected[i].tag) << i;
  }
  EXPECT_TRUE(merger.missing().empty());
  EXPECT_EQ(merger.first_ns(), 10'000'000);
  EXPECT_EQ(merger.last_ns(), 50'000'000);
}

TEST(RunMerger, AMissingSerialRecordingIsNamedAndThatStreamIsSilent) {
  TempRun run;
  write_run(run.dir, /*with_imu=*/false);
  RunMerger merger(run.dir, RunStreams{true, true, true}, 1'000'000'000);
  ASSERT_EQ(merger.missing().size(), 1u);
  EXPECT_NE(merger.missing().front().find("imu.trjb"), std::string::npos);
  InputItem item;
  std::size_t n = 0;
  std::int64_t first = 0;
  while (merger.next(item)) {
    EXPECT_NE(item.stream, Stream::kImu);
    if (n++ == 0) first = item.receive_ns;
  }
  EXPECT_EQ(n, 5u);
  EXPECT_EQ(first, 1'010'000'000) << "every time shifted by shift_ns";
  EXPECT_THROW(RunMerger(run.dir / "nowhere"), std::runtime_error);
}

TEST(RecordedInput, ALoopPlaysTheRunAgainWithItsTimesShiftedPastTheLastLap) {
  TempRun run;
  write_run(run.dir);
  RecordedOptions options;
  options.loop = true;
  RecordedInput input(run.dir, options);
  InputItem item;
  std::vector<std::int64_t> times;
  int notices = 0;
  while (times.size() < 14) {
    const auto next = input.next(item, 10ms);
    if (next == InputSource::Next::kNotice) {
      ++notices;
      EXPECT_EQ(input.notice().text, "replay: lap 2");
      continue;
    }
    ASSERT_EQ(next, InputSource::Next::kItem);
    times.push_back(item.receive_ns);
  }
  EXPECT_EQ(notices, 1);
  // The lap spans 10 … 50 ms; the next starts 40 ms + the 100 ms gap later.
  EXPECT_EQ(times[7] - times[0], 140'000'000);
  EXPECT_EQ(times[13] - times[6], 140'000'000);
}

TEST(Pacer, PlaysRecordedTimesAtTheRateAndAsFastAsPossibleAtZero) {
  EXPECT_THROW(Pacer(-1.0), std::invalid_argument);
  Pacer fast(0.0);
  EXPECT_FALSE(fast.paced());
  const std::int64_t due = fast.due_ns(1'000'000'000'000);
  EXPECT_LE(due, trajroi::host::monotonic_ns()) << "not paced: every item is due now";
  Pacer twice(2.0);
  const std::int64_t start = trajroi::host::monotonic_ns();
  EXPECT_TRUE(Pacer::sleep_until(twice.due_ns(5'000'000'000)));                // anchors: due now
  EXPECT_TRUE(Pacer::sleep_until(twice.due_ns(5'000'000'000 + 200'000'000)));  // 200 ms at 2x
  const std::int64_t elapsed = trajroi::host::monotonic_ns() - start;
  EXPECT_GE(elapsed, 100'000'000);
  EXPECT_LT(elapsed, 600'000'000);
  // A stop flag ends the wait early.
  std::atomic<bool> stop{true};
  EXPECT_FALSE(Pacer::sleep_until(trajroi::host::monotonic_ns() + 10'000'000'000, &stop));
}

TEST(RecordedInput, PacedAtTheRecordedRateTakesTheRecordingsTime) {
  TempRun run;
  write_run(run.dir);
  RecordedOptions options;
  options.rate = 1.0;
  RecordedInput input(run.dir, options);
  InputItem item;
  const std::int64_t start = trajroi::host::monotonic_ns();
  std::size_t n = 0;
  for (int i = 0; i < 1000 && n < 7; ++i)
    n += input.next(item, 5ms) == InputSource::Next::kItem ? 1U : 0U;
  EXPECT_EQ(n, 7u);
  // 40 ms of recording at real time (items leave at most one 2 ms quantum early).
  EXPECT_GE(trajroi::host::monotonic_ns() - start, 38'000'000);
  EXPECT_EQ(input.next(item, 5ms), InputSource::Next::kEnd);
}

TEST(UdpInput, DatagramsComeOutStampedInTheMonotonicClockByPort) {
  trajroi::vlp16::UdpOptions o;
  o.bind_address = "127.0.0.1";
  o.data_port = 0;
  o.position_port = 0;
  o.receive_buffer_bytes = 1 << 16;
  UdpInput input(o);
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  ASSERT_GE(fd, 0);
  sockaddr_in to{};
  to.sin_family = AF_INET;
  to.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const std::vector<std::uint8_t> payload = bytes(9, 1206);
  to.sin_port = htons(input.udp().position_port());
  ASSERT_EQ(::sendto(fd, payload.data(), 512, 0, reinterpret_cast<const sockaddr*>(&to), sizeof to), 512);
  to.sin_port = htons(input.udp().data_port());
  ASSERT_EQ(::sendto(fd, payload.data(), payload.size(), 0, reinterpret_cast<const sockaddr*>(&to), sizeof to), 1206);
  ::close(fd);
  InputItem item;
  std::size_t data = 0, position = 0;
  for (int i = 0; i < 50 && data + position < 2; ++i) {
    const auto next = input.next(item, 100ms);
    if (next != InputSource::Next::kItem) continue;
    const std::int64_t age = trajroi::host::monotonic_ns() - item.receive_ns;
    EXPECT_GE(age, 0) << "a CLOCK_MONOTONIC stamp, not CLOCK_REALTIME";
    EXPECT_LT(age, 2'000'000'000);
    (item.stream == Stream::kLidarData ? data : position) += 1;
    EXPECT_EQ(item.bytes.size(), item.stream == Stream::kLidarData ? 1206u : 512u);
  }
  EXPECT_EQ(data, 1u);
  EXPECT_EQ(position, 1u);
  EXPECT_EQ(input.counters().items, 2u);
}

TEST(SerialInput, SaysWhenThePortOpensThenHandsItsBytes) {
  int master = -1, slave = -1;
  char name[256] = {};
  ASSERT_EQ(openpty(&master, &slave, name, nullptr, nullptr), 0);
  trajroi::serial::SerialPortOptions o;
  o.device = name;
  o.baud = 115200;
  SerialInput input("gnss", Stream::kGnss, o);
  const std::vector<std::uint8_t> sent = bytes(0xB5, 64);
  InputItem item;
  bool opened = false;
  std::size_t received = 0;
  for (int i = 0; i < 100 && received < sent.size(); ++i) {
    const auto next = input.next(item, 20ms);
    if (next == InputSource::Next::kNotice) {
      opened = true;
      EXPECT_NE(input.notice().text.find(std::string("gnss: ") + name), std::string::npos) << input.notice().text;
      ASSERT_EQ(::write(master, sent.data(), sent.size()), static_cast<ssize_t>(sent.size()));
    } else if (next == InputSource::Next::kItem) {
      EXPECT_TRUE(opened) << "the opening is said before the first bytes";
      EXPECT_EQ(item.stream, Stream::kGnss);
      EXPECT_LE(item.receive_ns, trajroi::host::monotonic_ns());
      received += item.bytes.size();
    }
  }
  EXPECT_TRUE(opened);
  EXPECT_EQ(received, sent.size());
  ::close(master);
  ::close(slave);
}

}  // namespace

namespace {

// Real captures named one by one (what `trajroi feed --pcap --ubx` plays) go through the same
// merger: the u-blox log in epochs at their iTOW spacing (the neo-m8n log's 24 epochs, 5 Hz),
// the capture's datagrams at their recorded spacing from `lidar_start_ns`, every byte and every
// datagram once, in time order.
TEST(RunMerger, CapturesNamedOneByOneMergeByTheirOwnClocks) {
  TRAJROI_REQUIRE_DATA(pcap, "velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap");
  TRAJROI_REQUIRE_DATA(ubx, "ublox/gpsd/ublox-neo-m8n.log");
  trajroi::inputs::RunFiles files;
  files.lidar = pcap;
  files.lidar_start_ns = 1'000'000'000;
  files.gnss = ubx;
  files.gnss_options.raw_timing = trajroi::serial::RawTiming::kUbxTime;
  trajroi::inputs::RunMerger merger(files);
  InputItem item;
  std::int64_t previous = INT64_MIN, first_lidar = -1;
  std::size_t gnss_bytes = 0, lidar = 0;
  std::vector<std::int64_t> gnss_times;
  while (merger.next(item)) {
    EXPECT_GE(item.receive_ns, previous);
    previous = item.receive_ns;
    if (item.stream == Stream::kGnss) {
      gnss_bytes += item.bytes.size();
      gnss_times.push_back(item.receive_ns);
    } else {
      if (first_lidar < 0) first_lidar = item.receive_ns;
      ++lidar;
    }
  }
  EXPECT_EQ(first_lidar, 1'000'000'000);
  EXPECT_EQ(lidar, 293u + 57u);  // the data README: 293 data and 57 position packets
  EXPECT_EQ(gnss_bytes, std::filesystem::file_size(ubx));
  ASSERT_GE(gnss_times.size(), 24u);
  EXPECT_EQ(gnss_times.front(), 0);
  for (std::size_t i = 1; i < 24; ++i)
    EXPECT_EQ(gnss_times[i] - gnss_times[i - 1], 200'000'000) << "epoch " << i;
}

}  // namespace
