#include "corrections_link.hpp"

#include <poll.h>

#include <algorithm>
#include <chrono>

#include "lcm_corrections.hpp"
#include "log.hpp"
#include "realtime.hpp"
#include "trajroi/corrections/ntrip_client.hpp"
#include "trajroi/corrections/serial_corrections.hpp"
#include "trajroi/corrections/udp_corrections.hpp"

namespace trajroi::daemon {

namespace {

constexpr std::size_t kFrameRing = 256;  // ≈ 1 min of a base's 1 Hz messages; the GNSS thread drains it every read
constexpr std::size_t kRoverRing = 16;
constexpr std::int64_t kStatsEvery_ns = 100'000'000;

}  // namespace

std::optional<corrections::GgaFix> rover_fix(const ublox::NavPvt& pvt) {
  if (!pvt.utc_valid() || pvt.invalid_llh || pvt.fix_type_raw < 2 || pvt.fix_type_raw == 5) return std::nullopt;
  corrections::GgaFix f;
  f.utc_ns = pvt.utc_ns();
  f.latitude_deg = pvt.lat_deg();
  f.longitude_deg = pvt.lon_deg();
  f.height_msl_m = pvt.hmsl_m();
  f.geoid_separation_m = pvt.height_m() - pvt.hmsl_m();
  f.quality = pvt.carr_soln == ublox::CarrierSolution::kFixed   ? 4
              : pvt.carr_soln == ublox::CarrierSolution::kFloat ? 5
              : pvt.diff_soln                                   ? 2
                                                                : 1;
  f.satellites = pvt.num_sv;
  f.hdop = std::min(99.9, pvt.pdop_e2 * 0.01);
  return f;
}

CorrectionsLink::CorrectionsLink(const DaemonConfig& config, std::string lcm_url)
    : config_(config),
      lcm_url_(std::move(lcm_url)),
      url_(corrections::parse_corrections_url(config.gnss_corrections.url)),
      frames_(kFrameRing),
      rover_(kRoverRing) {
  stats_.source = url_.redacted();
  stats_.state = "not started";
}

CorrectionsLink::~CorrectionsLink() = default;

void CorrectionsLink::open() {
  const auto on_frame = [this](std::span<const std::uint8_t> frame) {
    // A full ring: the GNSS thread is behind (or its port closed); the ring counts the drop.
    (void)frames_.try_push([&frame](RtcmFrameSlot& slot) {
      slot.size = static_cast<std::uint16_t>(frame.size());
      std::copy(frame.begin(), frame.end(), slot.bytes.begin());
    });
  };
  const auto on_event = [](const std::string& text) { log::info("corrections: {}", text); };
  const DaemonConfig::GnssCorrections& c = config_.gnss_corrections;
  using Kind = corrections::CorrectionsUrl::Kind;
  switch (url_.kind) {
    case Kind::kNtrip:
    case Kind::kTcp: {
      corrections::NtripClientOptions o;
      o.url = url_.ntrip;
      o.raw_tcp = url_.kind == Kind::kTcp;
      o.gga_interval_s = c.gga_interval_s;
      o.stall_s = c.stall_s;
      o.user_agent = "NTRIP trajroi/" + std::string(TRAJROI_VERSION_TEXT);
      source_ = std::make_unique<corrections::NtripClient>(
          o, on_frame,
          [this]() -> std::string { return newest_rover_ ? corrections::gga_sentence(*newest_rover_) : ""; }, on_event);
      break;
    }
    case Kind::kUdp:
      source_ =
          std::make_unique<corrections::UdpCorrections>(url_.bind_address, url_.port, c.stall_s, on_frame, on_event);
      break;
    case Kind::kSerial:
      source_ = std::make_unique<corrections::SerialCorrections>(url_.device, url_.baud, c.stall_s, on_frame, on_event);
      break;
    case Kind::kLcm:
      source_ = std::make_unique<LcmCorrections>(lcm_url_, url_.channel, c.stall_s, on_frame, on_event);
      break;
  }
  stats_.state = source_->state();
}

void CorrectionsLink::publish_stats(std::int64_t now_ns) {
  if (now_ns - stats_at_ns_ < kStatsEvery_ns) return;
  stats_at_ns_ = now_ns;
  const std::lock_guard lock(stats_mutex_);
  stats_.in = source_->counters();
  stats_.state = source_->state();
  stats_.streaming = source_->streaming();
  stats_.last_frame_ns = source_->last_frame_ns();
  stats_.ring_drops = frames_.dropped();
}

CorrectionsStats CorrectionsLink::stats() const {
  const std::lock_guard lock(stats_mutex_);
  return stats_;
}

void CorrectionsLink::run(const std::atomic<bool>& stop) {
  if (const std::string w = apply_thread_config("trajroid-rtcm", ThreadConfig{}); !w.empty()) log::warn("{}", w);
  log::info("corrections: from {} into the GNSS port {}", url_.redacted(), config_.gnss.device);
  while (!stop.load(std::memory_order_relaxed)) {
    while (const corrections::GgaFix* f = rover_.front()) {
      newest_rover_ = *f;
      rover_.release();
    }
    const std::int64_t now = host::monotonic_ns();
    // Woken at least every 100 ms: the stop flag and the rover's position.
    const int timeout = std::min(source_->timeout_ms(now), kIdleWait_ms);
    pollfd p{source_->fd(), source_->events(), 0};
    const bool watch = p.fd >= 0 && p.events != 0;
    const int r = ::poll(watch ? &p : nullptr, watch ? 1 : 0, timeout);
    source_->service(r > 0 ? p.revents : short{0}, host::monotonic_ns());
    publish_stats(host::monotonic_ns());
  }
  stats_at_ns_ = 0;
  publish_stats(host::monotonic_ns());
}

void CorrectionsLink::write_waiting(serial::SerialPortSource& port) {
  while (const RtcmFrameSlot* slot = frames_.front()) {
    if (!port.is_open()) {
      not_written.fetch_add(1, std::memory_order_relaxed);  // stale by the time it reopens
    } else if (port.write(std::span(slot->bytes.data(), slot->size), std::chrono::milliseconds(100))) {
      written_frames.fetch_add(1, std::memory_order_relaxed);
      written_bytes.fetch_add(slot->size, std::memory_order_relaxed);
      last_written_ns.store(host::monotonic_ns(), std::memory_order_relaxed);
    } else {
      write_failures.fetch_add(1, std::memory_order_relaxed);
    }
    frames_.release();
  }
}

void CorrectionsLink::offer_rover(const ublox::NavPvt& pvt) {
  if (const auto f = rover_fix(pvt)) (void)rover_.try_push([&f](corrections::GgaFix& slot) { slot = *f; });
}

}  // namespace trajroi::daemon
