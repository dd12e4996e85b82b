#include "trajroi/inputs/capture.hpp"

#include <chrono>

namespace trajroi::inputs {

vlp16::PacketSource::Next CaptureDecoder::step(vlp16::FrameSink& sink) {
  using Next = vlp16::PacketSource::Next;
  for (;;) {
    const Next next = ended_ ? Next::kEnd : source_.next(datagram_, std::chrono::milliseconds::max());
    if (next == Next::kTimeout) continue;
    if (next != Next::kDatagram) {
      if (!ended_) decoder_.flush(sink);
      ended_ = true;
      return next;
    }
    if (datagram_.destination_port == position_port_) {
      decoder_.on_position_packet(datagram_.payload);
    } else if (datagram_.destination_port == data_port_) {
      decoder_.on_data_packet(datagram_.payload, datagram_.receive_time_ns, sink);
    } else {
      continue;
    }
    return Next::kDatagram;
  }
}

vlp16::PacketSource::Next CaptureDecoder::run(vlp16::FrameSink& sink) {
  vlp16::PacketSource::Next next;
  while ((next = step(sink)) == vlp16::PacketSource::Next::kDatagram) {
  }
  return next;
}

}  // namespace trajroi::inputs
