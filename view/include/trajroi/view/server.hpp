#pragma once

// The view's HTTP and WebSocket server: one thread, non-blocking sockets, poll(). It serves the
// page's files (assets) and, on /ws, streams the frames it is given (frames.hpp) to every
// connected page: each client holds at most one frame of each kind queued beside the one being
// sent, the newest replacing an older one, so a slow client skips sweeps and never holds up the
// others or the caller; sweeps go to a client at most max_sweep_rate_hz. A client that goes away
// mid-frame is closed alone.
#include <netinet/in.h>

#include <array>
#include <cstdint>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include "trajroi/view/frames.hpp"

namespace trajroi::view {

struct Asset {
  std::string path;  // "/", "/view.js"
  std::string content_type;
  std::shared_ptr<const std::vector<std::uint8_t>> body;
};

struct ServerOptions {
  std::string address = "127.0.0.1";  // numeric IPv4 (0.0.0.0: every interface)
  std::uint16_t port = 8090;          // 0: any free port (port() tells)
  double max_sweep_rate_hz = 10.0;    // per client: sweeps (and raw points) at most this often
};

struct ServerCounters {
  std::uint64_t connections = 0;      // TCP connections accepted
  std::uint64_t websockets = 0;       // upgraded to WebSocket
  std::uint64_t disconnects = 0;      // WebSocket clients gone (closed, reset, protocol error)
  std::uint64_t bad_requests = 0;     // malformed HTTP, bad upgrade, oversize or bad frames
  std::uint64_t frames_sent = 0;      // whole frames written to clients
  std::uint64_t frames_replaced = 0;  // a queued frame replaced by a newer one before it went
  std::uint64_t bytes_sent = 0;
};

class ViewServer {
 public:
  // Binds and listens. Throws std::runtime_error naming the address and why (in use, not an
  // address of this host, not numeric).
  ViewServer(const ServerOptions& options, std::vector<Asset> assets);
  ~ViewServer();
  ViewServer(const ViewServer&) = delete;
  ViewServer& operator=(const ViewServer&) = delete;

  [[nodiscard]] std::uint16_t port() const noexcept { return port_; }
  // Queues `frame` for every WebSocket client, replacing one of its kind still queued. The
  // newest of each kind also goes to a client as it connects.
  void publish(FrameKind kind, std::shared_ptr<const std::vector<std::uint8_t>> frame);
  // Waits up to `timeout_ms` for the sockets (and `extra_fd`, when ≥ 0), then accepts, reads
  // and writes what is ready. True when `extra_fd` is readable.
  bool poll(int extra_fd, int timeout_ms);
  // A page's text message ("drawn 1234": it drew sweep 1234), with CLOCK_MONOTONIC ns at receipt.
  void on_text(std::function<void(const std::string& text, std::int64_t received_ns)> handler) {
    on_text_ = std::move(handler);
  }
  // Something to say in the log (a client's protocol error, a refused request).
  void on_event(std::function<void(const std::string& text)> handler) { on_event_ = std::move(handler); }

  [[nodiscard]] std::size_t websocket_clients() const noexcept;
  [[nodiscard]] const ServerCounters& counters() const noexcept { return counters_; }

 private:
  struct Client;
  void accept_clients();
  void read_from(Client& c, std::int64_t now_ns);
  void write_to(Client& c, std::int64_t now_ns);
  void serve_http(Client& c);
  void handle_frames(Client& c, std::int64_t now_ns);
  // The next frame for a WebSocket client, if one may go now.
  bool start_next(Client& c, std::int64_t now_ns);
  void close_client(Client& c, const std::string& why);
  void event(const std::string& text) const;

  ServerOptions options_;
  std::vector<Asset> assets_;
  int listen_fd_ = -1;
  std::uint16_t port_ = 0;
  std::vector<std::unique_ptr<Client>> clients_;
  std::array<std::shared_ptr<const std::vector<std::uint8_t>>, kFrameKinds + 1> latest_{};
  std::function<void(const std::string&, std::int64_t)> on_text_;
  std::function<void(const std::string&)> on_event_;
  ServerCounters counters_;
};

}  // namespace trajroi::view
