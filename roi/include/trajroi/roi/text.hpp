#pragma once

#include <charconv>
#include <cstddef>
#include <span>
#include <string_view>
#include <system_error>

namespace trajroi::roi {

// Calls f(line) for every line of text (without its "\n" or "\r\n"); a last line without a
// newline counts too, an empty text has no lines.
template <typename F>
void for_each_line(std::string_view text, F&& f) {
  std::size_t start = 0;
  while (start < text.size()) {
    std::size_t end = text.find('\n', start);
    if (end == std::string_view::npos) end = text.size();
    std::string_view line = text.substr(start, end - start);
    if (!line.empty() && line.back() == '\r') line.remove_suffix(1);
    f(line);
    start = end + 1;
  }
}

// The line without a `#` comment and without leading/trailing spaces and tabs.
[[nodiscard]] inline std::string_view strip_comment_and_space(std::string_view line) noexcept {
  const std::size_t hash = line.find('#');
  if (hash != std::string_view::npos) line = line.substr(0, hash);
  const std::size_t first = line.find_first_not_of(" \t");
  if (first == std::string_view::npos) return {};
  const std::size_t last = line.find_last_not_of(" \t");
  return line.substr(first, last - first + 1);
}

// Parses comma-separated numbers (spaces around each allowed) into `out`. Returns the number
// of fields, or 0 when a field is not a number in full ("1.5x", "", "--1") or there are more
// fields than `out` holds. "nan" and "inf" parse; callers decide what to do with them.
[[nodiscard]] inline std::size_t parse_csv_doubles(std::string_view content, std::span<double> out) noexcept {
  std::size_t count = 0;
  std::size_t start = 0;
  while (true) {
    std::size_t end = content.find(',', start);
    const bool last = end == std::string_view::npos;
    if (last) end = content.size();
    std::string_view field = content.substr(start, end - start);
    const std::size_t first = field.find_first_not_of(" \t");
    if (first == std::string_view::npos || count == out.size()) return 0;
    field = field.substr(first, field.find_last_not_of(" \t") - first + 1);
    if (field.front() == '+') {  // from_chars rejects a leading '+'; allow one, not "+-1"
      field.remove_prefix(1);
      if (field.empty() || field.front() == '-' || field.front() == '+') return 0;
    }
    const auto [ptr, ec] = std::from_chars(field.data(), field.data() + field.size(), out[count]);
    if (ec != std::errc() || ptr != field.data() + field.size()) return 0;
    ++count;
    if (last) return count;
    start = end + 1;
  }
}

}  // namespace trajroi::roi
