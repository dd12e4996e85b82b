#include "raw_timing.hpp"

#include <optional>

#include "trajroi/framing/little_endian.hpp"
#include "trajroi/ublox/framer.hpp"
#include "trajroi/ublox/messages.hpp"

namespace trajroi::serial::raw_timing {
namespace {

constexpr std::int64_t kWeek_ms = 7LL * 24 * 3600 * 1000;
constexpr std::uint8_t kIdNavEoe = 0x61;

}  // namespace

std::vector<TimedSpan> ubx_epochs(std::span<const std::uint8_t> data, std::int64_t start_ns) {
  // The receiver's own framing (the daemon's framer), a byte at a time so that each message's
  // end is known.
  const auto each_message = [data](auto&& on_message) {
    ublox::Framer framer;
    for (std::size_t i = 0; i < data.size(); ++i)
      framer.feed(data.subspan(i, 1), [&](const ublox::Message& m) { on_message(m, i + 1); });
  };
  bool has_eoe = false;
  each_message([&](const ublox::Message& m, std::size_t) {
    has_eoe = has_eoe || (m.msg_class == ublox::kClassNav && m.msg_id == kIdNavEoe);
  });
  const std::uint8_t epoch_end = has_eoe ? kIdNavEoe : ublox::kIdNavPvt;
  std::vector<TimedSpan> out;
  std::size_t chunk_start = 0;
  std::optional<std::int64_t> first_itow;
  std::int64_t week_base = 0, last_itow = -1;
  each_message([&](const ublox::Message& m, std::size_t end) {
    if (m.msg_class != ublox::kClassNav || m.msg_id != epoch_end || m.payload.size() < 4) return;
    const std::int64_t itow = framing::le_u32(m.payload, 0);
    if (last_itow >= 0 && itow + kWeek_ms / 2 < last_itow) week_base += kWeek_ms;
    last_itow = itow;
    if (!first_itow) first_itow = itow;
    std::int64_t t = start_ns + (week_base + itow - *first_itow) * 1'000'000;
    if (!out.empty() && t < out.back().time_ns) t = out.back().time_ns;
    out.push_back({chunk_start, end - chunk_start, t});
    chunk_start = end;
  });
  if (!out.empty() && chunk_start < data.size())
    out.push_back({chunk_start, data.size() - chunk_start, out.back().time_ns});
  return out;
}

std::vector<TimedSpan> logger_markers(std::span<const std::uint8_t> b, std::int64_t start_ns) {
  std::vector<TimedSpan> out;
  std::size_t chunk_start = 0;
  std::optional<std::int64_t> first_ms;
  for (std::size_t i = 0; i + 4 < b.size(); ++i) {
    if (!(b[i] == 'M' && b[i + 1] == ',' && (i == 0 || b[i - 1] == '\n'))) continue;
    std::size_t k = i + 2;
    std::int64_t ms = 0;
    while (k < b.size() && k < i + 14 && b[k] >= '0' && b[k] <= '9')
      ms = ms * 10 + (b[k++] - '0');
    if (k == i + 2 || k + 1 >= b.size() || b[k] != '\r' || b[k + 1] != '\n') continue;
    if (!first_ms) first_ms = ms;
    std::int64_t t = start_ns + (ms - *first_ms) * 1'000'000;
    // A marker out of order (bytes that only looked like one) keeps the previous time.
    if (!out.empty() && (t < out.back().time_ns || t > out.back().time_ns + 10'000'000'000)) t = out.back().time_ns;
    out.push_back({chunk_start, k + 2 - chunk_start, t});
    chunk_start = k + 2;
  }
  if (!out.empty() && chunk_start < b.size()) out.push_back({chunk_start, b.size() - chunk_start, out.back().time_ns});
  return out;
}

std::vector<TimedSpan> at_sync_bytes(std::span<const std::uint8_t> b, std::uint8_t sync, double per_second,
                                     std::int64_t start_ns) {
  std::vector<TimedSpan> out;
  const auto period_ns = static_cast<std::int64_t>(1e9 / per_second);
  std::size_t chunk_start = 0;
  for (std::size_t i = 1; i <= b.size(); ++i) {
    if (i == b.size() || b[i] == sync) {
      out.push_back({chunk_start, i - chunk_start, start_ns + static_cast<std::int64_t>(out.size()) * period_ns});
      chunk_start = i;
    }
  }
  return out;
}

}  // namespace trajroi::serial::raw_timing
