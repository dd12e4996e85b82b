#include "trajroi/view/server.hpp"

#include <arpa/inet.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <sys/uio.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <ctime>
#include <stdexcept>

#include "trajroi/view/http.hpp"
#include "trajroi/view/websocket.hpp"

namespace trajroi::view {
namespace {

std::int64_t monotonic_ns() noexcept {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

constexpr std::size_t kMaxClientMessage = 4096;  // the page sends only short text

using Bytes = std::shared_ptr<const std::vector<std::uint8_t>>;

Bytes text_bytes(const std::string& s) {
  return std::make_shared<const std::vector<std::uint8_t>>(s.begin(), s.end());
}

// The order a client's queued frames go in: the small ones first.
constexpr FrameKind kOrder[] = {FrameKind::kStatus, FrameKind::kPose, FrameKind::kTrajectory, FrameKind::kSweep,
                                FrameKind::kRawPoints};

bool rate_capped(FrameKind k) noexcept {
  return k == FrameKind::kSweep || k == FrameKind::kRawPoints;
}

}  // namespace

struct ViewServer::Client {
  int fd = -1;
  std::string peer;
  bool websocket = false;
  bool close_after_write = false;
  bool closed = false;
  std::vector<std::uint8_t> in;
  // Being written: a header (a WebSocket frame's, or none) and a body, `sent` bytes of both.
  std::array<std::uint8_t, 10> header{};
  std::size_t header_size = 0;
  Bytes body;
  std::size_t sent = 0;
  bool counts_as_frame = false;
  std::vector<std::vector<std::uint8_t>> control;       // pongs and a close, before the next frame
  std::array<Bytes, kFrameKinds + 1> queued{};          // by FrameKind
  std::array<std::int64_t, kFrameKinds + 1> next_ns{};  // the rate cap, by FrameKind
  [[nodiscard]] bool writing() const noexcept { return body != nullptr; }
};

ViewServer::ViewServer(const ServerOptions& options, std::vector<Asset> assets)
    : options_(options), assets_(std::move(assets)) {
  const std::string where = options.address + ":" + std::to_string(options.port);
  sockaddr_in addr{};
  addr.sin_family = AF_INET;
  addr.sin_port = htons(options.port);
  if (inet_pton(AF_INET, options.address.c_str(), &addr.sin_addr) != 1)
    throw std::runtime_error("--listen " + where + ": not a numeric IPv4 address");
  listen_fd_ = ::socket(AF_INET, SOCK_STREAM | SOCK_NONBLOCK | SOCK_CLOEXEC, 0);
  if (listen_fd_ < 0) throw std::runtime_error("--listen " + where + ": socket: " + std::strerror(errno));
  const int one = 1;
  (void)setsockopt(listen_fd_, SOL_SOCKET, SO_REUSEADDR, &one, sizeof one);
  if (::bind(listen_fd_, reinterpret_cast<const sockaddr*>(&addr), sizeof addr) != 0 || ::listen(listen_fd_, 64) != 0) {
    const int e = errno;
    ::close(listen_fd_);
    std::string why = std::strerror(e);
    if (e == EADDRINUSE) why += " (another program listens there: choose another port with --listen)";
    if (e == EADDRNOTAVAIL) why += " (not an address of this host)";
    throw std::runtime_error("--listen " + where + ": " + why);
  }
  socklen_t len = sizeof addr;
  (void)getsockname(listen_fd_, reinterpret_cast<sockaddr*>(&addr), &len);
  port_ = ntohs(addr.sin_port);
}

ViewServer::~ViewServer() {
  for (const auto& c : clients_)
    if (c->fd >= 0) ::close(c->fd);
  if (listen_fd_ >= 0) ::close(listen_fd_);
}

std::size_t ViewServer::websocket_clients() const noexcept {
  std::size_t n = 0;
  for (const auto& c : clients_)
    n += c->websocket && !c->closed ? 1U : 0U;
  return n;
}

void ViewServer::event(const std::string& text) const {
  if (on_event_) on_event_(text);
}

void ViewServer::publish(FrameKind kind, std::shared_ptr<const std::vector<std::uint8_t>> frame) {
  const auto k = static_cast<std::size_t>(kind);
  latest_[k] = frame;
  for (const auto& c : clients_) {
    if (!c->websocket || c->closed) continue;
    if (c->queued[k]) ++counters_.frames_replaced;
    c->queued[k] = frame;
  }
}

bool ViewServer::poll(int extra_fd, int timeout_ms) {
  std::int64_t now = monotonic_ns();
  // Wake for a rate-capped sweep that may go before the timeout.
  for (const auto& c : clients_) {
    if (!c->websocket || c->writing()) continue;
    for (const FrameKind k : {FrameKind::kSweep, FrameKind::kRawPoints}) {
      if (!c->queued[static_cast<std::size_t>(k)]) continue;
      const auto wait_ms = static_cast<int>((c->next_ns[static_cast<std::size_t>(k)] - now + 999'999) / 1'000'000);
      timeout_ms = std::max(0, std::min(timeout_ms, wait_ms));
    }
  }
  // Start what may go now, so that POLLOUT is asked only with something to write.
  for (const auto& c : clients_)
    if (c->websocket && !c->writing()) (void)start_next(*c, now);
  std::vector<pollfd> fds;
  fds.push_back({listen_fd_, POLLIN, 0});
  fds.push_back({extra_fd, POLLIN, 0});
  for (const auto& c : clients_) {
    const bool out = c->writing() || !c->control.empty();
    fds.push_back({c->fd, static_cast<short>(POLLIN | (out ? POLLOUT : 0)), 0});
  }
  if (::poll(fds.data(), fds.size(), timeout_ms) < 0) return false;
  now = monotonic_ns();
  const std::size_t before = clients_.size();
  for (std::size_t i = 0; i < before; ++i) {
    Client& c = *clients_[i];
    const short r = fds[i + 2].revents;
    if ((r & (POLLIN | POLLHUP | POLLERR)) != 0) read_from(c, now);
    // Written at once: an answer just made (a page, the upgrade, a pong), or room again.
    if (!c.closed && ((r & POLLOUT) != 0 || c.writing() || !c.control.empty())) write_to(c, now);
  }
  for (const auto& c : clients_)
    if (!c->closed && c->websocket && !c->writing() && start_next(*c, now)) write_to(*c, now);
  std::erase_if(clients_, [](const std::unique_ptr<Client>& c) { return c->closed; });
  if ((fds[0].revents & POLLIN) != 0) accept_clients();
  return extra_fd >= 0 && (fds[1].revents & POLLIN) != 0;
}

void ViewServer::accept_clients() {
  for (;;) {
    sockaddr_in peer{};
    socklen_t len = sizeof peer;
    const int fd = ::accept4(listen_fd_, reinterpret_cast<sockaddr*>(&peer), &len, SOCK_NONBLOCK | SOCK_CLOEXEC);
    if (fd < 0) return;  // EAGAIN, or a connection that went before it was taken
    const int one = 1;
    (void)setsockopt(fd, IPPROTO_TCP, TCP_NODELAY, &one, sizeof one);
    auto c = std::make_unique<Client>();
    c->fd = fd;
    char text[INET_ADDRSTRLEN] = {};
    (void)inet_ntop(AF_INET, &peer.sin_addr, text, sizeof text);
    c->peer = std::string(text) + ":" + std::to_string(ntohs(peer.sin_port));
    clients_.push_back(std::move(c));
    ++counters_.connections;
  }
}

void ViewServer::close_client(Client& c, const std::string& why) {
  if (c.closed) return;
  if (c.websocket) {
    ++counters_.disconnects;
    if (!why.empty()) event("view client " + c.peer + " gone: " + why);
  }
  ::close(c.fd);
  c.fd = -1;
  c.closed = true;
}

void ViewServer::read_from(Client& c, std::int64_t now_ns) {
  std::uint8_t buf[16384];
  for (;;) {
    const ssize_t n = ::recv(c.fd, buf, sizeof buf, 0);
    if (n > 0) {
      c.in.insert(c.in.end(), buf, buf + n);
      if (c.in.size() > kMaxRequestHead + kMaxClientMessage) {
        ++counters_.bad_requests;
        close_client(c, "sent " + std::to_string(c.in.size()) + " bytes unasked");
        return;
      }
      continue;
    }
    if (n == 0) {
      close_client(c, c.websocket ? "closed the connection" : "");
      return;
    }
    if (errno == EINTR) continue;
    if (errno == EAGAIN || errno == EWOULDBLOCK) break;
    close_client(c, std::strerror(errno));
    return;
  }
  if (c.websocket) {
    handle_frames(c, now_ns);
  } else if (!c.writing()) {
    serve_http(c);
  }
}

void ViewServer::serve_http(Client& c) {
  const HttpParse p = parse_request(std::string_view(reinterpret_cast<const char*>(c.in.data()), c.in.size()));
  if (p.status == HttpParse::Status::kIncomplete) return;
  const auto answer = [&c](int status, std::string_view reason, std::string_view type, const Bytes& body) {
    std::string head = response_head(status, reason, type, body ? body->size() : 0, false);
    auto whole = std::make_shared<std::vector<std::uint8_t>>(head.begin(), head.end());
    if (body) whole->insert(whole->end(), body->begin(), body->end());
    c.body = std::move(whole);
    c.header_size = 0;
    c.sent = 0;
    c.counts_as_frame = false;
    c.close_after_write = true;
  };
  if (p.status == HttpParse::Status::kBad) {
    ++counters_.bad_requests;
    event("view: bad request from " + c.peer + ": " + p.error);
    answer(400, "Bad Request", "text/plain", text_bytes(p.error + "\n"));
    return;
  }
  const HttpRequest& r = p.request;
  c.in.erase(c.in.begin(), c.in.begin() + static_cast<std::ptrdiff_t>(p.consumed));
  if (r.path() == "/ws") {
    if (const std::string problem = websocket_upgrade_problem(r); !problem.empty()) {
      ++counters_.bad_requests;
      event("view: refused a WebSocket from " + c.peer + ": " + problem);
      answer(400, "Bad Request", "text/plain", text_bytes(problem + "\n"));
      return;
    }
    const std::string head = websocket_accept_head(r);
    c.body = text_bytes(head);
    c.header_size = 0;
    c.sent = 0;
    c.counts_as_frame = false;
    c.websocket = true;
    c.queued = latest_;
    ++counters_.websockets;
    event("view client " + c.peer + " connected");
    return;
  }
  if (r.method != "GET" && r.method != "HEAD") {
    answer(405, "Method Not Allowed", "text/plain", text_bytes("GET only\n"));
    return;
  }
  for (const Asset& a : assets_) {
    if (a.path == r.path()) {
      answer(200, "OK", a.content_type, r.method == "HEAD" ? nullptr : a.body);
      return;
    }
  }
  answer(404, "Not Found", "text/plain", text_bytes(std::string(r.path()) + " is not here\n"));
}

void ViewServer::handle_frames(Client& c, std::int64_t now_ns) {
  while (!c.closed) {
    ClientFrame f = parse_client_frame(c.in, kMaxClientMessage);
    if (f.status == ClientFrame::Status::kIncomplete) return;
    if (f.status == ClientFrame::Status::kError) {
      ++counters_.bad_requests;
      close_client(c, "WebSocket protocol error: " + f.error);
      return;
    }
    c.in.erase(c.in.begin(), c.in.begin() + static_cast<std::ptrdiff_t>(f.consumed));
    switch (f.opcode) {
      case Opcode::kText:
        if (on_text_ && f.fin) on_text_(std::string(f.payload.begin(), f.payload.end()), now_ns);
        break;
      case Opcode::kPing:
        c.control.push_back(server_frame(Opcode::kPong, f.payload));
        break;
      case Opcode::kClose:
        // Answered, then closed once written (RFC 6455 §5.5.1).
        c.control.push_back(
            server_frame(Opcode::kClose, std::span(f.payload).first(std::min<std::size_t>(2, f.payload.size()))));
        c.close_after_write = true;
        for (auto& q : c.queued)
          q.reset();
        break;
      default:
        break;  // binary, continuation, pong: nothing the page sends
    }
  }
}

bool ViewServer::start_next(Client& c, std::int64_t now_ns) {
  if (c.closed || c.writing() || c.close_after_write) return false;
  for (const FrameKind k : kOrder) {
    Bytes& q = c.queued[static_cast<std::size_t>(k)];
    if (!q) continue;
    if (rate_capped(k)) {
      std::int64_t& next = c.next_ns[static_cast<std::size_t>(k)];
      if (now_ns < next) continue;
      // Spaced from when the previous one was due, not sent: a sensor at the cap's own rate
      // whose sweeps come a little early or late is not pushed a period behind (its latency
      // grew by its jitter at every sweep, to a whole period, with next = now + period). A
      // page back after a pause starts afresh.
      const auto period = static_cast<std::int64_t>(1e9 / options_.max_sweep_rate_hz);
      next = next + period < now_ns ? now_ns + period : next + period;
    }
    c.header_size = server_frame_header(Opcode::kBinary, q->size(), c.header);
    c.body = std::move(q);
    q.reset();
    c.sent = 0;
    c.counts_as_frame = true;
    return true;
  }
  return false;
}

void ViewServer::write_to(Client& c, std::int64_t now_ns) {
  for (;;) {
    // Control frames go between whole frames, never inside one.
    if (!c.writing() && !c.control.empty()) {
      std::vector<std::uint8_t> f = std::move(c.control.front());
      c.control.erase(c.control.begin());
      c.header_size = 0;
      c.body = std::make_shared<const std::vector<std::uint8_t>>(std::move(f));
      c.sent = 0;
      c.counts_as_frame = false;
    }
    if (!c.writing() && !(c.websocket && start_next(c, now_ns))) {
      if (c.close_after_write) close_client(c, "");
      return;
    }
    iovec iov[2];
    int count = 0;
    if (c.sent < c.header_size) iov[count++] = {c.header.data() + c.sent, c.header_size - c.sent};
    const std::size_t body_from = c.sent > c.header_size ? c.sent - c.header_size : 0;
    iov[count++] = {const_cast<std::uint8_t*>(c.body->data()) + body_from, c.body->size() - body_from};
    msghdr msg{};
    msg.msg_iov = iov;
    msg.msg_iovlen = static_cast<std::size_t>(count);
    const ssize_t n = ::sendmsg(c.fd, &msg, MSG_NOSIGNAL);
    if (n < 0) {
      if (errno == EINTR) continue;
      if (errno == EAGAIN || errno == EWOULDBLOCK) return;
      close_client(c, std::strerror(errno));  // reset mid-frame: this client only
      return;
    }
    c.sent += static_cast<std::size_t>(n);
    counters_.bytes_sent += static_cast<std::uint64_t>(n);
    if (c.sent < c.header_size + c.body->size()) return;  // the socket is full: at POLLOUT
    if (c.counts_as_frame) ++counters_.frames_sent;
    c.body.reset();
    c.sent = 0;
    c.header_size = 0;
  }
}

}  // namespace trajroi::view
