#include "trajroi/cloud_io/lzf.hpp"

#include <array>
#include <cstring>

namespace trajroi::cloud_io {

namespace {

constexpr std::size_t kMaxLiteral = 32;   // a literal run's longest
constexpr std::size_t kMaxOffset = 8192;  // a back-reference reaches this far back
constexpr std::size_t kMaxMatch = 264;    // and copies at most this much (7 + 255 + 2)
constexpr unsigned kHashBits = 16;

std::uint32_t hash3(const std::uint8_t* p) noexcept {
  const std::uint32_t v = (std::uint32_t{p[0]} << 16) | (std::uint32_t{p[1]} << 8) | p[2];
  return (v * 2654435761U) >> (32 - kHashBits);
}

}  // namespace

std::vector<std::uint8_t> lzf_compress(std::span<const std::uint8_t> in) {
  std::vector<std::uint8_t> out;
  out.reserve(in.size() + in.size() / 16 + 64);
  std::vector<std::uint32_t> table(std::size_t{1} << kHashBits, ~0U);
  std::size_t literal_start = 0;  // first byte of the pending literal run
  const auto flush_literals = [&](std::size_t end) {
    while (literal_start < end) {
      const std::size_t n = std::min(kMaxLiteral, end - literal_start);
      out.push_back(static_cast<std::uint8_t>(n - 1));
      out.insert(out.end(), in.begin() + static_cast<std::ptrdiff_t>(literal_start),
                 in.begin() + static_cast<std::ptrdiff_t>(literal_start + n));
      literal_start += n;
    }
  };
  std::size_t i = 0;
  while (i + 2 < in.size()) {
    const std::uint32_t h = hash3(&in[i]);
    const std::uint32_t candidate = table[h];
    table[h] = static_cast<std::uint32_t>(i);
    if (candidate != ~0U && i - candidate <= kMaxOffset && std::memcmp(&in[candidate], &in[i], 3) == 0) {
      std::size_t length = 3;
      const std::size_t limit = std::min(kMaxMatch, in.size() - i);
      while (length < limit && in[candidate + length] == in[i + length])
        ++length;
      flush_literals(i);
      const std::size_t offset = i - candidate - 1;
      const std::size_t coded = length - 2;  // 1 … 262
      if (coded < 7) {
        out.push_back(static_cast<std::uint8_t>((coded << 5) | (offset >> 8)));
      } else {
        out.push_back(static_cast<std::uint8_t>((7U << 5) | (offset >> 8)));
        out.push_back(static_cast<std::uint8_t>(coded - 7));
      }
      out.push_back(static_cast<std::uint8_t>(offset & 0xFF));
      i += length;
      literal_start = i;
      continue;
    }
    ++i;
  }
  flush_literals(in.size());
  return out;
}

std::optional<std::vector<std::uint8_t>> lzf_decompress(std::span<const std::uint8_t> in, std::size_t size) {
  std::vector<std::uint8_t> out;
  out.reserve(size);
  std::size_t i = 0;
  while (i < in.size()) {
    const std::size_t control = in[i++];
    if (control < 32) {
      const std::size_t n = control + 1;
      if (i + n > in.size() || out.size() + n > size) return std::nullopt;
      out.insert(out.end(), in.begin() + static_cast<std::ptrdiff_t>(i),
                 in.begin() + static_cast<std::ptrdiff_t>(i + n));
      i += n;
      continue;
    }
    std::size_t length = control >> 5;
    if (length == 7) {
      if (i >= in.size()) return std::nullopt;
      length += in[i++];
    }
    if (i >= in.size()) return std::nullopt;
    const std::size_t back = ((control & 0x1F) << 8) + in[i++] + 1;
    length += 2;
    if (back > out.size() || out.size() + length > size) return std::nullopt;
    const std::size_t from = out.size() - back;
    for (std::size_t k = 0; k < length; ++k)
      out.push_back(out[from + k]);  // overlapping copies repeat, byte by byte
  }
  if (out.size() != size) return std::nullopt;
  return out;
}

}  // namespace trajroi::cloud_io
