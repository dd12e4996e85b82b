// `trajroi lidar-dump`: replays a Velodyne pcap through the VLP-16 stream decoder and
// reports what it holds (packets, rejections, model, frames, loss, GPRMC), optionally every
// point as CSV.
#include <algorithm>
#include <cerrno>
#include <cinttypes>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>

#include "commands.hpp"
#include "file_io.hpp"
#include "trajroi/framing/utc.hpp"
#include "trajroi/inputs/capture.hpp"
#include "trajroi/vlp16/pcap_source.hpp"
#include "trajroi/vlp16/stream_decoder.hpp"

namespace trajroi::cli {
namespace {

using namespace trajroi::vlp16;

struct LidarDumpOptions {
  std::string capture;
  std::string calibration;
  std::string model = "auto";
  std::string points_csv;
  bool json = false;
  double min_range_m = 0.0;
  double max_range_m = std::numeric_limits<double>::infinity();
  double cut_azimuth_deg = 0.0;
  std::uint16_t data_port = kDataPort;
  std::uint16_t position_port = kPositionPort;
};

// Writes every frame's points as CSV to a temporary file, renamed over the target at the end.
class CsvSink final : public FrameSink {
 public:
  explicit CsvSink(std::filesystem::path path) : path_(std::move(path)), temporary_(path_.string() + ".partial") {
    file_.reset(std::fopen(temporary_.c_str(), "w"));
    if (!file_) throw std::runtime_error(temporary_.string() + ": cannot write: " + std::strerror(errno));
    std::fputs("frame,x,y,z,intensity,ring,azimuth_deg,distance_m,time_ns,return_type\n", file_.get());
  }
  void on_frame(const Frame& frame) override {
    for (const Point& p : frame.points) {
      std::fprintf(file_.get(), "%" PRIu64 ",%.4f,%.4f,%.4f,%u,%u,%.3f,%.3f,%u,%s\n", frame.index,
                   static_cast<double>(p.x), static_cast<double>(p.y), static_cast<double>(p.z), unsigned{p.intensity},
                   unsigned{p.ring}, static_cast<double>(p.azimuth_deg), static_cast<double>(p.distance_m),
                   p.time_offset_ns, std::string(to_string(p.return_type)).c_str());
    }
  }
  void commit() {
    const bool ok = std::fflush(file_.get()) == 0 && std::ferror(file_.get()) == 0;
    file_.reset();
    if (!ok) throw std::runtime_error(temporary_.string() + ": write failed");
    std::filesystem::rename(temporary_, path_);
  }

 private:
  struct Close {
    void operator()(std::FILE* f) const { std::fclose(f); }
  };
  std::filesystem::path path_;
  std::filesystem::path temporary_;
  std::unique_ptr<std::FILE, Close> file_;
};

struct NullSink final : FrameSink {
  void on_frame(const Frame&) override {}
};

std::string json_string(const std::string& s) {
  std::string out = "\"";
  for (const char ch : s) {
    if (ch == '"' || ch == '\\') {
      out += '\\';
      out += ch;
    } else if (static_cast<unsigned char>(ch) < 0x20) {
      char escape[8];
      std::snprintf(escape, sizeof escape, "\\u%04x", static_cast<unsigned>(ch));
      out += escape;
    } else {
      out += ch;
    }
  }
  return out + "\"";
}

std::string rmc_json(const std::optional<PositionPacket>& p) {
  if (!p) return "null";
  char text[200];
  std::snprintf(text, sizeof text, "{\"utc\": \"%s\", \"valid\": %s, \"lat\": %.9f, \"lon\": %.9f}",
                format_utc_ms(p->rmc.utc_ns).c_str(), p->rmc.valid ? "true" : "false", p->rmc.latitude_deg,
                p->rmc.longitude_deg);
  return text;
}

std::string hex_byte(std::uint8_t b) {
  char text[8];
  std::snprintf(text, sizeof text, "0x%02X", unsigned{b});
  return text;
}

std::string return_mode_name(std::optional<ReturnMode> mode) {
  if (!mode) return "";
  switch (*mode) {
    case ReturnMode::kStrongest:
      return "strongest";
    case ReturnMode::kLast:
      return "last";
    case ReturnMode::kDual:
      return "dual";
  }
  return "";
}

void run_lidar_dump(const LidarDumpOptions& o) {
  const std::optional<Model> named = model_named(o.model);
  Calibration calibration = Calibration::for_model(named.value_or(Model::kVlp16));
  if (!o.calibration.empty()) {
    calibration = parse_calibration_file(read_text_file(o.calibration), o.calibration);
    const ModelSpec& s = spec(named.value_or(Model::kVlp16));
    if (calibration.laser_count != s.lasers) {
      throw std::runtime_error(o.calibration + ": " + std::to_string(calibration.laser_count) + " lasers, but a " +
                               std::string(s.name) + " has " + std::to_string(s.lasers) +
                               (named ? "" : " (--model for a 32-laser calibration: vlp32c or hdl32e)"));
    }
  }
  StreamOptions options;
  options.model = named.value_or(Model::kVlp16);
  options.detect_model = !named && o.calibration.empty();
  options.decode.min_range_m = o.min_range_m;
  options.decode.max_range_m = o.max_range_m;
  options.cut_azimuth_deg = o.cut_azimuth_deg;
  StreamDecoder decoder(calibration, options);

  PcapOptions pcap;
  pcap.ports = {o.data_port, o.position_port};
  PcapSource source(o.capture, pcap);
  std::optional<CsvSink> csv;
  if (!o.points_csv.empty()) csv.emplace(o.points_csv);
  NullSink null_sink;
  FrameSink& sink = csv ? static_cast<FrameSink&>(*csv) : null_sink;

  std::map<std::uint8_t, std::uint64_t> product_ids;  // byte 1205 of every 1206-byte payload
  inputs::CaptureDecoder capture(source, decoder, o.data_port, o.position_port);
  PacketSource::Next next;
  while ((next = capture.step(sink)) == PacketSource::Next::kDatagram) {
    const Datagram& datagram = capture.last();
    if (datagram.destination_port == o.data_port && datagram.payload.size() == kDataPacketBytes) {
      ++product_ids[product_id(datagram.payload)];
    }
  }
  if (csv) csv->commit();
  const std::string read_error = next == PacketSource::Next::kError ? source.error() : "";

  const StreamCounters& c = decoder.counters();
  std::optional<std::uint8_t> product = decoder.product_id();
  if (!product && !product_ids.empty()) {  // none decoded: the id most packets carried
    product = std::max_element(product_ids.begin(), product_ids.end(), [](const auto& a, const auto& b) {
                return a.second < b.second;
              })->first;
  }
  const std::string model = c.decoded_packets > 0 ? std::string(to_string(decoder.model_check().model()))
                            : product             ? std::string(product_name(*product))
                                                  : "";

  if (o.json) {
    std::string rejected = "{";
    for (std::size_t e = 1; e < kPacketErrorCount; ++e) {
      rejected += (e > 1 ? ", \"" : "\"") + std::string(to_string(static_cast<PacketError>(e))) +
                  "\": " + std::to_string(c.rejected[e]);
    }
    rejected += "}";
    std::printf(
        "{\"file\": %s, \"data_packets\": %" PRIu64 ", \"position_packets\": %" PRIu64
        ", \"rejected_packets\": %s, \"rejection\": %s, \"model\": %s, \"product_id\": %s, \"return_mode\": %s, "
        "\"frames\": %" PRIu64 ", \"partial_frames\": %" PRIu64 ", \"points\": %" PRIu64 ", \"no_return\": %" PRIu64
        ", \"out_of_range\": %" PRIu64 ", \"lost_packets\": %" PRIu64 ", \"out_of_order\": %" PRIu64
        ", \"duplicates\": %" PRIu64 ", \"skipped_records\": %" PRIu64
        ", \"gprmc\": {\"first\": %s, \"last\": %s}, "
        "\"read_error\": %s}\n",
        json_string(o.capture).c_str(), c.data_packets, c.position_packets, rejected.c_str(),
        c.rejected_total() > 0 && !decoder.model_check().reason().empty()
            ? json_string(decoder.model_check().reason()).c_str()
            : "null",
        model.empty() ? "null" : json_string(model).c_str(), product ? json_string(hex_byte(*product)).c_str() : "null",
        decoder.return_mode() ? json_string(return_mode_name(decoder.return_mode())).c_str() : "null", c.frames,
        c.partial_frames, c.points, c.no_return, c.out_of_range, c.lost_packets, c.out_of_order, c.duplicates,
        source.skipped_records(), rmc_json(decoder.first_rmc()).c_str(), rmc_json(decoder.last_rmc()).c_str(),
        read_error.empty() ? "null" : json_string(read_error).c_str());
  } else {
    std::printf("%s\n", o.capture.c_str());
    std::printf("  data packets      %" PRIu64 " (%" PRIu64 " decoded, %" PRIu64 " rejected)\n", c.data_packets,
                c.decoded_packets, c.rejected_total());
    for (std::size_t e = 1; e < kPacketErrorCount; ++e) {
      if (c.rejected[e] > 0) {
        std::printf("    %-22s %" PRIu64 "\n", std::string(to_string(static_cast<PacketError>(e))).c_str(),
                    c.rejected[e]);
      }
    }
    if (!decoder.model_check().reason().empty() && c.rejected_total() > 0)
      std::printf("    %s\n", decoder.model_check().reason().c_str());
    std::printf("  model             %s%s\n", model.empty() ? "-" : model.c_str(),
                product ? (" (product id " + hex_byte(*product) + ")").c_str() : "");
    std::printf("  return mode       %s\n",
                decoder.return_mode() ? return_mode_name(decoder.return_mode()).c_str() : "-");
    std::printf("  frames            %" PRIu64 " complete, %" PRIu64 " partial\n", c.frames, c.partial_frames);
    std::printf("  points            %" PRIu64 " (no return %" PRIu64 ", out of range %" PRIu64 ")\n", c.points,
                c.no_return, c.out_of_range);
    std::printf("  lost packets      %" PRIu64 " (out of order %" PRIu64 ", duplicates %" PRIu64 ")\n", c.lost_packets,
                c.out_of_order, c.duplicates);
    std::printf("  position packets  %" PRIu64 "\n", c.position_packets);
    if (decoder.first_rmc()) std::printf("  GPRMC first       %s\n", rmc_json(decoder.first_rmc()).c_str());
    if (decoder.last_rmc()) std::printf("  GPRMC last        %s\n", rmc_json(decoder.last_rmc()).c_str());
    if (!read_error.empty()) std::printf("  read error        %s\n", read_error.c_str());
  }
  if (!read_error.empty()) throw std::runtime_error(o.capture + ": " + read_error);
  // Nothing decoded is a failure, said as one: a script must not take an empty report for a capture.
  if (c.decoded_packets == 0) {
    const std::string why =
        c.data_packets == 0 ? "no datagram to UDP port " + std::to_string(o.data_port) + " (--data-port)"
        : !decoder.model_check().reason().empty()
            ? "all " + std::to_string(c.data_packets) + " data packets rejected: " + decoder.model_check().reason()
            : "all " + std::to_string(c.data_packets) + " data packets rejected (see the counts above)";
    throw std::runtime_error(o.capture + ": no data packet could be decoded: " + why);
  }
}

}  // namespace

void add_lidar_dump_command(CLI::App& app) {
  auto o = std::make_shared<LidarDumpOptions>();
  CLI::App* cmd = app.add_subcommand("lidar-dump",
                                     "Decode a Velodyne pcap capture (VLP-16, Puck LITE / Hi-Res, VLP-32C, HDL-32E) "
                                     "and report what it holds, the model first");
  cmd->add_option("capture", o->capture, "pcap file (Ethernet, VLAN, Linux SLL/SLL2 or raw IPv4)")
      ->required()
      ->check(CLI::ExistingFile);
  cmd->add_option("--model", o->model, "auto (from the packets' product id) or the sensor's model")
      ->check(CLI::IsMember({"auto", "vlp16", "puck_lite", "puck_hires", "vlp32c", "hdl32e"}));
  cmd->add_option("--calibration", o->calibration,
                  "calibration for --model: velodyne/nebula YAML or VeloView XML (default: the model's manual values)")
      ->check(CLI::ExistingFile);
  cmd->add_flag("--json", o->json, "print one JSON object");
  cmd->add_option("--points", o->points_csv,
                  "write frame,x,y,z,intensity,ring,azimuth_deg,distance_m,time_ns,return_type rows "
                  "(time_ns after the frame's start)");
  cmd->add_option("--min-range", o->min_range_m, "drop returns nearer than this, m")->check(CLI::NonNegativeNumber);
  cmd->add_option("--max-range", o->max_range_m, "drop returns farther than this, m")->check(CLI::PositiveNumber);
  cmd->add_option("--cut-azimuth", o->cut_azimuth_deg, "azimuth where a frame begins, degrees")
      ->check(CLI::Range(0.0, 360.0));
  cmd->add_option("--data-port", o->data_port, "UDP destination port of data packets");
  cmd->add_option("--position-port", o->position_port, "UDP destination port of position packets");
  cmd->callback([o] { run_lidar_dump(*o); });
}

}  // namespace trajroi::cli
