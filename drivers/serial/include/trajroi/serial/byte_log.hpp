#pragma once

// Recording and replay of serial byte streams.
//
// The recording format (".trjb") keeps every chunk exactly as it was read, with its host
// receive time, so a run replays exactly:
//   header  "TRJBYTES" (8 bytes), format version (uint32 LE, = 1), reserved (uint32, 0)
//   records receive_time_ns (int64 LE), length (uint32 LE, 1 … 1 MiB), the bytes
// A file cut inside a record replays every complete record and counts the cut one.
//
// Raw byte files (a capture with no timestamps, e.g. `cat /dev/ttyACM0 > gnss.ubx`) replay
// in chunks with times synthesised either at a nominal byte rate (a serial line at B baud
// carries B/10 bytes/s) or from the sensor's own clock: a u-blox receiver's epochs (NAV iTOW),
// a VN-100 logger's markers or its frames' TimeStartup.
#include <chrono>
#include <cstdint>
#include <cstdio>
#include <memory>
#include <string>
#include <vector>

#include "trajroi/serial/byte_source.hpp"

namespace trajroi::serial {

inline constexpr char kRecordingMagic[8] = {'T', 'R', 'J', 'B', 'Y', 'T', 'E', 'S'};
inline constexpr std::uint32_t kRecordingVersion = 1;
inline constexpr std::uint32_t kMaxRecordBytes = 1U << 20;

// Appends chunks to a recording. Throws std::runtime_error naming the file when it cannot be
// created or written.
class RecordingWriter {
 public:
  explicit RecordingWriter(const std::string& path);
  ~RecordingWriter();
  RecordingWriter(const RecordingWriter&) = delete;
  RecordingWriter& operator=(const RecordingWriter&) = delete;
  void write(const Chunk& chunk);
  void flush();

 private:
  std::string path_;
  std::FILE* file_ = nullptr;
};

enum class RawTiming : std::uint8_t {
  kNominalRate,  // chunk_bytes per chunk at bytes_per_second
  // One chunk per epoch, cut after its last NAV message (NAV-EOE, else NAV-PVT), at its iTOW:
  // the receiver's own bursts at its own pace. A log without a NAV epoch is an error.
  kUbxTime,
  // The LoggerWavesInIce logger's `M,<millis>` markers when the log has them; else one chunk
  // per VN-100 frame by its TimeStartup when frames carry it; else one chunk per 0xFA sync byte
  // at frames_per_second (nominal byte rate when 0).
  kVn100Time,
};

struct ReplayOptions {
  RawTiming raw_timing = RawTiming::kNominalRate;
  double bytes_per_second = 11'520.0;  // 115200 baud, 8N1
  std::size_t chunk_bytes = 64;
  std::int64_t start_time_ns = 0;  // host time given to the first byte of a raw file
  double frames_per_second = 0.0;  // kVn100Time's last resort
};

// Replays a recording (detected by its magic) or a raw byte file. Throws std::runtime_error
// naming the file when it cannot be read, std::invalid_argument for bad options.
class ReplaySource final : public ByteSource {
 public:
  ReplaySource(const std::string& path, ReplayOptions options = {});
  ReadStatus read(Chunk& chunk, std::chrono::milliseconds timeout) override;
  [[nodiscard]] const SourceCounters& counters() const noexcept override { return counters_; }
  [[nodiscard]] std::string describe() const override { return path_; }

  [[nodiscard]] bool is_recording() const noexcept { return recording_; }
  // Records of a recording cut by the end of the file (0 or 1).
  [[nodiscard]] std::uint64_t truncated_records() const noexcept { return truncated_records_; }

 private:
  struct Span {
    std::size_t offset;
    std::size_t length;
    std::int64_t time_ns;
  };
  void index_recording();
  void index_raw();

  std::string path_;
  ReplayOptions options_;
  std::vector<std::uint8_t> data_;
  std::vector<Span> spans_;
  std::size_t next_ = 0;
  bool recording_ = false;
  std::uint64_t truncated_records_ = 0;
  SourceCounters counters_;
};

}  // namespace trajroi::serial
