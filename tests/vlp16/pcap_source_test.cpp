// The pcap source on its own: real captures of ../shared/data cut, filtered and truncated while
// read, every link type it reads, and captures read in place agreeing with libpcap's reading of
// the same bytes datagram for datagram.
#include "trajroi/vlp16/pcap_source.hpp"

#include <fcntl.h>
#include <gtest/gtest.h>
#include <signal.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <string>
#include <thread>
#include <vector>

#include "test_data.hpp"
#include "trajroi/vlp16/packet.hpp"

namespace trajroi::vlp16 {
namespace {

// A capture cut inside a record: every whole record before the cut is delivered, then an
// error that says so.
TEST(Vlp16PcapSource, TruncatedCaptureDeliversEveryWholeRecordThenAnError) {
  TRAJROI_REQUIRE_DATA(path, "velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap");
  const std::string bytes = test::read_file(path);
  // Walk the record headers (24-byte file header, 16-byte record headers) to find where the
  // 100th record ends, and cut 500 bytes into the 101st.
  std::size_t at = 24;
  for (int record = 0; record < 100; ++record) {
    std::uint32_t captured = 0;
    std::memcpy(&captured, bytes.data() + at + 8, 4);
    at += 16 + captured;
  }
  const auto cut = test::scratch_path("trajroi_truncated.pcap");
  {
    std::ofstream out(cut, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(at + 500));
  }
  PcapSource source(cut);
  Datagram datagram;
  std::size_t delivered = 0;
  PacketSource::Next next;
  while ((next = source.next(datagram)) == PacketSource::Next::kDatagram)
    ++delivered;
  EXPECT_EQ(delivered, 100u);
  EXPECT_EQ(next, PacketSource::Next::kError);
  EXPECT_NE(source.error().find("truncated"), std::string::npos) << source.error();
  std::filesystem::remove(cut);
}

// A port filter leaves the other datagrams out (pacing is inputs::Pacer's, tested there).
TEST(Vlp16PcapSource, APortFilterLeavesTheOtherDatagramsOut) {
  TRAJROI_REQUIRE_DATA(path, "velodyne/vlp16/rust-lidar-utils_velodyne_vlp16_2014_productid0x21.pcap");
  PcapOptions options;
  options.ports = {kDataPort};
  PcapSource source(path, options);
  Datagram datagram;
  std::size_t delivered = 0;
  while (source.next(datagram) == PacketSource::Next::kDatagram) {
    EXPECT_EQ(datagram.destination_port, kDataPort);
    ++delivered;
  }
  EXPECT_EQ(delivered, 84u);
  EXPECT_EQ(source.skipped_records(), 16u);  // the position packets
}

// Every link type the pcap source reads, in captures written here (nanosecond pcap): one
// VLP-16 data packet to port 2368 and one datagram to another port, framed as each link
// layer frames IPv4/UDP.
// (Appends byte by byte: GCC 12 warns falsely on vector::insert of small arrays at -O3.)
std::vector<std::uint8_t> concat(std::vector<std::uint8_t> head, const std::vector<std::uint8_t>& tail) {
  head.reserve(head.size() + tail.size());
  for (const std::uint8_t b : tail)
    head.push_back(b);
  return head;
}

std::vector<std::uint8_t> ipv4_udp(std::uint16_t port, const std::vector<std::uint8_t>& payload) {
  const std::size_t total = 20 + 8 + payload.size();
  const auto hi = [](std::size_t v) { return static_cast<std::uint8_t>(v >> 8); };
  const auto lo = [](std::size_t v) { return static_cast<std::uint8_t>(v); };
  const std::array<std::uint8_t, 28> header = {0x45,
                                               0,
                                               hi(total),
                                               lo(total),
                                               0,
                                               0,
                                               0,
                                               0,
                                               64,
                                               17 /* UDP */,
                                               0,
                                               0,  // IPv4, no checksum
                                               192,
                                               168,
                                               1,
                                               201,
                                               255,
                                               255,
                                               255,
                                               255,  // addresses
                                               hi(port),
                                               lo(port),
                                               hi(port),
                                               lo(port),  // source, destination port
                                               hi(8 + payload.size()),
                                               lo(8 + payload.size()),
                                               0,
                                               0};  // UDP length, no checksum
  return concat({header.begin(), header.end()}, payload);
}

void write_pcap(const std::filesystem::path& path, std::uint32_t link_type,
                const std::vector<std::vector<std::uint8_t>>& frames) {
  std::string bytes;
  const auto put32 = [&](std::uint32_t v) { bytes.append(reinterpret_cast<const char*>(&v), 4); };
  const auto put16 = [&](std::uint16_t v) { bytes.append(reinterpret_cast<const char*>(&v), 2); };
  put32(0xA1B23C4D);  // nanosecond pcap, host (little-endian) order
  put16(2);
  put16(4);
  put32(0);
  put32(0);
  put32(65535);
  put32(link_type);
  std::uint32_t ns = 0;
  for (const auto& frame : frames) {
    put32(1'600'000'000);
    put32(ns += 1'327'000);
    put32(static_cast<std::uint32_t>(frame.size()));
    put32(static_cast<std::uint32_t>(frame.size()));
    bytes.append(reinterpret_cast<const char*>(frame.data()), frame.size());
  }
  std::ofstream(path, std::ios::binary).write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
}

TEST(Vlp16PcapSource, EveryLinkTypeYieldsTheSameDatagram) {
  std::vector<std::uint8_t> payload(kDataPacketBytes);
  for (std::size_t i = 0; i < payload.size(); ++i)
    payload[i] = static_cast<std::uint8_t>(i * 7);
  const auto data = ipv4_udp(kDataPort, payload);
  const auto other = ipv4_udp(5353, std::vector<std::uint8_t>(40, 1));
  const auto ethernet = [](std::vector<std::uint16_t> tags, const std::vector<std::uint8_t>& ip) {
    std::vector<std::uint8_t> f(12, 0xAB);  // destination and source MAC
    for (const std::uint16_t tpid : tags) {
      f = concat(f, {static_cast<std::uint8_t>(tpid >> 8), static_cast<std::uint8_t>(tpid), 0x00, 0x05});
    }
    return concat(concat(f, {0x08, 0x00}), ip);
  };
  const auto sll = [](const std::vector<std::uint8_t>& ip) {
    return concat(concat(std::vector<std::uint8_t>(14, 0), {0x08, 0x00}), ip);  // protocol at 14–15
  };
  const auto sll2 = [](const std::vector<std::uint8_t>& ip) {
    return concat(concat({0x08, 0x00}, std::vector<std::uint8_t>(18, 0)), ip);  // protocol at 0–1, 20 bytes
  };
  struct Case {
    const char* name;
    std::uint32_t link;
    std::vector<std::vector<std::uint8_t>> frames;
  };
  const std::vector<Case> cases = {
      {"ethernet", 1, {ethernet({}, other), ethernet({}, data)}},
      {"802.1Q", 1, {ethernet({0x8100}, other), ethernet({0x8100}, data)}},
      {"QinQ", 1, {ethernet({0x88A8, 0x8100}, other), ethernet({0x88A8, 0x8100}, data)}},
      {"SLL", 113, {sll(other), sll(data)}},
      {"SLL2", 276, {sll2(other), sll2(data)}},
      {"raw IPv4", 101, {other, data}},
      {"IPv4", 228, {other, data}},
  };
  for (const Case& c : cases) {
    const auto path = test::scratch_path("trajroi_link.pcap");
    write_pcap(path, c.link, c.frames);
    PcapSource source(path);
    Datagram datagram;
    ASSERT_EQ(source.next(datagram), PacketSource::Next::kDatagram) << c.name << ": " << source.error();
    EXPECT_EQ(datagram.destination_port, kDataPort) << c.name;
    ASSERT_EQ(datagram.payload.size(), payload.size()) << c.name;
    EXPECT_TRUE(std::equal(payload.begin(), payload.end(), datagram.payload.begin())) << c.name;
    EXPECT_EQ(datagram.receive_time_ns, 1'600'000'000'000'000'000 + 2 * 1'327'000) << c.name;
    EXPECT_EQ(source.next(datagram), PacketSource::Next::kEnd) << c.name;
    EXPECT_EQ(source.skipped_records(), 1u) << c.name;  // port 5353
    std::filesystem::remove(path);
  }
  // A link type it does not read is refused by name.
  const auto path = test::scratch_path("trajroi_link.pcap");
  write_pcap(path, 105, {});  // IEEE 802.11
  EXPECT_THROW(PcapSource{path}, std::runtime_error);
  std::filesystem::remove(path);
}

// What a capture gives, datagram by datagram, and how it ends.
struct Seen {
  std::vector<std::uint8_t> bytes;
  std::vector<std::int64_t> times;
  std::vector<std::uint16_t> ports;
  PacketSource::Next end = PacketSource::Next::kDatagram;
  std::uint64_t skipped = 0;
  std::string error;
};

Seen read_capture(const std::filesystem::path& from) {
  Seen seen;
  PcapSource source(from);
  Datagram datagram;
  while ((seen.end = source.next(datagram)) == PacketSource::Next::kDatagram) {
    seen.bytes.insert(seen.bytes.end(), datagram.payload.begin(), datagram.payload.end());
    seen.times.push_back(datagram.receive_time_ns);
    seen.ports.push_back(datagram.destination_port);
  }
  seen.skipped = source.skipped_records();
  seen.error = source.error();
  return seen;
}

// `bytes` as a regular file (mapped: a classic pcap file is read in place by trajroi) and
// through a pipe (read as a stream by libpcap), which must agree datagram for datagram.
void expect_read_in_place_as_libpcap_reads(const std::string& bytes, const std::string& what) {
  const auto file = test::scratch_path("trajroi_capture.pcap");
  const auto fifo = test::scratch_path("trajroi_capture.fifo");
  {
    std::ofstream out(file, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  }
  const Seen mapped = read_capture(file);
  // A reader that stops at an error closes the pipe on a writer with bytes left: EPIPE, not
  // the end of the test process.
  struct sigaction ignore {};
  struct sigaction before {};
  ignore.sa_handler = SIG_IGN;
  sigaction(SIGPIPE, &ignore, &before);
  std::filesystem::remove(fifo);
  ASSERT_EQ(mkfifo(fifo.c_str(), 0600), 0) << std::strerror(errno);
  std::thread writer([&] {
    std::ofstream out(fifo, std::ios::binary);
    out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
  });
  Seen streamed;
  try {
    streamed = read_capture(fifo);
  } catch (const std::exception& e) {
    ADD_FAILURE() << what << ": reading through the pipe threw: " << e.what();
    // A writer still waiting for a reader to open the pipe is released (then meets EPIPE), so
    // that it is joined on every path.
    const int release = ::open(fifo.c_str(), O_RDONLY | O_NONBLOCK);
    if (release >= 0) ::close(release);
  }
  writer.join();
  sigaction(SIGPIPE, &before, nullptr);
  std::filesystem::remove(fifo);
  std::filesystem::remove(file);
  EXPECT_EQ(mapped.times.size(), streamed.times.size()) << what;
  EXPECT_EQ(mapped.times, streamed.times) << what;
  EXPECT_EQ(mapped.ports, streamed.ports) << what;
  EXPECT_TRUE(mapped.bytes == streamed.bytes) << what;
  EXPECT_EQ(mapped.end, streamed.end) << what << ": in place '" << mapped.error << "', libpcap '" << streamed.error
                                      << "'";
  EXPECT_EQ(mapped.skipped, streamed.skipped) << what;
  if (streamed.error.find("truncated") != std::string::npos) {
    EXPECT_NE(mapped.error.find("truncated"), std::string::npos) << what << ": " << mapped.error;
  }
}

std::uint32_t get32(const std::string& b, std::size_t at) {
  std::uint32_t v = 0;
  std::memcpy(&v, b.data() + at, 4);
  return v;
}
void put32(std::string& b, std::size_t at, std::uint32_t v) {
  std::memcpy(b.data() + at, &v, 4);
}
void put16(std::string& b, std::size_t at, std::uint16_t v) {
  std::memcpy(b.data() + at, &v, 2);
}

// Offsets of the record headers of a little-endian classic pcap file.
std::vector<std::size_t> record_offsets(const std::string& b) {
  std::vector<std::size_t> at;
  for (std::size_t i = 24; i + 16 <= b.size(); i += 16 + get32(b, i + 8))
    at.push_back(i);
  return at;
}

// Every capture of the data folder, and variants of one made for the cases libpcap knows: time
// stamps in ns, the other byte order, a snap length shorter than the records, a file cut in a
// record header and in a record, a record longer than libpcap allows, and a file that is not a
// capture.
TEST(Vlp16PcapSource, ClassicCapturesAreReadInPlaceAsLibpcapReadsThem) {
  TRAJROI_REQUIRE_DATA(mrpt, "velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap");
  std::size_t files = 0;
  for (const auto& entry : std::filesystem::recursive_directory_iterator(test::data_dir() / "velodyne")) {
    if (entry.path().extension() != ".pcap") continue;
    expect_read_in_place_as_libpcap_reads(test::read_file(entry.path()), entry.path().filename().string());
    ++files;
  }
  EXPECT_GE(files, 7u);

  const std::string original = test::read_file(mrpt);
  ASSERT_EQ(get32(original, 0), 0xA1B2C3D4u);  // little-endian, µs
  const std::vector<std::size_t> records = record_offsets(original);
  ASSERT_GT(records.size(), 200u);

  std::string nanoseconds = original;
  put32(nanoseconds, 0, 0xA1B23C4D);
  expect_read_in_place_as_libpcap_reads(nanoseconds, "ns time stamps");

  std::string big_endian = original;
  const auto swap_field = [&big_endian](std::size_t at) {
    put32(big_endian, at, __builtin_bswap32(get32(big_endian, at)));
  };
  for (std::size_t at : {0u, 8u, 12u, 16u, 20u})
    swap_field(at);
  put16(big_endian, 4, __builtin_bswap16(2));
  put16(big_endian, 6, __builtin_bswap16(4));
  for (std::size_t r : records) {
    for (std::size_t field = 0; field < 16; field += 4)
      swap_field(r + field);
  }
  expect_read_in_place_as_libpcap_reads(big_endian, "big-endian");

  std::string short_snap = original;
  put32(short_snap, 16, 600);  // shorter than a data packet's frame: those are cut and skipped
  expect_read_in_place_as_libpcap_reads(short_snap, "snap length 600");

  expect_read_in_place_as_libpcap_reads(original.substr(0, records[150] + 9), "cut in a record header");
  expect_read_in_place_as_libpcap_reads(original.substr(0, records[150] + 16 + 700), "cut in a record");

  std::string oversized = original;
  put32(oversized, records[40] + 8, 300'000);
  expect_read_in_place_as_libpcap_reads(oversized, "a record over 262 144 bytes");

  const auto not_capture = test::scratch_path("trajroi_not_capture.pcap");
  {
    std::ofstream out(not_capture, std::ios::binary);
    out << "this is not a capture file, only text long enough to have a header";
  }
  EXPECT_THROW(PcapSource{not_capture}, std::runtime_error);
  std::filesystem::remove(not_capture);
  const auto empty = test::scratch_path("trajroi_empty.pcap");
  { std::ofstream out(empty, std::ios::binary); }
  EXPECT_THROW(PcapSource{empty}, std::runtime_error);
  std::filesystem::remove(empty);
}

// The message of the std::runtime_error `f` throws ("" when it throws none: a failed find).
template <typename F>
std::string error_of(F f) {
  try {
    f();
  } catch (const std::runtime_error& e) {
    return e.what();
  }
  return "";
}

// trajroid's recordings: written without libpcap in the classic format libpcap writes (its
// ns magic, version 2.4, snap length 65535, Ethernet), read by libpcap (a stream, through a
// pipe) as by the reader in place, each datagram as written (payload, time, port, sender).
TEST(Vlp16PcapSource, ARecordingIsTheClassicPcapFileLibpcapReads) {
  const auto path = test::scratch_path("trajroi_recorded.pcap");
  const std::vector<std::uint8_t> data(1206, 0x5A), position(512, 0xA5);
  {
    PcapWriter writer(path);
    writer.write(1'700'000'000'123'456'789, kDataPort, data);
    writer.write(1'700'000'000'223'456'789, kPositionPort, position, std::uint64_t{0x7F000002} << 16 | 40000);
    writer.close();
  }
  const std::string bytes = test::read_file(path);
  ASSERT_GE(bytes.size(), 24u);
  EXPECT_EQ(get32(bytes, 0), 0xA1B23C4Du);
  EXPECT_EQ(bytes.substr(4, 4), std::string("\x02\x00\x04\x00", 4));
  EXPECT_EQ(get32(bytes, 16), 65535u);
  EXPECT_EQ(get32(bytes, 20), 1u);
  ASSERT_EQ(record_offsets(bytes).size(), 2u);
  EXPECT_EQ(bytes.size(), 24u + 2 * (16 + 42) + 1206 + 512);
  expect_read_in_place_as_libpcap_reads(bytes, "a recording");

  PcapSource source(path);
  Datagram d;
  ASSERT_EQ(source.next(d), PacketSource::Next::kDatagram) << source.error();
  EXPECT_EQ(d.receive_time_ns, 1'700'000'000'123'456'789);
  EXPECT_EQ(d.destination_port, kDataPort);
  EXPECT_EQ(d.sender, std::uint64_t{0xC0A801C9} << 16 | kDataPort);  // the factory address
  EXPECT_TRUE(std::equal(data.begin(), data.end(), d.payload.begin(), d.payload.end()));
  ASSERT_EQ(source.next(d), PacketSource::Next::kDatagram) << source.error();
  EXPECT_EQ(d.receive_time_ns, 1'700'000'000'223'456'789);
  EXPECT_EQ(d.destination_port, kPositionPort);
  EXPECT_EQ(d.sender, std::uint64_t{0x7F000002} << 16 | 40000);
  EXPECT_TRUE(std::equal(position.begin(), position.end(), d.payload.begin(), d.payload.end()));
  EXPECT_EQ(source.next(d), PacketSource::Next::kEnd);
  std::filesystem::remove(path);
}

// A recording that cannot be created or written says which file.
TEST(Vlp16PcapSource, ARecordingThatCannotBeWrittenIsNamed) {
  const std::string error = error_of([] { PcapWriter writer("/nonexistent-dir/lidar.pcap"); });
  EXPECT_NE(error.find("/nonexistent-dir/lidar.pcap: cannot create"), std::string::npos) << error;
  PcapWriter full("/dev/full");
  full.write(1, kDataPort, std::vector<std::uint8_t>(1206, 1));
  EXPECT_THROW(full.close(), std::runtime_error);
}

// A capture another program truncates while it is replayed: the records read before (one
// read of the reader's buffer, 512 KiB and a few bytes) are delivered, then a read error that says
// so, neither a crash nor a quiet end; a capture read afterwards reads as before.
TEST(Vlp16PcapSource, ACaptureTruncatedWhileItIsReadIsAReadErrorNotACrash) {
  TRAJROI_REQUIRE_DATA(path, "velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap");
  // The capture's records three times over: longer than two reads.
  const std::string capture = test::read_file(path);
  const std::string bytes = capture + capture.substr(24) + capture.substr(24);
  constexpr std::size_t kFirstRead = 2 * (262'144 + 16);  // the reader's buffer
  ASSERT_GT(bytes.size(), 2 * kFirstRead);
  // The records whole in the first read, by the file's own record headers (little-endian).
  std::size_t in_first_read = 0;
  for (std::size_t at = 24; at + 16 <= kFirstRead;) {
    std::uint32_t captured = 0;
    std::memcpy(&captured, bytes.data() + at + 8, sizeof captured);
    if (at + 16 + captured > kFirstRead) break;
    at += 16 + captured;
    ++in_first_read;
  }
  const auto copy = test::scratch_path("trajroi_shrinking.pcap");
  for (int round = 0; round < 2; ++round) {
    {
      std::ofstream out(copy, std::ios::binary | std::ios::trunc);
      out.write(bytes.data(), static_cast<std::streamsize>(bytes.size()));
    }
    PcapSource source(copy);
    Datagram datagram;
    for (int k = 0; k < 5; ++k)
      ASSERT_EQ(source.next(datagram), PacketSource::Next::kDatagram) << source.error();
    std::filesystem::resize_file(copy, 16 * 1024);
    std::size_t records = 5;
    PacketSource::Next next;
    while ((next = source.next(datagram)) == PacketSource::Next::kDatagram)
      ++records;
    EXPECT_EQ(next, PacketSource::Next::kError) << "round " << round;
    EXPECT_NE(source.error().find("shrank"), std::string::npos) << source.error();
    EXPECT_EQ(records + source.skipped_records(), in_first_read) << "round " << round;
  }
  std::filesystem::remove(copy);
  const Seen after = read_capture(path);
  EXPECT_EQ(after.end, PacketSource::Next::kEnd) << after.error;
  EXPECT_GT(after.times.size(), 100u);
}

TEST(Vlp16PcapSource, UnreadableFileIsAClearError) {
  const std::string error = error_of([] { PcapSource source("/nonexistent/capture.pcap"); });
  EXPECT_NE(error.find("/nonexistent/capture.pcap"), std::string::npos) << error;
}

}  // namespace
}  // namespace trajroi::vlp16
