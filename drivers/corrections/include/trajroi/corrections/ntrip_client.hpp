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
// on a thread of its own, never one of the pipeline's. With `raw_tcp` the same client reads a
// plain TCP stream of RTCM3 (tcp://host:port: no request, no answer).
#include <cstdint>
#include <functional>
#include <span>
#include <string>
#include <vector>

#include "trajroi/corrections/correction_source.hpp"
#include "trajroi/corrections/ntrip.hpp"

namespace trajroi::corrections {

struct NtripClientOptions {
  NtripUrl url;
  std::string user_agent = "trajroi";
  double gga_interval_s = 10.0;  // 0: never
  double stall_s = 10.0;         // no byte for this long while streaming: reconnect
  double backoff_min_s = 1.0, backoff_max_s = 30.0;
  double connect_timeout_s = 10.0;
  bool raw_tcp = false;  // a plain TCP stream of RTCM3: no NTRIP request, no answer, no GGA
};

class NtripClient final : public CorrectionSource {
 public:
  using GgaSource = std::function<std::string()>;  // the rover's GGA sentence, "" when no fix yet

  NtripClient(NtripClientOptions options, FrameSink on_frame, GgaSource gga, EventSink on_event);
  ~NtripClient() override;
  NtripClient(const NtripClient&) = delete;
  NtripClient& operator=(const NtripClient&) = delete;

  [[nodiscard]] int fd() const noexcept override { return fd_; }
  [[nodiscard]] short events() const noexcept override;
  [[nodiscard]] int timeout_ms(std::int64_t now_ns) const noexcept override;
  void service(short revents, std::int64_t now_ns) override;
  [[nodiscard]] const CorrectionCounters& counters() const noexcept override { return intake_.counters(); }
  [[nodiscard]] const std::string& state() const noexcept override { return state_; }
  [[nodiscard]] bool streaming() const noexcept override { return phase_ == Phase::kStreaming; }
  [[nodiscard]] std::int64_t last_frame_ns() const noexcept override { return last_frame_ns_; }

 private:
  enum class Phase : std::uint8_t { kIdle, kConnecting, kAnswer, kStreaming };
  void connect(std::int64_t now_ns);
  void fail(const std::string& why, std::int64_t now_ns, bool refused = false);
  void on_connected(std::int64_t now_ns);
  void read(std::int64_t now_ns);
  void judge_answer(bool closed, std::int64_t now_ns);
  void start_stream(const std::string& how, std::int64_t now_ns);
  [[nodiscard]] std::string name() const;
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
  Rtcm3Intake intake_;
  std::int64_t reconnect_at_ns_ = 0, phase_since_ns_ = 0, last_byte_ns_ = 0, last_frame_ns_ = 0, next_gga_ns_ = 0;
  double backoff_s_;
};

}  // namespace trajroi::corrections
