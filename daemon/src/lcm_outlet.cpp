#include <lcm/lcm-cpp.hpp>
#include <stdexcept>

#include "outlet.hpp"
#include "trajroi/transport/lcm_subscribe.hpp"

namespace trajroi::daemon {

LcmOutlet::LcmOutlet(const std::string& url) : lcm_(std::make_unique<lcm::LCM>(url)) {
  if (!lcm_->good()) throw std::runtime_error("LCM: cannot open '" + url + "'");
}

LcmOutlet::~LcmOutlet() = default;

void LcmOutlet::publish(const std::string& channel, std::span<const std::uint8_t> bytes) {
  (void)lcm_->publish(channel, bytes.data(), static_cast<unsigned int>(bytes.size()));
}

bool LcmOutlet::subscribe(const std::string& channel, Handler handler) {
  handler_ = std::move(handler);
  return transport::subscribe_raw<&LcmOutlet::on_message>(*lcm_, channel, this) != nullptr;
}

int LcmOutlet::incoming_fd() const noexcept {
  return lcm_->getFileno();
}

void LcmOutlet::handle_incoming() {
  (void)lcm_->handleTimeout(0);
}

void LcmOutlet::on_message(const lcm::ReceiveBuffer* buffer, const std::string& channel) {
  if (handler_)
    handler_(std::span<const std::uint8_t>(static_cast<const std::uint8_t*>(buffer->data), buffer->data_size), channel);
}

}  // namespace trajroi::daemon
