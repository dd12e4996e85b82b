#pragma once

// A resumable framer over a byte stream in which frames of one protocol are mixed with
// anything else (other protocols, text, line noise). The protocol says where a frame may
// start, how long it claims to be and whether its checksum holds; this class does the rest:
//
//  - bytes arrive in chunks of any size; a frame split across chunks is kept until complete,
//    so feeding a stream byte by byte emits exactly the frames that feeding it whole does;
//  - a candidate whose length is impossible or whose checksum fails is dropped by moving ONE
//    byte past its sync, never past its claimed length: a corrupt length field cannot
//    swallow the good frames behind it;
//  - every byte that is not part of a good frame is counted (skipped_bytes), and every
//    rejected candidate is counted by reason.
//
// The buffer is allocated once (twice the largest frame); feed() never allocates.
#include <algorithm>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <stdexcept>
#include <vector>

namespace trajroi::framing {

// What a protocol makes of the bytes at a sync candidate.
struct Verdict {
  enum class Kind : std::uint8_t {
    kNeedMore,   // cannot decide before `length` bytes are available
    kNotSync,    // the first byte was a sync byte, the rest does not look like a header
    kBadLength,  // the header claims a length beyond the configured maximum
    kUnsizable,  // the header describes a frame whose size cannot be computed
    kFrame,      // a complete frame of `length` bytes, still to be checksummed
  };
  Kind kind = Kind::kNeedMore;
  std::size_t length = 0;
};

struct FramerCounters {
  std::uint64_t bytes = 0;            // every byte fed
  std::uint64_t frames = 0;           // good frames emitted
  std::uint64_t frame_bytes = 0;      // bytes inside good frames
  std::uint64_t skipped_bytes = 0;    // bytes outside any good frame (garbage, other protocols)
  std::uint64_t checksum_errors = 0;  // candidates whose checksum / CRC failed
  std::uint64_t bad_lengths = 0;      // candidates claiming an impossible length
  std::uint64_t unsizable = 0;        // candidates whose size cannot be computed
  std::uint64_t truncated = 0;        // candidates cut by the end of the stream (finish())
};

// Protocol requirements (see drivers/ublox and drivers/vn100):
//   static constexpr std::uint8_t kSync;                  first byte of every frame
//   std::size_t max_frame_bytes() const;                  bound on any frame, header included
//   Verdict inspect(std::span<const std::uint8_t>) const; bytes from a sync candidate on
//   bool checksum_ok(std::span<const std::uint8_t>) const; a whole frame
template <class Protocol>
class StreamFramer {
 public:
  explicit StreamFramer(Protocol protocol = Protocol{})
      : protocol_(std::move(protocol)), buffer_(2 * protocol_.max_frame_bytes()) {
    if (protocol_.max_frame_bytes() == 0) throw std::invalid_argument("framer: zero maximum frame size");
  }

  // Consumes `bytes`; calls sink(std::span<const std::uint8_t> frame) for every good frame,
  // in stream order. The span is valid only during the call.
  template <class Sink>
  void feed(std::span<const std::uint8_t> bytes, Sink&& sink) {
    counters_.bytes += bytes.size();
    while (!bytes.empty()) {
      const std::size_t n = std::min(bytes.size(), buffer_.size() - size_);
      std::memcpy(buffer_.data() + size_, bytes.data(), n);
      size_ += n;
      bytes = bytes.subspan(n);
      std::size_t used = scan(sink, /*at_end=*/false);
      if (used == 0 && size_ == buffer_.size()) {
        // Only reachable if the protocol asked for more than max_frame_bytes(): drop the
        // candidate rather than stall.
        ++counters_.bad_lengths;
        ++counters_.skipped_bytes;
        used = 1;
      }
      consume(used);
    }
  }

  // The stream has ended: frames that can still be completed from the pending bytes are
  // emitted; candidates cut by the end are counted as truncated and their bytes as skipped.
  template <class Sink>
  void finish(Sink&& sink) {
    consume(scan(sink, /*at_end=*/true));
  }

  [[nodiscard]] const FramerCounters& counters() const noexcept { return counters_; }
  [[nodiscard]] std::size_t pending_bytes() const noexcept { return size_; }
  [[nodiscard]] const Protocol& protocol() const noexcept { return protocol_; }

 private:
  using Kind = Verdict::Kind;

  template <class Sink>
  std::size_t scan(Sink& sink, bool at_end) {
    const std::uint8_t* data = buffer_.data();
    std::size_t at = 0;
    while (at < size_) {
      const auto* sync = static_cast<const std::uint8_t*>(std::memchr(data + at, Protocol::kSync, size_ - at));
      const std::size_t start = sync == nullptr ? size_ : static_cast<std::size_t>(sync - data);
      counters_.skipped_bytes += start - at;
      at = start;
      if (at == size_) break;

      const std::span<const std::uint8_t> candidate(data + at, size_ - at);
      const Verdict verdict = protocol_.inspect(candidate);
      bool good = false;
      switch (verdict.kind) {
        case Kind::kNeedMore:
          if (!at_end) return at;  // keep the candidate for the next chunk
          ++counters_.truncated;
          break;
        case Kind::kNotSync:
          break;
        case Kind::kBadLength:
          ++counters_.bad_lengths;
          break;
        case Kind::kUnsizable:
          ++counters_.unsizable;
          break;
        case Kind::kFrame:
          if (verdict.length > candidate.size()) {
            if (!at_end) return at;
            ++counters_.truncated;
          } else if (protocol_.checksum_ok(candidate.first(verdict.length))) {
            good = true;
          } else {
            ++counters_.checksum_errors;
          }
          break;
      }
      if (good) {
        ++counters_.frames;
        counters_.frame_bytes += verdict.length;
        sink(candidate.first(verdict.length));
        at += verdict.length;
      } else {
        ++counters_.skipped_bytes;  // resume one byte after the false sync
        ++at;
      }
    }
    return at;
  }

  void consume(std::size_t n) noexcept {
    if (n == 0) return;
    std::memmove(buffer_.data(), buffer_.data() + n, size_ - n);
    size_ -= n;
  }

  Protocol protocol_;
  std::vector<std::uint8_t> buffer_;
  std::size_t size_ = 0;
  FramerCounters counters_;
};

}  // namespace trajroi::framing
