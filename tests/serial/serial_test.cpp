// Serial sources: a live port through a real pseudo-terminal pair (openpty), including the
// device vanishing and coming back, and the recording / replay of byte streams.
#include <fcntl.h>
#include <gtest/gtest.h>
#include <pty.h>
#include <termios.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "test_data.hpp"
#include "trajroi/host/clock.hpp"
#include "trajroi/serial/byte_log.hpp"
#include "trajroi/serial/serial_port_source.hpp"
#include "trajroi/ublox/config.hpp"
#include "trajroi/ublox/framer.hpp"

namespace trajroi::serial {
namespace {

using namespace std::chrono_literals;
using Bytes = std::vector<std::uint8_t>;

// A pseudo-terminal pair: the "device" side (slave, what the source opens) and the side a
// test writes to (master), as a receiver would.
struct Pty {
  int master = -1;
  int slave = -1;
  std::string slave_path;
  Pty() {
    char name[128] = {};
    termios tio{};
    cfmakeraw(&tio);
    cfsetspeed(&tio, B115200);
    if (openpty(&master, &slave, name, &tio, nullptr) != 0) throw std::runtime_error("openpty failed");
    slave_path = name;
  }
  ~Pty() { close_all(); }
  void close_all() {
    if (master >= 0) ::close(master);
    if (slave >= 0) ::close(slave);
    master = slave = -1;
  }
  void write_all(const Bytes& b) const {
    std::size_t at = 0;
    while (at < b.size()) {
      const ssize_t n = ::write(master, b.data() + at, b.size() - at);
      if (n <= 0) throw std::runtime_error("pty write failed");
      at += static_cast<std::size_t>(n);
    }
  }
};

// Reads until `want` bytes have arrived or `deadline` passes.
Bytes read_bytes(ByteSource& source, std::size_t want, std::chrono::milliseconds deadline,
                 std::vector<std::int64_t>* stamps = nullptr) {
  Bytes got;
  const auto end = std::chrono::steady_clock::now() + deadline;
  while (got.size() < want && std::chrono::steady_clock::now() < end) {
    Chunk c;
    if (source.read(c, 50ms) == ReadStatus::kData) {
      got.insert(got.end(), c.bytes.begin(), c.bytes.end());
      if (stamps != nullptr) stamps->push_back(c.receive_time_ns);
    }
  }
  return got;
}

class TempDir {
 public:
  TempDir()
      : path_(std::filesystem::temp_directory_path() /
              ("trajroi-serial-" + std::to_string(::getpid()) + "-" + std::to_string(counter_++))) {
    std::filesystem::create_directories(path_);
  }
  ~TempDir() { std::filesystem::remove_all(path_); }
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

 private:
  static inline int counter_ = 0;
  std::filesystem::path path_;
};

Bytes ubx_stream(int frames) {
  Bytes out;
  for (int i = 0; i < frames; ++i) {
    Bytes payload(92, static_cast<std::uint8_t>(i));
    const Bytes f = ublox::encode_frame(0x01, 0x07, payload);
    out.insert(out.end(), f.begin(), f.end());
  }
  return out;
}

TEST(SerialPort, ReadsWhatTheDeviceSendsWithMonotonicStamps) {
  Pty pty;
  SerialPortSource source({pty.slave_path, 115200});
  const Bytes sent = ubx_stream(20);
  std::thread writer([&] {
    for (std::size_t at = 0; at < sent.size(); at += 100) {
      pty.write_all(Bytes(sent.begin() + static_cast<std::ptrdiff_t>(at),
                          sent.begin() + static_cast<std::ptrdiff_t>(std::min(at + 100, sent.size()))));
      std::this_thread::sleep_for(2ms);
    }
  });
  std::vector<std::int64_t> stamps;
  const std::int64_t before = trajroi::host::monotonic_ns();
  const Bytes got = read_bytes(source, sent.size(), 5s, &stamps);
  writer.join();
  EXPECT_EQ(got, sent);
  ASSERT_FALSE(stamps.empty());
  EXPECT_GE(stamps.front(), before);
  EXPECT_TRUE(std::is_sorted(stamps.begin(), stamps.end()));
  EXPECT_TRUE(source.is_open());
  // libserialport cannot open a pseudo-terminal; the termios path did.
  EXPECT_EQ(source.backend(), SerialPortSource::Backend::kTermios);
  EXPECT_EQ(source.counters().bytes, sent.size());
  EXPECT_EQ(source.counters().disconnects, 0U);
}

TEST(SerialPort, WritesReachTheDevice) {
  Pty pty;
  SerialPortSource source({pty.slave_path, 115200});
  Chunk c;
  (void)source.read(c, 10ms);  // opens the port
  ASSERT_TRUE(source.is_open()) << source.last_error();
  const Bytes cmd{'$', 'V', 'N', 'R', 'R', 'G', ',', '8', '*', '4', 'B', '\r', '\n'};
  ASSERT_TRUE(source.write(cmd, 100ms));
  Bytes got(cmd.size());
  std::size_t n = 0;
  while (n < got.size()) {
    const ssize_t r = ::read(pty.master, got.data() + n, got.size() - n);
    ASSERT_GT(r, 0);
    n += static_cast<std::size_t>(r);
  }
  EXPECT_EQ(got, cmd);
}

// The device is a udev-style symlink. It vanishes (the pty closes, the link dangles), the
// source reports the disconnect and keeps retrying; a new device appears under the same
// name and the source reads from it.
TEST(SerialPort, SurvivesTheDeviceVanishingAndReopens) {
  TempDir dir;
  const std::filesystem::path link = dir.path() / "gnss";
  auto pty = std::make_unique<Pty>();
  std::filesystem::create_symlink(pty->slave_path, link);
  SerialPortOptions options{link.string(), 115200};
  options.min_backoff = 20ms;
  options.max_backoff = 80ms;
  SerialPortSource source(options);

  pty->write_all({1, 2, 3});
  EXPECT_EQ(read_bytes(source, 3, 2s), (Bytes{1, 2, 3}));

  pty.reset();  // unplug
  bool disconnected = false;
  for (int i = 0; i < 40 && !disconnected; ++i) {
    Chunk c;
    disconnected = source.read(c, 20ms) == ReadStatus::kDisconnected;
  }
  EXPECT_TRUE(disconnected);
  EXPECT_EQ(source.counters().disconnects, 1U);
  // While the device is gone every read times out; nothing throws.
  for (int i = 0; i < 5; ++i) {
    Chunk c;
    EXPECT_EQ(source.read(c, 30ms), ReadStatus::kTimeout);
  }
  EXPECT_GT(source.counters().open_failures, 0U);
  EXPECT_FALSE(source.last_error().empty());

  auto replugged = std::make_unique<Pty>();
  std::filesystem::remove(link);
  std::filesystem::create_symlink(replugged->slave_path, link);
  replugged->write_all({4, 5, 6, 7});
  EXPECT_EQ(read_bytes(source, 4, 3s), (Bytes{4, 5, 6, 7}));
  EXPECT_EQ(source.counters().opens, 2U);
}

// The libserialport path needs a port libserialport can describe, such as a machine's 16550
// UART. It opens, configures 8N1 and reads (nothing, or console noise) without failing.
TEST(SerialPort, LibserialportOpensAPortItCanDescribe) {
  const char* device = "/dev/ttyS0";
  if (!std::filesystem::exists(device) || ::access(device, R_OK | W_OK) != 0) {
    GTEST_SKIP() << device << " is absent or not accessible: no real UART to open here";
  }
  SerialPortSource source({device, 9600});
  Chunk c;
  const ReadStatus status = source.read(c, 20ms);
  if (!source.is_open()) GTEST_SKIP() << "this machine's " << device << " cannot be opened: " << source.last_error();
  EXPECT_EQ(source.backend(), SerialPortSource::Backend::kLibserialport);
  EXPECT_NE(status, ReadStatus::kDisconnected);
  EXPECT_EQ(source.counters().disconnects, 0U);
}

TEST(SerialPort, RejectsBadConfiguration) {
  EXPECT_THROW(SerialPortSource({"", 115200}), std::invalid_argument);
  EXPECT_THROW(SerialPortSource({"/dev/ttyS0", 12345}), std::invalid_argument);
  // A device that does not exist is not an error at start: it is retried.
  SerialPortSource absent({"/dev/trajroi-does-not-exist", 115200});
  Chunk c;
  EXPECT_EQ(absent.read(c, 10ms), ReadStatus::kTimeout);
  EXPECT_EQ(absent.counters().open_failures, 1U);
}

// ---- Recording and replay ---------------------------------------------------------------------

TEST(Recording, ReplaysEveryChunkWithItsTimeExactly) {
  TempDir dir;
  const std::string path = (dir.path() / "run.trjb").string();
  std::vector<Bytes> chunks{{1, 2, 3}, {0xB5, 0x62}, Bytes(5000, 0xAA), {9}};
  std::vector<std::int64_t> times{1'000, 2'500, 2'500, 9'000'000'000};
  {
    RecordingWriter writer(path);
    for (std::size_t i = 0; i < chunks.size(); ++i)
      writer.write({chunks[i], times[i]});
  }
  ReplaySource replay(path);
  EXPECT_TRUE(replay.is_recording());
  for (std::size_t i = 0; i < chunks.size(); ++i) {
    Chunk c;
    ASSERT_EQ(replay.read(c, 10ms), ReadStatus::kData);
    EXPECT_EQ(Bytes(c.bytes.begin(), c.bytes.end()), chunks[i]);
    EXPECT_EQ(c.receive_time_ns, times[i]);
  }
  Chunk end;
  EXPECT_EQ(replay.read(end, 10ms), ReadStatus::kEnd);
  EXPECT_EQ(replay.truncated_records(), 0U);
}

TEST(Recording, ACutFileReplaysItsCompleteRecords) {
  TempDir dir;
  const std::string path = (dir.path() / "cut.trjb").string();
  {
    RecordingWriter writer(path);
    writer.write({Bytes{1, 2, 3}, 10});
    writer.write({Bytes{4, 5, 6}, 20});
  }
  const std::string full = test::read_file(path);
  for (std::size_t cut = 16; cut < full.size(); ++cut) {
    {
      std::FILE* f = std::fopen(path.c_str(), "wb");
      ASSERT_NE(f, nullptr);
      std::fwrite(full.data(), 1, cut, f);
      std::fclose(f);
    }
    ReplaySource replay(path);
    std::size_t records = 0;
    Chunk c;
    while (replay.read(c, 1ms) == ReadStatus::kData)
      ++records;
    EXPECT_EQ(records, cut >= 16 + 15 ? 1U : 0U) << "cut " << cut;
    // Cut on a record boundary (after the header, after the first record) loses nothing.
    EXPECT_EQ(replay.truncated_records(), cut == 16 || cut == 16 + 15 ? 0U : 1U) << "cut " << cut;
  }
}

TEST(Recording, UnreadableOrCorruptFilesAreNamed) {
  EXPECT_THROW(ReplaySource("/nonexistent/trajroi.trjb"), std::runtime_error);
  TempDir dir;
  const std::string path = (dir.path() / "bad.trjb").string();
  {
    RecordingWriter writer(path);
    writer.write({Bytes{1}, 1});
  }
  {  // corrupt the record length
    std::FILE* f = std::fopen(path.c_str(), "r+b");
    ASSERT_NE(f, nullptr);
    std::fseek(f, 16 + 8, SEEK_SET);
    const std::uint8_t huge[4] = {0xFF, 0xFF, 0xFF, 0x7F};
    std::fwrite(huge, 1, 4, f);
    std::fclose(f);
  }
  try {
    ReplaySource replay(path);
    FAIL() << "corrupt record accepted";
  } catch (const std::runtime_error& e) {
    EXPECT_NE(std::string(e.what()).find(path), std::string::npos);
  }
}

TEST(RawReplay, NominalRateSpacesChunksByTheirBytes) {
  TempDir dir;
  const std::string path = (dir.path() / "raw.bin").string();
  {
    std::FILE* f = std::fopen(path.c_str(), "wb");
    const Bytes b(1000, 0x55);
    std::fwrite(b.data(), 1, b.size(), f);
    std::fclose(f);
  }
  ReplayOptions o;
  o.bytes_per_second = 10'000.0;
  o.chunk_bytes = 100;
  ReplaySource replay(path, o);
  EXPECT_FALSE(replay.is_recording());
  std::vector<std::int64_t> t;
  Chunk c;
  std::size_t total = 0;
  while (replay.read(c, 1ms) == ReadStatus::kData) {
    t.push_back(c.receive_time_ns);
    total += c.bytes.size();
  }
  EXPECT_EQ(total, 1000U);
  ASSERT_EQ(t.size(), 10U);
  EXPECT_EQ(t[0], 10'000'000);  // 100 bytes at 10 kB/s
  EXPECT_EQ(t[9], 100'000'000);
}

TEST(RawReplay, UbxTimingFollowsNavPvtItow) {
  TRAJROI_REQUIRE_DATA(path, "ublox/gpsd/ublox-neo-m8n.log");
  ReplayOptions o;
  o.raw_timing = RawTiming::kUbxTime;
  ReplaySource replay(path.string(), o);
  // Chunk times follow the receiver's 5 Hz epochs: the log's 24 NAV-PVT span 4.6 s.
  ublox::Framer framer;
  std::vector<std::int64_t> pvt_times;
  Chunk c;
  std::size_t bytes = 0;
  std::int64_t previous = 0;
  while (replay.read(c, 1ms) == ReadStatus::kData) {
    EXPECT_GE(c.receive_time_ns, previous);
    previous = c.receive_time_ns;
    bytes += c.bytes.size();
    framer.feed(c.bytes, [&](const ublox::Message& m) {
      if (m.msg_class == 0x01 && m.msg_id == 0x07) pvt_times.push_back(c.receive_time_ns);
    });
  }
  EXPECT_EQ(bytes, std::filesystem::file_size(path));
  ASSERT_EQ(pvt_times.size(), 24U);
  for (std::size_t i = 1; i < pvt_times.size(); ++i)
    EXPECT_EQ(pvt_times[i] - pvt_times[i - 1], 200'000'000) << i;
}

}  // namespace
}  // namespace trajroi::serial
