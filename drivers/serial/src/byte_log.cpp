#include "trajroi/serial/byte_log.hpp"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstring>
#include <fstream>
#include <stdexcept>

#include "raw_timing.hpp"
#include "trajroi/framing/little_endian.hpp"
#include "trajroi/vn100/decoder.hpp"
#include "trajroi/vn100/framer.hpp"

namespace trajroi::serial {

namespace {

constexpr std::size_t kHeaderBytes = 16;
constexpr std::size_t kRecordHeaderBytes = 12;

// Whether any CRC-valid VN-100 frame of the file carries TimeStartup.
bool has_vn100_time_startup(std::span<const std::uint8_t> bytes) {
  bool found = false;
  vn100::Framer framer;
  framer.feed(bytes, [&found](std::span<const std::uint8_t> frame) {
    vn100::Sample s;
    found = found || (vn100::decode(frame, s) && s.has(vn100::Field::kTimeStartup));
  });
  return found;
}

std::string system_error(const std::string& path, const char* what) {
  return path + ": " + what + ": " + std::strerror(errno);
}

}  // namespace

// ---- RecordingWriter ------------------------------------------------------------------------

RecordingWriter::RecordingWriter(const std::string& path) : path_(path), file_(std::fopen(path.c_str(), "wb")) {
  if (file_ == nullptr) throw std::runtime_error(system_error(path, "cannot create recording"));
  std::vector<std::uint8_t> header(kRecordingMagic, kRecordingMagic + sizeof kRecordingMagic);
  framing::put_le_u32(header, kRecordingVersion);
  framing::put_le_u32(header, 0);
  if (std::fwrite(header.data(), 1, header.size(), file_) != header.size()) {
    std::fclose(file_);
    throw std::runtime_error(system_error(path, "cannot write recording header"));
  }
}

RecordingWriter::~RecordingWriter() {
  if (file_ != nullptr) std::fclose(file_);
}

void RecordingWriter::write(const Chunk& chunk) {
  for (std::size_t at = 0; at < chunk.bytes.size(); at += kMaxRecordBytes) {
    const std::size_t n = std::min<std::size_t>(kMaxRecordBytes, chunk.bytes.size() - at);
    std::vector<std::uint8_t> header;
    framing::put_le_u64(header, static_cast<std::uint64_t>(chunk.receive_time_ns));
    framing::put_le_u32(header, static_cast<std::uint32_t>(n));
    if (std::fwrite(header.data(), 1, header.size(), file_) != header.size() ||
        std::fwrite(chunk.bytes.data() + at, 1, n, file_) != n) {
      throw std::runtime_error(system_error(path_, "cannot write recording"));
    }
  }
}

void RecordingWriter::flush() {
  if (std::fflush(file_) != 0) throw std::runtime_error(system_error(path_, "cannot flush recording"));
}

// ---- ReplaySource ---------------------------------------------------------------------------

ReplaySource::ReplaySource(const std::string& path, ReplayOptions options) : path_(path), options_(options) {
  if (!(options_.bytes_per_second > 0.0) || options_.chunk_bytes == 0) {
    throw std::invalid_argument("replay " + path + ": the byte rate and the chunk size must be > 0");
  }
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(system_error(path, "cannot open replay file"));
  in.seekg(0, std::ios::end);
  const std::streamoff size = in.tellg();
  in.seekg(0);
  data_.resize(static_cast<std::size_t>(std::max<std::streamoff>(size, 0)));
  if (!in.read(reinterpret_cast<char*>(data_.data()), static_cast<std::streamsize>(data_.size()))) {
    throw std::runtime_error(system_error(path, "cannot read replay file"));
  }
  recording_ =
      data_.size() >= sizeof kRecordingMagic && std::memcmp(data_.data(), kRecordingMagic, sizeof kRecordingMagic) == 0;
  if (recording_) {
    index_recording();
  } else {
    index_raw();
  }
}

void ReplaySource::index_recording() {
  if (data_.size() < kHeaderBytes) {
    truncated_records_ = 1;
    return;
  }
  const std::span<const std::uint8_t> bytes(data_);
  const std::uint32_t version = framing::le_u32(bytes, 8);
  if (version != kRecordingVersion) {
    throw std::runtime_error(path_ + ": recording format version " + std::to_string(version) + " is not " +
                             std::to_string(kRecordingVersion));
  }
  std::size_t at = kHeaderBytes;
  while (at < data_.size()) {
    if (data_.size() - at < kRecordHeaderBytes) {
      truncated_records_ = 1;
      break;
    }
    const auto time_ns = static_cast<std::int64_t>(framing::le_u64(bytes, at));
    const std::uint32_t length = framing::le_u32(bytes, at + 8);
    if (length == 0 || length > kMaxRecordBytes) {
      throw std::runtime_error(path_ + ": corrupt record at byte " + std::to_string(at) + " (length " +
                               std::to_string(length) + ")");
    }
    if (data_.size() - at - kRecordHeaderBytes < length) {
      truncated_records_ = 1;
      break;
    }
    spans_.push_back({at + kRecordHeaderBytes, length, time_ns});
    at += kRecordHeaderBytes + length;
  }
}

void ReplaySource::index_raw() {
  const double ns_per_byte = 1e9 / options_.bytes_per_second;
  const auto nominal = [&](std::size_t offset) {
    return options_.start_time_ns + static_cast<std::int64_t>(std::llround(static_cast<double>(offset) * ns_per_byte));
  };
  const std::span<const std::uint8_t> bytes(data_);
  if (options_.raw_timing == RawTiming::kNominalRate) {
    for (std::size_t at = 0; at < data_.size(); at += options_.chunk_bytes) {
      const std::size_t n = std::min(options_.chunk_bytes, data_.size() - at);
      spans_.push_back({at, n, nominal(at + n)});
    }
    return;
  }

  const auto take = [this](const std::vector<raw_timing::TimedSpan>& spans) {
    for (const raw_timing::TimedSpan& t : spans)
      spans_.push_back({t.offset, t.length, t.time_ns});
    return !spans.empty();
  };
  if (options_.raw_timing == RawTiming::kUbxTime) {
    if (!take(raw_timing::ubx_epochs(bytes, options_.start_time_ns)) && !data_.empty()) {
      throw std::runtime_error(path_ + ": no UBX NAV epoch to time the log by");
    }
    return;
  }
  if (take(raw_timing::logger_markers(bytes, options_.start_time_ns))) return;
  if (options_.frames_per_second > 0.0 && !has_vn100_time_startup(bytes)) {
    (void)take(raw_timing::at_sync_bytes(bytes, vn100::kSync, options_.frames_per_second, options_.start_time_ns));
    return;
  }

  // Frame the file; each frame closes a chunk that starts where the previous one ended.
  std::size_t chunk_start = 0;
  std::size_t consumed = 0;
  std::int64_t last_time = options_.start_time_ns;
  bool have_sensor_time = false;
  std::int64_t sensor0 = 0;  // sensor clock (ns) of the first timed frame
  std::int64_t host0 = 0;    // host time given to it
  std::size_t last_timed_end = 0;
  std::int64_t last_timed_time = 0;

  const auto close_chunk = [&](std::size_t end, bool timed, std::int64_t sensor_ns) {
    std::int64_t t = 0;
    if (timed) {
      if (!have_sensor_time) {
        have_sensor_time = true;
        sensor0 = sensor_ns;
        host0 = std::max(last_time, nominal(end));
      }
      t = host0 + (sensor_ns - sensor0);
      last_timed_end = end;
      last_timed_time = t;
    } else if (have_sensor_time) {
      t = last_timed_time +
          static_cast<std::int64_t>(std::llround(static_cast<double>(end - last_timed_end) * ns_per_byte));
    } else {
      t = nominal(end);
    }
    t = std::max(t, last_time);  // never backwards
    last_time = t;
    if (end == chunk_start) return;  // several frames completed by the same byte
    spans_.push_back({chunk_start, end - chunk_start, t});
    chunk_start = end;
  };

  // The file is fed one byte at a time so that a frame's end offset is the byte that
  // completed it. (A frame held behind a false candidate comes out later, with that
  // candidate's bytes; the chunk then simply ends there. No byte is lost or reordered.)
  const auto feed_and_close = [&](auto& framer, auto&& on_frame) {
    for (std::size_t at = 0; at < data_.size(); ++at) {
      consumed = at + 1;
      framer.feed(bytes.subspan(at, 1), on_frame);
    }
    framer.finish(on_frame);
  };

  vn100::Framer framer;
  feed_and_close(framer, [&](std::span<const std::uint8_t> frame) {
    vn100::Sample s;
    const bool timed = vn100::decode(frame, s) && s.has(vn100::Field::kTimeStartup);
    close_chunk(consumed, timed, timed ? static_cast<std::int64_t>(s.time_startup_ns) : 0);
  });
  if (chunk_start < data_.size()) close_chunk(data_.size(), false, 0);
}

// Read as fast as asked: pacing is the caller's (inputs::Pacer, the one pacer).
ReadStatus ReplaySource::read(Chunk& chunk, std::chrono::milliseconds /*timeout*/) {
  if (next_ >= spans_.size()) return ReadStatus::kEnd;
  const Span& s = spans_[next_];
  chunk.bytes = std::span<const std::uint8_t>(data_).subspan(s.offset, s.length);
  chunk.receive_time_ns = s.time_ns;
  ++next_;
  ++counters_.chunks;
  counters_.bytes += s.length;
  return ReadStatus::kData;
}

}  // namespace trajroi::serial
