#pragma once

// LCM's UDP multicast wire format ("LCM UDP Multicast Protocol Description", lcm-proj), as
// liblcm 1.3 on Linux writes it: a message whose channel, NUL and payload fit in 65 499 bytes
// goes in one "LC02" datagram, a longer one in "LC03" fragments of 65 487 bytes (the first
// carrying the channel). Bytes in, values out: the sockets are the daemon's (UdpmOutlet).
//
// trajroid sends and receives with its own sockets, in this format, so that it can keep its
// own datagrams out of its receive socket (a kernel filter on its sender's address): through
// liblcm, whose receive socket it cannot reach, it read back every cloud it published.
#include <array>
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace trajroi::transport::udpm {

inline constexpr std::uint32_t kMagicShort = 0x4c433032;  // "LC02"
inline constexpr std::uint32_t kMagicLong = 0x4c433033;   // "LC03"
inline constexpr std::size_t kShortHeaderBytes = 8;       // magic, sequence number
inline constexpr std::size_t kLongHeaderBytes = 20;       // + size, offset, fragment number and count
inline constexpr std::size_t kShortMessageMax = 65499;    // channel + NUL + payload in one LC02 datagram
inline constexpr std::size_t kFragmentMax = 65487;        // channel (first) + payload per LC03 datagram
inline constexpr std::size_t kMaxChannelBytes = 63;       // LCM_MAX_CHANNEL_NAME_LENGTH
inline constexpr std::size_t kMaxDatagramBytes = kLongHeaderBytes + kFragmentMax;  // 65 507, UDP's limit

// One datagram of a message: its header, then part of the channel (with its NUL) and of the
// payload, both pointing into the caller's message.
struct Datagram {
  std::array<std::uint8_t, kLongHeaderBytes> header{};
  std::size_t header_bytes = 0;
  std::span<const std::uint8_t> channel;  // empty after the first fragment
  std::span<const std::uint8_t> payload;
};

// The datagrams of `payload` on `channel` with sequence number `seqno`, into `out` (cleared).
// False, and `out` empty, when the channel is empty or longer than 63 bytes or the message
// needs more than 65 535 fragments. `channel` must outlive the datagrams (its NUL is sent).
bool split_message(const std::string& channel, std::span<const std::uint8_t> payload, std::uint32_t seqno,
                   std::vector<Datagram>& out);

// Messages from datagrams, for a set of channels (exact names): fragments of other channels'
// messages are dropped at their first fragment, without storage. One partial message per
// sender, as liblcm does: a sender's new message abandons its unfinished one (counted); at
// most 16 partial messages and 16 MiB of them (the least recently fed go first, counted).
class Reassembler {
 public:
  struct Message {
    std::string_view channel;
    std::span<const std::uint8_t> payload;  // valid until the next accept()
  };
  enum class Verdict {
    kMessage,  // `out` holds a whole message on a wanted channel
    kPending,  // a fragment of a wanted message that is not whole yet
    kOtherChannel,
    kMalformed,  // not LCM, or inconsistent (counted in malformed())
  };
  struct Counters {
    std::uint64_t messages = 0;
    std::uint64_t malformed = 0;
    std::uint64_t abandoned = 0;  // partial messages a sender's next one (or a full table) replaced
  };

  // `max_message_bytes`: longer messages are malformed for this reader (its memory bound).
  explicit Reassembler(std::vector<std::string> channels, std::size_t max_message_bytes = 16u << 20);

  // `sender`: the datagram's source (address and port), any key that tells senders apart.
  Verdict accept(std::uint64_t sender, std::span<const std::uint8_t> datagram, Message& out);
  [[nodiscard]] const Counters& counters() const noexcept { return counters_; }

 private:
  struct Partial {
    std::uint64_t sender = 0;
    std::uint32_t seqno = 0;
    std::uint16_t fragments = 0;
    std::uint16_t remaining = 0;
    std::size_t channel = 0;  // index into channels_
    std::vector<std::uint8_t> data;
    std::vector<bool> received;
    std::uint64_t last_use = 0;
  };
  [[nodiscard]] bool wanted(std::string_view channel, std::size_t& index) const noexcept;
  Partial* find(std::uint64_t sender) noexcept;
  Partial& make_room(std::size_t bytes);

  std::vector<std::string> channels_;
  std::size_t max_message_bytes_;
  std::vector<Partial> partials_;  // reserved for all of them
  std::vector<std::uint8_t> whole_;
  std::uint64_t uses_ = 0;
  Counters counters_;
};

}  // namespace trajroi::transport::udpm
