#pragma once

// Receiver configuration over the serial port the daemon reads (gnss.configure: true,
// imu.configure: true, or `trajroi configure gnss|imu` for a one-off). Every step is checked
// and reported; nothing here throws for what the device answers or does not.
//
// u-blox: the pose messages once per solution at the rate, on the port in use. A receiver of
// the F9 generation (and later) takes one UBX-CFG-VALSET; an M8 does not know it (no answer,
// or ACK-NAK) and gets UBX-CFG-RATE then one UBX-CFG-MSG per message. Each is answered by
// ACK-ACK or ACK-NAK for its class and id; no answer within the timeout is a failure.
//
// VN-100: Binary Output Register 1 (75) written with $VNWRG (the sensor echoes the command;
// $VNERR is a refusal), then read back with $VNRRG and compared field by field.
#include <chrono>
#include <string>
#include <vector>

#include "trajroi/serial/serial_port_source.hpp"
#include "trajroi/ublox/config.hpp"

namespace trajroi::configure {

struct Step {
  std::string what;  // "CFG-VALSET (F9): NAV-PVT, NAV-HPPOSLLH at 5 Hz on USB"
  bool ok = false;
  std::string answer;  // "ACK-ACK", "ACK-NAK", "no answer within 1000 ms", "$VNERR,03 (invalid parameter)"
};

struct Result {
  bool ok = false;
  std::string summary;  // one line for the log
  std::vector<Step> steps;
};

struct UbloxSettings {
  double rate_hz = 5.0;
  ublox::Port port = ublox::Port::kUsb;  // the receiver's port the device is (F9 keys only)
  bool high_precision = true;            // NAV-HPPOSLLH too (optional: a NAK is a warning)
  bool relposned = false;                // NAV-RELPOSNED (pose.source gnss, moving base)
  bool rtcm3_input = false;              // the port accepts RTCM3 corrections (gnss.corrections)
  std::chrono::milliseconds timeout{1000};
};
// The port a device path most likely is: ttyACM (CDC-ACM: the receiver's own USB) → USB, else
// UART1 (a USB-serial adapter or a board UART).
[[nodiscard]] ublox::Port guess_ublox_port(const std::string& device) noexcept;

[[nodiscard]] Result configure_ublox(serial::SerialPortSource& port, const UbloxSettings& settings);

struct Vn100Settings {
  double rate_hz = 40.0;  // of the 800 Hz IMU rate: a divisor of 800 / rate
  int async_port = 3;     // 1, 2, or 3 (both)
  std::chrono::milliseconds timeout{1000};
};
// TimeStartup + YawPitchRoll (common group) on Binary Output Register 1.
[[nodiscard]] Result configure_vn100(serial::SerialPortSource& port, const Vn100Settings& settings);

}  // namespace trajroi::configure
