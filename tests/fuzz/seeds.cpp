// Seed inputs for the fuzz targets that need cutting or encoding (scripts/fuzz.sh copies the
// text and byte-stream seeds itself): single packets and datagram streams from captures, and
// encoded trajectory messages.
// Usage: fuzz_seeds OUT_DIR PCAP...
#include <cstdint>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "trajroi/trajectory_t.hpp"
#include "trajroi/vlp16/pcap_source.hpp"

namespace fs = std::filesystem;

namespace {

void write(const fs::path& file, const std::vector<std::uint8_t>& bytes) {
  fs::create_directories(file.parent_path());
  std::ofstream out(file, std::ios::binary);
  out.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

// Packets 0 … 7 alone, and a stream (fuzz_input.hpp's datagram format) of the first 48.
void packet_seeds(const fs::path& pcap, const fs::path& out, int& count) {
  trajroi::vlp16::PcapSource source(pcap);
  trajroi::vlp16::Datagram d;
  std::vector<std::uint8_t> stream;
  for (int k = 0; k < 48 && source.next(d) == trajroi::vlp16::PacketSource::Next::kDatagram; ++k) {
    const bool position = d.destination_port == trajroi::vlp16::kPositionPort;
    if (k < 8 || position) {
      write(out / (pcap.stem().string() + "_" + std::to_string(k) + (position ? "_position" : "_data")),
            std::vector<std::uint8_t>(d.payload.begin(), d.payload.end()));
      ++count;
    }
    const auto n = static_cast<unsigned>(d.payload.size()) | (position ? 0x8000U : 0U);
    stream.push_back(static_cast<std::uint8_t>(n & 0xFFU));
    stream.push_back(static_cast<std::uint8_t>(n >> 8U));
    stream.insert(stream.end(), d.payload.begin(), d.payload.end());
  }
  write(out / (pcap.stem().string() + "_stream"), stream);
  ++count;
}

void trajectory_seeds(const fs::path& out, int& count) {
  trajroi::trajectory_t m;
  m.id = 3;
  m.coordinates = trajroi::trajectory_t::GLOBAL_XY;
  m.u = {-12.0, 0.0, 3.0, 3.0};
  m.v = {-2.0, -2.0, 1.0, 11.0};
  m.num_waypoints = static_cast<std::int32_t>(m.u.size());
  for (int variant = 0; variant < 2; ++variant) {
    if (variant == 1) {
      m.coordinates = trajroi::trajectory_t::LAT_LON;
      m.u = {48.1351, 48.1352, 48.1354};
      m.v = {11.5820, 11.5822, 11.5822};
      m.num_waypoints = 3;
    }
    std::vector<std::uint8_t> bytes(static_cast<std::size_t>(m.getEncodedSize()));
    m.encode(bytes.data(), 0, static_cast<int>(bytes.size()));
    write(out / ("trajectory_" + std::to_string(variant)), bytes);
    ++count;
  }
}

}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: fuzz_seeds OUT_DIR PCAP...\n");
    return 2;
  }
  const fs::path out(argv[1]);
  int count = 0;
  trajectory_seeds(out / "trajectory_message", count);
  for (int i = 2; i < argc; ++i) {
    try {
      packet_seeds(argv[i], out / "vlp16_packets", count);
    } catch (const std::exception& e) {
      std::fprintf(stderr, "fuzz_seeds: %s: %s\n", argv[i], e.what());
      return 1;
    }
  }
  std::printf("fuzz_seeds: %d seeds in %s\n", count, out.c_str());
  return 0;
}
