#pragma once

// Receiver configuration: the UBX messages that make a receiver output what trajroi reads.
//  - F9 generation (and later): UBX-CFG-VALSET with configuration keys (one per message and
//    port, plus CFG-RATE-MEAS / CFG-RATE-NAV).
//  - M8 generation: UBX-CFG-MSG (rate per message on the current port) and UBX-CFG-RATE.
// The receiver answers each with ACK-ACK or ACK-NAK (decode_ack in messages.hpp).
#include <cstdint>
#include <span>
#include <utility>
#include <vector>

namespace trajroi::ublox {

// A whole frame (sync, header, payload, checksum) around `payload`. Throws
// std::invalid_argument when the payload does not fit the 16-bit length field.
[[nodiscard]] std::vector<std::uint8_t> encode_frame(std::uint8_t msg_class, std::uint8_t msg_id,
                                                     std::span<const std::uint8_t> payload);

enum class Port : std::uint8_t { kI2c, kUart1, kUart2, kUsb, kSpi };

// The pose messages trajroi decodes.
enum class PoseMessage : std::uint8_t { kNavPvt, kNavHpposllh, kNavRelposned, kNavCov, kNavStatus };

// CFG-MSGOUT-UBX_NAV_* key of `message` on `port` (u-blox F9 configuration interface).
[[nodiscard]] std::uint32_t msgout_key(PoseMessage message, Port port) noexcept;
// CFG-<port>INPROT-RTCM3X (L): the port accepts RTCM3 corrections (F9 interface description,
// CFG-I2CINPROT … CFG-SPIINPROT groups: 0x10710004, 0x10730004, 0x10750004, 0x10770004, 0x10790004).
[[nodiscard]] std::uint32_t rtcm3_input_key(Port port) noexcept;
inline constexpr std::uint32_t kKeyRateMeas = 0x30210001;  // U2, ms between measurements
inline constexpr std::uint32_t kKeyRateNav = 0x30210002;   // U2, measurements per solution

// Configuration layers of CFG-VALSET (bit mask).
inline constexpr std::uint8_t kLayerRam = 0x01;
inline constexpr std::uint8_t kLayerBbr = 0x02;
inline constexpr std::uint8_t kLayerFlash = 0x04;

// UBX-CFG-VALSET (version 0, no transaction) setting each key to its value; the value size
// comes from the key's size bits (28–30). Throws std::invalid_argument for a key whose size
// is unknown or a value that does not fit it, and for more than 64 keys (the receiver's limit).
[[nodiscard]] std::vector<std::uint8_t> encode_cfg_valset(
    std::span<const std::pair<std::uint32_t, std::uint64_t>> items, std::uint8_t layers = kLayerRam);

// UBX-CFG-MSG (M8): output `msg_class`/`msg_id` every `rate` navigation solutions on the
// port the message is sent on (0 disables).
[[nodiscard]] std::vector<std::uint8_t> encode_cfg_msg(std::uint8_t msg_class, std::uint8_t msg_id, std::uint8_t rate);

// UBX-CFG-RATE (M8): one measurement every `meas_rate_ms`, one solution every `nav_rate`
// measurements, aligned to GPS time (timeRef 1). Throws for a zero rate.
[[nodiscard]] std::vector<std::uint8_t> encode_cfg_rate(std::uint16_t meas_rate_ms, std::uint16_t nav_rate = 1);

// The messages that configure a receiver to output `messages` once per solution on `port` at
// `rate_hz` (F9: one CFG-VALSET; M8: a CFG-RATE, then a CFG-MSG per message). Each one is
// answered by an ACK. Throws for a rate outside 0.1 … 50 Hz.
enum class Generation : std::uint8_t { kM8, kF9 };
[[nodiscard]] std::vector<std::vector<std::uint8_t>> pose_output_configuration(Generation generation, Port port,
                                                                               double rate_hz,
                                                                               std::span<const PoseMessage> messages);

}  // namespace trajroi::ublox
