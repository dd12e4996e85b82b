#pragma once

// Where the publisher's messages go and trajectory messages come from: LCM in the daemon
// (LcmOutlet), a recording fake in the unit tests. Messages travel encoded (LCM wire bytes).
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>

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
  // the transport cannot receive (LCM's self test: its own multicast does not come back).
  virtual bool subscribe(const std::string& channel, Handler handler) = 0;
  // A descriptor readable when handle_incoming() has something to do (-1: never).
  [[nodiscard]] virtual int incoming_fd() const noexcept = 0;
  virtual void handle_incoming() = 0;
};

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
  bool receives_ = true;  // false: its own multicast does not come back (nothing subscribed)
  Handler handler_;
};

}  // namespace trajroi::daemon
