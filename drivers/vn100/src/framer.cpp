#include "trajroi/vn100/framer.hpp"

#include <bit>
#include <stdexcept>
#include <string>

#include "trajroi/framing/little_endian.hpp"

namespace trajroi::vn100 {

namespace {

// Field sizes in bytes by bit (VN-100 ICD, binary output groups). 0 = reserved / not a
// VN-100 field.
constexpr std::array<std::uint8_t, 16> kCommon{8, 8, 8, 12, 16, 12, 24, 12, 12, 24, 20, 28, 2, 4, 8, 0};
constexpr std::array<std::uint8_t, 16> kTime{8, 8, 8, 2, 8, 8, 8, 4, 4, 1, 0, 0, 0, 0, 0, 0};
constexpr std::array<std::uint8_t, 16> kImu{2, 12, 12, 12, 4, 4, 16, 12, 12, 12, 12, 2, 0, 0, 0, 0};
constexpr std::array<std::uint8_t, 16> kAttitude{2, 12, 16, 36, 12, 12, 12, 12, 12, 0, 0, 0, 0, 0, 0, 0};

}  // namespace

std::size_t field_size(Group group, unsigned bit) noexcept {
  if (bit >= 16) return 0;
  switch (group) {
    case Group::kCommon:
      return kCommon[bit];
    case Group::kTime:
      return kTime[bit];
    case Group::kImu:
      return kImu[bit];
    case Group::kAttitude:
      return kAttitude[bit];
    default:
      return 0;  // GPS, INS, GPS2: VN-200/300 only
  }
}

std::optional<Layout> parse_layout(std::span<const std::uint8_t> frame) noexcept {
  if (frame.size() < 2 || frame[0] != kSync || frame[1] == 0) return std::nullopt;
  Layout layout;
  layout.groups = frame[1];
  layout.header_bytes = 2 + 2 * static_cast<std::size_t>(std::popcount(layout.groups));
  if (frame.size() < layout.header_bytes) return std::nullopt;
  std::size_t at = 2;
  for (unsigned g = 0; g < 8; ++g) {
    if ((layout.groups & (1U << g)) == 0) continue;
    const std::uint16_t mask = framing::le_u16(frame, at);
    at += 2;
    if (mask == 0) return std::nullopt;
    for (unsigned bit = 0; bit < 16; ++bit) {
      if ((mask & (1U << bit)) == 0) continue;
      const std::size_t size = field_size(static_cast<Group>(g), bit);
      if (size == 0) return std::nullopt;
      layout.payload_bytes += size;
    }
    layout.fields[g] = mask;
  }
  return layout;
}

std::vector<std::uint8_t> encode_frame(const std::array<std::uint16_t, 8>& group_fields,
                                       std::span<const std::uint8_t> payload) {
  std::vector<std::uint8_t> frame{kSync, 0};
  for (std::size_t g = 0; g < group_fields.size(); ++g) {
    if (group_fields[g] == 0) continue;
    frame[1] = static_cast<std::uint8_t>(frame[1] | (1U << g));
    framing::put_le_u16(frame, group_fields[g]);
  }
  const std::optional<Layout> layout = parse_layout(frame);
  if (!layout) throw std::invalid_argument("VN-100 frame: field selection cannot be sized");
  if (layout->payload_bytes != payload.size()) {
    throw std::invalid_argument("VN-100 frame: payload of " + std::to_string(payload.size()) + " bytes, layout needs " +
                                std::to_string(layout->payload_bytes));
  }
  for (const std::uint8_t b : payload)
    frame.push_back(b);
  const std::uint16_t crc = crc16_ccitt(std::span<const std::uint8_t>(frame).subspan(1));
  frame.push_back(static_cast<std::uint8_t>(crc >> 8));
  frame.push_back(static_cast<std::uint8_t>(crc & 0xFF));
  return frame;
}

framing::Verdict Protocol::inspect(std::span<const std::uint8_t> bytes) const noexcept {
  using Kind = framing::Verdict::Kind;
  if (bytes.size() < 2) return {Kind::kNeedMore, 2};
  if (bytes[1] == 0) return {Kind::kNotSync, 0};
  const std::size_t header = 2 + 2 * static_cast<std::size_t>(std::popcount(bytes[1]));
  if (bytes.size() < header) return {Kind::kNeedMore, header};
  const std::optional<Layout> layout = parse_layout(bytes);
  if (!layout) return {Kind::kUnsizable, 0};
  return {Kind::kFrame, layout->frame_bytes()};
}

bool Protocol::checksum_ok(std::span<const std::uint8_t> frame) const noexcept {
  return crc16_ccitt(frame.subspan(1)) == 0;
}

}  // namespace trajroi::vn100
