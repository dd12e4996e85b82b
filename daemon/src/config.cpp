#include "trajroi/daemon/config.hpp"

#include <arpa/inet.h>

#include <string>
#include <utility>
#include <vector>

#include "config_keys.hpp"
#include "trajroi/config/text_file.hpp"

namespace trajroi::daemon {
namespace {

using config::MapReader;

// The key=value options after '?' in a udpm:// URL's rest (after "udpm://"), in order.
std::vector<std::pair<std::string, std::string>> udpm_options(const std::string& rest) {
  std::vector<std::pair<std::string, std::string>> options;
  const std::size_t question = rest.find('?');
  std::size_t at = question == std::string::npos ? rest.size() : question + 1;
  while (at < rest.size()) {
    const std::size_t end = std::min(rest.find('&', at), rest.size());
    const std::string option = rest.substr(at, end - at);
    const std::size_t eq = option.find('=');
    options.emplace_back(option.substr(0, eq), eq == std::string::npos ? "" : option.substr(eq + 1));
    at = end + 1;
  }
  return options;
}

// The maps of a key's path ("pose.gnss_heading" of "pose.gnss_heading.min_speed_mps") and its name.
std::pair<std::string_view, std::string_view> split_key(std::string_view path) {
  const std::size_t dot = path.rfind('.');
  return {path.substr(0, dot), path.substr(dot + 1)};
}

const ConfigSection* section_named(std::string_view name) {
  for (const ConfigSection& s : config_sections()) {
    if (s.name == name) return &s;
  }
  return nullptr;
}

// The readers of the maps the walk is in, outermost first, each with its dotted path.
class OpenMaps {
 public:
  OpenMaps(MapReader& root, DaemonConfig& c) : root_(root), config_(c) {}
  // The reader of `maps` ("lidar", "pose.gnss_heading"), closing and opening maps on the way.
  MapReader& at(std::string_view maps) {
    while (!open_.empty() && !within(maps, open_.back().first))
      close();
    while (open_.empty() || open_.back().first != maps) {
      const std::string_view parent = open_.empty() ? std::string_view() : std::string_view(open_.back().first);
      const std::string_view rest = parent.empty() ? maps : maps.substr(parent.size() + 1);
      const std::string_view name = rest.substr(0, rest.find('.'));
      MapReader& from = open_.empty() ? root_ : open_.back().second;
      const ConfigSection* section = parent.empty() ? section_named(name) : nullptr;
      const bool optional = section == nullptr || !section->required;
      std::string path = parent.empty() ? std::string(name) : std::string(parent) + "." + std::string(name);
      open_.emplace_back(std::move(path), from.map(name, optional));
    }
    return open_.back().second;
  }
  void close_all() {
    while (!open_.empty())
      close();
  }

 private:
  static bool within(std::string_view maps, std::string_view open) {
    return maps == open || (maps.size() > open.size() && maps.starts_with(open) && maps[open.size()] == '.');
  }
  void close() {
    auto& [path, reader] = open_.back();
    if (const ConfigSection* s = section_named(path); s != nullptr && s->check) s->check(reader, config_);
    reader.finish();
    open_.pop_back();
  }
  MapReader& root_;
  DaemonConfig& config_;
  std::vector<std::pair<std::string, MapReader>> open_;
};

// `lidars:` (a list, each entry the keys of `lidar:` and a name) or the one `lidar:`.
void read_lidars(MapReader& root, DaemonConfig& c, const std::filesystem::path& dir) {
  const ConfigSection* section = section_named("lidar");
  if (root.has("lidars")) {
    root.require(!root.has("lidar"), "lidars", "give either lidar: (one sensor) or lidars: (a list), not both");
    c.lidars.clear();
    root.each("lidars", [&](MapReader& item) {
      DaemonConfig one;
      one.lidar.name = item.text("name");
      item.require(!one.lidar.name.empty() && one.lidar.name.size() <= 32 &&
                       one.lidar.name.find_first_not_of(
                           "abcdefghijklmnopqrstuvwxyzABCDEFGHIJKLMNOPQRSTUVWXYZ0123456789_-") == std::string::npos,
                   "name", "must be 1 … 32 letters, digits, '_' or '-'");
      for (const ConfigKey& key : config_keys()) {
        const auto [map_path, name] = split_key(key.path);
        if (map_path == "lidar") key.read(item, name, one, dir);
      }
      if (section != nullptr && section->check) section->check(item, one);
      for (const DaemonConfig::Lidar& before : c.lidars)
        item.require(before.name != one.lidar.name, "name", "is the name of another sensor");
      c.lidars.push_back(one.lidar);
    });
    root.require(!c.lidars.empty() && c.lidars.size() <= kMaxLidars, "lidars",
                 "must list 1 … " + std::to_string(kMaxLidars) + " sensors");
    c.lidar = c.lidars.front();
  } else {
    c.lidars = {c.lidar};
  }
  // Sensors on one port are told apart by their addresses: each must have its own.
  for (std::size_t i = 0; i < c.lidars.size(); ++i) {
    for (std::size_t j = 0; j < i; ++j) {
      const DaemonConfig::Lidar& a = c.lidars[j];
      const DaemonConfig::Lidar& b = c.lidars[i];
      const std::string both = "lidars: " + a.name + " and " + b.name;
      const bool same_data = a.data_port == b.data_port, same_position = a.position_port == b.position_port;
      if (a.data_port == b.position_port || a.position_port == b.data_port) {
        root.fail("lidars", both + ": one's data port is the other's position port");
      }
      if (same_data != same_position || (same_data && a.bind_address != b.bind_address)) {
        root.fail("lidars", both +
                                " share one port but not the other (or not the bind_address): sensors on one "
                                "port share both ports and the address they bind");
      }
      if (!same_data) continue;
      if (a.sensor_address.empty() || b.sensor_address.empty()) {
        root.fail("lidars", both + " share UDP ports " + std::to_string(a.data_port) + "/" +
                                std::to_string(a.position_port) +
                                " without sensor_address: give each its address, so that their packets are told apart");
      }
      if (a.sensor_address == b.sensor_address) {
        root.fail("lidars", both + " share UDP port " + std::to_string(a.data_port) + " and sensor_address " +
                                a.sensor_address + ": one sender cannot be two sensors");
      }
    }
  }
}

std::string markdown_cell(std::string_view text) {
  std::string out;
  for (const char ch : text) {
    if (ch == '|') out += '\\';
    out += ch;
  }
  return out;
}

}  // namespace

std::optional<LcmGroup> lcm_multicast_group(const std::string& url) {
  if (!url.starts_with("udpm://")) return std::nullopt;
  const std::string rest = url.substr(7);
  const std::string target = rest.substr(0, rest.find('?'));
  LcmGroup group;
  const std::size_t colon = target.find(':');
  group.address = target.substr(0, colon);
  if (group.address.empty()) group.address = "239.255.76.67";
  if (colon != std::string::npos) group.port = std::stoi(target.substr(colon + 1));
  // Options as check_lcm_url accepts them (checked there); others are ignored here.
  for (const auto& [key, value] : udpm_options(rest)) {
    if (key == "ttl") group.ttl = std::stoi(value);
    if (key == "recv_buf_size") group.recv_buf_size = std::stoi(value);
  }
  return group;
}

std::string check_lcm_url(const std::string& url) {
  const std::size_t scheme_end = url.find("://");
  if (scheme_end == std::string::npos) return "must be an LCM URL, provider://[address[:port]][?options]";
  const std::string provider = url.substr(0, scheme_end);
  if (provider != "udpm" && provider != "memq" && provider != "file" && provider != "tcpq") {
    return "provider '" + provider + "' is not one of udpm, memq, file, tcpq";
  }
  if (provider != "udpm") return {};
  const std::string rest = url.substr(scheme_end + 3);
  const std::string target = rest.substr(0, rest.find('?'));
  const std::string address = target.substr(0, target.find(':'));
  if (!address.empty()) {
    in_addr parsed{};
    if (inet_pton(AF_INET, address.c_str(), &parsed) != 1) return "address '" + address + "' is not an IPv4 address";
    const std::uint32_t first = ntohl(parsed.s_addr) >> 24;
    if (first < 224 || first > 239) return "address '" + address + "' is not a multicast address (224–239.x.x.x)";
  }
  const auto whole_number = [](const std::string& text, long lo, long hi) {
    if (text.empty() || text.find_first_not_of("0123456789") != std::string::npos || text.size() > 9) return false;
    const long v = std::stol(text);
    return v >= lo && v <= hi;
  };
  if (target.find(':') != std::string::npos) {
    const std::string port_text = target.substr(target.find(':') + 1);
    if (!whole_number(port_text, 1, 65535)) return "port '" + port_text + "' is not a UDP port 1 … 65535";
  }
  for (const auto& [key, value] : udpm_options(rest)) {
    if (key == "ttl") {
      if (!whole_number(value, 0, 255)) return "ttl '" + value + "' is not 0 … 255";
    } else if (key == "recv_buf_size") {
      if (!whole_number(value, 1, 1 << 30)) return "recv_buf_size '" + value + "' is not a byte count";
    } else {
      return "option '" + key + "' is not one of ttl, recv_buf_size";
    }
  }
  return {};
}

std::string_view to_string(PoseSource source) noexcept {
  switch (source) {
    case PoseSource::kGnssImu:
      return "gnss_imu";
    case PoseSource::kGnss:
      return "gnss";
    case PoseSource::kLcm:
      return "lcm";
    case PoseSource::kFixed:
      return "fixed";
  }
  return "unknown";
}

DaemonConfig parse_daemon_config(std::string_view text, const std::filesystem::path& file) {
  DaemonConfig c;
  c.file = file;
  const std::filesystem::path dir = file.has_parent_path() ? file.parent_path() : std::filesystem::path(".");
  MapReader root = MapReader::parse(text, file.string());
  OpenMaps maps(root, c);
  for (const ConfigKey& key : config_keys()) {
    const auto [map_path, name] = split_key(key.path);
    key.read(maps.at(map_path), name, c, dir);
  }
  maps.close_all();
  read_lidars(root, c, dir);
  root.finish();
  return c;
}

std::string describe(const DaemonConfig& c) {
  std::string out;
  for (const ConfigKey& key : config_keys())
    out.append(key.path).append(": ").append(key.show(c)).append("\n");
  if (c.lidars.size() > 1) {
    for (std::size_t i = 0; i < c.lidars.size(); ++i) {
      DaemonConfig one = c;
      one.lidar = c.lidars[i];
      const std::string at = "lidars[" + std::to_string(i) + "].";
      out.append(at).append("name: ").append(one.lidar.name).append("\n");
      for (const ConfigKey& key : config_keys()) {
        if (key.path.starts_with("lidar."))
          out.append(at).append(key.path.substr(6)).append(": ").append(key.show(one)).append("\n");
      }
    }
  }
  return out;
}

std::string config_reference() {
  const DaemonConfig defaults;
  std::string out;
  std::string_view section;
  for (const ConfigKey& key : config_keys()) {
    const std::string_view top = key.path.substr(0, key.path.find('.'));
    if (top != section) {
      section = top;
      const ConfigSection* s = section_named(top);
      out.append("\n## `").append(top).append("`: ").append(s != nullptr ? s->title : top).append("\n\n");
      if (s != nullptr && !s->meaning.empty()) out.append(s->meaning).append("\n\n");
      out.append("| key | type | default | meaning |\n|---|---|---|---|\n");
    }
    const std::string value = key.show(defaults);
    const std::string fallback = key.required ? "required" : value.empty() ? "`\"\"`" : "`" + value + "`";
    out.append("| `").append(key.path).append("` | ").append(markdown_cell(key.type)).append(" | ");
    out.append(markdown_cell(fallback)).append(" | ").append(markdown_cell(key.meaning)).append(" |\n");
  }
  return out;
}

DaemonConfig load_daemon_config(const std::filesystem::path& file) {
  return parse_daemon_config(config::read_text_file(file), file);
}

}  // namespace trajroi::daemon
