#pragma once

// An NTRIP client on a non-blocking TCP socket, driven by the caller's poll loop (never
// blocking it): connects, asks for the mountpoint, reads the caster's answer, then the RTCM3
// stream (HTTP/1.1 chunked for NTRIP 2.0), handing on whole CRC-correct frames only. It sends
// the rover's GGA every gga_interval_s when the caller has one (VRS casters need it), notices a
// stalled stream, and reconnects with a backoff doubling from backoff_min_s to backoff_max_s.
// Every change of state is said in words through the event callback ("connected to …",
// "refused by the caster: HTTP/1.0 401 Unauthorized", "mountpoint X is not on the caster; it
// has: A, B", "caster closed the connection", "no data for 10.0 s"). Resolving the caster's
// name (getaddrinfo) may block the calling thread for the resolver's timeout: run the client
// on a thread of its own, never one of the pipeline's.
#include <cstdint>
#include <functional>
#include <map>
#include <span>
#include <string>
#include <vector>

#include "trajroi/corrections/ntrip.hpp"
#include "trajroi/framing/rtcm3.hpp"

namespace trajroi::corrections {

struct NtripClientOptions {
  NtripUrl url;
  std::string user_agent = "trajroi";
  double gga_interval_s = 10.0;  // 0: never
  double stall_s = 10.0;         // no byte for this long while streaming: reconnect
  double backoff_min_s = 1.0, backoff_max_s = 30.0;
  double connect_timeout_s = 10.0;
};

struct CorrectionCounters {
  std::uint64_t bytes = 0;        // stream bytes received (after the answer, unchunked)
  std::uint64_t frames = 0;       // whole CRC-correct RTCM3 frames handed on
  std::uint64_t crc_errors = 0;   // frame candidates whose CRC-24Q failed
  std::uint64_t other_bytes = 0;  // bytes in no frame (not RTCM3)
  std::uint64_t connects = 0;     // streams started
  std::uint64_t disconnects = 0;  // streams lost (closed, reset, stalled, garbage)
  std::uint64_t refusals = 0;     // answers other than a stream
  std::uint64_t gga_sent = 0;
  std::map<std::uint16_t, std::uint64_t> by_message;  // frames by RTCM message number
};

class NtripClient {
 public:
  using FrameSink = std::function<void(std::span<const std::uint8_t> frame)>;
  using GgaSource = std::function<std::string()>;  // the rover's GGA sentence, "" when no fix yet
  using EventSink = std::function<void(const std::string& text)>;

  NtripClient(NtripClientOptions options, FrameSink on_frame, GgaSource gga, EventSink on_event);
  ~NtripClient();
  NtripClient(const NtripClient&) = delete;
  NtripClient& operator=(const NtripClient&) = delete;

  // For poll(): the socket (−1 while waiting to reconnect) and what to wait for.
  [[nodiscard]] int fd() const noexcept { return fd_; }
  [[nodiscard]] short events() const noexcept;
  // Milliseconds until the next thing to do without the socket (reconnect, GGA, stall check).
  [[nodiscard]] int timeout_ms(std::int64_t now_ns) const noexcept;
  // After poll() (revents 0 on a timeout), with CLOCK_MONOTONIC now.
  void service(short revents, std::int64_t now_ns);

  [[nodiscard]] const CorrectionCounters& counters() const noexcept { return counters_; }
  // "streaming from ntrip://…", "connecting to …", "waiting 4 s to reconnect: <why>".
  [[nodiscard]] const std::string& state() const noexcept { return state_; }
  [[nodiscard]] bool streaming() const noexcept { return phase_ == Phase::kStreaming; }
  // CLOCK_MONOTONIC of the newest frame (0: none yet).
  [[nodiscard]] std::int64_t last_frame_ns() const noexcept { return last_frame_ns_; }

 private:
  enum class Phase : std::uint8_t { kIdle, kConnecting, kAnswer, kStreaming };
  void connect(std::int64_t now_ns);
  void fail(const std::string& why, std::int64_t now_ns, bool refused = false);
  void on_connected(std::int64_t now_ns);
  void read(std::int64_t now_ns);
  void judge_answer(bool closed, std::int64_t now_ns);
  void stream(std::span<const std::uint8_t> bytes, std::int64_t now_ns);
  void send(const std::string& bytes, std::int64_t now_ns);
  void say(const std::string& text);

  NtripClientOptions o_;
  FrameSink on_frame_;
  GgaSource gga_;
  EventSink on_event_;
  int fd_ = -1;
  Phase phase_ = Phase::kIdle;
  std::string state_;
  std::string out_;  // request or GGA bytes not sent yet
  std::string answer_;
  bool chunked_ = false;
  ChunkedDecoder chunks_;
  std::vector<std::uint8_t> unchunked_;
  framing::Rtcm3Framer framer_;
  framing::FramerCounters framer_seen_{};  // the framers of earlier connections
  std::int64_t reconnect_at_ns_ = 0, phase_since_ns_ = 0, last_byte_ns_ = 0, last_frame_ns_ = 0, next_gga_ns_ = 0;
  double backoff_s_;
  CorrectionCounters counters_;
};

}  // namespace trajroi::corrections
