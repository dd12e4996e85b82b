#pragma once

// The systemd unit's allow-lists, derived from the configuration: which IP addresses the
// daemon's sockets may talk to (IPAddressAllow=) and which serial devices it may open
// (DeviceAllow=). The unit runs `trajroid --apply-to-unit %n` as a privileged ExecStartPre,
// which sets them on the starting unit (systemctl set-property --runtime), so a sensor on
// 10.0.0.x, another LCM group or /dev/ttyTHS1 work without editing the unit;
// `trajroid --unit-drop-in` prints the same lists as a drop-in file.
#include <string>
#include <vector>

#include "trajroi/daemon/config.hpp"

namespace trajroi::daemon {

struct UnitAllowLists {
  std::vector<std::string> ip_allow;      // IPAddressAllow= entries, after a reset of the unit's list
  std::vector<std::string> device_allow;  // DeviceAllow= entries ("/dev/ttyACM0 rw", "char-ttyACM rw")
  std::vector<std::string> reasons;       // one line per entry group: why it is there
  std::vector<std::string> problems;      // what the unit could not honour (a missing device…)
};

// `host_addresses`: this machine's IPv4 addresses (host_ipv4_addresses()): multicast from
// local LCM peers, and the daemon's own looped back, arrives with one of them as its source.
[[nodiscard]] UnitAllowLists unit_allow_lists(const DaemonConfig& config, const std::string& lcm_url,
                                              const std::vector<std::string>& host_addresses);

// The IPv4 addresses of this machine's interfaces that are up (loopback's excluded: localhost
// is always allowed).
[[nodiscard]] std::vector<std::string> host_ipv4_addresses();

// The lists as a drop-in file for /etc/systemd/system/<unit>.d/ (comments give the reasons).
[[nodiscard]] std::string unit_drop_in(const UnitAllowLists& lists, const std::string& config_file);

// systemctl's arguments that set the lists on `unit` for this boot (set-property --runtime).
[[nodiscard]] std::vector<std::string> set_property_arguments(const UnitAllowLists& lists, const std::string& unit);

}  // namespace trajroi::daemon
