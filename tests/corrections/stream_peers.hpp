#pragma once

// Real stream peers for the corrections tests (Debian rtklib's str2str, socat): started and stopped
// by PID, fed through its TCP server input with the RTCM3 frames of a real u-blox stream, line
// noise and bit-flipped copies between them.
#include <arpa/inet.h>
#include <gtest/gtest.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <cstdint>
#include <cstdlib>
#include <ctime>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "trajroi/framing/rtcm3.hpp"

namespace trajroi::corrections_test {

using Bytes = std::vector<std::uint8_t>;

inline std::int64_t now_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

inline bool have_peers() {
  return std::system("command -v str2str >/dev/null 2>&1 && command -v socat >/dev/null 2>&1") == 0;
}

inline std::uint16_t free_port() {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  (void)::bind(fd, reinterpret_cast<sockaddr*>(&a), sizeof a);
  socklen_t len = sizeof a;
  (void)::getsockname(fd, reinterpret_cast<sockaddr*>(&a), &len);
  ::close(fd);
  return ntohs(a.sin_port);
}

// A real stream server fed through its TCP input: str2str as an NTRIP caster (mountpoint
// F9T, user rover:s3cret) or with another output in its own syntax ("tcpsvr://:PORT"), or
// socat sending what it reads as UDP datagrams (str2str 2.4.3 b34 has no UDP output).
class Caster {
 public:
  Caster(std::uint16_t input_port, std::uint16_t caster_port)
      : Caster(input_port, "ntripc://rover:s3cret@:" + std::to_string(caster_port) + "/F9T") {}
  Caster(std::uint16_t input_port, const std::string& str2str_output)
      : Caster(input_port, std::vector<std::string>{"str2str", "-in", "tcpsvr://:" + std::to_string(input_port), "-out",
                                                    str2str_output}) {}
  Caster(std::uint16_t input_port, std::vector<std::string> argv) : input_(input_port), argv_(std::move(argv)) {
    start();
  }
  static Caster udp_sender(std::uint16_t input_port, std::uint16_t udp_port) {
    return Caster(input_port, std::vector<std::string>{"socat", "-u",
                                                       "TCP-LISTEN:" + std::to_string(input_port) + ",bind=127.0.0.1",
                                                       "UDP-SENDTO:127.0.0.1:" + std::to_string(udp_port)});
  }
  Caster(Caster&& other) noexcept
      : input_(other.input_),
        argv_(std::move(other.argv_)),
        pid_(std::exchange(other.pid_, -1)),
        input_fds_(std::move(other.input_fds_)) {}
  Caster& operator=(Caster&&) = delete;
  ~Caster() { stop(); }
  void start() {
    std::vector<char*> args;
    for (std::string& a : argv_)
      args.push_back(a.data());
    args.push_back(nullptr);
    pid_ = ::fork();
    if (pid_ == 0) {
      if (::freopen("/dev/null", "w", stderr) == nullptr) ::_exit(126);
      if (::freopen("/dev/null", "w", stdout) == nullptr) ::_exit(126);
      ::execvp(args[0], args.data());
      ::_exit(127);
    }
  }
  void stop() {
    if (pid_ <= 0) return;
    ::kill(pid_, SIGTERM);
    int status = 0;
    ::waitpid(pid_, &status, 0);
    pid_ = -1;
  }
  // Connects to the caster's input and writes `bytes` (retrying while str2str starts).
  void write(const Bytes& bytes) {
    const auto until = std::chrono::steady_clock::now() + std::chrono::seconds(10);
    while (std::chrono::steady_clock::now() < until) {
      const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
      sockaddr_in a{};
      a.sin_family = AF_INET;
      a.sin_port = htons(input_);
      a.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
      if (::connect(fd, reinterpret_cast<sockaddr*>(&a), sizeof a) == 0) {
        // str2str reads its input in pieces; a little at a time, as a base station sends.
        for (std::size_t at = 0; at < bytes.size(); at += 512) {
          const std::size_t n = std::min<std::size_t>(512, bytes.size() - at);
          (void)::send(fd, bytes.data() + at, n, MSG_NOSIGNAL);
          ::usleep(2000);
        }
        input_fds_.push_back(fd);
        return;
      }
      ::close(fd);
      ::usleep(100'000);
    }
    FAIL() << argv_[0] << "'s input never accepted a connection";
  }
  void close_inputs() {
    for (const int fd : input_fds_)
      ::close(fd);
    input_fds_.clear();
  }

 private:
  std::uint16_t input_;
  std::vector<std::string> argv_;
  pid_t pid_ = -1;
  std::vector<int> input_fds_;
};

// The log's RTCM3 frames (the rtcm3 test checks them against gpsd's decoding).
inline std::vector<Bytes> log_frames(const std::string& bytes) {
  std::vector<Bytes> out;
  framing::Rtcm3Framer framer;
  framer.feed(std::span(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()),
              [&out](std::span<const std::uint8_t> f) { out.emplace_back(f.begin(), f.end()); });
  return out;
}

// Frames [from, to) with line noise between them and, before every 7th, a copy with one bit
// flipped (a CRC failure the client must not hand on).
inline Bytes with_noise(const std::vector<Bytes>& frames, std::size_t from, std::size_t to, std::size_t& corrupted) {
  Bytes out;
  std::mt19937 random(static_cast<unsigned>(from));
  for (std::size_t i = from; i < to; ++i) {
    for (int k = 0; k < 20; ++k)
      out.push_back(static_cast<std::uint8_t>(random() % 0xD0));  // never a 0xD3 preamble
    if (i % 7 == 0) {
      Bytes bad = frames[i];
      bad[bad.size() / 2] ^= 0x10;
      out.insert(out.end(), bad.begin(), bad.end());
      ++corrupted;
    }
    out.insert(out.end(), frames[i].begin(), frames[i].end());
  }
  return out;
}

#define REQUIRE_STREAM_PEERS()                                                                                \
  if (!have_peers()) {                                                                                        \
    const char* ci = std::getenv("CI");                                                                       \
    if (ci != nullptr && std::string(ci) == "true") FAIL() << "str2str or socat missing under CI";            \
    GTEST_SKIP() << "str2str (Debian rtklib) or socat not installed (scripts/install-deps.sh installs them)"; \
  }

}  // namespace trajroi::corrections_test
