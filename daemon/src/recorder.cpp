// The recorder: every item the processing thread handled, written as a run folder (lidar.pcap,
// gnss.trjb, imu.trjb, pose.trjb with pose.source lcm) that replays to the same output.
#include <memory>

#include "log.hpp"
#include "threads.hpp"
#include "trajroi/inputs/run_merger.hpp"
#include "trajroi/serial/byte_log.hpp"
#include "trajroi/vlp16/pcap_source.hpp"

namespace trajroi::daemon {

namespace {

void record_to(Pipeline& pipeline, const std::filesystem::path& dir) {
  vlp16::PcapWriter pcap(dir / inputs::kLidarFile);
  serial::RecordingWriter gnss((dir / inputs::kGnssFile).string());
  serial::RecordingWriter imu((dir / inputs::kImuFile).string());
  std::unique_ptr<serial::RecordingWriter> pose;  // made at the first pose message
  Lane<InputSlot>& ring = *pipeline.record;
  const bool several = pipeline.config.all_lidars().size() > 1;
  for (;;) {
    bool any = false;
    while (InputSlot* s = ring.front()) {
      const std::span<const std::uint8_t> bytes(s->bytes.data(), s->size);
      switch (s->stream) {
        // One LiDAR: on the standard ports from the factory address. Several: each datagram
        // with its sender and port, which tell the sensors apart in the replay.
        case inputs::Stream::kLidarData:
          if (several) {
            pcap.write(s->receive_ns, s->port != 0 ? s->port : vlp16::kDataPort, bytes, s->sender);
          } else {
            pcap.write(s->receive_ns, vlp16::kDataPort, bytes);
          }
          break;
        case inputs::Stream::kLidarPosition:
          if (several) {
            pcap.write(s->receive_ns, s->port != 0 ? s->port : vlp16::kPositionPort, bytes, s->sender);
          } else {
            pcap.write(s->receive_ns, vlp16::kPositionPort, bytes);
          }
          break;
        case inputs::Stream::kGnss:
          gnss.write(serial::Chunk{bytes, s->receive_ns});
          break;
        case inputs::Stream::kImu:
          imu.write(serial::Chunk{bytes, s->receive_ns});
          break;
        case inputs::Stream::kPose:
          if (!pose) pose = std::make_unique<serial::RecordingWriter>((dir / inputs::kPoseFile).string());
          pose->write(serial::Chunk{bytes, s->receive_ns});
          break;
      }
      ring.release();
      any = true;
    }
    if (!any && pipeline.processing_done.load(std::memory_order_acquire) && ring.front() == nullptr) break;
    if (!any) pipeline.record_wake.wait(kIdleWait_ms);
  }
  pcap.close();
  gnss.flush();
  imu.flush();
  if (pose) pose->flush();
}

}  // namespace

void recorder_loop(Pipeline& pipeline, const std::filesystem::path& dir) {
  pthread_setname_np(pthread_self(), "trajroid-rec");
  try {
    record_to(pipeline, dir);
  } catch (const std::exception& e) {
    // The pipeline goes on; what cannot be recorded fills the record ring, counted.
    pipeline.record_failed.store(true, std::memory_order_relaxed);
    log::error("--record stopped: {}; the pipeline goes on, unrecorded", e.what());
  }
}

}  // namespace trajroi::daemon
