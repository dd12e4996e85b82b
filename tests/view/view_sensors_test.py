"""trajroi view colours the points of several LiDARs by sensor, in a real browser.

A two-LiDAR run is made from real captures: the MRPT VLP-16 (strongest return, from
10.0.0.100) and nebula's VLP-16 (dual return, from 192.168.1.201), on one port, each played
twelve times over as a sensor running that long (each play's record times and VLP-16 clock moved
on by the capture's length; the azimuth starts again at each play: a partial sweep there). trajroid replays it at real time with lidars: front and rear (told
apart by address, mounted apart); `trajroi view` serves the page to Debian's headless chromium.
The page must name the sensors in its legend, and with "colour by sensor" the pixels where it
put each sensor's points must be that sensor's colour.

Arguments: TRAJROI_CLI TRAJROID OUT_DIR (TRAJROI_DATA_DIR: the shared captures).
Exit 0 pass, 1 fail, 77 skip."""

import os
import shutil
import signal
import struct
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import png  # noqa: E402
import webdriver  # noqa: E402
from view_page_test import check, need, run_main, start_view, wait_for  # noqa: E402
from view_rtk_test import data_file  # noqa: E402

DATA_FRAME = 42 + 1206  # Ethernet + IPv4 + UDP + a VLP-16 data packet
TOH = 42 + 1200  # the packet's timestamp (µs past the hour)


def read_pcap(path):
    """(time ns, frame) of each record of a classic little-endian pcap (µs or ns stamps)."""
    data = open(path, "rb").read()
    magic = struct.unpack("<I", data[:4])[0]
    check(magic in (0xA1B2C3D4, 0xA1B23C4D), "%s: a little-endian pcap" % path)
    scale = 1000 if magic == 0xA1B2C3D4 else 1
    out, at = [], 24
    while at + 16 <= len(data):
        sec, frac, length, _ = struct.unpack("<IIII", data[at:at + 16])
        out.append((sec * 1_000_000_000 + frac * scale, bytearray(data[at + 16:at + 16 + length])))
        at += 16 + length
    return out


def played(records, plays, source, start_ns):
    """The records played `plays` times as one sensor running longer, from `source`, the first at
    `start_ns`; position packets in the first play only."""
    data = [(t, f) for t, f in records if len(f) == DATA_FRAME]
    tohs = [struct.unpack("<I", f[TOH:TOH + 4])[0] for _, f in data]
    period_us = sorted(b - a for a, b in zip(tohs, tohs[1:]))[len(tohs) // 2]  # 1327 strongest, 664 dual
    length_us = tohs[-1] - tohs[0] + period_us
    out = []
    for play in range(plays):
        for t, frame in records:
            if play > 0 and len(frame) != DATA_FRAME:
                continue
            f = bytearray(frame)
            f[26:30] = bytes(int(b) for b in source.split("."))
            f[24:26] = b"\0\0"
            words = struct.unpack(">10H", bytes(f[14:34]))
            total = sum(words)
            while total > 0xFFFF:
                total = (total & 0xFFFF) + (total >> 16)
            f[24:26] = struct.pack(">H", ~total & 0xFFFF)
            if len(f) == DATA_FRAME:
                toh = (struct.unpack("<I", f[TOH:TOH + 4])[0] + play * length_us) % 3_600_000_000
                f[TOH:TOH + 4] = struct.pack("<I", toh)
            out.append((start_ns + (t - records[0][0]) + play * length_us * 1000, f))
    return out


def write_pcap(path, records):
    with open(path, "wb") as f:
        f.write(struct.pack("<IHHiIII", 0xA1B23C4D, 2, 4, 0, 0, 65535, 1))
        for t, frame in sorted(records, key=lambda r: r[0]):
            f.write(struct.pack("<IIII", t // 1_000_000_000, t % 1_000_000_000, len(frame), len(frame)))
            f.write(frame)


CONFIG = """global_frame:
  origin: {lat_deg: 50.135, lon_deg: 14.43, height_m: 300}
trajectory:
  file: trajectory.csv
lidars:
  - name: front
    sensor_address: 10.0.0.100
    mounting: {xyz: [0.5, 0, 0.8]}
    min_range_m: 0.5
  - name: rear
    sensor_address: 192.168.1.201
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
    if not os.path.exists("/usr/share/javascript/three/three.min.js"):
        need("/nonexistent/three", "libjs-three")
    strongest = data_file("velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap")
    dual = data_file("velodyne/vlp16/nebula_vlp16_dual_1673400471.DERIVED.pcap")

    work = os.path.join(out, "view_sensors_test")
    shutil.rmtree(work, ignore_errors=True)
    run = os.path.join(work, "run")
    os.makedirs(run)
    start = 1_000_000_000_000
    write_pcap(os.path.join(run, "lidar.pcap"),
               played(read_pcap(strongest), 12, "10.0.0.100", start) +
               played(read_pcap(dual), 12, "192.168.1.201", start))
    with open(os.path.join(run, "trajectory.csv"), "w") as f:
        f.write("x,y\n-30,0\n30,0\n")
    with open(os.path.join(run, "trajroid.yaml"), "w") as f:
        f.write(CONFIG)

    lcm_port = webdriver.free_port()
    url = "udpm://239.255.76.67:%d?ttl=0&recv_buf_size=8388608" % lcm_port
    view_port = webdriver.free_port()
    view_log = open(os.path.join(work, "view.log"), "w")
    processes, browser = [], None
    try:
        view = start_view(cli, url, view_port, view_log)
        processes.append(view)
        daemon = subprocess.Popen([trajroid, "--config", os.path.join(run, "trajroid.yaml"), "--replay", run,
                                   "--rate", "1", "--lcm-url", url],
                                  stdout=subprocess.DEVNULL, stderr=open(os.path.join(work, "trajroid.log"), "w"))
        processes.append(daemon)
        browser = webdriver.Browser()
        browser.open("http://127.0.0.1:%d/" % view_port)
        stats = lambda: browser.script("return window.trajroiStats;")  # noqa: E731
        both = "var s = window.trajroiProject(400).map(function (p) { return p[2]; });" \
               "return s.indexOf(0) >= 0 && s.indexOf(1) >= 0;"
        wait_for("sweeps of both sensors drawn", lambda: stats()["sweepsDrawn"] >= 5 and browser.script(both), 30)
        legend = browser.text("sensors")
        check("front" in legend and "rear" in legend, "the legend names the sensors: '%s'" % legend)
        browser.script("document.getElementById('colour-sensor').click();")
        browser.script("document.getElementById('pause').click();")
        time.sleep(0.5)
        colours = browser.script("return window.trajroiSensorColours;")
        spots = browser.script("return window.trajroiProject(400);")
        shot = os.path.join(out, "view-sensors-screenshot.png")
        browser.screenshot(shot)
        print("page: legend '%s', %s" % (legend, browser.text("counters")))
    finally:
        if browser:
            browser.close()
        for p in reversed(processes):
            if p.poll() is None:
                p.send_signal(signal.SIGINT)
                try:
                    p.wait(10)
                except subprocess.TimeoutExpired:
                    p.kill()

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
