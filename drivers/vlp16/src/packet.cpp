#include "trajroi/vlp16/packet.hpp"

namespace trajroi::vlp16 {

std::string_view to_string(PacketError error) noexcept {
  switch (error) {
    case PacketError::kNone:
      return "none";
    case PacketError::kWrongSize:
      return "wrong_size";
    case PacketError::kBadBlockFlag:
      return "bad_block_flag";
    case PacketError::kAzimuthOutOfRange:
      return "azimuth_out_of_range";
    case PacketError::kUnknownReturnMode:
      return "unknown_return_mode";
    case PacketError::kUnsupportedProduct:
      return "unsupported_product";
  }
  return "unknown";
}

std::string_view product_name(std::uint8_t id) noexcept {
  switch (id) {
    case 0x21:
      return "HDL-32E";
    case 0x22:
      return "VLP-16";
    case 0x24:
      return "Puck Hi-Res";
    case 0x28:
      return "VLP-32C";
    case 0x31:
      return "Velarray";
    case 0xA1:
      return "VLS-128";
    default:
      return "unknown model";
  }
}

PacketError validate_data_packet(std::span<const std::uint8_t> packet) noexcept {
  if (packet.size() != kDataPacketBytes) return PacketError::kWrongSize;
  for (std::size_t block = 0; block < kBlocks; ++block) {
    if (read_u16(packet, block * kBlockBytes) != kBlockFlag) return PacketError::kBadBlockFlag;
    if (block_azimuth(packet, block) >= kAzimuthLimit) return PacketError::kAzimuthOutOfRange;
  }
  const std::uint8_t mode = return_mode_byte(packet);
  if (mode != static_cast<std::uint8_t>(ReturnMode::kStrongest) &&
      mode != static_cast<std::uint8_t>(ReturnMode::kLast) && mode != static_cast<std::uint8_t>(ReturnMode::kDual)) {
    return PacketError::kUnknownReturnMode;
  }
  const std::uint8_t product = product_id(packet);
  if (product != kProductVlp16 && product != kProductHdl32e && product != kProductPuckHiRes &&
      product != kProductVlp32c) {
    return PacketError::kUnsupportedProduct;
  }
  return PacketError::kNone;
}

}  // namespace trajroi::vlp16
