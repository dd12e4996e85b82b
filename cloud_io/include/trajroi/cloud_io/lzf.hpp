#pragma once

// LZF (Marc Lehmann's liblzf format), the compression of PCD's binary_compressed data: literal
// runs (a control byte c < 32, then c + 1 bytes) and back-references (length in the control's
// top 3 bits, 7 meaning one more length byte; offset in its low 5 bits and the next byte).
#include <cstdint>
#include <optional>
#include <span>
#include <vector>

namespace trajroi::cloud_io {

[[nodiscard]] std::vector<std::uint8_t> lzf_compress(std::span<const std::uint8_t> in);
// nullopt for data that is not LZF or does not give exactly `size` bytes.
[[nodiscard]] std::optional<std::vector<std::uint8_t>> lzf_decompress(std::span<const std::uint8_t> in,
                                                                      std::size_t size);

}  // namespace trajroi::cloud_io
