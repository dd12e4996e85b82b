#include "trajroi/daemon/unit_allow.hpp"

#include <arpa/inet.h>
#include <ifaddrs.h>
#include <net/if.h>
#include <netdb.h>
#include <netinet/in.h>
#include <sys/stat.h>
#include <sys/sysmacros.h>

#include <algorithm>
#include <array>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "trajroi/corrections/corrections_url.hpp"

namespace trajroi::daemon {
namespace {

// The name /proc/devices gives a character device's major number ("ttyACM", "ttyTHS"…): what
// DeviceAllow=char-NAME allows, so the device is still allowed when it comes back under
// another minor (a USB receiver re-plugged as ttyACM1). A major with several names (4: tty,
// ttyS) gives the longest that starts the node's name ("ttyS" for ttyS0).
std::string char_device_class(unsigned major_number, const std::string& node_name) {
  std::ifstream devices("/proc/devices");
  std::string line, best;
  std::vector<std::string> names;
  bool in_character = false;
  while (std::getline(devices, line)) {
    if (line.starts_with("Character devices:")) {
      in_character = true;
    } else if (line.starts_with("Block devices:")) {
      in_character = false;
    } else if (in_character) {
      std::istringstream fields(line);
      unsigned number = 0;
      std::string name;
      if (fields >> number >> name && number == major_number && !name.starts_with("/")) names.push_back(name);
    }
  }
  for (const std::string& name : names) {
    if (node_name.starts_with(name) && name.size() > best.size()) best = name;
  }
  if (best.empty() && names.size() == 1) best = names.front();
  return best;
}

void add_unique(std::vector<std::string>& list, const std::string& entry) {
  if (std::find(list.begin(), list.end(), entry) == list.end()) list.push_back(entry);
}

// gnss.corrections: the caster's or server's addresses (its name resolved now: the unit is set
// at each start), a radio's serial device; UDP and LCM senders are not known here.
template <class AddDevice>
void corrections_allow(const DaemonConfig& config, UnitAllowLists& lists, const AddDevice& add_device) {
  const std::string& url = config.gnss_corrections.url;
  if (url.empty()) return;
  corrections::CorrectionsUrl u;
  try {
    u = corrections::parse_corrections_url(url);
  } catch (const std::exception&) {
    return;  // the configuration check names it
  }
  using Kind = corrections::CorrectionsUrl::Kind;
  if (u.kind == Kind::kNtrip || u.kind == Kind::kTcp) {
    addrinfo hints{};
    hints.ai_family = AF_INET;
    hints.ai_socktype = SOCK_STREAM;
    addrinfo* found = nullptr;
    const int rc = getaddrinfo(u.ntrip.host.c_str(), nullptr, &hints, &found);
    if (rc != 0) {
      lists.problems.push_back("gnss.corrections.url: cannot resolve " + u.ntrip.host + " now (" + gai_strerror(rc) +
                               "): the caster is not allowed; restart the unit once it resolves");
      return;
    }
    std::string joined;
    for (const addrinfo* a = found; a != nullptr; a = a->ai_next) {
      char text[INET_ADDRSTRLEN] = "";
      inet_ntop(AF_INET, &reinterpret_cast<const sockaddr_in*>(a->ai_addr)->sin_addr, text, sizeof text);
      if (std::find(lists.ip_allow.begin(), lists.ip_allow.end(), text) == lists.ip_allow.end()) {
        lists.ip_allow.emplace_back(text);
        joined.append(joined.empty() ? "" : " ").append(text);
      }
    }
    freeaddrinfo(found);
    if (!joined.empty()) lists.reasons.push_back("the corrections' server " + u.redacted() + " at " + joined);
  } else if (u.kind == Kind::kUdp) {
    lists.problems.push_back("gnss.corrections.url " + u.redacted() +
                             ": the base station's address is not known here: outside the private ranges, admit it "
                             "with a drop-in of your own (IPAddressAllow=)");
  } else if (u.kind == Kind::kSerial) {
    DaemonConfig::Serial radio;
    radio.device = u.device;
    add_device(radio, "gnss.corrections.url (radio)");
  }
}

}  // namespace

UnitAllowLists unit_allow_lists(const DaemonConfig& config, const std::string& lcm_url,
                                const std::vector<std::string>& host_addresses) {
  UnitAllowLists lists;
  lists.ip_allow.push_back("localhost");
  if (const std::optional<LcmGroup> group = lcm_multicast_group(lcm_url)) {
    add_unique(lists.ip_allow, group->address);
    lists.reasons.push_back("LCM group " + group->address + " (" + lcm_url + ")");
    for (const std::string& address : host_addresses)
      add_unique(lists.ip_allow, address);
    if (!host_addresses.empty()) {
      std::string joined;
      for (const std::string& address : host_addresses)
        joined.append(joined.empty() ? "" : " ").append(address);
      lists.reasons.push_back("this host's addresses " + joined +
                              ": the source of LCM multicast from local peers and of the daemon's own");
    }
  }
  bool any_sender = false;
  for (const DaemonConfig::Lidar& l : config.all_lidars()) {
    if (l.sensor_address.empty()) {
      any_sender = true;
      continue;
    }
    add_unique(lists.ip_allow, l.sensor_address);
    lists.reasons.push_back(config.lidars.size() == 1
                                ? "the LiDAR at " + l.sensor_address + " (lidar.sensor_address)"
                                : "the LiDAR " + l.name + " at " + l.sensor_address + " (lidars: sensor_address)");
  }
  if (any_sender) {
    // Any sender is accepted: the ranges a sensor on a robot's network has (RFC 1918, link-local).
    for (const char* range : {"10.0.0.0/8", "172.16.0.0/12", "192.168.0.0/16", "169.254.0.0/16"})
      add_unique(lists.ip_allow, range);
    lists.reasons.push_back(
        "the LiDAR from any private or link-local address (lidar.sensor_address unset; set it to admit only the "
        "sensor)");
  }

  const auto add_device = [&](const DaemonConfig::Serial& serial, const char* key) {
    if (serial.device.empty()) return;
    struct stat s {};
    if (stat(serial.device.c_str(), &s) != 0) {
      lists.problems.push_back(std::string(key) + " " + serial.device +
                               " does not exist now: allowed by path only when it exists at the unit's start");
      add_unique(lists.device_allow, serial.device + " rw");
      return;
    }
    if (!S_ISCHR(s.st_mode)) {
      lists.problems.push_back(std::string(key) + " " + serial.device + " is not a character device");
      return;
    }
    // The node itself (systemd takes only paths below /dev: a udev link like /dev/gnss is
    // resolved to its node), and its class, which still holds when it is re-plugged.
    std::error_code ignored;
    const std::filesystem::path node = std::filesystem::canonical(serial.device, ignored);
    if (node.string().starts_with("/dev/")) add_unique(lists.device_allow, node.string() + " rw");
    const std::string name = char_device_class(major(s.st_rdev), node.filename().string());
    if (!name.empty()) add_unique(lists.device_allow, "char-" + name + " rw");
    lists.reasons.push_back(std::string(key) + " " + serial.device +
                            (name.empty() ? "" : " (class char-" + name + ")"));
  };
  if (config.pose_source == PoseSource::kGnssImu || config.pose_source == PoseSource::kGnss)
    add_device(config.gnss, "gnss.device");
  if (config.pose_source == PoseSource::kGnssImu) add_device(config.imu, "imu.device");
  corrections_allow(config, lists, add_device);
  return lists;
}

std::vector<std::string> host_ipv4_addresses() {
  std::vector<std::string> addresses;
  ifaddrs* list = nullptr;
  if (getifaddrs(&list) != 0) return addresses;
  for (const ifaddrs* i = list; i != nullptr; i = i->ifa_next) {
    if (i->ifa_addr == nullptr || i->ifa_addr->sa_family != AF_INET) continue;
    if ((i->ifa_flags & IFF_UP) == 0 || (i->ifa_flags & IFF_LOOPBACK) != 0) continue;
    std::array<char, INET_ADDRSTRLEN> text{};
    const auto* address = reinterpret_cast<const sockaddr_in*>(i->ifa_addr);
    if (inet_ntop(AF_INET, &address->sin_addr, text.data(), text.size()) != nullptr) add_unique(addresses, text.data());
  }
  freeifaddrs(list);
  return addresses;
}

std::string unit_drop_in(const UnitAllowLists& lists, const std::string& config_file) {
  std::string out = "# Generated by `trajroid --config " + config_file + " --unit-drop-in`.\n";
  for (const std::string& reason : lists.reasons)
    out += "# allows " + reason + "\n";
  for (const std::string& problem : lists.problems)
    out += "# NOTE: " + problem + "\n";
  out += "[Service]\nIPAddressAllow=\n";
  for (const std::string& entry : lists.ip_allow)
    out += "IPAddressAllow=" + entry + "\n";
  for (const std::string& entry : lists.device_allow)
    out += "DeviceAllow=" + entry + "\n";
  return out;
}

std::vector<std::string> set_property_arguments(const UnitAllowLists& lists, const std::string& unit) {
  std::vector<std::string> args{"systemctl", "set-property", "--runtime", unit, "IPAddressAllow="};
  for (const std::string& entry : lists.ip_allow)
    args.push_back("IPAddressAllow=" + entry);
  for (const std::string& entry : lists.device_allow)
    args.push_back("DeviceAllow=" + entry);
  return args;
}

}  // namespace trajroi::daemon
