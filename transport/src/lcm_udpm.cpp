#include "trajroi/transport/lcm_udpm.hpp"

#include <algorithm>
#include <cstring>

namespace trajroi::transport::udpm {
namespace {

constexpr std::size_t kMaxSenders = 16;              // partial messages held at once
constexpr std::size_t kMaxPartialBytes = 16u << 20;  // and their bytes (liblcm's MAX_FRAG_BUF_TOTAL_SIZE)

void put_u32(std::uint8_t* p, std::uint32_t v) noexcept {
  p[0] = static_cast<std::uint8_t>(v >> 24);
  p[1] = static_cast<std::uint8_t>(v >> 16);
  p[2] = static_cast<std::uint8_t>(v >> 8);
  p[3] = static_cast<std::uint8_t>(v);
}

void put_u16(std::uint8_t* p, std::uint16_t v) noexcept {
  p[0] = static_cast<std::uint8_t>(v >> 8);
  p[1] = static_cast<std::uint8_t>(v);
}

std::uint32_t get_u32(const std::uint8_t* p) noexcept {
  return static_cast<std::uint32_t>(p[0]) << 24 | static_cast<std::uint32_t>(p[1]) << 16 |
         static_cast<std::uint32_t>(p[2]) << 8 | static_cast<std::uint32_t>(p[3]);
}

std::uint16_t get_u16(const std::uint8_t* p) noexcept {
  return static_cast<std::uint16_t>(p[0] << 8 | p[1]);
}

// The NUL-terminated channel at the start of `bytes` (without its NUL); false when there is no
// NUL within the longest channel, or the channel is empty.
bool read_channel(std::span<const std::uint8_t> bytes, std::string_view& channel) noexcept {
  const std::size_t limit = std::min(bytes.size(), kMaxChannelBytes + 1);
  const auto* end = static_cast<const std::uint8_t*>(std::memchr(bytes.data(), 0, limit));
  if (end == nullptr || end == bytes.data()) return false;
  channel = std::string_view(reinterpret_cast<const char*>(bytes.data()), static_cast<std::size_t>(end - bytes.data()));
  return true;
}

}  // namespace

bool split_message(const std::string& channel, std::span<const std::uint8_t> payload, std::uint32_t seqno,
                   std::vector<Datagram>& out) {
  out.clear();
  if (channel.empty() || channel.size() > kMaxChannelBytes) return false;
  const std::span<const std::uint8_t> name(reinterpret_cast<const std::uint8_t*>(channel.c_str()), channel.size() + 1);
  const std::size_t total = name.size() + payload.size();
  if (total <= kShortMessageMax) {
    Datagram& d = out.emplace_back();
    put_u32(d.header.data(), kMagicShort);
    put_u32(d.header.data() + 4, seqno);
    d.header_bytes = kShortHeaderBytes;
    d.channel = name;
    d.payload = payload;
    return true;
  }
  const std::size_t fragments = (total + kFragmentMax - 1) / kFragmentMax;
  if (fragments > 0xFFFF) return false;
  out.reserve(fragments);
  std::size_t offset = 0;
  for (std::size_t i = 0; i < fragments; ++i) {
    Datagram& d = out.emplace_back();
    const std::size_t room = i == 0 ? kFragmentMax - name.size() : kFragmentMax;
    const std::size_t length = std::min(room, payload.size() - offset);
    put_u32(d.header.data(), kMagicLong);
    put_u32(d.header.data() + 4, seqno);
    put_u32(d.header.data() + 8, static_cast<std::uint32_t>(payload.size()));
    put_u32(d.header.data() + 12, static_cast<std::uint32_t>(offset));
    put_u16(d.header.data() + 16, static_cast<std::uint16_t>(i));
    put_u16(d.header.data() + 18, static_cast<std::uint16_t>(fragments));
    d.header_bytes = kLongHeaderBytes;
    if (i == 0) d.channel = name;
    d.payload = payload.subspan(offset, length);
    offset += length;
  }
  return true;
}

Reassembler::Reassembler(std::vector<std::string> channels, std::size_t max_message_bytes)
    : channels_(std::move(channels)), max_message_bytes_(max_message_bytes) {
  partials_.reserve(kMaxSenders);
}

bool Reassembler::wanted(std::string_view channel, std::size_t& index) const noexcept {
  for (std::size_t i = 0; i < channels_.size(); ++i) {
    if (channels_[i] == channel) {
      index = i;
      return true;
    }
  }
  return false;
}

Reassembler::Partial* Reassembler::find(std::uint64_t sender) noexcept {
  for (Partial& p : partials_)
    if (p.sender == sender) return &p;
  return nullptr;
}

Reassembler::Partial& Reassembler::make_room(std::size_t bytes) {
  // Bounded as liblcm bounds its fragment buffers: a few senders' messages, 16 MiB in all; the
  // least recently fed partial messages go first.
  const auto held = [this] {
    std::size_t total = 0;
    for (const Partial& p : partials_)
      total += p.data.size();
    return total;
  };
  while (!partials_.empty() && (partials_.size() == kMaxSenders || held() + bytes > kMaxPartialBytes)) {
    ++counters_.abandoned;
    partials_.erase(std::min_element(partials_.begin(), partials_.end(),
                                     [](const Partial& a, const Partial& b) { return a.last_use < b.last_use; }));
  }
  return partials_.emplace_back();  // reserved: no reallocation
}

Reassembler::Verdict Reassembler::accept(std::uint64_t sender, std::span<const std::uint8_t> datagram, Message& out) {
  const auto malformed = [this] {
    ++counters_.malformed;
    return Verdict::kMalformed;
  };
  if (datagram.size() < kShortHeaderBytes) return malformed();
  const std::uint32_t magic = get_u32(datagram.data());
  if (magic == kMagicShort) {
    std::string_view channel;
    if (!read_channel(datagram.subspan(kShortHeaderBytes), channel)) return malformed();
    std::size_t index = 0;
    if (!wanted(channel, index)) return Verdict::kOtherChannel;
    out.channel = channels_[index];
    out.payload = datagram.subspan(kShortHeaderBytes + channel.size() + 1);
    ++counters_.messages;
    return Verdict::kMessage;
  }
  if (magic != kMagicLong || datagram.size() < kLongHeaderBytes) return malformed();
  const std::uint32_t seqno = get_u32(datagram.data() + 4);
  const std::uint32_t size = get_u32(datagram.data() + 8);
  const std::uint32_t offset = get_u32(datagram.data() + 12);
  const std::uint16_t number = get_u16(datagram.data() + 16);
  const std::uint16_t fragments = get_u16(datagram.data() + 18);
  std::span<const std::uint8_t> body = datagram.subspan(kLongHeaderBytes);
  if (fragments == 0 || number >= fragments) return malformed();
  Partial* partial = find(sender);
  if (partial != nullptr && partial->seqno != seqno) {
    // The sender moved on: its unfinished message will not complete.
    ++counters_.abandoned;
    partials_.erase(partials_.begin() + (partial - partials_.data()));
    partial = nullptr;
  }
  if (number == 0) {
    std::string_view channel;
    if (offset != 0 || !read_channel(body, channel)) return malformed();
    body = body.subspan(channel.size() + 1);
    std::size_t index = 0;
    if (!wanted(channel, index)) return Verdict::kOtherChannel;
    if (size > max_message_bytes_ || body.size() > size) return malformed();
    if (partial == nullptr) {
      partial = &make_room(size);
      partial->sender = sender;
      partial->seqno = seqno;
      partial->fragments = fragments;
      partial->remaining = fragments;
      partial->channel = index;
      partial->data.assign(size, 0);
      partial->received.assign(fragments, false);
    }
  } else if (partial == nullptr) {
    // Without its first fragment a message's channel is unknown: another channel's, or one
    // whose start was lost (liblcm drops these too).
    return Verdict::kOtherChannel;
  }
  if (fragments != partial->fragments || size != partial->data.size() || offset > size || body.size() > size - offset) {
    return malformed();
  }
  partial->last_use = ++uses_;
  if (!partial->received[number]) {
    partial->received[number] = true;
    --partial->remaining;
    std::copy(body.begin(), body.end(), partial->data.begin() + offset);
  }
  if (partial->remaining > 0) return Verdict::kPending;
  whole_.swap(partial->data);
  out.channel = channels_[partial->channel];
  out.payload = whole_;
  partials_.erase(partials_.begin() + (partial - partials_.data()));
  ++counters_.messages;
  return Verdict::kMessage;
}

}  // namespace trajroi::transport::udpm
