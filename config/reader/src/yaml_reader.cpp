#include "trajroi/config/yaml_reader.hpp"

#include <yaml-cpp/yaml.h>

#include <charconv>
#include <cmath>
#include <memory>

namespace trajroi::config {

struct MapReader::State {
  std::shared_ptr<const std::string> source;
  std::string prefix;  // "robot." for a nested map, "" at the top
  YAML::Node node;
  std::set<std::string, std::less<>> used;
};

namespace {

int line_of(const YAML::Node& node) {
  return node.Mark().line >= 0 ? node.Mark().line + 1 : 0;
}

std::string located(const std::string& source, int line) {
  return line > 0 ? source + ":" + std::to_string(line) : source;
}

}  // namespace

MapReader::MapReader(std::unique_ptr<State> state) : state_(std::move(state)) {}
MapReader::MapReader(MapReader&&) noexcept = default;
MapReader& MapReader::operator=(MapReader&&) noexcept = default;
MapReader::~MapReader() = default;

MapReader MapReader::parse(std::string_view text, std::string source) {
  YAML::Node root;
  try {
    root = YAML::Load(std::string(text));
  } catch (const YAML::Exception& e) {
    throw ConfigError(located(source, e.mark.line + 1) + ": " + e.msg);
  }
  if (!root.IsMap()) throw ConfigError(source + ": the top level must be a mapping of keys");
  auto state = std::make_unique<State>();
  state->source = std::make_shared<const std::string>(std::move(source));
  state->node = root;
  return MapReader(std::move(state));
}

const std::string& MapReader::source() const noexcept {
  return *state_->source;
}

std::string MapReader::path(std::string_view key) const {
  std::string p = state_->prefix;
  p += key;
  return p;
}

void MapReader::fail(std::string_view key, std::string_view problem) const {
  const YAML::Node value = node(key);
  std::string message = located(source(), line_of(value ? value : state_->node));
  message += ": ";
  message += path(key);
  message += ": ";
  message += problem;
  if (value && value.IsScalar()) {
    message += " (got '";
    message += value.Scalar();
    message += "')";
  }
  throw ConfigError(message);
}

void MapReader::missing(std::string_view key) const {
  std::string message = located(source(), line_of(state_->node));
  message += ": ";
  message += path(key);
  message += ": missing (required)";
  throw ConfigError(message);
}

bool MapReader::has(std::string_view key) const {
  return static_cast<bool>(node(key));
}

YAML::Node MapReader::node(std::string_view key) const {
  for (const auto& item : state_->node) {
    if (item.first.IsScalar() && item.first.Scalar() == key) return item.second;
  }
  return YAML::Node(YAML::NodeType::Undefined);
}

YAML::Node MapReader::scalar(std::string_view key) {
  const YAML::Node value = node(key);
  if (!value) {
    missing(key);
  }
  state_->used.emplace(key);
  if (!value.IsScalar()) fail(key, "must be a single value");
  return value;
}

double MapReader::number(std::string_view key) {
  const std::string text = scalar(key).Scalar();
  double value = 0.0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc{} || end != text.data() + text.size() || !std::isfinite(value))
    fail(key, "must be a finite number");
  return value;
}

double MapReader::number(std::string_view key, double fallback) {
  return has(key) ? number(key) : fallback;
}

double MapReader::positive(std::string_view key, double fallback) {
  const double v = number(key, fallback);
  require(v > 0.0, key, "must be > 0");
  return v;
}

double MapReader::non_negative(std::string_view key, double fallback) {
  const double v = number(key, fallback);
  require(v >= 0.0, key, "must be >= 0");
  return v;
}

std::int64_t MapReader::integer(std::string_view key) {
  const std::string text = scalar(key).Scalar();
  std::int64_t value = 0;
  const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
  if (ec != std::errc{} || end != text.data() + text.size()) fail(key, "must be an integer");
  return value;
}

std::int64_t MapReader::integer(std::string_view key, std::int64_t fallback) {
  return has(key) ? integer(key) : fallback;
}

std::string MapReader::text(std::string_view key) {
  return scalar(key).Scalar();
}

std::string MapReader::text(std::string_view key, std::string_view fallback) {
  return has(key) ? text(key) : std::string(fallback);
}

bool MapReader::boolean(std::string_view key, bool fallback) {
  if (!has(key)) return fallback;
  const std::string value = text(key);
  if (value == "true") return true;
  if (value == "false") return false;
  fail(key, "must be true or false");
}

std::vector<double> MapReader::numbers(std::string_view key, std::size_t count) {
  return number_list(key, count, count);
}

std::vector<double> MapReader::number_list(std::string_view key, std::size_t min_count, std::size_t max_count) {
  const YAML::Node list = node(key);
  if (!list) {
    missing(key);
  }
  state_->used.emplace(key);
  const std::string expected = min_count == max_count ? "a list of " + std::to_string(min_count) + " finite numbers"
                                                      : "a list of " + std::to_string(min_count) + " to " +
                                                            std::to_string(max_count) + " finite numbers";
  if (!list.IsSequence() || list.size() < min_count || list.size() > max_count) fail(key, "must be " + expected);
  std::vector<double> values;
  for (const auto& item : list) {
    double value = 0.0;
    const std::string text = item.IsScalar() ? item.Scalar() : std::string();
    const auto [end, ec] = std::from_chars(text.data(), text.data() + text.size(), value);
    if (!item.IsScalar() || ec != std::errc{} || end != text.data() + text.size() || !std::isfinite(value)) {
      fail(key, "must be " + expected);
    }
    values.push_back(value);
  }
  return values;
}

std::vector<double> MapReader::numbers(std::string_view key, std::vector<double> fallback) {
  return has(key) ? numbers(key, fallback.size()) : fallback;
}

std::string MapReader::choice(std::string_view key, std::initializer_list<std::string_view> choices,
                              std::string_view fallback) {
  const std::string value = text(key, fallback);
  for (const std::string_view c : choices) {
    if (c == value) return value;
  }
  std::string allowed = "must be one of";
  for (const std::string_view c : choices) {
    allowed += ' ';
    allowed += c;
  }
  fail(key, allowed);
}

MapReader MapReader::map(std::string_view key, bool optional) {
  YAML::Node value = node(key);
  if (!value && !optional) {
    missing(key);
  }
  state_->used.emplace(key);
  if (value && !value.IsMap()) fail(key, "must be a mapping of keys");
  auto state = std::make_unique<State>();
  state->source = state_->source;
  state->prefix = path(key) + ".";
  state->node = value ? value : YAML::Node(YAML::NodeType::Map);
  return MapReader(std::move(state));
}

void MapReader::each(std::string_view key, const std::function<void(MapReader&)>& read) {
  const YAML::Node list = node(key);
  if (!list) return;
  state_->used.emplace(key);
  if (!list.IsSequence()) fail(key, "must be a list");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const YAML::Node item = list[i];
    const std::string item_path = path(key) + "[" + std::to_string(i) + "]";
    if (!item.IsMap()) {
      throw ConfigError(located(source(), line_of(item)) + ": " + item_path + ": must be a mapping of keys");
    }
    auto state = std::make_unique<State>();
    state->source = state_->source;
    state->prefix = item_path + ".";
    state->node = item;
    MapReader reader(std::move(state));
    read(reader);
    reader.finish();
  }
}

void MapReader::finish() const {
  for (const auto& item : state_->node) {
    const std::string key = item.first.IsScalar() ? item.first.Scalar() : std::string("?");
    if (state_->used.find(key) == state_->used.end()) {
      throw ConfigError(located(source(), line_of(item.first)) + ": " + path(key) + ": unknown key");
    }
  }
}

}  // namespace trajroi::config
