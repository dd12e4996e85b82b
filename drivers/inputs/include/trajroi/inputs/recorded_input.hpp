#pragma once

// A recorded run as an input source: the run folder's recordings merged by receive time
// (RunMerger), paced (Pacer), and with `loop` played again and again, each lap's times shifted
// to follow the previous lap's (soak tests; the sensors' own clocks restart each lap).
#include <atomic>
#include <filesystem>
#include <memory>

#include "trajroi/inputs/input_source.hpp"
#include "trajroi/inputs/pacer.hpp"
#include "trajroi/inputs/run_merger.hpp"

namespace trajroi::inputs {

struct RecordedOptions {
  double rate = 0.0;  // 0 as fast as possible, 1 real time, N × real time
  bool loop = false;
  RunStreams streams;
  LidarPorts lidar_ports;
};

class RecordedInput final : public InputSource {
 public:
  // Throws std::runtime_error naming the file when the run cannot be opened; the missing
  // serial recordings are announced as notices.
  RecordedInput(std::filesystem::path dir, RecordedOptions options);
  ~RecordedInput() override;

  Next next(InputItem& item, std::chrono::milliseconds timeout) override;
  [[nodiscard]] bool ready() const noexcept override { return ready_; }
  [[nodiscard]] const Notice& notice() const noexcept override { return notice_; }
  [[nodiscard]] const std::string& error() const noexcept override { return error_; }
  [[nodiscard]] InputCounters counters() const noexcept override;
  [[nodiscard]] std::string describe() const override;

  // Items due within this much of now go out together (one wake-up of the consumer). Small,
  // so that a paced replay hands packets over when the sensor would: with 2 ms, the last packet
  // of a sweep went out up to 2 ms before its time and the packet that closes the sweep in the
  // next batch, which the latency (last packet → LCM) counted as the pipeline's.
  static constexpr std::int64_t kPacingQuantum_ns = 200'000;

 private:
  std::filesystem::path dir_;
  RecordedOptions options_;
  std::unique_ptr<RunMerger> merger_;
  Pacer pacer_;
  std::uint64_t lap_ = 1;
  std::int64_t shift_ns_ = 0;
  std::size_t missing_reported_ = 0;
  bool error_reported_ = false;
  bool ready_ = false;
  std::uint64_t items_ = 0, oversize_ = 0;
  Notice notice_;
  std::string error_;
};

}  // namespace trajroi::inputs
