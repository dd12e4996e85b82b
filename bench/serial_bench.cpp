// Framer throughput on the largest real serial logs, held in memory and fed in 64-byte chunks
// (a typical serial read). Goal (issue 4): at least 1,000× what a serial port can deliver
// (about 0.1 MB/s at 921600 baud), i.e. ≥ 100 MB/s. The "x_serial" counter is that ratio
// (Google Benchmark prints it with a "/s" suffix: read "16.3k/s" as 16,300×).
// Logs are found through TRAJROI_DATA_DIR (default: the build's data folder).
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "machine_context.hpp"
#include "trajroi/ublox/framer.hpp"
#include "trajroi/ublox/messages.hpp"
#include "trajroi/vn100/decoder.hpp"
#include "trajroi/vn100/framer.hpp"

namespace {

constexpr double kSerialBytesPerSecond = 92'160.0;  // 921600 baud, 8N1
constexpr std::size_t kChunk = 64;

std::vector<std::uint8_t> load(const char* relative) {
  const char* dir = std::getenv("TRAJROI_DATA_DIR");
  const std::filesystem::path path = std::filesystem::path(dir != nullptr ? dir : TRAJROI_DEFAULT_DATA_DIR) / relative;
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path.string() + ": cannot open");
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

void report(benchmark::State& state, std::size_t bytes, std::uint64_t frames) {
  const double total = static_cast<double>(bytes) * static_cast<double>(state.iterations());
  state.SetBytesProcessed(static_cast<std::int64_t>(total));
  state.counters["frames/s"] = benchmark::Counter(static_cast<double>(frames), benchmark::Counter::kIsRate);
  state.counters["x_serial"] = benchmark::Counter(total / kSerialBytesPerSecond, benchmark::Counter::kIsRate);
}

// UBX framing plus NAV-PVT decoding of every fix.
void BM_Ubx(benchmark::State& state, const char* file) {
  const std::vector<std::uint8_t> bytes = load(file);
  std::uint64_t frames = 0;
  std::int64_t sum = 0;
  for (auto _ : state) {
    trajroi::ublox::Framer framer;
    const auto sink = [&](const trajroi::ublox::Message& m) {
      ++frames;
      if (m.msg_class == trajroi::ublox::kClassNav && m.msg_id == trajroi::ublox::kIdNavPvt) {
        sum += trajroi::ublox::decode_nav_pvt(m.payload).value.lat_e7;
      }
    };
    for (std::size_t at = 0; at < bytes.size(); at += kChunk) {
      framer.feed(std::span<const std::uint8_t>(bytes).subspan(at, std::min(kChunk, bytes.size() - at)), sink);
    }
    framer.finish(sink);
    benchmark::DoNotOptimize(sum);
  }
  report(state, bytes.size(), frames);
}

// VN-100 framing (CRC included) plus decoding of every frame.
void BM_Vn100(benchmark::State& state, const char* file) {
  const std::vector<std::uint8_t> bytes = load(file);
  std::uint64_t frames = 0;
  trajroi::vn100::Sample sample;
  for (auto _ : state) {
    trajroi::vn100::Framer framer;
    const auto sink = [&](std::span<const std::uint8_t> frame) {
      ++frames;
      benchmark::DoNotOptimize(trajroi::vn100::decode(frame, sample));
    };
    for (std::size_t at = 0; at < bytes.size(); at += kChunk) {
      framer.feed(std::span<const std::uint8_t>(bytes).subspan(at, std::min(kChunk, bytes.size() - at)), sink);
    }
    framer.finish(sink);
  }
  report(state, bytes.size(), frames);
}

BENCHMARK_CAPTURE(BM_Ubx, glo, "ublox/gpsd/ublox-glo.log")->Name("ubx/glo (169 kB)")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Ubx, f9r, "ublox/gpsd/ublox-zed-f9r.log")
    ->Name("ubx/zed-f9r (158 kB, NMEA+RTCM3 mixed)")
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_Vn100, f00379, "vectornav/LoggerWavesInIce_F00379.raw")
    ->Name("vn100/F00379 raw (1.4 MB)")
    ->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
