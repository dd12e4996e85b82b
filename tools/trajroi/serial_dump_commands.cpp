// `trajroi gnss-dump` and `trajroi imu-dump`: read a u-blox or VN-100 byte log (a raw capture
// or a .trjb recording) through the same framers and decoders the daemon uses, and report
// what it holds.
#include <cinttypes>
#include <cstdio>
#include <functional>
#include <string>
#include <vector>

#include "commands.hpp"
#include "trajroi/framing/utc.hpp"
#include "trajroi/serial/byte_log.hpp"
#include "trajroi/ublox/framer.hpp"
#include "trajroi/ublox/messages.hpp"
#include "trajroi/vn100/decoder.hpp"
#include "trajroi/vn100/framer.hpp"

namespace trajroi::cli {
namespace {

// Feeds every byte of `path` (raw or recording) to `feed`, in order.
template <class Feed>
void for_each_chunk(const std::string& path, Feed&& feed) {
  serial::ReplaySource source(path);
  serial::Chunk chunk;
  while (source.read(chunk, std::chrono::milliseconds(0)) == serial::ReadStatus::kData)
    feed(chunk.bytes);
  if (source.truncated_records() != 0)
    std::fprintf(stderr, "trajroi: %s: the recording ends inside a record\n", path.c_str());
}

void print_framer_counts_json(const framing::FramerCounters& c) {
  std::printf("  \"bytes\": %" PRIu64 ",\n  \"checksum_errors\": %" PRIu64 ",\n  \"skipped_bytes\": %" PRIu64
              ",\n  \"bad_lengths\": %" PRIu64 ",\n  \"truncated_frames\": %" PRIu64 ",\n",
              c.bytes, c.checksum_errors, c.skipped_bytes, c.bad_lengths, c.truncated);
}

void print_framer_counts_text(const framing::FramerCounters& c) {
  std::printf("bytes            %" PRIu64 "\nframes           %" PRIu64 "\nchecksum errors  %" PRIu64
              "\nskipped bytes    %" PRIu64 "\nbad lengths      %" PRIu64 "\ntruncated frames %" PRIu64 "\n",
              c.bytes, c.frames, c.checksum_errors, c.skipped_bytes, c.bad_lengths, c.truncated);
}

// ---- gnss-dump ----------------------------------------------------------------------------------

void gnss_dump(const std::string& path, bool json) {
  ublox::Framer framer;
  std::vector<ublox::NavPvt> fixes;
  std::uint64_t malformed_nav_pvt = 0;  // framed, but a payload NAV-PVT cannot be
  const auto on_message = [&](const ublox::Message& m) {
    if (m.msg_class != ublox::kClassNav || m.msg_id != ublox::kIdNavPvt) return;
    const auto d = ublox::decode_nav_pvt(m.payload);
    if (d.ok()) {
      fixes.push_back(d.value);
    } else {
      ++malformed_nav_pvt;
    }
  };
  for_each_chunk(path, [&](std::span<const std::uint8_t> bytes) { framer.feed(bytes, on_message); });
  framer.finish(on_message);

  const framing::FramerCounters& c = framer.counters();
  if (!json) {
    std::printf("file             %s\n", path.c_str());
    print_framer_counts_text(c);
    for (const auto& [key, n] : framer.frames_by_type()) {
      std::printf(
          "  %-14s %" PRIu64 "\n",
          ublox::message_name(static_cast<std::uint8_t>(key >> 8), static_cast<std::uint8_t>(key & 0xFF)).c_str(), n);
    }
    if (malformed_nav_pvt != 0) std::printf("malformed NAV-PVT %" PRIu64 "\n", malformed_nav_pvt);
    std::printf("NAV-PVT epochs   %zu\n", fixes.size());
    for (const ublox::NavPvt& f : fixes) {
      std::printf("  %s fix %u %-5s sv %2u  %.7f %.7f  h %.3f m  msl %.3f m  hacc %.3f m\n",
                  f.utc_valid() ? format_utc_ms(f.utc_ns()).c_str() : "(no UTC)                ",
                  unsigned{f.fix_type_raw}, std::string(to_string(f.carr_soln)).c_str(), unsigned{f.num_sv},
                  f.lat_deg(), f.lon_deg(), f.height_m(), f.hmsl_m(), f.h_acc_m());
    }
    return;
  }
  std::printf("{\n  \"file\": \"%s\",\n", path.c_str());
  print_framer_counts_json(c);
  std::printf("  \"frames\": {");
  bool first = true;
  for (const auto& [key, n] : framer.frames_by_type()) {
    std::printf("%s\"%s\": %" PRIu64, first ? "" : ", ",
                ublox::message_name(static_cast<std::uint8_t>(key >> 8), static_cast<std::uint8_t>(key & 0xFF)).c_str(),
                n);
    first = false;
  }
  std::printf("},\n  \"frames_total\": %" PRIu64 ",\n  \"malformed_nav_pvt\": %" PRIu64 ",\n  \"fixes\": [", c.frames,
              malformed_nav_pvt);
  for (std::size_t i = 0; i < fixes.size(); ++i) {
    const ublox::NavPvt& f = fixes[i];
    std::printf(
        "%s\n    {\"utc\": %s%s%s, \"itow_ms\": %" PRIu32
        ", \"fix_type\": %u, \"gnss_fix_ok\": %s, \"carr_soln\": \"%s\", "
        "\"num_sv\": %u, \"lat\": %.9f, \"lon\": %.9f, \"height_m\": %.3f, \"hmsl_m\": %.3f, \"h_acc_m\": %.3f, "
        "\"v_acc_m\": %.3f, \"ground_speed_mps\": %.3f, \"head_mot_deg\": %.5f}",
        i == 0 ? "" : ",", f.utc_valid() ? "\"" : "", f.utc_valid() ? format_utc_ms(f.utc_ns()).c_str() : "null",
        f.utc_valid() ? "\"" : "", f.itow_ms, unsigned{f.fix_type_raw}, f.gnss_fix_ok ? "true" : "false",
        std::string(to_string(f.carr_soln)).c_str(), unsigned{f.num_sv}, f.lat_deg(), f.lon_deg(), f.height_m(),
        f.hmsl_m(), f.h_acc_m(), f.v_acc_m(), f.ground_speed_mps(), f.head_mot_deg());
  }
  std::printf("%s]\n}\n", fixes.empty() ? "" : "\n  ");
}

// ---- imu-dump -----------------------------------------------------------------------------------

struct Column {
  std::string name;
  std::function<bool(const vn100::Sample&)> present;
  std::function<double(const vn100::Sample&)> value;
};

double f(float v) {
  return static_cast<double>(v);
}

// accel/gyro/mag: the compensated value when the frame carries it, else the uncompensated one.
template <std::size_t N>
Column pick(std::string name, vn100::Field comp, vn100::Field uncomp, std::array<float, N> vn100::Sample::*comp_member,
            std::array<float, N> vn100::Sample::*uncomp_member, std::size_t i) {
  return {std::move(name), [=](const vn100::Sample& s) { return s.has(comp) || s.has(uncomp); },
          [=](const vn100::Sample& s) { return f(s.has(comp) ? (s.*comp_member)[i] : (s.*uncomp_member)[i]); }};
}

template <std::size_t N>
Column member(std::string name, vn100::Field field, std::array<float, N> vn100::Sample::*m, std::size_t i) {
  return {std::move(name), [=](const vn100::Sample& s) { return s.has(field); },
          [=](const vn100::Sample& s) { return f((s.*m)[i]); }};
}

std::vector<Column> imu_columns() {
  using vn100::Field;
  using S = vn100::Sample;
  std::vector<Column> c{
      member("yaw_deg", Field::kYawPitchRoll, &S::ypr_deg, 0),
      member("pitch_deg", Field::kYawPitchRoll, &S::ypr_deg, 1),
      member("roll_deg", Field::kYawPitchRoll, &S::ypr_deg, 2),
      pick("accel_x", Field::kAccel, Field::kUncompAccel, &S::accel_mps2, &S::uncomp_accel_mps2, 0),
      pick("accel_y", Field::kAccel, Field::kUncompAccel, &S::accel_mps2, &S::uncomp_accel_mps2, 1),
      pick("accel_z", Field::kAccel, Field::kUncompAccel, &S::accel_mps2, &S::uncomp_accel_mps2, 2),
      pick("gyro_x", Field::kAngularRate, Field::kUncompGyro, &S::angular_rate_rps, &S::uncomp_gyro_rps, 0),
      pick("gyro_y", Field::kAngularRate, Field::kUncompGyro, &S::angular_rate_rps, &S::uncomp_gyro_rps, 1),
      pick("gyro_z", Field::kAngularRate, Field::kUncompGyro, &S::angular_rate_rps, &S::uncomp_gyro_rps, 2),
      pick("mag_x", Field::kMag, Field::kUncompMag, &S::mag_gauss, &S::uncomp_mag_gauss, 0),
      pick("mag_y", Field::kMag, Field::kUncompMag, &S::mag_gauss, &S::uncomp_mag_gauss, 1),
      pick("mag_z", Field::kMag, Field::kUncompMag, &S::mag_gauss, &S::uncomp_mag_gauss, 2),
      {"temp_c", [](const S& s) { return s.has(Field::kTemperature); }, [](const S& s) { return f(s.temperature_c); }},
      {"pres_kpa", [](const S& s) { return s.has(Field::kPressure); }, [](const S& s) { return f(s.pressure_kpa); }},
  };
  const char* quat[] = {"quat_x", "quat_y", "quat_z", "quat_w"};
  for (std::size_t i = 0; i < 4; ++i)
    c.push_back(member(quat[i], Field::kQuaternion, &S::quaternion_xyzw, i));
  const char* dcm[] = {"dcm_1", "dcm_2", "dcm_3", "dcm_4", "dcm_5", "dcm_6", "dcm_7", "dcm_8", "dcm_9"};
  for (std::size_t i = 0; i < 9; ++i)
    c.push_back(member(dcm[i], Field::kDcm, &S::dcm, i));
  const char* ned[] = {"n", "e", "d"};
  const auto triple = [&](const char* prefix, Field field, std::array<float, 3> S::*m) {
    for (std::size_t i = 0; i < 3; ++i)
      c.push_back(member(std::string(prefix) + ned[i], field, m, i));
  };
  triple("mag_ned_", Field::kMagNed, &S::mag_ned_gauss);
  triple("accel_ned_", Field::kAccelNed, &S::accel_ned_mps2);
  triple("linear_accel_ned_", Field::kLinearAccelNed, &S::linear_accel_ned_mps2);
  const char* xyz[] = {"x", "y", "z"};
  for (std::size_t i = 0; i < 3; ++i) {
    c.push_back(
        member(std::string("linear_accel_body_") + xyz[i], Field::kLinearAccelBody, &S::linear_accel_body_mps2, i));
  }
  const char* ypr_u[] = {"yaw_u_deg", "pitch_u_deg", "roll_u_deg"};
  for (std::size_t i = 0; i < 3; ++i)
    c.push_back(member(ypr_u[i], Field::kYprUncertainty, &S::ypr_uncertainty_deg, i));
  c.push_back({"time_startup_ns", [](const S& s) { return s.has(Field::kTimeStartup); },
               [](const S& s) { return static_cast<double>(s.time_startup_ns); }});
  c.push_back({"time_gps_ns", [](const S& s) { return s.has(Field::kTimeGps); },
               [](const S& s) { return static_cast<double>(s.time_gps_ns); }});
  return c;
}

void imu_dump(const std::string& path, bool csv) {
  vn100::Framer framer;
  std::vector<vn100::Sample> samples;
  std::uint64_t undecodable = 0;
  const auto on_frame = [&](std::span<const std::uint8_t> frame) {
    vn100::Sample s;
    if (vn100::decode(frame, s)) {
      samples.push_back(s);
    } else {
      ++undecodable;
    }
  };
  for_each_chunk(path, [&](std::span<const std::uint8_t> bytes) { framer.feed(bytes, on_frame); });
  framer.finish(on_frame);

  const std::vector<Column> all = imu_columns();
  std::vector<const Column*> columns;
  for (std::size_t i = 0; i < all.size(); ++i) {
    bool any = i < 6;  // the six leading columns are always printed
    for (const vn100::Sample& s : samples) {
      if (any) break;
      any = all[i].present(s);
    }
    if (any) columns.push_back(&all[i]);
  }
  if (!csv) {
    const framing::FramerCounters& c = framer.counters();
    std::printf("file             %s\n", path.c_str());
    print_framer_counts_text(c);
    std::printf("unsizable        %" PRIu64 "\nundecodable      %" PRIu64 "\nfields          ", c.unsizable,
                undecodable);
    for (const Column* col : columns)
      std::printf(" %s", col->name.c_str());
    std::printf("\n");
    if (!samples.empty() && samples.front().has(vn100::Field::kYawPitchRoll)) {
      std::printf("first yaw/pitch/roll  %.7g %.7g %.7g deg\n", f(samples.front().ypr_deg[0]),
                  f(samples.front().ypr_deg[1]), f(samples.front().ypr_deg[2]));
    }
    return;
  }
  for (std::size_t i = 0; i < columns.size(); ++i)
    std::printf("%s%s", i == 0 ? "" : ",", columns[i]->name.c_str());
  std::printf("\n");
  for (const vn100::Sample& s : samples) {
    for (std::size_t i = 0; i < columns.size(); ++i) {
      if (i != 0) std::putchar(',');
      if (columns[i]->present(s)) std::printf("%.9g", columns[i]->value(s));
    }
    std::putchar('\n');
  }
}

}  // namespace

void add_serial_dump_commands(CLI::App& app) {
  auto gnss = std::make_shared<std::pair<std::string, bool>>();
  CLI::App* g = app.add_subcommand("gnss-dump", "Frame and decode a u-blox UBX log (raw bytes or a .trjb recording)");
  g->add_option("file", gnss->first, "UBX byte log")->required()->check(CLI::ExistingFile);
  g->add_flag("--json", gnss->second, "Print counts and every NAV-PVT epoch as JSON");
  g->callback([gnss] { gnss_dump(gnss->first, gnss->second); });

  auto imu = std::make_shared<std::pair<std::string, bool>>();
  CLI::App* i =
      app.add_subcommand("imu-dump", "Frame and decode a VectorNav VN-100 binary log (raw bytes or a .trjb recording)");
  i->add_option("file", imu->first, "VN-100 byte log")->required()->check(CLI::ExistingFile);
  i->add_flag("--csv", imu->second,
              "Print one CSV row per frame (accel/gyro/mag are the compensated values when the frame carries them, "
              "otherwise the uncompensated ones)");
  i->callback([imu] { imu_dump(imu->first, imu->second); });
}

}  // namespace trajroi::cli
