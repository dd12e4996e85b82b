#!/usr/bin/env python3
"""trajroi view's and trajroi export's figures, printed (not a timed test), with the machine.

A dual-return scenario (tests/daemon/corridor.yaml, 28.8 s, 10 sweeps/s) is played live into
trajroid by `trajroi feed` (UDP on loopback, pseudo-terminals for the GNSS and the IMU), with
outputs.raw_points on; `trajroi view` forwards it to:
  1. no page, twice (the daemon's latency p99 without clients, and its run-to-run noise);
  2. one page in Debian's headless chromium (WebGL through SwiftShader): sweeps drawn per second
     (the page's own count), sensor-to-screen latency (the sweep's last firing on the host clock
     to the page saying it drew it: p50, p95), the view process's CPU;
  3. four WebSocket clients reading every frame (the daemon's latency p99 with them).
Then one minute of dual-return data (the corridor driven at 0.45 m/s) is replayed into an LCM log
and exported (PCD per sweep, LAS per sweep, an accumulated PCD map): seconds each.

Usage: /usr/bin/python3 bench/view_figures.py [BUILD_DIR]   (default build/release)"""

import os
import platform
import re
import signal
import socket
import statistics
import subprocess
import sys
import tempfile
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tests", "view"))
import webdriver  # noqa: E402

BUILD = os.path.abspath(sys.argv[1] if len(sys.argv) > 1 else os.path.join(ROOT, "build", "release"))
CLI = os.path.join(BUILD, "tools", "trajroi")
TRAJROID = os.path.join(BUILD, "daemon", "trajroid")


def cpu_model():
    for line in open("/proc/cpuinfo"):
        if line.startswith("model name"):
            return line.split(":", 1)[1].strip()
    return platform.processor()


def live_config(run, work, data_port):
    """The run folder's configuration, pointed at live inputs."""
    text = open(os.path.join(run, "trajroid.yaml")).read()
    text = text.replace("trajectory:\n  file: trajectory.csv", "trajectory:\n  file: %s" % os.path.join(run, "trajectory.csv"))
    text = text.replace("lidar:\n", "lidar:\n  data_port: %d\n  position_port: %d\n" % (data_port, data_port + 1), 1)
    text = text.replace("gnss:\n", "gnss:\n  device: %s\n" % os.path.join(work, "gnss"), 1)
    text = text.replace("imu:\n", "imu:\n  device: %s\n" % os.path.join(work, "imu"), 1)
    text += "\noutputs:\n  raw_points: true\n  raw_points_decimation: 4\n"
    path = os.path.join(work, "live.yaml")
    open(path, "w").write(text)
    return path


class SocketClient(threading.Thread):
    """A WebSocket client that reads every frame as it comes (a page that keeps up)."""

    def __init__(self, port):
        super().__init__(daemon=True)
        self.port, self.frames, self.stop = port, 0, False

    def run(self):
        s = socket.create_connection(("127.0.0.1", self.port))
        s.sendall(b"GET /ws HTTP/1.1\r\nHost: x\r\nUpgrade: websocket\r\nConnection: Upgrade\r\n"
                  b"Sec-WebSocket-Key: dGhlIHNhbXBsZSBub25jZQ==\r\nSec-WebSocket-Version: 13\r\n\r\n")
        s.settimeout(1.0)
        buffered = b""
        while not self.stop:
            try:
                chunk = s.recv(1 << 20)
            except socket.timeout:
                continue
            if not chunk:
                break
            buffered += chunk
            if b"\r\n\r\n" in buffered and buffered.startswith(b"HTTP"):
                buffered = buffered.split(b"\r\n\r\n", 1)[1]
            while len(buffered) >= 2:
                n, at = buffered[1] & 0x7F, 2
                if n == 126:
                    n, at = int.from_bytes(buffered[2:4], "big"), 4
                elif n == 127:
                    n, at = int.from_bytes(buffered[2:10], "big"), 10
                if len(buffered) < at + n:
                    break
                buffered = buffered[at + n:]
                self.frames += 1
        s.close()


def run_live(run, clients, label):
    work = tempfile.mkdtemp(prefix="trajroi_view_figures_")
    data_port = webdriver.free_port()
    config = live_config(run, work, data_port)
    url = "udpm://239.255.76.67:%d?ttl=0&recv_buf_size=8388608" % webdriver.free_port()
    view_port = webdriver.free_port()
    daemon_log = open(os.path.join(work, "trajroid.log"), "w+")
    view_log = open(os.path.join(work, "view.log"), "w+")
    daemon = subprocess.Popen([TRAJROID, "--config", config, "--lcm-url", url], stdout=daemon_log, stderr=daemon_log)
    view = subprocess.Popen([CLI, "view", "--listen", "127.0.0.1:%d" % view_port, "--lcm-url", url,
                             "--report-interval", "5"], stdout=view_log, stderr=view_log)
    while not webdriver.port_open(view_port):
        time.sleep(0.1)
    browser, sockets, drawn = None, [], []
    if clients == "browser":
        browser = webdriver.Browser()
        browser.open("http://127.0.0.1:%d/" % view_port)
    elif clients == "sockets":
        sockets = [SocketClient(view_port) for _ in range(4)]
        for s in sockets:
            s.start()
    feed = subprocess.Popen([CLI, "feed", run, "--gnss-link", os.path.join(work, "gnss"), "--imu-link",
                             os.path.join(work, "imu"), "--data-port", str(data_port), "--position-port",
                             str(data_port + 1)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    last = None
    while feed.poll() is None:
        time.sleep(1.0)
        if browser:
            now = browser.script("return window.trajroiStats.sweepsDrawn;")
            if last is not None:
                drawn.append(now - last)
            last = now
    time.sleep(2.0)
    if browser:
        browser.close()
    for s in sockets:
        s.stop = True
    view.send_signal(signal.SIGINT)
    view.wait(20)
    daemon.send_signal(signal.SIGINT)
    daemon.wait(30)
    daemon_log.seek(0)
    summary = [line for line in daemon_log.read().splitlines() if "summary:" in line]
    m = re.search(r"latency p50 ([0-9.]+) ms p99 ([0-9.]+) ms over (\d+) sweeps", summary[-1] if summary else "")
    view_log.seek(0)
    reports = [line for line in view_log.read().splitlines() if "pages connected" in line]
    latency = [re.search(r"p50 ([0-9.]+) ms, p95 ([0-9.]+) ms over (\d+)", r) for r in reports]
    latency = [(float(x.group(1)), float(x.group(2)), int(x.group(3))) for x in latency if x]
    cpu = [float(re.search(r"CPU ([0-9.]+) %", r).group(1)) for r in reports if "CPU" in r]
    result = {"label": label, "p50": float(m.group(1)) if m else None, "p99": float(m.group(2)) if m else None,
              "sweeps": int(m.group(3)) if m else 0, "drawn": drawn, "latency": latency, "cpu": cpu,
              "socket_frames": [s.frames for s in sockets]}
    subprocess.call(["rm", "-rf", work])
    return result


def main():
    print("machine: %s, %d cores; %s" % (cpu_model(), os.cpu_count(),
                                       subprocess.run(["chromium", "--version"], capture_output=True,
                                                      text=True).stdout.strip()))
    work = tempfile.mkdtemp(prefix="trajroi_view_figures_")
    run = os.path.join(work, "corridor")
    subprocess.check_call([CLI, "sim", "--quiet", "--scenario", os.path.join(ROOT, "tests/daemon/corridor.yaml"),
                           "--out", run], stdout=subprocess.DEVNULL)
    runs = [run_live(run, "none", "view, no page (%d)" % i) for i in (1, 2, 3)]
    runs += [run_live(run, "sockets", "four WebSocket clients (%d)" % i) for i in (1, 2)]
    runs.append(run_live(run, "browser", "one page in headless chromium"))
    print("\nlive: tests/daemon/corridor.yaml (dual return, 10 sweeps/s) fed by trajroi feed over loopback")
    for r in runs:
        print("  %-32s trajroid latency p50 %6.2f ms, p99 %6.2f ms over %d sweeps" % (
            r["label"], r["p50"] or -1, r["p99"] or -1, r["sweeps"]))
    alone = [r["p99"] for r in runs[:3]]
    four = [r["p99"] for r in runs[3:5]]
    print("  trajroid p99 without clients %.2f … %.2f ms (the noise: %.2f ms); with four clients %s ms" % (
        min(alone), max(alone), max(alone) - min(alone), ", ".join("%.2f" % p for p in four)))
    print("  the four clients read %s frames each" % runs[3]["socket_frames"])
    page = runs[5]
    # Seconds of the feed with sweeps drawn (the scenario withholds sweeps in its GNSS outage).
    steady = [d for d in page["drawn"][2:-2] if d > 0]
    print("  one page: sweeps drawn in each second of the feed: %s" % " ".join(str(d) for d in page["drawn"]))
    print("  one page: median %s sweeps/s drawn over the %d seconds with sweeps (the scenario withholds sweeps in "
          "its GNSS outage, 14-16 s: fewer there)" % (statistics.median(steady) if steady else "-", len(steady)))
    if page["latency"]:
        print("  one page: sensor-to-screen latency per 5 s report: %s" % ", ".join(
            "p50 %.1f / p95 %.1f ms (%d sweeps)" % x for x in page["latency"]))
    print("  trajroi view's CPU per 5 s report (one page): %s %% of a core" % ", ".join("%.1f" % c for c in page["cpu"]))

    # Export: one minute of dual-return data.
    scenario = open(os.path.join(ROOT, "tests/daemon/corridor.yaml")).read().replace("speed_mps: 1.0", "speed_mps: 0.45")
    minute_yaml = os.path.join(work, "minute.yaml")
    open(minute_yaml, "w").write(scenario)
    minute = os.path.join(work, "minute")
    subprocess.check_call([CLI, "sim", "--quiet", "--scenario", minute_yaml, "--out", minute], stdout=subprocess.DEVNULL)
    duration = [line.split()[1] for line in open(os.path.join(minute, "summary.txt")) if line.startswith("duration_s")]
    log = os.path.join(work, "minute.lcmlog")
    subprocess.check_call([TRAJROID, "--config", os.path.join(minute, "trajroid.yaml"), "--replay", minute, "--rate",
                           "max", "--lcm-url", "file://%s?mode=w" % log], stderr=subprocess.DEVNULL)
    print("\nexport: %s s of dual-return data (%.0f MB of LCM log)" % (
        duration[0] if duration else "?", os.path.getsize(log) / 1e6))
    for label, args in [("PCD (binary), one file per sweep", ["--format", "pcd"]),
                        ("PCD binary_compressed per sweep", ["--format", "pcd", "--pcd-data", "binary_compressed"]),
                        ("PLY per sweep", ["--format", "ply"]),
                        ("LAS 1.4 (UTM) per sweep", ["--format", "las", "--config", os.path.join(minute, "trajroid.yaml")]),
                        ("PCD map, --accumulate --voxel 0.05", ["--format", "pcd", "--accumulate", "--voxel", "0.05"])]:
        out = os.path.join(work, "export_" + str(abs(hash(label))))
        start = time.time()
        subprocess.check_call([CLI, "export", log, "--out", out, "--quiet"] + args, stdout=subprocess.DEVNULL)
        print("  %-36s %6.2f s" % (label, time.time() - start))
    start = time.time()
    subprocess.check_call([CLI, "export", minute, "--out", os.path.join(work, "from_run"), "--format", "las",
                           "--quiet"], stdout=subprocess.DEVNULL)
    print("  %-36s %6.2f s (decoding and filtering included)" % ("LAS from the run folder", time.time() - start))
    subprocess.call(["rm", "-rf", work])


if __name__ == "__main__":
    main()
