// trajroi configure gnss|imu: a one-off receiver configuration through its serial port (what
// gnss.configure / imu.configure do when trajroid opens the device). Prints each step and its
// answer; exit 0 when every step was acknowledged, 1 otherwise.
#include <cstdio>
#include <memory>
#include <string>

#include "commands.hpp"
#include "trajroi/configure/receiver_config.hpp"

namespace trajroi::cli {
namespace {

struct ConfigureOptions {
  std::string device;
  int baud = 115200;
  double rate_hz = 0.0;  // 0: the device's default (u-blox 5 Hz, VN-100 40 Hz)
  bool relposned = false;
  int timeout_ms = 1000;
};

int report(const configure::Result& r) {
  for (const configure::Step& s : r.steps)
    std::printf("%s %s: %s\n", s.ok ? "ok  " : "FAIL", s.what.c_str(), s.answer.c_str());
  std::printf("%s\n", r.summary.c_str());
  return r.ok ? 0 : 1;
}

serial::SerialPortOptions port_options(const ConfigureOptions& o) {
  serial::SerialPortOptions p;
  p.device = o.device;
  p.baud = o.baud;
  return p;
}

}  // namespace

void add_configure_command(CLI::App& app) {
  auto o = std::make_shared<ConfigureOptions>();
  CLI::App* cmd = app.add_subcommand("configure", "Configure a receiver's output through its serial port");
  cmd->require_subcommand(1);
  const auto common = [o](CLI::App* sub) {
    sub->add_option("--device", o->device, "Serial device, e.g. /dev/ttyACM0")->required();
    sub->add_option("--baud", o->baud, "Baud rate")->capture_default_str();
    sub->add_option("--rate", o->rate_hz, "Output rate, Hz (u-blox default 5, VN-100 default 40)");
    sub->add_option("--timeout-ms", o->timeout_ms, "Wait for each answer this long")->capture_default_str();
  };
  CLI::App* gnss = cmd->add_subcommand("gnss", "u-blox: NAV-PVT (+ NAV-HPPOSLLH) at the rate, each message ACKed");
  common(gnss);
  gnss->add_flag("--relposned", o->relposned, "Also NAV-RELPOSNED (a moving-base heading, pose.source gnss)");
  gnss->callback([o] {
    serial::SerialPortSource port(port_options(*o));
    configure::UbloxSettings s;
    if (o->rate_hz > 0.0) s.rate_hz = o->rate_hz;
    s.port = configure::guess_ublox_port(o->device);
    s.relposned = o->relposned;
    s.timeout = std::chrono::milliseconds(o->timeout_ms);
    const int code = report(configure::configure_ublox(port, s));
    if (code != 0) throw CLI::RuntimeError(code);
  });
  CLI::App* imu = cmd->add_subcommand("imu", "VN-100: binary output register 75 written and read back");
  common(imu);
  imu->callback([o] {
    serial::SerialPortSource port(port_options(*o));
    configure::Vn100Settings s;
    if (o->rate_hz > 0.0) s.rate_hz = o->rate_hz;
    s.timeout = std::chrono::milliseconds(o->timeout_ms);
    const int code = report(configure::configure_vn100(port, s));
    if (code != 0) throw CLI::RuntimeError(code);
  });
}

}  // namespace trajroi::cli
