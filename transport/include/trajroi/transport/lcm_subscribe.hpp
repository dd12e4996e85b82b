// Subscribing a member function to an LCM channel.
//
// liblcm's own `LCM::subscribe(channel, &Class::method, object)` stores a pointer to member in
// the subscription and calls it through that pointer. GCC 12 built with
// -fsanitize=undefined (its vptr check) miscompiles that call: the handler receives a
// garbage object pointer and the process crashes on the first message (reproducible with a
// ten-line program). These helpers bind the method at compile time instead and go through
// `subscribeFunction`, which has no pointer to member, so sanitizer builds and release
// builds run the same code. Include together with trajroi::lcmtypes (liblcm).
#pragma once

#include <lcm/lcm-cpp.hpp>
#include <string>

namespace trajroi::transport {

namespace detail {
template <typename T>
struct MemberTraits;

template <typename Owner, typename Message>
struct MemberTraits<void (Owner::*)(const lcm::ReceiveBuffer*, const std::string&, const Message*)> {
  using owner = Owner;
  using message = Message;
};
}  // namespace detail

/// Decoded messages: `void Owner::method(const lcm::ReceiveBuffer*, const std::string&, const M*)`.
template <auto Method>
lcm::Subscription* subscribe(lcm::LCM& lcm, const std::string& channel,
                             typename detail::MemberTraits<decltype(Method)>::owner* owner) {
  using Owner = typename detail::MemberTraits<decltype(Method)>::owner;
  using Message = typename detail::MemberTraits<decltype(Method)>::message;
  return lcm.subscribeFunction(
      channel,
      +[](const lcm::ReceiveBuffer* buffer, const std::string& name, const Message* message, Owner* self) {
        (self->*Method)(buffer, name, message);
      },
      owner);
}

/// Raw bytes: `void Owner::method(const lcm::ReceiveBuffer*, const std::string&)`.
template <auto Method, typename Owner>
lcm::Subscription* subscribe_raw(lcm::LCM& lcm, const std::string& channel, Owner* owner) {
  return lcm.subscribeFunction(
      channel,
      +[](const lcm::ReceiveBuffer* buffer, const std::string& name, Owner* self) { (self->*Method)(buffer, name); },
      owner);
}

}  // namespace trajroi::transport
