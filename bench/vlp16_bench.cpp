// VLP-16 decode throughput over real captures held in memory (single thread): the MRPT
// capture's 293 strongest-return data packets and nebula's dual-return capture. Goal (issue 3):
// at least 100 M points/s, > 300× a dual-return VLP-16's output. The captures are found
// through TRAJROI_DATA_DIR (default: the build's data folder).
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

Capture load_capture(const char* relative) {
  const char* dir = std::getenv("TRAJROI_DATA_DIR");
  const std::filesystem::path path = std::filesystem::path(dir != nullptr ? dir : TRAJROI_DEFAULT_DATA_DIR) / relative;
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
}

const Capture& mrpt_capture() {
  static const Capture capture = load_capture("velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap");
  return capture;
}

const Capture& dual_capture() {
  static const Capture capture = load_capture("velodyne/vlp16/nebula_vlp16_dual_1673400471.DERIVED.pcap");
  return capture;
}

// The decoder build decode() runs here, as its start-up timing chose it.
const int kDecoderContext = (benchmark::AddCustomContext("vlp16 decoder", describe(decoder_calibration())), 0);

// PacketDecoder alone: bytes to points, output vector reused. `decode`: PacketDecoder::decode
// (the build the start-up timing chose), or one build forced (decode_avx2 only where the
// processor has AVX2).
using DecodeFn = PacketDecoder::Result (PacketDecoder::*)(std::span<const std::uint8_t>, std::vector<Point>&) const;
void BM_DecodePackets(benchmark::State& state, const Capture& (*which)(), DecodeFn decode) {
  if (decode == &PacketDecoder::decode_avx2 && !decoder_calibration().avx2_available) {
    state.SkipWithError("this processor has no AVX2");
    return;
  }
  const Capture& capture = which();
  const PacketDecoder decoder(Calibration::vlp16_default());
  std::vector<Point> points;
  points.reserve(capture.packets.size() * 384);
  std::size_t decoded = 0;
  for (auto _ : state) {
    points.clear();
    for (const auto& packet : capture.packets)
      decoded += (decoder.*decode)(packet, points).points;
    benchmark::DoNotOptimize(points.data());
    benchmark::ClobberMemory();
  }
  state.SetItemsProcessed(static_cast<std::int64_t>(decoded));
  state.counters["packets/s"] =
      benchmark::Counter(static_cast<double>(capture.packets.size()) * static_cast<double>(state.iterations()),
                         benchmark::Counter::kIsRate);
}
BENCHMARK_CAPTURE(BM_DecodePackets, mrpt, mrpt_capture, &PacketDecoder::decode)
    ->Name("vlp16/decode/mrpt")
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_DecodePackets, dual, dual_capture, &PacketDecoder::decode)
    ->Name("vlp16/decode/dual")
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_DecodePackets, mrpt_baseline, mrpt_capture, &PacketDecoder::decode_baseline)
    ->Name("vlp16/decode/mrpt/baseline")
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_DecodePackets, mrpt_avx2, mrpt_capture, &PacketDecoder::decode_avx2)
    ->Name("vlp16/decode/mrpt/avx2")
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_DecodePackets, dual_baseline, dual_capture, &PacketDecoder::decode_baseline)
    ->Name("vlp16/decode/dual/baseline")
    ->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_DecodePackets, dual_avx2, dual_capture, &PacketDecoder::decode_avx2)
    ->Name("vlp16/decode/dual/avx2")
    ->Unit(benchmark::kMicrosecond);

// The whole stream path: validation, model check, sequencing, decoding and frame assembly.
struct CountingSink final : FrameSink {
  std::size_t points = 0;
  void on_frame(const Frame& frame) override { points += frame.points.size(); }
};

void BM_StreamDecoder(benchmark::State& state, const Capture& (*which)()) {
  const Capture& capture = which();
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
BENCHMARK_CAPTURE(BM_StreamDecoder, mrpt, mrpt_capture)->Name("vlp16/stream/mrpt")->Unit(benchmark::kMicrosecond);
BENCHMARK_CAPTURE(BM_StreamDecoder, dual, dual_capture)->Name("vlp16/stream/dual")->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
