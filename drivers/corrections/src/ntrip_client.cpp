#include "trajroi/corrections/ntrip_client.hpp"

#include <netdb.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>

namespace trajroi::corrections {
namespace {

std::int64_t seconds_ns(double s) noexcept {
  return static_cast<std::int64_t>(s * 1e9);
}

std::string one_decimal(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.1f", v);
  return buf;
}

}  // namespace

NtripClient::NtripClient(NtripClientOptions options, FrameSink on_frame, GgaSource gga, EventSink on_event)
    : o_(std::move(options)),
      on_frame_(std::move(on_frame)),
      gga_(std::move(gga)),
      on_event_(std::move(on_event)),
      state_("not connected yet"),
      backoff_s_(o_.backoff_min_s) {}

NtripClient::~NtripClient() {
  if (fd_ >= 0) ::close(fd_);
}

void NtripClient::say(const std::string& text) {
  if (on_event_) on_event_(text);
}

short NtripClient::events() const noexcept {
  if (fd_ < 0) return 0;
  if (phase_ == Phase::kConnecting) return POLLOUT;
  return static_cast<short>(POLLIN | (out_.empty() ? 0 : POLLOUT));
}

int NtripClient::timeout_ms(std::int64_t now_ns) const noexcept {
  std::int64_t next = now_ns + seconds_ns(1.0);
  if (phase_ == Phase::kIdle) next = std::min(next, reconnect_at_ns_);
  if (phase_ == Phase::kStreaming && !o_.raw_tcp && o_.gga_interval_s > 0.0) next = std::min(next, next_gga_ns_);
  return static_cast<int>(std::max<std::int64_t>(0, (next - now_ns + 999'999) / 1'000'000));
}

void NtripClient::connect(std::int64_t now_ns) {
  addrinfo hints{};
  hints.ai_family = AF_INET;
  hints.ai_socktype = SOCK_STREAM;
  addrinfo* found = nullptr;
  const int rc = ::getaddrinfo(o_.url.host.c_str(), std::to_string(o_.url.port).c_str(), &hints, &found);
  if (rc != 0) {
    fail("cannot resolve " + o_.url.host + ": " + ::gai_strerror(rc), now_ns);
    return;
  }
  fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  const int one = 1;
  (void)::setsockopt(fd_, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
  const int c = ::connect(fd_, found->ai_addr, found->ai_addrlen);
  const int error = errno;
  ::freeaddrinfo(found);
  phase_since_ns_ = now_ns;
  if (c != 0 && error != EINPROGRESS) {
    fail(std::string("cannot connect: ") + std::strerror(error), now_ns);
    return;
  }
  phase_ = Phase::kConnecting;
  state_ = "connecting to " + name();
  if (c == 0) on_connected(now_ns);
}

void NtripClient::on_connected(std::int64_t now_ns) {
  if (o_.raw_tcp) {
    out_.clear();
    start_stream("TCP", now_ns);
    return;
  }
  phase_ = Phase::kAnswer;
  phase_since_ns_ = now_ns;
  answer_.clear();
  chunks_ = ChunkedDecoder();
  unchunked_.clear();
  chunked_ = false;
  const std::string gga = gga_ ? gga_() : std::string();
  if (!gga.empty()) ++intake_.counters().gga_sent;
  out_ = ntrip_request(o_.url, o_.user_agent, gga);
  state_ = "waiting for the caster's answer from " + name();
}

void NtripClient::fail(const std::string& why, std::int64_t now_ns, bool refused) {
  if (fd_ >= 0) ::close(fd_);
  fd_ = -1;
  if (phase_ == Phase::kStreaming) ++intake_.counters().disconnects;
  if (refused) ++intake_.counters().refusals;
  phase_ = Phase::kIdle;
  out_.clear();
  reconnect_at_ns_ = now_ns + seconds_ns(backoff_s_);
  state_ = "waiting " + one_decimal(backoff_s_) + " s to reconnect to " + name() + ": " + why;
  say(name() + ": " + why + "; reconnecting in " + one_decimal(backoff_s_) + " s");
  backoff_s_ = std::min(o_.backoff_max_s, backoff_s_ * 2.0);
}

void NtripClient::service(short revents, std::int64_t now_ns) {
  switch (phase_) {
    case Phase::kIdle:
      if (now_ns >= reconnect_at_ns_) connect(now_ns);
      return;
    case Phase::kConnecting: {
      if ((revents & (POLLOUT | POLLERR | POLLHUP)) != 0) {
        int error = 0;
        socklen_t len = sizeof error;
        (void)::getsockopt(fd_, SOL_SOCKET, SO_ERROR, &error, &len);
        if (error != 0) {
          fail(std::string("cannot connect: ") + std::strerror(error), now_ns);
          return;
        }
        on_connected(now_ns);
      } else if (now_ns - phase_since_ns_ > seconds_ns(o_.connect_timeout_s)) {
        fail("no connection within " + one_decimal(o_.connect_timeout_s) + " s", now_ns);
        return;
      }
      break;
    }
    case Phase::kAnswer:
      if (now_ns - phase_since_ns_ > seconds_ns(o_.connect_timeout_s)) {
        fail("no answer within " + one_decimal(o_.connect_timeout_s) + " s", now_ns);
        return;
      }
      break;
    case Phase::kStreaming:
      if (now_ns - last_byte_ns_ > seconds_ns(o_.stall_s)) {
        fail("no data for " + one_decimal(o_.stall_s) + " s (stalled)", now_ns);
        return;
      }
      if (!o_.raw_tcp && o_.gga_interval_s > 0.0 && now_ns >= next_gga_ns_) {
        next_gga_ns_ = now_ns + seconds_ns(o_.gga_interval_s);
        if (const std::string gga = gga_ ? gga_() : std::string(); !gga.empty()) {
          out_ += gga;
          ++intake_.counters().gga_sent;
        }
      }
      break;
  }
  if (fd_ < 0) return;
  if ((revents & (POLLIN | POLLHUP | POLLERR)) != 0) read(now_ns);
  if (fd_ >= 0 && !out_.empty()) send(std::string(), now_ns);
}

void NtripClient::send(const std::string& bytes, std::int64_t now_ns) {
  out_ += bytes;
  while (!out_.empty()) {
    const ssize_t n = ::send(fd_, out_.data(), out_.size(), MSG_NOSIGNAL);
    if (n > 0) {
      out_.erase(0, static_cast<std::size_t>(n));
      continue;
    }
    if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) return;
    if (n < 0 && errno == EINTR) continue;
    fail(std::string("cannot send: ") + std::strerror(errno), now_ns);
    return;
  }
}

void NtripClient::read(std::int64_t now_ns) {
  std::uint8_t buf[16384];
  for (;;) {
    const ssize_t n = ::recv(fd_, buf, sizeof buf, 0);
    if (n > 0) {
      const std::span<const std::uint8_t> got(buf, static_cast<std::size_t>(n));
      if (phase_ == Phase::kAnswer) {
        answer_.append(reinterpret_cast<const char*>(buf), static_cast<std::size_t>(n));
        judge_answer(false, now_ns);
      } else {
        stream(got, now_ns);
      }
      if (fd_ < 0) return;
      continue;
    }
    if (n == 0) {
      if (phase_ == Phase::kAnswer) {
        judge_answer(true, now_ns);
        if (fd_ < 0) return;
      }
      fail(o_.raw_tcp ? "the server closed the connection" : "the caster closed the connection", now_ns);
      return;
    }
    if (errno == EINTR) continue;
    if (errno == EAGAIN || errno == EWOULDBLOCK) return;
    fail(std::string("connection lost: ") + std::strerror(errno), now_ns);
    return;
  }
}

void NtripClient::judge_answer(bool closed, std::int64_t now_ns) {
  const NtripAnswer a = parse_ntrip_answer(answer_, closed);
  switch (a.kind) {
    case NtripAnswer::Kind::kIncomplete:
      return;
    case NtripAnswer::Kind::kGarbage:
      fail("its answer is not NTRIP (" + std::to_string(answer_.size()) + " bytes not a status line)", now_ns, true);
      return;
    case NtripAnswer::Kind::kRefused:
      fail("refused by the caster: " + a.status_line, now_ns, true);
      return;
    case NtripAnswer::Kind::kSourceTable: {
      if (!closed) return;  // the table comes whole before the caster closes
      std::string names;
      for (const SourceTableStream& s : parse_source_table(std::string_view(answer_).substr(a.head_bytes)))
        names += (names.empty() ? "" : ", ") + s.mountpoint;
      fail("mountpoint " + o_.url.mountpoint + " is not on the caster; it has: " + (names.empty() ? "none" : names),
           now_ns, true);
      return;
    }
    case NtripAnswer::Kind::kStream: {
      chunked_ = a.chunked;
      start_stream(a.status_line + (a.chunked ? ", chunked" : ""), now_ns);
      const std::string rest = answer_.substr(a.head_bytes);
      answer_.clear();
      if (!rest.empty()) stream(std::span(reinterpret_cast<const std::uint8_t*>(rest.data()), rest.size()), now_ns);
      return;
    }
  }
}

void NtripClient::start_stream(const std::string& how, std::int64_t now_ns) {
  phase_ = Phase::kStreaming;
  last_byte_ns_ = now_ns;
  next_gga_ns_ = now_ns + seconds_ns(o_.gga_interval_s);
  backoff_s_ = o_.backoff_min_s;
  ++intake_.counters().connects;
  intake_.restart();  // a frame cut by the previous connection's end is not completed by this one's bytes
  state_ = "streaming from " + name();
  say("connected to " + name() + " (" + how + ")");
}

std::string NtripClient::name() const {
  return o_.raw_tcp ? "tcp://" + o_.url.host + ":" + std::to_string(o_.url.port) : o_.url.redacted();
}

void NtripClient::stream(std::span<const std::uint8_t> bytes, std::int64_t now_ns) {
  last_byte_ns_ = now_ns;
  if (chunked_) {
    unchunked_.clear();
    if (chunks_.feed(bytes, unchunked_) == ChunkedDecoder::Status::kError) {
      fail("its chunked stream is broken: " + chunks_.error(), now_ns);
      return;
    }
    bytes = unchunked_;
  }
  intake_.feed(bytes, [this, now_ns](std::span<const std::uint8_t> frame) {
    last_frame_ns_ = now_ns;
    on_frame_(frame);
  });
}

}  // namespace trajroi::corrections
