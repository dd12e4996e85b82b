// The input thread: one source, one ring. Live and replay run this same loop; only the source
// object differs (inputs::UdpInput, inputs::SerialInput or inputs::RecordedInput).
#include <algorithm>
#include <chrono>
#include <thread>

#include "log.hpp"
#include "realtime.hpp"
#include "threads.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace trajroi::daemon {

namespace {

// Publishes the source's counters for the status (a few relaxed stores).
void copy_counters(const inputs::InputSource& source, InputLane& lane) {
  const inputs::InputCounters c = source.counters();
  lane.oversize.store(c.oversize, std::memory_order_relaxed);
  lane.errors.store(c.errors, std::memory_order_relaxed);
  lane.disconnects.store(c.disconnects, std::memory_order_relaxed);
  lane.rejected_sources.store(c.rejected_sources, std::memory_order_relaxed);
  lane.kernel_drops.store(c.kernel_drops, std::memory_order_relaxed);
  lane.closed_streams.store(c.closed_streams, std::memory_order_relaxed);
}

// The processing thread is also woken this far ahead of the cut, so the items held then are
// handled before the closing packet comes and do not add to its latency.
constexpr std::uint16_t kDrainAhead_cdeg = 500;

// Where the configured LiDARs cut their sweeps, each cut once, and the drain point ahead of each
// (several LiDARs may cut at different azimuths: a rear sensor's sweep may end where a front
// one's is halfway).
struct Cuts {
  std::vector<std::uint16_t> cut_cdeg, drain_cdeg;
  explicit Cuts(const DaemonConfig& config) {
    for (const DaemonConfig::Lidar& l : config.all_lidars()) {
      const std::uint16_t cut = vlp16::cut_centidegrees(l.cut_azimuth_deg);
      if (std::find(cut_cdeg.begin(), cut_cdeg.end(), cut) != cut_cdeg.end()) continue;
      cut_cdeg.push_back(cut);
      drain_cdeg.push_back(
          static_cast<std::uint16_t>((cut + vlp16::kAzimuthLimit - kDrainAhead_cdeg) % vlp16::kAzimuthLimit));
    }
  }
};

// A LiDAR data packet that may close a sweep at one of the cuts (vlp16::may_complete_frame), or
// that is at the drain point ahead of one.
bool wake_now(const inputs::InputItem& item, const Cuts& cuts) noexcept {
  if (item.stream != inputs::Stream::kLidarData) return false;
  for (std::size_t i = 0; i < cuts.cut_cdeg.size(); ++i) {
    if (vlp16::may_complete_frame(item.bytes, cuts.cut_cdeg[i]) ||
        vlp16::may_complete_frame(item.bytes, cuts.drain_cdeg[i]))
      return true;
  }
  return false;
}

// Decodes a LiDAR data packet ahead into the lane's ring of decoded packets, so that the
// processing thread, on the other core, only copies its points. Answers whether it did: not for
// other items, nor for a packet the decoder does not take (the processing thread counts and
// says why), nor when that ring is full (the processing thread then decodes it itself: the same
// points either way).
// `scratch`: the thread's own room for one packet's points. The decoder's scattered stores land
// in it (in this core's cache) and the points then go to the ring's slot in one copy; decoded
// straight into the slot, whose lines the other core read last, each store waited for its line
// to come back (as-fast replay of the dual-return corridor on an AMD EPYC, Zen 5: a thread
// decoding 43 271 packets for another 107–125 ms, 78–81 ms so).
bool decode_ahead(const Pipeline& pipeline, InputLane& lane, const InputSlot& slot,
                  std::vector<vlp16::Point>& scratch) {
  if (slot.stream != inputs::Stream::kLidarData || pipeline.processor == nullptr || !lane.decoded) return false;
  // Only while the processing thread is behind (busy, and items wait in the ring; items this
  // thread holds back while it sleeps do not count): otherwise it decodes the packet itself, as
  // at real time, where decoding ahead would only add the copy between the cores. The work goes
  // to whichever core has room.
  const std::size_t backlog = std::min(kDecodeAheadBacklog, lane.ring->capacity() / 4);
  if (pipeline.processing_waits.load(std::memory_order_relaxed) || lane.ring->size() < backlog) return false;
  const std::span<const std::uint8_t> packet(slot.bytes.data(), slot.size);
  if (vlp16::validate_data_packet(packet) != vlp16::PacketError::kNone) return false;
  const int sensor =
      pipeline.processor->lane_for(inputs::InputItem{slot.stream, packet, slot.receive_ns, slot.sender, slot.port});
  if (sensor < 0) return false;
  const vlp16::PacketDecoder* decoder =
      pipeline.processor->lidar_stream(static_cast<std::size_t>(sensor)).decoder_for(packet);
  if (decoder == nullptr) return false;
  return lane.decoded->try_push([&](vlp16::DecodedPacket& d) {
    d.tag = slot.seq;
    d.model = decoder->model();
    scratch.clear();
    const vlp16::PacketDecoder::Result result = decoder->decode(packet, scratch);
    d.assign(scratch, result);
  });
}

}  // namespace

void input_loop(Pipeline& pipeline, InputLane& lane) {
  if (const std::string w = apply_thread_config(lane.thread_name.c_str(), lane.thread); !w.empty()) log::warn("{}", w);
  prefault_stack();
  const std::int64_t cpu_start = host::thread_cpu_ns();
  inputs::InputSource& source = *lane.source;
  InputRing& ring = *lane.ring;
  log::RateLimited error_limit(pipeline.config.logging.warning_interval_s);
  // The processing thread is woken once per batch of items, not per item: items that arrive
  // together go together (capped, so a replay running behind still wakes it); an item alone
  // waits up to kMaxHold_ns for company, unless it is a LiDAR packet that may close a sweep,
  // whose latency is the daemon's (it goes at once, with the few items held since the drain
  // ahead of the cut). A sweep's other packets cost no wake-up of their own: at 1 500
  // packets/s that was most of the processing thread's CPU at real time.
  // At most a quarter of the ring is held back (a small configured ring still never fills
  // while the processing thread sleeps).
  const auto max_batch = static_cast<int>(std::min<std::size_t>(64, std::max<std::size_t>(1, ring.capacity() / 4)));
  constexpr std::int64_t kMaxHold_ns = 20'000'000;
  const Cuts cuts(pipeline.config);
  int unnotified = 0;
  std::int64_t held_since_ns = 0;
  std::uint32_t items = 0;
  inputs::InputItem item;
  std::vector<vlp16::Point> scratch;
  if (lane.decoded) scratch.reserve(vlp16::kPointsPerPacket);  // one packet: decode() never grows it
  while (!pipeline.stop.load(std::memory_order_relaxed)) {
    // Held items bound the wait: they go when their time is up even if nothing follows.
    std::int64_t wait_ms = kIdleWait_ms;
    if (unnotified > 0)
      wait_ms = std::max<std::int64_t>(1, (held_since_ns + kMaxHold_ns - host::monotonic_ns() + 999'999) / 1'000'000);
    const auto next = source.next(item, std::chrono::milliseconds(wait_ms));
    if (next != inputs::InputSource::Next::kItem) {
      copy_counters(source, lane);
      if (unnotified > 0) {
        pipeline.process_wake.notify();
        unnotified = 0;
      }
    }
    if (next == inputs::InputSource::Next::kEnd) break;
    if (next == inputs::InputSource::Next::kTimeout) continue;
    if (next == inputs::InputSource::Next::kNotice) {
      const inputs::Notice& n = source.notice();
      if (n.level == inputs::Notice::Level::kWarning) {
        log::warn("{}", n.text);
      } else {
        log::info("{}", n.text);
      }
      continue;
    }
    if (next == inputs::InputSource::Next::kError) {
      std::uint64_t suppressed = 0;
      if (error_limit.allow(host::monotonic_ns(), suppressed)) {
        log::warn("{}: {}{}", source.describe(), source.error(),
                  suppressed > 0 ? " (" + std::to_string(suppressed) + " similar suppressed)" : std::string());
      }
      continue;
    }
    if (item.stream == inputs::Stream::kLidarData) {
      const vlp16::PacketError e = vlp16::validate_data_packet(item.bytes);
      if (e != vlp16::PacketError::kNone && e != vlp16::PacketError::kUnsupportedProduct)
        lane.foreign.add(item.bytes.size(), item.sender);
    }
    // One slot per datagram; serial bytes in slot-sized pieces with the same receive time.
    std::span<const std::uint8_t> rest = item.bytes;
    // A datagram is never split: the source drops (and counts) longer ones; this guards the slot.
    if (inputs::is_lidar(item.stream) && rest.size() > kMaxItemBytes) continue;
    do {
      const auto piece = rest.first(std::min(kMaxItemBytes, rest.size()));
      rest = rest.subspan(piece.size());
      const auto fill = [&](InputSlot& slot) {
        slot.receive_ns = item.receive_ns;
        slot.stream = item.stream;
        slot.size = static_cast<std::uint16_t>(piece.size());
        slot.sender = item.sender;
        slot.port = item.port;
        std::copy(piece.begin(), piece.end(), slot.bytes.begin());
        slot.arrival_ns = host::monotonic_ns();  // before decoding: the latency figures include it
        slot.seq = pipeline.sequence.fetch_add(1, std::memory_order_relaxed);
        slot.decoded = decode_ahead(pipeline, lane, slot, scratch);
      };
      (void)ring.push(fill, static_cast<std::size_t>(item.stream));  // a drop is counted by the ring, by stream
    } while (!rest.empty());
    if ((++items & 255U) == 0) copy_counters(source, lane);  // current under constant traffic
    if (unnotified++ == 0) held_since_ns = host::monotonic_ns();
    // An as-fast replay's processing thread that waits for input is woken at once: it would
    // idle for the batch. (A flag seen too late delays it to the batch's end, as before.)
    const bool waits = pipeline.exact && pipeline.processing_waits.load();
    if (waits || unnotified >= max_batch || wake_now(item, cuts) ||
        (!source.ready() && host::monotonic_ns() - held_since_ns >= kMaxHold_ns)) {
      pipeline.process_wake.notify();
      unnotified = 0;
    }
  }
  copy_counters(source, lane);
  pipeline.cpu_sources_ns.fetch_add(host::thread_cpu_ns() - cpu_start);
  lane.done.store(true, std::memory_order_release);
  pipeline.process_wake.notify();
}

}  // namespace trajroi::daemon
