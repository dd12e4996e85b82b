// trajroi feed: plays a run folder into a live trajroid as its sensors would — the VLP-16
// datagrams over UDP to 127.0.0.1, the GNSS and IMU recordings through pseudo-terminals named
// by udev-like symlinks — paced by their recorded receive times. For fault tests it can
// unplug a serial device mid-frame and plug it back, flood the UDP port with copies and
// malformed packets, and send from an address that is not the sensor's. It sends to the
// loopback interface only.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <memory>
#include <random>
#include <stdexcept>
#include <string>
#include <vector>

#include "commands.hpp"
#include "feed_devices.hpp"
#include "trajroi/host/clock.hpp"
#include "trajroi/inputs/pacer.hpp"
#include "trajroi/inputs/run_merger.hpp"
#include "trajroi/vlp16/packet_source.hpp"

namespace trajroi::cli {
namespace {

namespace fs = std::filesystem;
using feed::PtyDevice;
using feed::UdpSender;

// "gnss@6+2": the stream's device vanishes 6 s into the data and comes back 2 s later.
struct Hangup {
  std::string stream;
  double at_s = 0.0;
  double for_s = 0.0;
};

Hangup parse_hangup(const std::string& text) {
  Hangup h;
  const auto at = text.find('@');
  const auto plus = text.find('+', at == std::string::npos ? 0 : at);
  if (at == std::string::npos || plus == std::string::npos) {
    throw std::invalid_argument("--hangup '" + text + "': expected STREAM@AT_S+FOR_S, e.g. gnss@6+2");
  }
  h.stream = text.substr(0, at);
  try {
    h.at_s = std::stod(text.substr(at + 1, plus - at - 1));
    h.for_s = std::stod(text.substr(plus + 1));
  } catch (const std::exception&) {
    throw std::invalid_argument("--hangup '" + text + "': AT_S and FOR_S must be numbers");
  }
  if (h.stream != "gnss" && h.stream != "imu")
    throw std::invalid_argument("--hangup '" + text + "': stream is gnss or imu");
  if (!(h.at_s >= 0.0) || !(h.for_s > 0.0))
    throw std::invalid_argument("--hangup '" + text + "': AT_S >= 0, FOR_S > 0");
  return h;
}

// Real captures instead of a run folder, each paced by its own clock through the run merger
// (inputs::RunFiles): a pcap (UDP payloads by their destination port, at their recorded
// spacing), a raw UBX log (by its epochs' iTOW), a raw VN-100 log (by the LoggerWavesInIce
// logger's `M,<millis>` markers, or its frames' TimeStartup, else a frame per 0xFA at
// --vn100-rate).
struct Captures {
  std::string pcap, ubx, vn100;  // empty: not fed
  double lidar_after_s = 0.0;    // the capture's first datagram this long into the serial data
  double vn100_rate_hz = 10.0;
};

struct FeedOptions {
  std::string run_dir;
  Captures captures;
  double until_s = 0.0;  // > 0: stop after this much data (a long serial log)
  double rate = 1.0;
  std::uint16_t data_port = vlp16::kDataPort;
  std::uint16_t position_port = vlp16::kPositionPort;
  std::string from = "127.0.0.1";  // the sensor's (loopback) address
  std::string gnss_link, imu_link;
  double wait_for_readers_s = 30.0;
  double linger_s = 0.0;  // after the data, the devices stay this long (the reader sees no unplug)
  std::vector<std::string> hangups;
  double flood_at_s = -1.0;  // < 0: no flood
  double flood_for_s = 10.0;
  double flood_factor = 20.0;
  double malformed_fraction = 0.5;
  std::string foreign_from;  // a second sender, not the sensor
  unsigned foreign_every = 10;
};

void run_feed(const FeedOptions& o) {
  if (!(o.rate > 0.0)) throw std::invalid_argument("--rate must be > 0");
  if (o.foreign_every == 0) throw std::invalid_argument("--foreign-every must be >= 1");
  const fs::path dir = o.run_dir;
  // The run's recordings in receive-time order (the daemon's own merger), or the real
  // captures merged by their own times; either paced by the pacer.
  inputs::RunStreams streams;
  streams.gnss = !o.gnss_link.empty();
  streams.imu = !o.imu_link.empty();
  std::unique_ptr<inputs::RunMerger> merger;
  const Captures& c = o.captures;
  if (o.run_dir.empty()) {
    if (c.pcap.empty() && c.ubx.empty() && c.vn100.empty()) {
      throw std::invalid_argument("feed: give a run folder, or captures (--pcap, --ubx, --vn100)");
    }
    if (!c.ubx.empty() && !streams.gnss) throw std::invalid_argument("--ubx needs --gnss-link");
    if (!c.vn100.empty() && !streams.imu) throw std::invalid_argument("--vn100 needs --imu-link");
    if (!(c.vn100_rate_hz > 0.0)) throw std::invalid_argument("--vn100-rate must be > 0");
    streams.gnss = !c.ubx.empty();
    streams.imu = !c.vn100.empty();
    // The same merger over the captures, each timed by its own clock (serial::RawTiming).
    inputs::RunFiles files;
    files.lidar = c.pcap;
    files.lidar_start_ns = static_cast<std::int64_t>(c.lidar_after_s * 1e9);
    files.gnss = c.ubx;
    files.gnss_options.raw_timing = serial::RawTiming::kUbxTime;
    files.imu = c.vn100;
    files.imu_options.raw_timing = serial::RawTiming::kVn100Time;
    files.imu_options.frames_per_second = c.vn100_rate_hz;
    merger = std::make_unique<inputs::RunMerger>(files);
  } else {
    merger = std::make_unique<inputs::RunMerger>(dir, streams);
    for (const std::string& missing : merger->missing())
      throw std::runtime_error(missing + ": not found");
  }
  std::unique_ptr<PtyDevice> gnss_dev, imu_dev;
  if (streams.gnss) gnss_dev = std::make_unique<PtyDevice>("gnss", o.gnss_link);
  if (streams.imu) imu_dev = std::make_unique<PtyDevice>("imu", o.imu_link);
  std::vector<Hangup> hangups;
  for (const std::string& h : o.hangups)
    hangups.push_back(parse_hangup(h));
  UdpSender sensor(o.from);
  std::unique_ptr<UdpSender> foreign;
  if (!o.foreign_from.empty()) foreign = std::make_unique<UdpSender>(o.foreign_from);

  // The readers open their devices first (a daemon starting), then the clock starts.
  const std::int64_t give_up = host::monotonic_ns() + static_cast<std::int64_t>(o.wait_for_readers_s * 1e9);
  while ((gnss_dev && !gnss_dev->reader_open()) || (imu_dev && !imu_dev->reader_open())) {
    if (host::monotonic_ns() > give_up) {
      throw std::runtime_error("no reader opened the serial devices within --wait-for-readers");
    }
    inputs::Pacer::sleep_until(host::monotonic_ns() + 10'000'000);
  }

  std::int64_t t0 = 0;
  if (!merger->peek_time(t0)) throw std::runtime_error("feed: nothing to feed");
  inputs::Pacer pacer(o.rate);
  const std::int64_t start = host::monotonic_ns();
  double data_s = 0.0;
  std::uint64_t flood_sent = 0, malformed_sent = 0, foreign_sent = 0, data_sent = 0;
  std::uint64_t serial_undelivered[2] = {0, 0};
  std::uint64_t generation[2] = {0, 0};
  std::vector<bool> hung(hangups.size(), false), back(hangups.size(), false);
  std::mt19937 random(12345);
  const double flood_extra = std::max(0.0, o.flood_factor - 1.0);
  double flood_credit = 0.0;

  inputs::InputItem item;
  while (merger->next(item)) {
    data_s = static_cast<double>(item.receive_ns - t0) * 1e-9;
    if (o.until_s > 0.0 && data_s > o.until_s) break;
    inputs::Pacer::sleep_until(pacer.due_ns(item.receive_ns));

    for (std::size_t i = 0; i < hangups.size(); ++i) {  // devices coming back
      PtyDevice* dev = hangups[i].stream == "gnss" ? gnss_dev.get() : imu_dev.get();
      if (dev != nullptr && hung[i] && !back[i] && data_s >= hangups[i].at_s + hangups[i].for_s) {
        back[i] = true;
        dev->appear();
        ++generation[hangups[i].stream == "gnss" ? 0 : 1];
      }
    }
    if (gnss_dev) gnss_dev->report_reopen(generation[0]);
    if (imu_dev) imu_dev->report_reopen(generation[1]);

    if (inputs::is_lidar(item.stream)) {
      const bool data = item.stream == inputs::Stream::kLidarData;
      sensor.send(item.bytes, data ? o.data_port : o.position_port);
      if (data) {
        ++data_sent;
        if (foreign && data_sent % o.foreign_every == 0) {
          foreign->send(item.bytes, o.data_port);
          ++foreign_sent;
        }
        if (o.flood_at_s >= 0.0 && data_s >= o.flood_at_s && data_s < o.flood_at_s + o.flood_for_s) {
          flood_credit += flood_extra;
          for (; flood_credit >= 1.0; flood_credit -= 1.0) {
            if (std::uniform_real_distribution<double>(0.0, 1.0)(random) < o.malformed_fraction) {
              sensor.send(feed::malformed(item.bytes, malformed_sent++, random), o.data_port);
            } else {
              sensor.send(item.bytes, o.data_port);  // a copy: a duplicate to the decoder
            }
            ++flood_sent;
          }
        }
      }
      continue;
    }
    const int k = item.stream == inputs::Stream::kGnss ? 0 : 1;
    PtyDevice& dev = k == 0 ? *gnss_dev : *imu_dev;
    bool wrote = false;
    for (std::size_t i = 0; i < hangups.size(); ++i) {
      if (!hung[i] && hangups[i].stream == (k == 0 ? "gnss" : "imu") && data_s >= hangups[i].at_s) {
        // Unplugged in the middle of this chunk: half of it goes out, then the device is gone.
        hung[i] = true;
        const std::size_t half = item.bytes.size() / 2;
        dev.write(item.bytes.first(half));
        dev.vanish();
        std::printf("feed: %s device vanished at %.3f s of data, %zu bytes into a %zu-byte chunk\n",
                    k == 0 ? "gnss" : "imu", data_s, half, item.bytes.size());
        std::fflush(stdout);
        wrote = true;
      }
    }
    if (!wrote && !dev.write(item.bytes)) ++serial_undelivered[k];
  }
  std::printf(
      "feed: done: %.3f s of data in %.3f s; UDP sent %llu (%llu data, %llu flood of which %llu malformed)"
      " from %s, %llu from %s; serial chunks with no reader: gnss %llu, imu %llu\n",
      data_s, static_cast<double>(host::monotonic_ns() - start) * 1e-9, static_cast<unsigned long long>(sensor.sent()),
      static_cast<unsigned long long>(data_sent), static_cast<unsigned long long>(flood_sent),
      static_cast<unsigned long long>(malformed_sent), o.from.c_str(), static_cast<unsigned long long>(foreign_sent),
      o.foreign_from.empty() ? "-" : o.foreign_from.c_str(), static_cast<unsigned long long>(serial_undelivered[0]),
      static_cast<unsigned long long>(serial_undelivered[1]));
  std::fflush(stdout);
  inputs::Pacer::sleep_until(host::monotonic_ns() + static_cast<std::int64_t>(o.linger_s * 1e9));
}

}  // namespace

void add_feed_command(CLI::App& app) {
  auto o = std::make_shared<FeedOptions>();
  CLI::App* cmd = app.add_subcommand(
      "feed", "Play a run folder into a live trajroid: UDP to 127.0.0.1, serial streams through pseudo-terminals");
  cmd->add_option("run", o->run_dir, "Run folder (lidar.pcap, gnss.trjb, imu.trjb); or real captures below")
      ->check(CLI::ExistingDirectory);
  cmd->add_option("--pcap", o->captures.pcap,
                  "Real capture: a pcap whose UDP payloads are sent at their recorded spacing")
      ->check(CLI::ExistingFile);
  cmd->add_option("--ubx", o->captures.ubx,
                  "Real capture: a raw UBX log, written to --gnss-link epoch by epoch at its iTOW pace")
      ->check(CLI::ExistingFile);
  cmd->add_option("--vn100", o->captures.vn100,
                  "Real capture: a raw VN-100 log, written to --imu-link at its logger's M,<millis> pace")
      ->check(CLI::ExistingFile);
  cmd->add_option("--lidar-after", o->captures.lidar_after_s,
                  "With --pcap: its first datagram this many seconds into the feed")
      ->capture_default_str();
  cmd->add_option("--until", o->until_s, "Stop after this many seconds of data (0: all of it)")->capture_default_str();
  cmd->add_option("--vn100-rate", o->captures.vn100_rate_hz, "With --vn100 and no logger markers: frames per second")
      ->capture_default_str();
  cmd->add_option("--rate", o->rate, "Pace: 1 real time, N × real time")->capture_default_str();
  cmd->add_option("--data-port", o->data_port, "UDP port for data packets")->capture_default_str();
  cmd->add_option("--position-port", o->position_port, "UDP port for position packets")->capture_default_str();
  cmd->add_option("--from", o->from, "Loopback address the sensor sends from")->capture_default_str();
  cmd->add_option("--gnss-link", o->gnss_link,
                  "Symlink to create for the GNSS pseudo-terminal (the daemon's gnss.device)");
  cmd->add_option("--imu-link", o->imu_link, "Symlink to create for the IMU pseudo-terminal (the daemon's imu.device)");
  cmd->add_option("--wait-for-readers", o->wait_for_readers_s, "Seconds to wait for the devices to be opened")
      ->capture_default_str();
  cmd->add_option("--linger", o->linger_s, "Seconds the devices stay after the data ends")->capture_default_str();
  cmd->add_option("--hangup", o->hangups, "STREAM@AT_S+FOR_S: the device vanishes mid-chunk, back FOR_S later");
  cmd->add_option("--flood-at", o->flood_at_s, "Data time (s) a UDP flood starts");
  cmd->add_option("--flood-for", o->flood_for_s, "Flood duration, s of data")->capture_default_str();
  cmd->add_option("--flood-factor", o->flood_factor, "Flood rate as a multiple of the data packet rate")
      ->capture_default_str();
  cmd->add_option("--malformed-fraction", o->malformed_fraction, "Share of the flood that is malformed")
      ->capture_default_str();
  cmd->add_option("--foreign-from", o->foreign_from, "Also send copies from this loopback address (not the sensor)");
  cmd->add_option("--foreign-every", o->foreign_every, "One copy from --foreign-from per this many data packets")
      ->capture_default_str();
  cmd->callback([o] { run_feed(*o); });
}

}  // namespace trajroi::cli
