#pragma once

// The one loop from a capture to the VLP-16 stream decoder: each datagram goes to the decoder
// by its destination port (data or position), and the end of the capture flushes the frame in
// progress. The tools (lidar-dump, watch, the evaluations) decode captures through it.
#include <cstdint>

#include "trajroi/vlp16/packet_source.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace trajroi::inputs {

class CaptureDecoder {
 public:
  CaptureDecoder(vlp16::PacketSource& source, vlp16::StreamDecoder& decoder, std::uint16_t data_port = vlp16::kDataPort,
                 std::uint16_t position_port = vlp16::kPositionPort)
      : source_(source), decoder_(decoder), data_port_(data_port), position_port_(position_port) {}

  // Decodes the next datagram (frames finished by it go to `sink`). kDatagram: one was
  // decoded (last() is it); kEnd or kError (the source's error()): the capture ended and the
  // frame in progress was flushed to `sink`. Datagrams to other ports are skipped.
  vlp16::PacketSource::Next step(vlp16::FrameSink& sink);
  // Steps to the end of the capture.
  vlp16::PacketSource::Next run(vlp16::FrameSink& sink);
  [[nodiscard]] const vlp16::Datagram& last() const noexcept { return datagram_; }

 private:
  vlp16::PacketSource& source_;
  vlp16::StreamDecoder& decoder_;
  std::uint16_t data_port_, position_port_;
  vlp16::Datagram datagram_;
  bool ended_ = false;
};

}  // namespace trajroi::inputs
