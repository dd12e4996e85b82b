#pragma once

// The configuration's readers and formatters shared by its key table (config_keys.cpp) and the
// parse (config.cpp). Internal to daemon/src.
#include <Eigen/Geometry>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>

#include "trajroi/config/yaml_reader.hpp"
#include "trajroi/daemon/config.hpp"

namespace trajroi::daemon::config_read {

using config::MapReader;

// A relative path against the configuration file's folder; empty stays empty.
[[nodiscard]] std::filesystem::path resolve(const std::filesystem::path& base_dir, const std::string& value);
// An integer in [lo, hi].
[[nodiscard]] std::size_t count(MapReader& m, std::string_view key, std::size_t fallback, std::size_t lo,
                                std::size_t hi);
[[nodiscard]] std::uint16_t port(MapReader& m, std::string_view key, std::uint16_t fallback);
// A dotted IPv4 address; `allow_empty` for an optional one.
[[nodiscard]] std::string ipv4(MapReader& m, std::string_view key, const std::string& fallback, bool allow_empty);
// A number, or `none` (also when the key is left out).
[[nodiscard]] std::optional<double> optional_number(MapReader& m, std::string_view key);
// {xyz: [x, y, z], roll_deg, pitch_deg, yaw_deg} → a_from_b.
[[nodiscard]] Eigen::Isometry3d read_mounting(MapReader m);
// {policy: other | fifo | rr, priority, cpus: [..]}; the default when the key is absent.
[[nodiscard]] ThreadConfig read_thread(MapReader& parent, std::string_view key);

// As --check-config prints them: "%.9g" ("none" for an absent limit), "[x, y, z]", the
// mounting as YAML, a thread's settings as YAML.
[[nodiscard]] std::string format_number(double v);
[[nodiscard]] std::string format_vector(const Eigen::Vector3d& v);
[[nodiscard]] std::string format_mounting(const Eigen::Isometry3d& t);
[[nodiscard]] std::string format_thread(const ThreadConfig& t);

}  // namespace trajroi::daemon::config_read
