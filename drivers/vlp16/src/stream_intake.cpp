// What reaches the stream: each data packet validated and its model decided (ModelCheck) before
// it is decoded by that model's decoder, 0x21 packets held until their timing says which
// model sent them; the decoder another thread may decode ahead with; position packets.
#include <algorithm>

#include "trajroi/vlp16/stream_decoder.hpp"

namespace trajroi::vlp16 {

std::uint64_t StreamCounters::rejected_total() const noexcept {
  std::uint64_t total = 0;
  for (const std::uint64_t n : rejected)
    total += n;
  return total;
}

StreamCounters& StreamCounters::operator+=(const StreamCounters& o) noexcept {
  data_packets += o.data_packets;
  decoded_packets += o.decoded_packets;
  decoded_ahead += o.decoded_ahead;
  for (std::size_t e = 0; e < rejected.size(); ++e)
    rejected[e] += o.rejected[e];
  lost_packets += o.lost_packets;
  out_of_order += o.out_of_order;
  late_dropped += o.late_dropped;
  duplicates += o.duplicates;
  clock_resets += o.clock_resets;
  restarts += o.restarts;
  clock_jumps += o.clock_jumps;
  points += o.points;
  no_return += o.no_return;
  out_of_range += o.out_of_range;
  merged_returns += o.merged_returns;
  frames += o.frames;
  partial_frames += o.partial_frames;
  position_packets += o.position_packets;
  position_wrong_size += o.position_wrong_size;
  for (std::size_t e = 0; e < nmea.size(); ++e)
    nmea[e] += o.nmea[e];
  return *this;
}

void StreamDecoder::on_data_packet(std::span<const std::uint8_t> payload, std::int64_t receive_time_ns, FrameSink& sink,
                                   const DecodedPacket* decoded) {
  ++counters_.data_packets;
  // A packet decoded ahead was valid there (its bytes are the same).
  const PacketError error = decoded != nullptr ? PacketError::kNone : validate_data_packet(payload);
  if (error != PacketError::kNone) {
    ++counters_.rejected[static_cast<std::size_t>(error)];
    if (error == PacketError::kUnsupportedProduct) (void)model_.check(payload);  // records the reason
    return;
  }
  switch (model_.check(payload)) {
    case ModelCheck::Verdict::kDecided:
      current_ = decoders_[static_cast<std::size_t>(model_.model())].get();
      for (const HeldPacket& held : held_)
        accept(held.bytes, held.receive_time_ns, sink, nullptr);
      held_.clear();
      // Points decoded ahead by another model's decoder are decoded again here.
      accept(payload, receive_time_ns, sink,
             decoded != nullptr && decoded->model == model_.model() ? decoded : nullptr);
      return;
    case ModelCheck::Verdict::kUndecided:
      if (held_.size() < ModelCheck::kMaxUndecided) {
        HeldPacket& held = held_.emplace_back();
        std::copy(payload.begin(), payload.end(), held.bytes.begin());
        held.receive_time_ns = receive_time_ns;
        return;
      }
      break;  // cannot happen: the check decides within kMaxUndecided packets
    case ModelCheck::Verdict::kRejected:
      break;
  }
  counters_.rejected[static_cast<std::size_t>(PacketError::kUnsupportedProduct)] += 1 + held_.size();
  held_.clear();
}

const PacketDecoder* StreamDecoder::decoder_for(std::span<const std::uint8_t> packet) const noexcept {
  if (packet.size() != kDataPacketBytes) return nullptr;
  std::optional<Model> model = unambiguous_model(vlp16::product_id(packet));
  if (!model && vlp16::product_id(packet) == kProductHdl32e && !options_.detect_model) model = options_.model;
  return model ? decoders_[static_cast<std::size_t>(*model)].get() : nullptr;
}

void StreamDecoder::on_position_packet(std::span<const std::uint8_t> payload) {
  ++counters_.position_packets;
  PositionPacket packet;
  if (!parse_position_packet(payload, packet)) {
    ++counters_.position_wrong_size;
    return;
  }
  ++counters_.nmea[static_cast<std::size_t>(packet.nmea)];
  last_position_ = packet;
  if (packet.nmea == NmeaError::kNone) {
    if (!first_rmc_) first_rmc_ = packet;
    last_rmc_ = packet;
  }
  utc_clock_.on_position(packet);
}

}  // namespace trajroi::vlp16
