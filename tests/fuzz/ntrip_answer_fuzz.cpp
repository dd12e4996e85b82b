// What an NTRIP caster (or anything listening on its port) answers: the answer's head, a source
// table body, and an NTRIP 2.0 chunked stream cut anywhere. Each input is a value or a named
// error; nothing is read past its end.
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "trajroi/corrections/ntrip.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string_view text(reinterpret_cast<const char*>(data), size);
  for (const bool closed : {false, true}) {
    const trajroi::corrections::NtripAnswer a = trajroi::corrections::parse_ntrip_answer(text, closed);
    if (a.head_bytes > size) __builtin_trap();
  }
  (void)trajroi::corrections::parse_source_table(text);
  trajroi::corrections::ChunkedDecoder chunks;
  std::vector<std::uint8_t> out;
  const std::size_t half = size / 2;
  if (chunks.feed(std::span(data, half), out) != trajroi::corrections::ChunkedDecoder::Status::kError)
    (void)chunks.feed(std::span(data + half, size - half), out);
  if (out.size() > size) __builtin_trap();
  return 0;
}
