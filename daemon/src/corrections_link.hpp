#pragma once

// RTK corrections into the u-blox through the port trajroid owns (gnss.corrections). The
// corrections thread runs the source (NTRIP caster, TCP or UDP stream, a radio's serial port,
// an LCM channel) on its own poll loop and hands each whole CRC-correct RTCM3 frame through a
// lock-free ring to the GNSS input thread, which writes the frames waiting into the port
// before each read: whole frames only, never inside the receiver configuration the same thread
// writes when the port opens. The processing thread hands the rover's newest NAV-PVT through
// another ring, for the GGA sentence a VRS caster needs. No network I/O ever runs on a
// pipeline thread.
#include <array>
#include <atomic>
#include <cstdint>
#include <memory>
#include <mutex>
#include <optional>
#include <string>

#include "pipeline.hpp"
#include "trajroi/corrections/correction_source.hpp"
#include "trajroi/corrections/corrections_url.hpp"
#include "trajroi/corrections/gga.hpp"
#include "trajroi/framing/rtcm3.hpp"
#include "trajroi/serial/serial_port_source.hpp"
#include "trajroi/ublox/messages.hpp"

namespace trajroi::daemon {

struct RtcmFrameSlot {
  std::uint16_t size = 0;
  std::array<std::uint8_t, framing::kRtcm3MaxFrame> bytes{};
};

// The corrections' figures for the status and the log (copied under the link's lock by the
// corrections thread at most every 100 ms; read by the publisher once a second).
struct CorrectionsStats {
  corrections::CorrectionCounters in;
  std::string source;  // the URL without its password
  std::string state;   // the source's state in words
  bool streaming = false;
  std::int64_t last_frame_ns = 0;  // CLOCK_MONOTONIC of the newest frame received (0: none)
  std::uint64_t ring_drops = 0;    // frames the GNSS thread had no room for (it is behind)
};

class CorrectionsLink {
 public:
  // `url` must have passed corrections::parse_corrections_url (the configuration checked it).
  CorrectionsLink(const DaemonConfig& config, std::string lcm_url);
  ~CorrectionsLink();
  CorrectionsLink(const CorrectionsLink&) = delete;
  CorrectionsLink& operator=(const CorrectionsLink&) = delete;

  // Opens the source (binds a UDP port, opens LCM): throws std::runtime_error naming it.
  void open();
  // The corrections thread's loop, until `stop`.
  void run(const std::atomic<bool>& stop);

  // GNSS input thread, before each read: the frames waiting, written whole into `port`.
  void write_waiting(serial::SerialPortSource& port);
  // Processing thread: the rover's newest NAV-PVT (for the caster's GGA).
  void offer_rover(const ublox::NavPvt& pvt);

  // Publisher thread.
  [[nodiscard]] CorrectionsStats stats() const;
  std::atomic<std::uint64_t> written_frames{0}, written_bytes{0};
  std::atomic<std::uint64_t> write_failures{0};  // the port refused or timed out: frame lost
  std::atomic<std::uint64_t> not_written{0};     // the port was closed (unplugged): frame dropped
  std::atomic<std::int64_t> last_written_ns{0};  // CLOCK_MONOTONIC of the newest frame written (0: none)
  [[nodiscard]] const corrections::CorrectionsUrl& url() const noexcept { return url_; }

 private:
  void publish_stats(std::int64_t now_ns);

  const DaemonConfig& config_;
  std::string lcm_url_;
  corrections::CorrectionsUrl url_;
  std::unique_ptr<corrections::CorrectionSource> source_;
  Ring<RtcmFrameSlot> frames_;
  Ring<corrections::GgaFix> rover_;
  std::optional<corrections::GgaFix> newest_rover_;  // the corrections thread's
  mutable std::mutex stats_mutex_;
  CorrectionsStats stats_;
  std::int64_t stats_at_ns_ = 0;
};

// The rover's GGA fields from a NAV-PVT (quality 4 RTK fixed, 5 float, 2 differential, 1 GNSS,
// 0 no fix; NAV-PVT has no HDOP: its PDOP stands in).
[[nodiscard]] std::optional<corrections::GgaFix> rover_fix(const ublox::NavPvt& pvt);

}  // namespace trajroi::daemon
