"""trajroi view in a real browser: Debian's chromium, headless (WebGL through SwiftShader),
driven by Debian's chromedriver, fed by a real replay through trajroid over LCM.

The corridor is replayed at its recorded pace through trajroid (outputs.raw_points on);
lcm-logger (liblcm-bin) logs what trajroid published; `trajroi view` serves the page. The
test checks what the page shows against the logged messages: its counters ("sweeps received
N · sweep I · points P · ROIs R") against points_t and roi_t of sweep I, the grey decoded
points against that sweep's raw points_t; the DOM is dumped and kept; a screenshot has drawn
pixels where the page says the points are (and is kept). It also stops `trajroi view` and
starts it again (the page reconnects and draws again), and sees the page say that no data
comes once the replay has ended.

Arguments: TRAJROI_CLI TRAJROID SCENARIO OUT_DIR. Exit 0 pass, 1 fail, 77 skip."""

import os
import shutil
import signal
import subprocess
import sys
import time

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
import png  # noqa: E402
from panel import panel_text  # noqa: E402
import webdriver  # noqa: E402

SKIP = 77


def need(program, package):
    if shutil.which(program):
        return
    message = "%s not installed (Debian package %s; scripts/install-deps.sh installs it)" % (program, package)
    if os.environ.get("CI") == "true":
        print("FAIL: " + message + " under CI")
        sys.exit(1)
    print("SKIP: " + message)
    sys.exit(SKIP)


def wait_for(what, predicate, timeout_s):
    deadline = time.time() + timeout_s
    while time.time() < deadline:
        value = predicate()
        if value:
            return value
        time.sleep(0.2)
    raise AssertionError("timed out after %.0f s waiting for %s" % (timeout_s, what))


def check(condition, message):
    if not condition:
        raise AssertionError(message)
    print("ok: " + message)


def start_view(cli, url, port, log):
    p = subprocess.Popen([cli, "view", "--listen", "127.0.0.1:%d" % port, "--lcm-url", url,
                          "--report-interval", "2"], stdout=log, stderr=subprocess.STDOUT)
    wait_for("trajroi view to listen", lambda: webdriver.port_open(port), 10)
    return p


def stop_all(browser, processes):
    """Closes the browser and ends the processes, newest first (SIGINT, then SIGKILL after 10 s)."""
    if browser:
        browser.close()
    for p in reversed(processes):
        if p.poll() is None:
            p.send_signal(signal.SIGINT)
            try:
                p.wait(10)
            except subprocess.TimeoutExpired:
                p.kill()


def main():
    cli, trajroid, scenario, out = sys.argv[1:5]
    need("chromium", "chromium")
    need("chromedriver", "chromium-driver")
    need("lcm-logger", "liblcm-bin")
    if not os.path.exists("/usr/share/javascript/three/three.min.js"):
        need("/nonexistent/three", "libjs-three")
    import trajroi_lcm  # noqa: E402  (PYTHONPATH from ctest)

    work = os.path.join(out, "view_page_test")
    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    run = os.path.join(work, "run")
    subprocess.check_call([cli, "sim", "--quiet", "--scenario", scenario, "--out", run], stdout=subprocess.DEVNULL)
    with open(os.path.join(run, "trajroid.yaml"), "a") as f:
        f.write("\noutputs:\n  raw_points: true\n  raw_points_decimation: 4\n")
    lcm_port = webdriver.free_port()
    url = "udpm://239.255.76.67:%d?ttl=0&recv_buf_size=8388608" % lcm_port
    log_path = os.path.join(work, "published.lcmlog")
    view_port = webdriver.free_port()
    view_log = open(os.path.join(work, "view.log"), "w")
    processes = []
    browser = None
    try:
        logger = subprocess.Popen(["lcm-logger", "--lcm-url=" + url, "-f", log_path], stdout=subprocess.DEVNULL,
                                  stderr=subprocess.STDOUT)
        processes.append(logger)
        view = start_view(cli, url, view_port, view_log)
        processes.append(view)
        daemon = subprocess.Popen([trajroid, "--config", os.path.join(run, "trajroid.yaml"), "--replay", run,
                                   "--rate", "1", "--lcm-url", url],
                                  stdout=subprocess.DEVNULL, stderr=open(os.path.join(work, "trajroid.log"), "w"))
        processes.append(daemon)
        browser = webdriver.Browser()
        page = "http://127.0.0.1:%d/" % view_port
        browser.open(page)
        stats = lambda: browser.script("return window.trajroiStats;")  # noqa: E731
        wait_for("10 sweeps drawn", lambda: stats()["sweepsDrawn"] >= 10, 60)

        # trajroi view stops and starts again: the page says so and reconnects.
        view.send_signal(signal.SIGTERM)
        view.wait(10)
        wait_for("the page to say it is disconnected",
                 lambda: "reconnecting" in browser.text("connection"), 5)
        print("ok: the page says: " + browser.text("connection"))
        before = stats()["sweepsDrawn"]
        view = start_view(cli, url, view_port, view_log)
        processes.append(view)
        wait_for("sweeps drawn after reconnecting", lambda: stats()["sweepsDrawn"] >= before + 5, 30)
        print("ok: reconnected and drew %d more sweeps" % (stats()["sweepsDrawn"] - before))

        # A planner replaces the trajectory (shifted 0.5 m north): trajroid takes it at a sweep's
        # start and publishes it as the active one; the page draws it.
        waypoints = [tuple(float(v) for v in line.split(","))
                     for line in open(os.path.join(run, "trajectory.csv")) if line[0] not in "#xl\n"]
        shifted = [(x, y + 0.5) for x, y in waypoints]
        trajroi_lcm.Publisher(url).publish("TRAJROI_TRAJECTORY", trajroi_lcm.trajectory(7, shifted))
        wait_for("the page to draw trajectory 7", lambda: stats()["trajectoryId"] == 7, 5)
        print("ok: the page drew trajectory 7 within 5 s of its message")

        # Paused on a sweep with its decoded points: the counters, the DOM and the picture.
        wait_for("decoded points of the shown sweep",
                 lambda: stats().get("rawSweep") is not None and stats()["rawSweep"] == stats()["lastSweep"], 20)
        browser.script("document.getElementById('pause').click();")
        time.sleep(0.5)
        shown = stats()
        counters = browser.text("counters")
        raw_counters = browser.text("raw-counters")
        panel = browser.texts(("pose", "corrections", "time"))  # one status_t's, not two
        dom = browser.dom()
        with open(os.path.join(work, "page.html"), "w") as f:
            f.write(dom)
        spots = browser.script("return window.trajroiProject(400);")
        shot = os.path.join(out, "view-screenshot.png")
        browser.screenshot(shot)
        print("page: " + counters + " | " + raw_counters + " | " + " | ".join(panel.values()))

        # The replay ends: the page says no data comes.
        daemon.wait(120)
        wait_for("the page to say no data comes",
                 lambda: "no data from trajroid" in browser.text("connection"), 10)
        print("ok: the page says: " + browser.text("connection"))
    finally:
        stop_all(browser, processes)

    # What trajroid published, as lcm-logger logged it.
    points, rois, raws, trajectories, statuses = {}, {}, {}, [], []
    for channel, _, data in trajroi_lcm.read_log(log_path):
        if channel == "TRAJROI_POINTS":
            m = trajroi_lcm.decode(data)
            points[m.sweep_index] = m
        elif channel == "TRAJROI_ROI":
            m = trajroi_lcm.decode(data)
            rois[m.sweep_index] = m
        elif channel == "TRAJROI_RAW_POINTS":
            m = trajroi_lcm.decode(data)
            raws[m.sweep_index] = m
        elif channel == "TRAJROI_ACTIVE_TRAJECTORY":
            trajectories.append(trajroi_lcm.decode(data))
        elif channel == "TRAJROI_STATUS":
            statuses.append(trajroi_lcm.decode(data))
    check(len(points) > 100, "lcm-logger logged %d sweeps" % len(points))
    expected = "sweeps received %d · sweep %d · points %d · ROIs %d" % (
        shown["sweepsReceived"], shown["lastSweep"], points[shown["lastSweep"]].num_points,
        rois[shown["lastSweep"]].num_centres)
    check(counters == expected, "the page's counters '%s' are the published sweep's: '%s'" % (counters, expected))
    check('id="counters">' + counters in dom, "the DOM holds the counters")
    check(0 < shown["sweepsReceived"] <= len(points),
          "sweeps received %d of %d published" % (shown["sweepsReceived"], len(points)))
    raw = raws[shown["rawSweep"]]
    check(shown["rawDrawn"] == raw.num_points,
          "decoded points drawn %d = raw points_t of sweep %d: %d (of %d decoded)" % (
              shown["rawDrawn"], shown["rawSweep"], raw.num_points, raw.points_in))

    # The panel's pose, corrections and time lines are one status message's, in words.
    shown_panels = [panel_text(s) for s in statuses]
    check(any(p == panel for p in shown_panels),
          "the panel %s is a published status_t's (the last: %s)" % (panel, shown_panels[-1] if shown_panels else None))

    # The active trajectory trajroid published (once a second): the run's (id 0), then the
    # planner's (id 7), in the global frame, as the sweeps used them.
    check(len(trajectories) >= 10, "%d active trajectory messages (one a second)" % len(trajectories))
    for wanted, expected in ((0, waypoints), (7, shifted)):
        t = [m for m in trajectories if m.id == wanted]
        check(t and t[-1].coordinates == t[-1].GLOBAL_XY and t[-1].num_waypoints == len(expected) and
              all(abs(u - w[0]) < 1e-6 and abs(v - w[1]) < 1e-6 for u, v, w in zip(t[-1].u, t[-1].v, expected)),
              "active trajectory %d published with its %d waypoints" % (wanted, len(expected)))
    first7 = min(i for i, m in points.items() if m.trajectory_id == 7)
    check(all(m.trajectory_id == (7 if i >= first7 else 0) for i, m in points.items()),
          "every sweep from %d was filtered against trajectory 7, every one before against 0" % first7)
    check(shown["trajectoryId"] == 7, "the page shows trajectory 7")

    width, height, pixel = png.read_png(shot)
    background = (0x10, 0x14, 0x18)
    inside = [(x, y) for x, y, _sensor in spots if 2 <= x < width - 2 and 2 <= y < height - 2]
    lit = 0
    for x, y in inside:
        near = [pixel(int(x) + dx, int(y) + dy) for dx in (-1, 0, 1) for dy in (-1, 0, 1)]
        if any(max(abs(a - b) for a, b in zip(p, background)) > 40 for p in near):
            lit += 1
    check(len(inside) >= 100, "%d of 400 sampled kept points fall on the %dx%d screenshot" % (len(inside), width, height))
    check(lit >= 0.9 * len(inside), "%d of %d have drawn pixels where the page put them" % (lit, len(inside)))
    blank = sum(1 for x in range(0, width, 16) for y in range(0, height, 16) if pixel(x, y) == background)
    total = len(range(0, width, 16)) * len(range(0, height, 16))
    check(blank < total, "the screenshot is not blank (%d of %d sampled pixels background)" % (blank, total))
    print("PASS: screenshot kept as " + shot)


def run_main(main):
    """Runs a test's main: an AssertionError is its failure, said in one line, exit 1."""
    try:
        main()
    except AssertionError as e:
        print("FAIL: %s" % e)
        sys.exit(1)


if __name__ == "__main__":
    run_main(main)
