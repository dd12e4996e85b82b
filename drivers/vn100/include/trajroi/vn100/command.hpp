#pragma once

// VN-100 ASCII commands: "$" + body + "*" + two hex digits of the 8-bit XOR of the body's
// bytes + "\r\n".
#include <array>
#include <cstdint>
#include <string>
#include <string_view>

namespace trajroi::vn100 {

[[nodiscard]] std::uint8_t nmea_xor(std::string_view body) noexcept;
[[nodiscard]] std::string ascii_command(std::string_view body);

// Write Binary Output Register 1…3 (registers 75…77): asynchronous output on `serial_port`
// (1, 2 or 3 for both) every `rate_divisor` of the 800 Hz IMU rate, with the given field
// mask per group (index 0 = Common … 5 = INS; 0 leaves the group out). Throws for a register
// outside 1…3, a port outside 0…3, a zero divisor or no field at all.
[[nodiscard]] std::string write_binary_output(int output_register, int serial_port, int rate_divisor,
                                              const std::array<std::uint16_t, 6>& group_fields);

}  // namespace trajroi::vn100
