#pragma once

// From a VLP-16's UDP packets to whole rotations ("frames"). Pure: the caller hands over
// each payload with its receive time (from a socket or a pcap record) and gets frames back
// through a FrameSink; nothing here reads a clock, a socket or a file.
//
// Time. Every frame is stamped in the receive clock: the first packet anchors the sensor's
// top-of-hour timestamps to its receive time (less the packet's own duration, since it is
// sent after its last firing), and later packets are spaced by their sensor timestamps, so
// receive jitter does not reach the points. The anchor follows the least latency seen, as
// receive delays only ever add to it: a packet received earlier than the anchor foretells
// moves it earlier (a first packet that waited in a busy host's socket does not make every
// later sweep late), and when every packet of kClockWindow_ns came later, it moves later by
// the least of those delays (a sensor clock running slow). It moves only where a frame
// starts, so a frame's points share one anchor. The anchor is reset (and counted) when the
// two clocks part by more than kClockResetThreshold_ns. When position packets carry a valid RMC
// with the PPS locked, frames also carry their start in UTC.
//
// The end of a frame. A frame ends where a point's firing azimuth passes the cut. Where the cut
// falls between two packets (after the last firing of one, before the first of the next), the
// frame is whole with the first of them, and it is delivered then, not when the next comes: the
// next packet's first firing is foreseen a block step on (the step measured inside the packet),
// less kForesightMargin_cdeg (on the real captures of the shared data set the next packet's
// first block never came more than 2 hundredths of a degree before the foreseen azimuth). A
// next packet that still has firings before the cut (a motor slowing by more than the margin
// in one packet) begins the next frame with them: nothing is lost and no frame is cut short.
// A packet that comes out of order after its frame was delivered is dropped and counted, as
// after any frame's end.
//
// Sequence. A timestamp step beyond 1.5 × the packet period (1327.1 µs single, 663.6 µs
// dual), or, with a normal step, an azimuth advance beyond 1.5 × the expected one, counts
// the packets in between as lost. A packet older than the previous one is counted out of
// order and joins the current frame if it falls inside it; a repeated timestamp is a
// duplicate and dropped. A timestamp more than kRestartThreshold_us behind the previous one
// is no reordering but a sensor that restarted its clock (a power cycle, a replay looping):
// the frame in progress ends (partial) and the stream starts afresh (counted as a restart).
// A timestamp step far beyond the host time that passed between the two packets (more than
// twice it plus kClockResetThreshold_ns) is the sensor's clock jumping forward (a PPS
// re-sync), not loss: it is counted as a clock jump and only the packets the host time had
// room for are counted lost.
#include <array>
#include <cstddef>
#include <cstdint>
#include <limits>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "trajroi/vlp16/decoder.hpp"
#include "trajroi/vlp16/model_check.hpp"
#include "trajroi/vlp16/packet.hpp"
#include "trajroi/vlp16/position.hpp"

namespace trajroi::vlp16 {

inline constexpr std::int64_t kClockResetThreshold_ns = 100'000'000;
inline constexpr std::int64_t kRestartThreshold_us = 1'000'000;
// The window over which the least receive latency is taken to follow a slow sensor clock.
inline constexpr std::int64_t kClockWindow_ns = 5'000'000'000;
// A frame is cut after this long even without an azimuth wrap (a stalled motor): ten times
// the slowest sweep (5 Hz).
inline constexpr std::int64_t kMaxFrameDuration_ns = 2'000'000'000;
// The next packet's first firing is foreseen this much short of a block step past the last
// firing's azimuth (the end of a frame, above); no end is foreseen from a block step over
// kMaxForeseenStep_cdeg (faster than any model turns: the packet's azimuths are not a rotation).
inline constexpr double kForesightMargin_cdeg = 3.0;
inline constexpr double kMaxForeseenStep_cdeg = 100.0;

struct StreamOptions {
  DecodeOptions decode;
  // The model the calibration is for. Alone (detect_model false: lidar.model names it) the
  // packets of any other model are rejected and named; with detect_model (lidar.model: auto)
  // the model of the packets is taken, any of model.hpp's, the others with their manuals'
  // geometry (Calibration::for_model).
  Model model = Model::kVlp16;
  bool detect_model = false;
  // A frame begins with the first point whose (interpolated) firing azimuth is at or past
  // this azimuth; a firing that straddles it is split between the two frames.
  double cut_azimuth_deg = 0.0;
};

struct Frame {
  std::uint64_t index = 0;                   // 0, 1, … in the order frames complete
  std::int64_t start_time_ns = 0;            // first point, receive clock
  std::int64_t end_time_ns = 0;              // last point, receive clock
  std::optional<std::int64_t> start_utc_ns;  // first point in UTC, when the clock is locked
  std::uint32_t packets = 0;                 // packets whose first firing is in this frame
  std::uint32_t lost_packets = 0;            // detected inside this frame
  ReturnMode return_mode = ReturnMode::kStrongest;
  // Not a whole sweep: the first frame (the stream started mid-sweep), the last one at
  // flush(), and a frame cut by kMaxFrameDuration_ns.
  bool partial = false;
  std::vector<Point> points;  // time_offset_ns after start_time_ns
};

class FrameSink {
 public:
  virtual ~FrameSink() = default;
  // The frame is valid during the call only; its storage is reused.
  virtual void on_frame(const Frame& frame) = 0;
  // Points were appended to the frame in progress: frame.points[first …] are new (their
  // time offsets final). Called after every packet that added points, and before on_frame
  // for the points not yet reported, so a sink can process a sweep packet by packet and
  // only close it in on_frame. `frame.index` is not yet set.
  virtual void on_points(const Frame& frame, std::size_t first) {
    (void)frame;
    (void)first;
  }
};

struct StreamCounters {
  std::uint64_t data_packets = 0;  // handed to on_data_packet
  std::uint64_t decoded_packets = 0;
  std::uint64_t decoded_ahead = 0;  // of those, decoded before they were handed over (DecodedPacket)
  std::array<std::uint64_t, kPacketErrorCount> rejected{};  // by PacketError (kNone unused)
  std::uint64_t lost_packets = 0;
  std::uint64_t out_of_order = 0;
  std::uint64_t late_dropped = 0;  // out of order and older than the current frame
  std::uint64_t duplicates = 0;
  std::uint64_t clock_resets = 0;
  std::uint64_t restarts = 0;     // sensor time jumped back by more than kRestartThreshold_us
  std::uint64_t clock_jumps = 0;  // sensor time jumped forward far beyond the host time elapsed
  std::uint64_t points = 0;
  std::uint64_t no_return = 0;
  std::uint64_t out_of_range = 0;
  std::uint64_t merged_returns = 0;
  std::uint64_t frames = 0;  // complete sweeps delivered
  std::uint64_t partial_frames = 0;
  std::uint64_t position_packets = 0;  // handed to on_position_packet
  std::uint64_t position_wrong_size = 0;
  std::array<std::uint64_t, kNmeaErrorCount> nmea{};  // by NmeaError (kNone: good RMCs)

  [[nodiscard]] std::uint64_t rejected_total() const noexcept;
  // Another stream's counts added (several sensors' together).
  StreamCounters& operator+=(const StreamCounters& other) noexcept;
};

// The cut azimuth (StreamOptions::cut_azimuth_deg, any real) in hundredths of a degree, [0, 36000).
[[nodiscard]] std::uint16_t cut_centidegrees(double cut_azimuth_deg) noexcept;

// Whether a data packet may complete a frame cut at `cut_cdeg`, from its block azimuths alone
// (no decoding): the cut lies within its azimuths (first block to last, plus
// kFrameEndMargin_cdeg for the last block's firings), or its first azimuth is at most that far
// past the cut (the packet after a cut that fell between two packets, or after a lost one). A
// reader thread wakes its consumer at once for such a packet and lets the others wait for
// company. False for a packet shorter than a data packet. (A frame cut by
// kMaxFrameDuration_ns, a stalled motor, is not foreseen.)
inline constexpr std::uint32_t kFrameEndMargin_cdeg = 100;
[[nodiscard]] bool may_complete_frame(std::span<const std::uint8_t> packet, std::uint16_t cut_cdeg) noexcept;

// A data packet's points as PacketDecoder::decode() gave them, decoded ahead of the stream
// (by the thread that received the packet, while the stream's own thread works on earlier
// ones). `tag` ties it to its packet (the caller's sequence number).
struct DecodedPacket {
  std::uint64_t tag = 0;
  Model model = Model::kVlp16;  // of the decoder that decoded it
  PacketDecoder::Result result;
  // The first `count` of `points`: room for a whole packet inside the object, so that a ring
  // of them is one allocation, made resident at once (SpscRing), that never allocates again.
  std::uint32_t count = 0;
  std::array<Point, kPointsPerPacket> points;

  [[nodiscard]] std::span<const Point> decoded() const noexcept { return {points.data(), count}; }
  // Keeps the points PacketDecoder::decode() gave (at most kPointsPerPacket) with its result.
  void assign(std::span<const Point> decoded_points, const PacketDecoder::Result& decode_result) noexcept;
};

class StreamDecoder {
 public:
  StreamDecoder(const Calibration& calibration, StreamOptions options);

  // One port-2368 payload. May complete a frame (rarely two) into `sink`. `decoded`: the
  // points of a payload that passed validate_data_packet(), already decoded by
  // decoder().decode() (the same points as decoding it here; it is not validated again), or
  // null.
  void on_data_packet(std::span<const std::uint8_t> payload, std::int64_t receive_time_ns, FrameSink& sink,
                      const DecodedPacket* decoded = nullptr);
  // The packet decoder of StreamOptions::model; decode() is const and keeps no state, so
  // another thread may decode packets ahead with it.
  [[nodiscard]] const PacketDecoder& decoder() const noexcept {
    return *decoders_[static_cast<std::size_t>(options_.model)];
  }
  // The decoder a packet would be decoded with, from its product id alone (safe on any
  // thread: the decoders never change), or null when its bytes cannot tell (an 0x21 packet
  // while the model is detected) or no decoder of this stream takes it. A packet decoded
  // ahead with it is still checked by the stream (DecodedPacket::model).
  [[nodiscard]] const PacketDecoder* decoder_for(std::span<const std::uint8_t> packet) const noexcept;
  // One port-8308 payload.
  void on_position_packet(std::span<const std::uint8_t> payload);
  // Delivers the frame in progress (partial), e.g. at the end of a capture.
  void flush(FrameSink& sink);

  [[nodiscard]] const StreamCounters& counters() const noexcept { return counters_; }
  // The product id and return mode of the last decoded packet.
  [[nodiscard]] std::optional<std::uint8_t> product_id() const noexcept { return product_id_; }
  [[nodiscard]] std::optional<ReturnMode> return_mode() const noexcept { return return_mode_; }
  // The model check: why the last packet rejected for its model was (reason(), empty if none
  // was) and the packet period that decided a 0x21 stream.
  [[nodiscard]] const ModelCheck& model_check() const noexcept { return model_; }
  [[nodiscard]] const std::optional<PositionPacket>& first_rmc() const noexcept { return first_rmc_; }
  [[nodiscard]] const std::optional<PositionPacket>& last_rmc() const noexcept { return last_rmc_; }
  // The newest position packet parsed (its PPS status and RMC validity), whatever its NMEA.
  [[nodiscard]] const std::optional<PositionPacket>& last_position() const noexcept { return last_position_; }
  [[nodiscard]] const TopOfHourClock& utc_clock() const noexcept { return utc_clock_; }

 private:
  void accept(std::span<const std::uint8_t> packet, std::int64_t receive_time_ns, FrameSink& sink,
              const DecodedPacket* decoded);
  // Appends the packet's points to the frame (time after the packet's first firing), decoded
  // here or ahead, and counts them.
  PacketDecoder::Result decode_onto_frame(std::span<const std::uint8_t> packet, const DecodedPacket* decoded);
  void append_late(std::span<const std::uint8_t> packet, std::int64_t packet_time_ns, FrameSink& sink,
                   const DecodedPacket* decoded);
  std::int64_t packet_time_ns(std::uint32_t toh_us, std::int64_t receive_time_ns, double period_us);
  // Where a frame starts: moves the anchor to the least latency seen (see Time above) and
  // answers by how much (to add to the packet's time).
  std::int64_t settle_anchor(std::int64_t receive_time_ns) noexcept;
  void finish_frame(FrameSink& sink, bool partial);
  void report_points(FrameSink& sink);
  // Whether the next packet's every firing is past the cut, foreseen from the last firing's
  // azimuth and the block step (see "The end of a frame").
  [[nodiscard]] bool next_packet_past_cut(std::uint16_t last_azimuth_cdeg, double step_cdeg) const noexcept;

  std::array<std::unique_ptr<PacketDecoder>, kModelCount> decoders_;  // options_.model's, and with
                                                                      // detect_model every model's
  const PacketDecoder* current_ = nullptr;                            // the stream's model's
  StreamOptions options_;
  ModelCheck model_;
  TopOfHourClock utc_clock_;
  StreamCounters counters_;

  // 0x21 packets waiting for the model check's verdict (at most ModelCheck::kMaxUndecided).
  struct HeldPacket {
    std::array<std::uint8_t, kDataPacketBytes> bytes;
    std::int64_t receive_time_ns;
  };
  std::vector<HeldPacket> held_;

  // Sequence and clock state of the last accepted packet.
  bool have_last_ = false;
  std::uint32_t last_toh_us_ = 0;
  std::int64_t last_receive_ns_ = 0;
  std::uint16_t last_first_azimuth_ = 0;
  double rate_cdeg_per_us_ = 0.0;  // measured inside the last packet
  std::int64_t anchor_time_ns_ = 0;
  std::int64_t unwrapped_toh_us_ = 0;  // last packet's timestamp, unwrapped from the anchor
  // The least of (receive − anchored sensor time) since window_start_ns_, or kNoLatency.
  static constexpr std::int64_t kNoLatency = std::numeric_limits<std::int64_t>::max();
  std::int64_t latency_min_ns_ = kNoLatency;
  std::int64_t window_start_ns_ = 0;
  double last_phase_deg_ = 0.0;  // of the last point placed, from the cut azimuth
  bool have_phase_ = false;
  bool cut_foreseen_ = false;  // the frame was delivered at a foreseen end; no point past the cut yet

  Frame frame_;
  std::size_t reported_ = 0;  // points of frame_ handed to on_points
  bool first_frame_ = true;
  std::uint64_t next_index_ = 0;
  std::vector<Point> carried_;  // a packet's points after a frame's end, to the next frame

  std::optional<std::uint8_t> product_id_;
  std::optional<ReturnMode> return_mode_;
  std::optional<PositionPacket> first_rmc_;
  std::optional<PositionPacket> last_rmc_;
  std::optional<PositionPacket> last_position_;
};

}  // namespace trajroi::vlp16
