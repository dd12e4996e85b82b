#pragma once

// Strict reading of YAML configuration files: every key is either read or rejected, and every
// problem names the file, the line, the key's full path and the offending value:
//   config/scenarios/factory.yaml:42: robot.speed_mps: must be > 0 (got -0.5)
// Used by the scenario files of the simulator and by the daemon's configuration.
#include <cstdint>
#include <functional>
#include <memory>
#include <set>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace YAML {
class Node;
}

namespace trajroi::config {

class ConfigError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

// A YAML mapping being read. Reading a key marks it used; finish() rejects any key left
// unread. Values are checked when read: a number must be finite and parse completely.
class MapReader {
 public:
  // Parses `text` (the content of `source`); throws ConfigError for a syntax error or a
  // document whose top level is not a mapping.
  static MapReader parse(std::string_view text, std::string source);

  MapReader(const MapReader&) = delete;
  MapReader& operator=(const MapReader&) = delete;
  MapReader(MapReader&&) noexcept;
  MapReader& operator=(MapReader&&) noexcept;
  ~MapReader();

  [[nodiscard]] bool has(std::string_view key) const;

  [[nodiscard]] double number(std::string_view key);  // required
  [[nodiscard]] double number(std::string_view key, double fallback);
  // A number that must be > 0 / ≥ 0 (checked, "must be > 0" / "must be >= 0").
  [[nodiscard]] double positive(std::string_view key, double fallback);
  [[nodiscard]] double non_negative(std::string_view key, double fallback);
  [[nodiscard]] std::int64_t integer(std::string_view key);
  [[nodiscard]] std::int64_t integer(std::string_view key, std::int64_t fallback);
  [[nodiscard]] std::string text(std::string_view key);
  [[nodiscard]] std::string text(std::string_view key, std::string_view fallback);
  [[nodiscard]] bool boolean(std::string_view key, bool fallback);
  // A fixed-size list of numbers, e.g. `xyz: [0, 0, 1.2]`.
  [[nodiscard]] std::vector<double> numbers(std::string_view key, std::size_t count);
  [[nodiscard]] std::vector<double> numbers(std::string_view key, std::vector<double> fallback);
  // A list of min_count … max_count numbers (required).
  [[nodiscard]] std::vector<double> number_list(std::string_view key, std::size_t min_count, std::size_t max_count);
  // One of `choices`.
  [[nodiscard]] std::string choice(std::string_view key, std::initializer_list<std::string_view> choices,
                                   std::string_view fallback);

  // A nested mapping (required, or empty when absent and `optional`).
  [[nodiscard]] MapReader map(std::string_view key, bool optional = false);
  // Each element of a list of mappings, in order; an absent key is an empty list.
  void each(std::string_view key, const std::function<void(MapReader&)>& read);

  // Throws ConfigError naming the first key that was never read.
  void finish() const;

  // Throws ConfigError for `key` with `problem` (the key's line, path and value included).
  [[noreturn]] void fail(std::string_view key, std::string_view problem) const;
  // Checks `ok`, else fail(key, problem).
  void require(bool ok, std::string_view key, std::string_view problem) const {
    if (!ok) fail(key, problem);
  }

  [[nodiscard]] const std::string& source() const noexcept;
  [[nodiscard]] std::string path(std::string_view key) const;  // "robot.speed_mps"

 private:
  struct State;
  explicit MapReader(std::unique_ptr<State> state);
  [[nodiscard]] YAML::Node node(std::string_view key) const;
  [[noreturn]] void missing(std::string_view key) const;
  [[nodiscard]] YAML::Node scalar(std::string_view key);
  std::unique_ptr<State> state_;
};

}  // namespace trajroi::config
