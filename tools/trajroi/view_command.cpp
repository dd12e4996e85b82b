// trajroi view: a live view of trajroid in any browser. Subscribes to trajroid's LCM channels
// and serves one page (view/web/, compiled in) and three.js (Debian's libjs-three) over HTTP,
// and the sweeps, the ROI chain, the active trajectory, the pose and the status over a
// WebSocket as binary frames (view/include/trajroi/view/frames.hpp). A separate process, never
// in the daemon's real-time path: a slow page skips sweeps (the newest wins, per client).
//
// The pages say which sweep they drew; the view matches that with the sweep's last firing
// (points_t.sweep_end_ns, CLOCK_MONOTONIC on this host) for the sensor-to-screen latency it
// logs every 10 s with its own CPU time.
#include <sys/resource.h>

#include <algorithm>
#include <atomic>
#include <csignal>
#include <cstdio>
#include <ctime>
#include <deque>
#include <filesystem>
#include <fstream>
#include <lcm/lcm-cpp.hpp>
#include <map>
#include <optional>
#include <sstream>
#include <string>
#include <vector>

#include "commands.hpp"
#include "trajroi/points_t.hpp"
#include "trajroi/pose_t.hpp"
#include "trajroi/roi_t.hpp"
#include "trajroi/status_t.hpp"
#include "trajroi/trajectory_t.hpp"
#include "trajroi/transport/lcm_subscribe.hpp"
#include "trajroi/transport/receive_buffer.hpp"
#include "trajroi/view/assets.hpp"
#include "trajroi/view/frames.hpp"
#include "trajroi/view/server.hpp"

namespace trajroi::cli {
namespace {

namespace fs = std::filesystem;

std::atomic<bool> g_stop{false};

std::int64_t clock_ns(clockid_t clock) {
  timespec ts{};
  clock_gettime(clock, &ts);
  return static_cast<std::int64_t>(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

// The status's named counter `name` (0 when it has none: an older trajroid).
std::int64_t named_counter(const trajroi::status_t& s, std::string_view name) {
  for (std::size_t i = 0; i < s.counter_names.size() && i < s.counter_values.size(); ++i)
    if (s.counter_names[i] == name) return s.counter_values[i];
  return 0;
}

struct ViewOptions {
  std::string listen = "127.0.0.1:8090";
  std::string url = "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608";
  std::string prefix = "TRAJROI";
  std::string three_dir = "/usr/share/javascript/three";
  double max_rate_hz = 10.0;
  double seconds = 0.0;
  double report_s = 10.0;
};

std::shared_ptr<const std::vector<std::uint8_t>> shared(std::vector<std::uint8_t> bytes) {
  return std::make_shared<const std::vector<std::uint8_t>>(std::move(bytes));
}

std::shared_ptr<const std::vector<std::uint8_t>> read_file(const fs::path& p) {
  std::ifstream in(p, std::ios::binary);
  if (!in) return nullptr;
  std::vector<std::uint8_t> bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  return shared(std::move(bytes));
}

// The page's files: the compiled-in page, three.js and its orbit controls from `three_dir`.
std::vector<view::Asset> page_assets(const fs::path& three_dir) {
  std::vector<view::Asset> assets;
  for (const view::EmbeddedFile& f : view::page_files()) {
    const bool html = f.name.ends_with(".html");
    assets.push_back({html ? "/" : "/" + f.name, html ? "text/html; charset=utf-8" : "text/javascript; charset=utf-8",
                      shared(std::vector<std::uint8_t>(f.content.begin(), f.content.end()))});
  }
  const std::pair<const char*, fs::path> three[] = {
      {"/three/three.min.js", three_dir / "three.min.js"},
      {"/three/OrbitControls.js", three_dir / "examples/js/controls/OrbitControls.js"}};
  for (const auto& [path, file] : three) {
    auto body = read_file(file);
    if (!body) {
      throw std::runtime_error("three.js: cannot read " + file.string() +
                               " (Debian's libjs-three: apt-get install libjs-three; or --three-dir DIR)");
    }
    assets.push_back({path, "text/javascript; charset=utf-8", std::move(body)});
  }
  return assets;
}

double percentile(std::vector<double> v, double q) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(q * static_cast<double>(v.size())))];
}

class Viewer {
 public:
  Viewer(const ViewOptions& o, view::ViewServer& server)
      : o_(o), server_(server), lcm_(transport::without_receive_buffer(o.url)) {
    if (!lcm_.good()) throw std::runtime_error("LCM: cannot open " + o.url);
    const std::string p = o.prefix;
    transport::subscribe<&Viewer::on_points>(lcm_, p + "_POINTS", this);
    transport::subscribe<&Viewer::on_raw>(lcm_, p + "_RAW_POINTS", this);
    transport::subscribe<&Viewer::on_roi>(lcm_, p + "_ROI", this);
    transport::subscribe<&Viewer::on_pose>(lcm_, p + "_POSE", this);
    transport::subscribe<&Viewer::on_status>(lcm_, p + "_STATUS", this);
    transport::subscribe<&Viewer::on_trajectory>(lcm_, p + "_ACTIVE_TRAJECTORY", this);
    take_receive_buffer();
    server_.on_text([this](const std::string& text, std::int64_t at_ns) { on_page_text(text, at_ns); });
    server_.on_event([](const std::string& text) { std::printf("trajroi view: %s\n", text.c_str()); });
  }

  void run() {
    const std::int64_t start = clock_ns(CLOCK_MONOTONIC);
    std::int64_t next_report = start + static_cast<std::int64_t>(o_.report_s * 1e9);
    cpu_at_report_ = clock_ns(CLOCK_PROCESS_CPUTIME_ID);
    report_start_ = start;
    while (!g_stop.load()) {
      if (server_.poll(lcm_.getFileno(), 100)) {
        while (lcm_.handleTimeout(0) > 0) {
        }
      }
      const std::int64_t now = clock_ns(CLOCK_MONOTONIC);
      if (now >= next_report) {
        report(now);
        next_report = now + static_cast<std::int64_t>(o_.report_s * 1e9);
      }
      if (o_.seconds > 0.0 && now - start >= static_cast<std::int64_t>(o_.seconds * 1e9)) break;
    }
    report(clock_ns(CLOCK_MONOTONIC));
  }

 private:
  // A dual-return sweep is ~1.2 MB in up to 20 datagrams: with the kernel's default buffer
  // (208 KiB) most would be lost. 8 MiB unless the URL's recv_buf_size says otherwise.
  void take_receive_buffer() {
    int bytes = 0;
    std::uint16_t port = 0;
    if (!transport::udpm_receive_options(o_.url, bytes, port)) return;
    if (bytes <= 0) bytes = 8 << 20;
    (void)lcm_.getFileno();
    const transport::ReceiveBuffer buffer = transport::set_udp_receive_buffers(port, bytes);
    if (buffer.capped()) std::fprintf(stderr, "%s\n", transport::describe_capped("trajroi view", buffer).c_str());
  }

  void on_roi(const lcm::ReceiveBuffer*, const std::string&, const trajroi::roi_t* m) {
    rois_[m->sweep_index] = *m;
    while (rois_.size() > 8)
      rois_.erase(rois_.begin());
  }

  void on_points(const lcm::ReceiveBuffer*, const std::string&, const trajroi::points_t* m) {
    ++sweeps_heard_;
    view::SweepView s;
    s.sweep_index = m->sweep_index;
    s.sweep_end_ns = m->sweep_end_ns;
    s.trajectory_id = m->trajectory_id;
    s.partial = m->partial != 0;
    s.points_in = m->points_in;
    s.robot_x_m = m->pose.position_m[0];
    s.robot_y_m = m->pose.position_m[1];
    s.robot_z_m = m->pose.position_m[2];
    s.yaw_rad = m->pose.yaw_rad;
    s.pose_valid = m->pose.valid != 0;
    s.x = m->x;
    s.y = m->y;
    s.z = m->z;
    s.intensity = std::span(reinterpret_cast<const std::uint8_t*>(m->intensity.data()), m->intensity.size());
    s.sensor = std::span(reinterpret_cast<const std::uint8_t*>(m->sensor.data()), m->sensor.size());
    s.sensor_names = m->sensor_names;
    const auto roi = rois_.find(m->sweep_index);
    if (roi != rois_.end()) {
      const trajroi::roi_t& r = roi->second;
      s.have_roi = true;
      s.roi = {r.shape == trajroi::roi_t::CIRCULAR, r.radius_m, r.height_m, r.width_m, r.cx, r.cy, r.theta_rad};
    }
    server_.publish(view::FrameKind::kSweep, shared(view::encode_sweep(s)));
    sent_end_ns_[m->sweep_index] = m->sweep_end_ns;
    while (sent_end_ns_.size() > 64)
      sent_end_ns_.erase(sent_end_ns_.begin());
  }

  void on_raw(const lcm::ReceiveBuffer*, const std::string&, const trajroi::points_t* m) {
    server_.publish(view::FrameKind::kRawPoints, shared(view::encode_raw_points(m->sweep_index, m->x, m->y, m->z)));
  }

  void on_trajectory(const lcm::ReceiveBuffer*, const std::string&, const trajroi::trajectory_t* m) {
    // Sent once a second by trajroid: a new frame only when it changed.
    if (trajectory_id_ == m->id && trajectory_size_ == m->num_waypoints) return;
    trajectory_id_ = m->id;
    trajectory_size_ = m->num_waypoints;
    server_.publish(view::FrameKind::kTrajectory, shared(view::encode_trajectory(m->id, m->u, m->v)));
  }

  void on_pose(const lcm::ReceiveBuffer*, const std::string&, const trajroi::pose_t* m) {
    if (m->valid) return;  // a valid pose comes with its sweep's points
    view::Json j;
    j.begin_object().field("valid", false).field("status_text", std::string_view(m->status_text));
    j.field("pose_source", std::string_view(m->pose_source)).field("sweep", m->sweep_index).end_object();
    server_.publish(view::FrameKind::kPose, shared(view::encode_frame(view::FrameKind::kPose, j.text())));
  }

  void on_status(const lcm::ReceiveBuffer*, const std::string&, const trajroi::status_t* m) {
    view::Json j;
    j.begin_object().field("state", std::string_view(m->state));
    j.begin_array("faults");
    // The state lists each missing or wrong input, "; " between them; a healthy one says
    // "publishing N sweeps/s".
    if (!m->state.starts_with("publishing ")) {
      std::string_view rest = m->state;
      while (!rest.empty()) {
        const std::size_t at = rest.find("; ");
        j.value(rest.substr(0, at));
        if (at == std::string_view::npos) break;
        rest.remove_prefix(at + 2);
      }
    }
    j.end_array();
    double rate = std::numeric_limits<double>::quiet_NaN();
    double kept_pct = std::numeric_limits<double>::quiet_NaN();
    if (last_status_ && m->uptime_s > last_status_->uptime_s) {
      // The messages drawn: with several LiDARs, the merger's (sweeps_published counts the
      // sensors' sweeps in them).
      const std::int64_t merged = named_counter(*m, "lidar_merge.published");
      const std::int64_t published = merged > 0 ? merged - named_counter(*last_status_, "lidar_merge.published")
                                                : m->sweeps_published - last_status_->sweeps_published;
      rate = static_cast<double>(published) / (m->uptime_s - last_status_->uptime_s);
      const auto in = m->points_in - last_status_->points_in;
      if (in > 0)
        kept_pct = 100.0 * static_cast<double>(m->points_kept - last_status_->points_kept) / static_cast<double>(in);
    }
    j.field("sweeps_per_s", rate).field("kept_pct", kept_pct);
    j.field("latency_ms_p50", m->latency_ms_p50).field("latency_ms_p99", m->latency_ms_p99);
    j.field("pose_source", std::string_view(m->pose_source)).field("pose_valid", m->pose_valid != 0);
    j.field("pose_status", std::string_view(m->pose_status)).field("pose_age_s", m->pose_age_s);
    j.field("fix_type", std::int64_t{m->fix_type}).field("h_acc_m", m->h_acc_m);
    j.field("rtk_solution", std::int64_t{m->rtk_solution}).field("corrections", std::string_view(m->corrections));
    j.field("correction_age_s", m->correction_age_s).field("corrections_bytes_per_s", m->corrections_bytes_per_s);
    j.field("host_minus_gnss_utc_s", m->host_minus_gnss_utc_s).field("gnss_time_accuracy_s", m->gnss_time_accuracy_s);
    j.field("host_minus_lidar_utc_s", m->host_minus_lidar_utc_s);
    j.field("lidar_pps_status", std::int64_t{m->lidar_pps_status});
    j.field("lidar_gprmc_valid", std::int64_t{m->lidar_gprmc_valid});
    j.field("trajectory_id", std::int64_t{m->trajectory_id}).field("replay", m->replay != 0);
    j.field("sweeps", m->sweeps).field("sweeps_published", m->sweeps_published);
    j.field("recording", std::string_view(m->recording)).end_object();
    server_.publish(view::FrameKind::kStatus, shared(view::encode_frame(view::FrameKind::kStatus, j.text())));
    last_status_ = *m;
  }

  void on_page_text(const std::string& text, std::int64_t at_ns) {
    long long index = 0;
    if (std::sscanf(text.c_str(), "drawn %lld", &index) != 1) return;
    ++sweeps_drawn_;
    const auto it = sent_end_ns_.find(index);
    if (it == sent_end_ns_.end()) return;
    const double ms = static_cast<double>(at_ns - it->second) * 1e-6;
    // A replay's sweep times are the recorded host times, not this host's now.
    if (ms >= 0.0 && ms < 10'000.0) latency_ms_.push_back(ms);
  }

  void report(std::int64_t now_ns) {
    const std::int64_t cpu = clock_ns(CLOCK_PROCESS_CPUTIME_ID);
    const double wall_s = static_cast<double>(now_ns - report_start_) * 1e-9;
    const double cpu_pct = wall_s > 0.0 ? 100.0 * static_cast<double>(cpu - cpu_at_report_) * 1e-9 / wall_s : 0.0;
    const view::ServerCounters& c = server_.counters();
    std::string latency = "sensor→screen latency: none measured (no page drew a live sweep)";
    if (!latency_ms_.empty()) {
      char buf[160];
      std::snprintf(buf, sizeof buf, "sensor→screen latency p50 %.1f ms, p95 %.1f ms over %zu sweeps",
                    percentile(latency_ms_, 0.50), percentile(latency_ms_, 0.95), latency_ms_.size());
      latency = buf;
    }
    std::printf(
        "trajroi view: %zu pages connected | sweeps heard %llu, drawn by pages %llu, skipped for slow pages %llu | %s "
        "| CPU %.1f %% of a core over %.0f s\n",
        server_.websocket_clients(), static_cast<unsigned long long>(sweeps_heard_),
        static_cast<unsigned long long>(sweeps_drawn_), static_cast<unsigned long long>(c.frames_replaced),
        latency.c_str(), cpu_pct, wall_s);
    std::fflush(stdout);
    latency_ms_.clear();
    cpu_at_report_ = cpu;
    report_start_ = now_ns;
  }

  const ViewOptions& o_;
  view::ViewServer& server_;
  lcm::LCM lcm_;
  std::map<std::int64_t, trajroi::roi_t> rois_;
  std::map<std::int64_t, std::int64_t> sent_end_ns_;  // sweep index → its last firing
  std::optional<trajroi::status_t> last_status_;
  std::int32_t trajectory_id_ = -1, trajectory_size_ = -1;
  std::uint64_t sweeps_heard_ = 0, sweeps_drawn_ = 0;
  std::vector<double> latency_ms_;
  std::int64_t cpu_at_report_ = 0, report_start_ = 0;
};

int run_view(const ViewOptions& o) {
  view::ServerOptions so;
  const std::size_t colon = o.listen.rfind(':');
  try {
    if (colon == std::string::npos) throw std::runtime_error("--listen " + o.listen + ": give ADDRESS:PORT");
    so.address = o.listen.substr(0, colon);
    const int port = std::stoi(o.listen.substr(colon + 1));
    if (port < 0 || port > 65535) throw std::runtime_error("--listen " + o.listen + ": port out of range");
    so.port = static_cast<std::uint16_t>(port);
  } catch (const std::invalid_argument&) {
    std::fprintf(stderr, "trajroi view: --listen %s: the port is not a number\n", o.listen.c_str());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "trajroi view: %s\n", e.what());
    return 2;
  }
  so.max_sweep_rate_hz = o.max_rate_hz;
  try {
    view::ViewServer server(so, page_assets(o.three_dir));
    Viewer viewer(o, server);
    struct sigaction sa {};
    sa.sa_handler = [](int) { g_stop.store(true); };
    sigaction(SIGINT, &sa, nullptr);
    sigaction(SIGTERM, &sa, nullptr);
    std::printf(
        "trajroi view: serving http://%s:%u/ (LCM %s, channels %s_*); on a robot: ssh -L %u:localhost:%u ROBOT\n",
        so.address.c_str(), server.port(), o.url.c_str(), o.prefix.c_str(), server.port(), server.port());
    std::fflush(stdout);
    viewer.run();
  } catch (const std::exception& e) {
    std::fprintf(stderr, "trajroi view: %s\n", e.what());
    return 1;
  }
  return 0;
}

}  // namespace

void add_view_command(CLI::App& app) {
  auto o = std::make_shared<ViewOptions>();
  CLI::App* cmd = app.add_subcommand("view", "A live view of trajroid in the browser (HTTP + WebSocket)");
  cmd->add_option("--listen", o->listen, "ADDRESS:PORT to serve on (0.0.0.0: every interface; port 0: any)")
      ->capture_default_str();
  cmd->add_option("--lcm-url", o->url, "LCM URL trajroid publishes on")->capture_default_str();
  cmd->add_option("--channel-prefix", o->prefix, "Channels <prefix>_POINTS, _ROI, _POSE, _STATUS, ...")
      ->capture_default_str();
  cmd->add_option("--three-dir", o->three_dir, "Where three.js is (Debian's libjs-three)")->capture_default_str();
  cmd->add_option("--max-rate", o->max_rate_hz, "Sweeps per second sent to each page at most")
      ->check(CLI::Range(0.1, 100.0))
      ->capture_default_str();
  cmd->add_option("--report-interval", o->report_s, "Seconds between the figures it prints")
      ->check(CLI::Range(0.5, 3600.0))
      ->capture_default_str();
  cmd->add_option("--seconds", o->seconds, "Stop after this long (0: at SIGINT or SIGTERM)")->capture_default_str();
  cmd->callback([o] { std::exit(run_view(*o)); });
}

}  // namespace trajroi::cli
