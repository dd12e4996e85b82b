// VLP-16 decode throughput over the MRPT capture's 293 data packets held in memory (single
// thread). Goal (issue 3): at least 100 M points/s, > 300× a dual-return VLP-16's output.
// The capture is found through TRAJROI_DATA_DIR (default: the build's data folder).
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <stdexcept>
#include <vector>

#include "machine_context.hpp"
#include "trajroi/vlp16/pcap_source.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace {

using namespace trajroi::vlp16;

struct Capture {
  std::vector<std::vector<std::uint8_t>> packets;
  std::vector<std::int64_t> times;
};

const Capture& mrpt_capture() {
  static const Capture capture = [] {
    const char* dir = std::getenv("TRAJROI_DATA_DIR");
    const std::filesystem::path path = std::filesystem::path(dir != nullptr ? dir : TRAJROI_DEFAULT_DATA_DIR) /
                                       "velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap";
    Capture c;
    PcapSource source(path);
    Datagram d;
    while (source.next(d) == PacketSource::Next::kDatagram) {
      if (d.destination_port != kDataPort) continue;
      c.packets.emplace_back(d.payload.begin(), d.payload.end());
      c.times.push_back(d.receive_time_ns);
    }
    if (c.packets.empty()) throw std::runtime_error(path.string() + ": no data packets");
    return c;
  }();
  return capture;
}

// PacketDecoder alone: bytes to points, output vector reused.
void BM_DecodePackets(benchmark::State& state) {
  const Capture& capture = mrpt_capture();
  const PacketDecoder decoder(Calibration::vlp16_default());
  std::vector<Point> points;
  points.reserve(capture.packets.size() * 384);
  std::size_t decoded = 0;
  for (auto _ : state) {
    points.clear();
    for (const auto& packet : capture.packets)
      decoded += decoder.decode(packet, points).points;
    benchmark::DoNotOptimize(points.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(decoded));
  state.counters["packets/s"] =
      benchmark::Counter(static_cast<double>(capture.packets.size()) * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate);
}
BENCHMARK(BM_DecodePackets)->Name("vlp16/decode/mrpt")->Unit(benchmark::kMicrosecond);

// The whole stream path: validation, model check, sequencing, decoding and frame assembly.
struct CountingSink final : FrameSink {
  std::size_t points = 0;
  void on_frame(const Frame& frame) override { points += frame.points.size(); }
};

void BM_StreamDecoder(benchmark::State& state) {
  const Capture& capture = mrpt_capture();
  std::size_t decoded = 0;
  for (auto _ : state) {
    state.PauseTiming();
    StreamDecoder decoder(Calibration::vlp16_default(), {});
    CountingSink sink;
    state.ResumeTiming();
    for (std::size_t i = 0; i < capture.packets.size(); ++i)
      decoder.on_data_packet(capture.packets[i], capture.times[i], sink);
    decoder.flush(sink);
    decoded += sink.points;
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(decoded));
}
BENCHMARK(BM_StreamDecoder)->Name("vlp16/stream/mrpt")->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
