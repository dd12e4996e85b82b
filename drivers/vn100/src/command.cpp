#include "trajroi/vn100/command.hpp"

#include <cstdio>
#include <stdexcept>

namespace trajroi::vn100 {

std::uint8_t nmea_xor(std::string_view body) noexcept {
  std::uint8_t x = 0;
  for (const char c : body)
    x = static_cast<std::uint8_t>(x ^ static_cast<std::uint8_t>(c));
  return x;
}

std::string ascii_command(std::string_view body) {
  char tail[8];
  std::snprintf(tail, sizeof tail, "*%02X\r\n", nmea_xor(body));
  std::string command;
  command.reserve(body.size() + 6);
  command.push_back('$');
  command.append(body);
  command.append(tail);
  return command;
}

std::string write_binary_output(int output_register, int serial_port, int rate_divisor,
                                const std::array<std::uint16_t, 6>& group_fields) {
  if (output_register < 1 || output_register > 3)
    throw std::invalid_argument("VN-100: binary output register must be 1, 2 or 3");
  if (serial_port < 0 || serial_port > 3) throw std::invalid_argument("VN-100: async mode (serial port) must be 0 … 3");
  if (rate_divisor < 1 || rate_divisor > 65535) throw std::invalid_argument("VN-100: rate divisor must be 1 … 65535");
  unsigned groups = 0;
  for (std::size_t g = 0; g < group_fields.size(); ++g) {
    if (group_fields[g] != 0) groups |= 1U << g;
  }
  if (groups == 0) throw std::invalid_argument("VN-100: binary output selects no field");
  char text[96];
  int n =
      std::snprintf(text, sizeof text, "VNWRG,%d,%d,%d,%02X", 74 + output_register, serial_port, rate_divisor, groups);
  for (const std::uint16_t fields : group_fields) {
    if (fields != 0) n += std::snprintf(text + n, sizeof text - static_cast<std::size_t>(n), ",%04X", fields);
  }
  return ascii_command(text);
}

}  // namespace trajroi::vn100
