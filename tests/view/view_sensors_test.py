"""trajroi view colours the points of several LiDARs by sensor, in a real browser.

Two real captures are sent live over UDP at their recorded pace by `trajroi feed`, to one port:
the MRPT VLP-16 (strongest return) from 127.0.0.2 and nebula's VLP-16 (dual return) from
127.0.0.3, each played twelve times over as a sensor running that long (each play's record
times and VLP-16 clock moved on by the capture's length; the azimuth starts again at each play:
a partial sweep there). trajroid runs live with lidars: front and rear (told apart by address,
mounted apart); `trajroi view` serves the page to Debian's headless chromium; lcm-logger logs
what trajroid published. The page must name the sensors in its legend, hold for the sweep it
shows as many points of each sensor as the published points_t does, and with "colour by
sensor" the pixels where it put each sensor's points must be that sensor's colour. Its panel's
sweeps/s is the merged sweeps' it draws (about 10), not the sensors' (about 20), and the state
says both.

Arguments: TRAJROI_CLI TRAJROID OUT_DIR (TRAJROI_DATA_DIR: the shared captures).
Exit 0 pass, 1 fail, 77 skip."""

import os
import re
import shutil
import struct
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
sys.path.insert(0, os.path.join(HERE, "..", "..", "bench"))
import png  # noqa: E402
import webdriver  # noqa: E402
from four_lidars import records  # noqa: E402
from view_page_test import check, need, run_main, start_view, stop_all, wait_for  # noqa: E402
from view_rtk_test import data_file  # noqa: E402

DATA_FRAME = 42 + 1206  # Ethernet + IPv4 + UDP + a VLP-16 data packet
TOH = 42 + 1200  # the packet's timestamp (µs past the hour)


def played(path, plays, out):
    """The capture played `plays` times as one sensor running that much longer, written to `out`
    (a nanosecond pcap); position packets in the first play only."""
    original = list(records(path))
    tohs = [struct.unpack("<I", f[TOH:TOH + 4])[0] for _, f in original if len(f) == DATA_FRAME]
    period_us = sorted(b - a for a, b in zip(tohs, tohs[1:]))[len(tohs) // 2]  # 1327 strongest, 664 dual
    length_us = tohs[-1] - tohs[0] + period_us
    with open(out, "wb") as f:
        f.write(struct.pack("<IHHiIII", 0xA1B23C4D, 2, 4, 0, 0, 65535, 1))
        for play in range(plays):
            for t, frame in original:
                if play > 0 and len(frame) != DATA_FRAME:
                    continue
                frame = bytearray(frame)
                if len(frame) == DATA_FRAME:
                    toh = (struct.unpack("<I", frame[TOH:TOH + 4])[0] + play * length_us) % 3_600_000_000
                    frame[TOH:TOH + 4] = struct.pack("<I", toh)
                t += play * length_us * 1000
                f.write(struct.pack("<IIII", t // 1_000_000_000, t % 1_000_000_000, len(frame), len(frame)))
                f.write(frame)
    return out


STATE_RATES = re.compile(r"publishing (\d+\.\d) merged sweeps/s of 2 LiDARs \((\d+\.\d) sensor sweeps/s\)")


def steady_pairs(samples):
    """The (panel's sweeps/s, state match) of the samples whose status spans a whole second of
    both sensors' sweeps (15 or more sensor sweeps/s)."""
    matched = [(rate, STATE_RATES.match(state)) for rate, state in samples if rate is not None]
    return [(rate, m) for rate, m in matched if m and float(m.group(2)) >= 15]


CONFIG = """global_frame:
  origin: {lat_deg: 50.135, lon_deg: 14.43, height_m: 300}
trajectory:
  file: trajectory.csv
lidars:
  - name: front
    sensor_address: 127.0.0.2
    data_port: %(data)d
    position_port: %(position)d
    mounting: {xyz: [0.5, 0, 0.8]}
    min_range_m: 0.5
  - name: rear
    sensor_address: 127.0.0.3
    data_port: %(data)d
    position_port: %(position)d
    mounting: {xyz: [-0.5, 0, 0.8], yaw_deg: 180}
    min_range_m: 0.5
pose:
  source: fixed
  fixed: {xyz: [0, 0, 0], yaw_deg: 0}
  mode: per_sweep
roi:
  circle_diameter_m: 8
  look_ahead_m: 30
"""


def main():
    cli, trajroid, out = sys.argv[1:4]
    need("chromium", "chromium")
    need("chromedriver", "chromium-driver")
    need("lcm-logger", "liblcm-bin")
    if not os.path.exists("/usr/share/javascript/three/three.min.js"):
        need("/nonexistent/three", "libjs-three")
    import trajroi_lcm  # noqa: E402  (PYTHONPATH from ctest)
    strongest = data_file("velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap")
    dual = data_file("velodyne/vlp16/nebula_vlp16_dual_1673400471.DERIVED.pcap")

    work = os.path.join(out, "view_sensors_test")
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    front = played(strongest, 12, os.path.join(work, "front.pcap"))
    rear = played(dual, 12, os.path.join(work, "rear.pcap"))
    with open(os.path.join(work, "trajectory.csv"), "w") as f:
        f.write("x,y\n-30,0\n30,0\n")
    data_port, position_port = webdriver.free_port(), webdriver.free_port()
    with open(os.path.join(work, "trajroid.yaml"), "w") as f:
        f.write(CONFIG % {"data": data_port, "position": position_port})

    lcm_port = webdriver.free_port()
    url = "udpm://239.255.76.67:%d?ttl=0&recv_buf_size=8388608" % lcm_port
    log_path = os.path.join(work, "published.lcmlog")
    view_port = webdriver.free_port()
    view_log = open(os.path.join(work, "view.log"), "w")
    processes, browser = [], None
    try:
        processes.append(subprocess.Popen(["lcm-logger", "--lcm-url=" + url, "-f", log_path],
                                          stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT))
        processes.append(start_view(cli, url, view_port, view_log))
        daemon_log = os.path.join(work, "trajroid.log")
        processes.append(subprocess.Popen([trajroid, "--config", os.path.join(work, "trajroid.yaml"), "--lcm-url", url],
                                          stdout=subprocess.DEVNULL, stderr=open(daemon_log, "w")))
        wait_for("trajroid to listen", lambda: "trajroid running" in open(daemon_log).read(), 10)
        # The page first: the feeds last about 5 s, less than a browser's start on a busy machine.
        browser = webdriver.Browser()
        browser.open("http://127.0.0.1:%d/" % view_port)
        for pcap, address, name in ((front, "127.0.0.2", "front"), (rear, "127.0.0.3", "rear")):
            processes.append(subprocess.Popen([cli, "feed", "--pcap", pcap, "--from", address, "--data-port",
                                               str(data_port), "--position-port", str(position_port)],
                                              stdout=subprocess.DEVNULL,
                                              stderr=open(os.path.join(work, "feed_%s.log" % name), "w")))
        stats = lambda: browser.script("return window.trajroiStats;")  # noqa: E731
        both = "var s = window.trajroiProject(400).map(function (p) { return p[2]; });" \
               "return s.indexOf(0) >= 0 && s.indexOf(1) >= 0;"
        samples = []  # the panel's sweeps/s and the state, read together, while the feeds last

        def sample():
            figure = re.search(r"sweeps/s (\d+\.\d)", browser.text("figures"))
            samples.append((float(figure.group(1)) if figure else None, browser.text("state")))

        def drawn():
            sample()
            return stats()["sweepsDrawn"] >= 5 and browser.script(both)

        def steady():  # a status over a whole second of both sensors' sweeps
            sample()
            return steady_pairs(samples)

        wait_for("sweeps of both sensors drawn", drawn, 30)
        # The first status's rates span trajroid's start: a whole second of sweeps is in the next.
        wait_for("a status over a whole second of sweeps", steady, 5)
        legend = browser.text("sensors")
        check("front" in legend and "rear" in legend, "the legend names the sensors: '%s'" % legend)
        browser.script("document.getElementById('colour-sensor').click();")
        browser.script("document.getElementById('pause').click();")
        time.sleep(0.5)
        shown = stats()
        colours = browser.script("return window.trajroiSensorColours;")
        spots = browser.script("return window.trajroiProject(400);")
        shot = os.path.join(out, "view-sensors-screenshot.png")
        browser.screenshot(shot)
        print("page: legend '%s', %s" % (legend, browser.text("counters")))
        time.sleep(0.5)  # the shown sweep is logged
    finally:
        stop_all(browser, processes)

    # Two sensors of 10 sweeps/s merged: the state says 10 merged sweeps/s and 20 sensor sweeps/s,
    # and the panel's rate is the merged one (the messages it draws).
    pairs = steady_pairs(samples)
    print("page: sweeps/s and state %s" % sorted(set((r, m.group(0)) for r, m in pairs)))
    for rate, m in pairs:
        merged, sensors = float(m.group(1)), float(m.group(2))
        check(8.0 <= merged <= 12.0 and 18.0 <= sensors <= 22.0, "the state's rates: '%s'" % m.group(0))
        check(abs(rate - merged) < abs(rate - sensors),
              "the panel's sweeps/s %.1f is the merged sweeps' (%s)" % (rate, m.group(0)))

    # The sweep the page shows, as trajroid published it: the same points of each sensor.
    published = None
    for channel, _, data in trajroi_lcm.read_log(log_path):
        if channel == "TRAJROI_POINTS":
            m = trajroi_lcm.decode(data)
            if m.sweep_index == shown["lastSweep"]:
                published = m
    check(published is not None, "lcm-logger logged the shown sweep %s" % shown["lastSweep"])
    check(list(published.sensor_names) == ["front", "rear"], "published sensors %s" % list(published.sensor_names))
    counts = [sum(1 for s in published.sensor if s == k) for k in (0, 1)]
    check(shown["sensorCounts"] == counts, "the page holds %s points of front and rear, the published sweep %s" % (
        shown["sensorCounts"], counts))

    # Each sensor's points drawn in its colour, where the page put them (a point may lie under
    # the other sensor's: most, not all).
    width, height, pixel = png.read_png(shot)
    for sensor, name in enumerate(("front", "rear")):
        colour = colours[sensor]
        mine = [(x, y) for x, y, s in spots if s == sensor and 2 <= x < width - 2 and 2 <= y < height - 2]
        hit = 0
        for x, y in mine:
            near = [pixel(int(x) + dx, int(y) + dy) for dx in (-1, 0, 1) for dy in (-1, 0, 1)]
            if any(max(abs(a - b) for a, b in zip(p[:3], colour)) <= 40 for p in near):
                hit += 1
        check(len(mine) >= 20, "%d of 400 sampled points are the %s sensor's, on the screenshot" % (len(mine), name))
        check(hit >= 0.8 * len(mine), "%d of %d of the %s sensor's points drawn in its colour %s" % (
            hit, len(mine), name, colour))
    print("PASS: screenshot kept as " + shot)


if __name__ == "__main__":
    run_main(main)
