"""trajroi view shows a live robot's RTK state, corrections and time, in a real browser.

trajroid runs live: its GNSS port is a pseudo-terminal playing a real ZED-F9R log (an RTK float
rover) at its recorded 1 Hz, and its corrections come from RTKLIB's str2str as a real NTRIP
caster, fed with a real ZED-F9T stream. `trajroi view` serves the page to Debian's headless
chromium; lcm-logger logs what trajroid published. The page's pose, corrections and time lines
must be one logged status_t's, in words (tests/view/panel.py), and say "RTK float" and that the
corrections stream from the caster (password hidden) with their age.

Arguments: TRAJROI_CLI TRAJROID OUT_DIR (TRAJROI_DATA_DIR: the shared captures).
Exit 0 pass, 1 fail, 77 skip."""

import os
import pty
import shutil
import signal
import socket
import subprocess
import sys
import threading
import time
import tty

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import webdriver  # noqa: E402
from panel import panel_text  # noqa: E402
from view_page_test import SKIP, check, need, run_main, start_view, wait_for  # noqa: E402


def data_file(relative):
    root = os.environ.get("TRAJROI_DATA_DIR", os.path.join(HERE, "..", "..", "..", "shared", "data"))
    path = os.path.join(root, relative)
    if os.path.exists(path):
        return path
    if os.environ.get("CI") == "true":
        print("FAIL: %s missing under CI (TRAJROI_DATA_DIR)" % path)
        sys.exit(1)
    print("SKIP: %s missing (set TRAJROI_DATA_DIR to the shared captures)" % path)
    sys.exit(SKIP)


class Receiver:
    """The u-blox side of a pseudo-terminal: the log one epoch (up to each NAV-PVT's end) a second;
    what trajroid writes (the corrections) is read and counted."""

    def __init__(self, log):
        self.master, slave = pty.openpty()
        tty.setraw(self.master)
        self.path = os.ttyname(slave)
        os.close(slave)
        self.epochs, start, at = [], 0, log.find(b"\xb5\x62\x01\x07")
        while at >= 0 and at + 6 <= len(log):
            end = min(len(log), at + 8 + (log[at + 4] | log[at + 5] << 8))
            self.epochs.append(log[start:end])
            start, at = end, log.find(b"\xb5\x62\x01\x07", end)
        self.written = 0
        self.stop = False
        self.thread = threading.Thread(target=self.serve, daemon=True)
        self.thread.start()

    def serve(self):
        import select
        n, next_at = 0, time.time()
        while not self.stop:
            if time.time() >= next_at:
                os.write(self.master, self.epochs[n % len(self.epochs)])
                n, next_at = n + 1, next_at + 1.0
            if select.select([self.master], [], [], 0.01)[0]:
                try:
                    self.written += len(os.read(self.master, 4096))
                except OSError:
                    pass


def feed_caster(port, data, stop):
    """str2str's TCP input: the F9T stream a piece at a time, over again, as a base station sends."""
    while not stop.is_set():
        try:
            with socket.create_connection(("127.0.0.1", port), timeout=2) as s:
                while not stop.is_set():
                    for at in range(0, len(data), 512):
                        s.sendall(data[at:at + 512])
                        time.sleep(0.02)
                        if stop.is_set():
                            return
        except OSError:
            time.sleep(0.2)


def main():
    cli, trajroid, out = sys.argv[1:4]
    need("chromium", "chromium")
    need("chromedriver", "chromium-driver")
    need("lcm-logger", "liblcm-bin")
    need("str2str", "rtklib")
    import trajroi_lcm  # noqa: E402  (PYTHONPATH from ctest)

    rover = open(data_file("ublox/gpsd/ublox-zed-f9r.log"), "rb").read()
    corrections = open(data_file("ublox/gpsd/ublox-zed-f9t-rtcm3.log"), "rb").read()
    work = os.path.join(out, "view_rtk_test")
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    caster_in, caster_port = webdriver.free_port(), webdriver.free_port()
    lcm_port, view_port = webdriver.free_port(), webdriver.free_port()
    url = "udpm://239.255.76.67:%d?ttl=0&recv_buf_size=4194304" % lcm_port
    receiver = Receiver(rover)
    with open(os.path.join(work, "trajectory.csv"), "w") as f:
        f.write("0,0\n10,0\n")
    ntrip = "ntrip://rover:s3cret@127.0.0.1:%d/F9T?version=1" % caster_port
    with open(os.path.join(work, "trajroid.yaml"), "w") as f:
        f.write("global_frame:\n  origin: {lat_deg: 45.0657, lon_deg: 7.6590, height_m: 300.0}\n"
                "trajectory:\n  file: trajectory.csv\n"
                "lidar:\n  data_port: 0\n  position_port: 0\n"
                "gnss:\n  device: %s\n  configure: false\n  corrections: {url: '%s', gga_interval_s: 1}\n"
                "pose:\n  source: gnss\n  gnss_heading: {initial_heading_deg: 90}\n  require_rtk: float\n"
                "  max_extrapolation_s: 1.5\n" % (receiver.path, ntrip))
    log_path = os.path.join(work, "published.lcmlog")
    stop = threading.Event()
    processes, browser, panel = [], None, None
    try:
        processes.append(subprocess.Popen(
            ["str2str", "-in", "tcpsvr://:%d" % caster_in, "-out", "ntripc://rover:s3cret@:%d/F9T" % caster_port],
            stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL))
        threading.Thread(target=feed_caster, args=(caster_in, corrections, stop), daemon=True).start()
        processes.append(subprocess.Popen(["lcm-logger", "--lcm-url=" + url, "-f", log_path],
                                          stdout=subprocess.DEVNULL, stderr=subprocess.STDOUT))
        time.sleep(1.0)  # lcm-logger subscribed before trajroid's first status
        view_log = open(os.path.join(work, "view.log"), "w")
        processes.append(start_view(cli, url, view_port, view_log))
        trajroid_log = open(os.path.join(work, "trajroid.log"), "w")
        processes.append(subprocess.Popen([trajroid, "--config", os.path.join(work, "trajroid.yaml"),
                                           "--lcm-url", url], stdout=subprocess.DEVNULL, stderr=trajroid_log))
        browser = webdriver.Browser()
        browser.open("http://127.0.0.1:%d/" % view_port)
        streaming = "corrections: streaming from ntrip://rover:***@127.0.0.1:%d/F9T · age " % caster_port
        wait_for("the page to show the corrections streaming and RTK float",
                 lambda: browser.text("corrections").startswith(streaming) and "RTK float" in browser.text("pose"),
                 30)
        time.sleep(2.5)  # past the first seconds' figures
        panel = browser.texts(("pose", "corrections", "time"))  # one status_t's, not two
        print("page: " + " | ".join(panel.values()))
        time.sleep(1.5)  # the status shown is logged before the logger stops
    finally:
        stop.set()
        if browser:
            browser.close()
        for p in reversed(processes):
            if p.poll() is None:
                p.send_signal(signal.SIGINT if p.args[0] != "str2str" else signal.SIGTERM)
                try:
                    p.wait(10)
                except subprocess.TimeoutExpired:
                    p.kill()
        receiver.stop = True

    statuses = [trajroi_lcm.decode(data) for channel, _, data in trajroi_lcm.read_log(log_path)
                if channel == "TRAJROI_STATUS"]
    shown = [panel_text(s) for s in statuses]
    check(any(p == panel for p in shown),
          "the panel %s is one of %d published status_t's (the last: %s)" % (panel, len(shown), shown[-1]))
    check(receiver.written > 0, "trajroid wrote %d bytes of corrections into the receiver's port" % receiver.written)
    check("s3cret" not in open(os.path.join(work, "trajroid.log")).read() + str(panel),
          "the caster's password is in neither the log nor the page")
    print("PASS")


if __name__ == "__main__":
    run_main(main)
