#pragma once

// VectorNav binary output framing (VN-100 ICD, "Binary output"): sync 0xFA, a group byte
// (bit i = group i+1), one uint16 LE field mask per active group in group order, the payload
// (every selected field, in group then bit order, little-endian), and CRC-16/CCITT (poly
// 0x1021, init 0, big-endian on the wire) over everything after the sync, so the CRC of the
// bytes after the sync including the CRC is 0.
//
// The payload length is not sent: it is computed from the field-size tables of the groups a
// VN-100 can output (1 Common, 2 Time, 3 IMU, 5 Attitude). A frame naming any other group,
// a reserved field or an extended mask (bit 15) cannot be sized; it is skipped and counted
// (FramerCounters::unsizable).
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

#include "trajroi/framing/checksums.hpp"
#include "trajroi/framing/stream_framer.hpp"

namespace trajroi::vn100 {

inline constexpr std::uint8_t kSync = 0xFA;
inline constexpr std::size_t kCrcBytes = 2;

enum class Group : std::uint8_t { kCommon = 0, kTime = 1, kImu = 2, kGps = 3, kAttitude = 4, kIns = 5, kGps2 = 6 };

// Size in bytes of field `bit` of `group`, or 0 when the VN-100 has no such field.
[[nodiscard]] std::size_t field_size(Group group, unsigned bit) noexcept;

// Bytes from the group byte to the last CRC byte, CRC-16/CCITT with init 0.
using framing::crc16_ccitt;  // trajroi/framing/checksums.hpp

// The layout a header describes.
struct Layout {
  std::uint8_t groups = 0;
  std::array<std::uint16_t, 8> fields{};  // per group index, 0 when the group is absent
  std::size_t header_bytes = 0;           // sync + group byte + masks
  std::size_t payload_bytes = 0;
  [[nodiscard]] std::size_t frame_bytes() const noexcept { return header_bytes + payload_bytes + kCrcBytes; }
};

// The layout of the header at the start of `frame` (sync included), or nothing when the
// header is incomplete or cannot be sized.
[[nodiscard]] std::optional<Layout> parse_layout(std::span<const std::uint8_t> frame) noexcept;

// A whole frame: sync, group byte, the masks of the groups present in `group_fields` (index =
// group − 1), `payload` and the CRC. Throws std::invalid_argument when the payload size does
// not match the layout the masks describe or the layout cannot be sized.
[[nodiscard]] std::vector<std::uint8_t> encode_frame(const std::array<std::uint16_t, 8>& group_fields,
                                                     std::span<const std::uint8_t> payload);

class Protocol {
 public:
  static constexpr std::uint8_t kSync = vn100::kSync;
  // Every VN-100 field selected at once fits in 600 bytes.
  [[nodiscard]] std::size_t max_frame_bytes() const noexcept { return 600; }
  [[nodiscard]] framing::Verdict inspect(std::span<const std::uint8_t> bytes) const noexcept;
  [[nodiscard]] bool checksum_ok(std::span<const std::uint8_t> frame) const noexcept;
};

using Framer = framing::StreamFramer<Protocol>;

}  // namespace trajroi::vn100
