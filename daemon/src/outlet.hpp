#pragma once

// Where the publisher's messages go and trajectory messages come from: LCM in the daemon
// (UdpmOutlet for udpm:// URLs, LcmOutlet through liblcm for the other providers), a recording
// fake in the unit tests. Messages travel encoded (LCM wire bytes).
#include <cstdint>
#include <functional>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "log.hpp"
#include "trajroi/daemon/config.hpp"
#include "trajroi/transport/lcm_udpm.hpp"
#include "udpm_receiver.hpp"

namespace lcm {
class LCM;
class ReceiveBuffer;
}  // namespace lcm

namespace trajroi::daemon {

class Outlet {
 public:
  using Handler = std::function<void(std::span<const std::uint8_t> bytes, const std::string& channel)>;
  virtual ~Outlet() = default;
  virtual void publish(const std::string& channel, std::span<const std::uint8_t> bytes) = 0;
  // Incoming messages on `channel` go to `handler`, from handle_incoming() only. False when
  // the transport cannot receive (udpm: this process's own multicast does not come back).
  virtual bool subscribe(const std::string& channel, Handler handler) = 0;
  // A descriptor readable when handle_incoming() has something to do (-1: never).
  [[nodiscard]] virtual int incoming_fd() const noexcept = 0;
  virtual void handle_incoming() = 0;
};

// The outlet for a URL: UdpmOutlet for udpm://, LcmOutlet otherwise. Throws
// std::runtime_error naming the URL when it cannot be opened.
std::unique_ptr<Outlet> make_outlet(const std::string& url);

// LCM over UDP multicast with the daemon's own sockets, in liblcm's wire format (lcm-spy,
// lcm-logger and every liblcm subscriber read it; liblcm publishers are read by it). Its
// receive socket (UdpmReceiver, opened by subscribe()) carries a kernel filter that drops the
// datagrams of its own send socket: through liblcm, the daemon read back every cloud it
// published (an as-fast corridor replay: 20 ms of a thread's CPU, 15 % of the process's with
// the dearer sends; docs/lcm.md, "LCM without reading itself back").
class UdpmOutlet final : public Outlet {
 public:
  // Opens the send socket and probes (up to 0.5 s) that its multicast comes back. Throws
  // std::runtime_error naming the URL when the socket cannot be opened.
  UdpmOutlet(const std::string& url, const LcmGroup& group);
  ~UdpmOutlet() override;
  UdpmOutlet(const UdpmOutlet&) = delete;
  UdpmOutlet& operator=(const UdpmOutlet&) = delete;
  void publish(const std::string& channel, std::span<const std::uint8_t> bytes) override;
  bool subscribe(const std::string& channel, Handler handler) override;
  [[nodiscard]] int incoming_fd() const noexcept override;
  void handle_incoming() override;
  // The source address and port of this outlet's datagrams as receivers see them, which the
  // process's receive sockets drop (nullopt: its multicast does not come back to this host).
  [[nodiscard]] const std::optional<sockaddr_in>& own_source() const noexcept { return own_source_; }
  // Whether the subscription's socket has the kernel drop this outlet's own datagrams.
  [[nodiscard]] bool filters_own() const noexcept { return receiver_ && receiver_->filters(); }

 private:
  std::string url_;
  LcmGroup group_;
  sockaddr_in destination_;  // the group and its port
  int send_fd_ = -1;
  std::optional<sockaddr_in> own_source_;
  std::uint32_t seqno_ = 0;
  std::vector<transport::udpm::Datagram> datagrams_;
  std::unique_ptr<UdpmReceiver> receiver_;
  Handler handler_;
  log::RateLimited send_limit_{10.0};
};

// Through liblcm: the memq://, file:// and tcpq:// providers.
class LcmOutlet final : public Outlet {
 public:
  // Throws std::runtime_error naming the URL when LCM cannot open it.
  explicit LcmOutlet(const std::string& url);
  ~LcmOutlet() override;
  void publish(const std::string& channel, std::span<const std::uint8_t> bytes) override;
  bool subscribe(const std::string& channel, Handler handler) override;
  [[nodiscard]] int incoming_fd() const noexcept override;
  void handle_incoming() override;

 private:
  void on_message(const lcm::ReceiveBuffer* buffer, const std::string& channel);
  std::unique_ptr<lcm::LCM> lcm_;
  Handler handler_;
};

}  // namespace trajroi::daemon
