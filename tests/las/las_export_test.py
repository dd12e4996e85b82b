"""trajroi export --format las read back by independent readers: copc.js (Hobu's LAS 1.4
reader, npm) reads every field of the files; PROJ (python3-pyproj) places the LCM messages'
global-frame points in UTM on its own (ENU → geocentric → geodetic → UTM) and names the EPSG
code of the file's WKT. The corridor is replayed through trajroid into an LCM log (liblcm's
file:// provider); its points_t are the expected points. The same export from the run folder
replayed through the pipeline gives the same files. Debian's CloudCompare 2.11 has no LAS
reader (its plugins: no PDAL, no libLAS), hence copc.js.

Arguments: TRAJROI_CLI TRAJROID SCENARIO WORK_DIR LAS_READER_DIR. Exit 0 pass, 1 fail, 77 skip."""

import json
import math
import os
import shutil
import subprocess
import sys

SKIP = 77


def fail(message):
    print("FAIL: " + message)
    sys.exit(1)


def check(condition, message):
    if not condition:
        fail(message)
    print("ok: " + message)


def need(available, what):
    if available:
        return
    if os.environ.get("CI") == "true":
        fail(what + " missing under CI")
    print("SKIP: " + what + " missing")
    sys.exit(SKIP)


def main():
    cli, trajroid, scenario, work, reader_dir = sys.argv[1:6]
    try:
        import pyproj
    except ImportError:
        pyproj = None
    need(pyproj is not None, "python3-pyproj (scripts/install-deps.sh)")
    need(shutil.which("node") is not None, "node")
    need(os.path.isdir(os.path.join(reader_dir, "node_modules", "copc")),
         "copc.js in %s (the test fixture las_reader_npm_ci installs it from the npm registry)" % reader_dir)
    import trajroi_lcm

    shutil.rmtree(work, ignore_errors=True)
    os.makedirs(work)
    run = os.path.join(work, "run")
    log = os.path.join(work, "run.lcmlog")
    subprocess.check_call([cli, "sim", "--quiet", "--scenario", scenario, "--out", run])
    subprocess.check_call([trajroid, "--config", os.path.join(run, "trajroid.yaml"), "--replay", run, "--rate", "max",
                           "--lcm-url", "file://%s?mode=w" % log], stderr=subprocess.DEVNULL)
    config = os.path.join(run, "trajroid.yaml")
    from_log = os.path.join(work, "from_log")
    from_run = os.path.join(work, "from_run")
    subprocess.check_call([cli, "export", log, "--format", "las", "--config", config, "--out", from_log, "--quiet"])
    subprocess.check_call([cli, "export", run, "--format", "las", "--out", from_run, "--quiet"])

    sweeps = {}
    for channel, _, data in trajroi_lcm.read_log(log):
        if channel == "TRAJROI_POINTS":
            m = trajroi_lcm.decode(data)
            sweeps[m.sweep_index] = m
    check(len(sweeps) > 100, "%d sweeps in the log" % len(sweeps))

    # The origin, from the configuration the daemon used.
    origin = None
    for line in open(config):
        if line.strip().startswith("origin:"):
            fields = dict(p.split(":") for p in line.split("{")[1].split("}")[0].replace(" ", "").split(","))
            origin = (float(fields["lat_deg"]), float(fields["lon_deg"]), float(fields["height_m"]))
    zone = int(math.floor((origin[1] + 180.0) / 6.0)) + 1
    enu_to_utm = pyproj.Transformer.from_pipeline(
        "+proj=pipeline +step +inv +proj=topocentric +ellps=WGS84 +lat_0=%.12f +lon_0=%.12f +h_0=%.6f "
        "+step +inv +proj=cart +ellps=WGS84 +step +proj=utm +zone=%d +ellps=WGS84" % (origin + (zone,)))

    reader = os.path.join(os.path.dirname(os.path.abspath(__file__)), "read_las.js")
    indices = sorted(sweeps)
    chosen = [indices[0], indices[len(indices) // 2], indices[-1]]
    for index in chosen:
        name = "sweep_%06d.las" % index
        out = subprocess.run(["node", reader, os.path.join(from_log, name)], capture_output=True, text=True,
                             env=dict(os.environ, NODE_PATH=os.path.join(reader_dir, "node_modules")))
        if out.returncode != 0:
            fail("copc.js cannot read %s: %s" % (name, out.stderr))
        las = json.loads(out.stdout)
        m = sweeps[index]
        h = las["header"]
        check((h["majorVersion"], h["minorVersion"], h["pointDataRecordFormat"]) == (1, 4, 6),
              "%s: LAS 1.4, point format 6" % name)
        check(h["pointCount"] == m.num_points == len(las["points"]),
              "%s: %d points, as points_t of sweep %d" % (name, h["pointCount"], index))
        crs = pyproj.CRS.from_wkt(las["wkt"])
        check(crs.to_epsg() == 32600 + zone, "%s: its WKT is EPSG:%s for PROJ (UTM zone %d N)" % (
            name, crs.to_epsg(), zone))
        check(h["globalEncoding"] & 0x10 != 0, "%s: global encoding says WKT" % name)
        e, n, up = enu_to_utm.transform(list(m.x), list(m.y), list(m.z))
        utc = m.sweep_start_utc_ns
        worst_xy = worst_z = worst_t = 0.0
        for i, p in enumerate(las["points"]):
            x, y, z, intensity, number, count, user, gps = p
            worst_xy = max(worst_xy, abs(x - e[i]), abs(y - n[i]))
            worst_z = max(worst_z, abs(z - up[i]))
            if intensity != m.intensity[i] * 257 or user != m.ring[i]:
                fail("%s point %d: intensity %d ring %d, the message says %d, %d" % (
                    name, i, intensity, user, m.intensity[i], m.ring[i]))
            expected = (1, 1)
            if m.return_mode == 0x39 and m.return_type[i] != 3:
                expected = (2, 2) if m.return_type[i] == 2 else (1, 2)
            if (number, count) != expected:
                fail("%s point %d: return %d of %d, expected %s" % (name, i, number, count, expected))
            t = m.time_offset_ns[i] * 1e-9
            if utc:
                # Adjusted standard GPS time: GPS seconds since 1980-01-06 − 1e9; GPS − UTC = 18 s.
                t += utc * 1e-9 + 18 - 315964800 - 1e9
            worst_t = max(worst_t, abs(gps - t))
        check(worst_xy < 0.002, "%s: easting and northing within %.2f mm of PROJ's" % (name, worst_xy * 1e3))
        check(worst_z < 0.002, "%s: ellipsoidal heights within %.2f mm of PROJ's" % (name, worst_z * 1e3))
        check(worst_t < 2e-6, "%s: GPS times within %.2f µs (%s)" % (
            name, worst_t * 1e6, "adjusted standard GPS time" if utc else "seconds after the sweep's start"))
        check(bool(h["globalEncoding"] & 1) == bool(utc), "%s: global encoding bit 0 as the sweep's UTC is %s" % (
            name, "known" if utc else "unknown"))
        same = open(os.path.join(from_log, name), "rb").read() == open(os.path.join(from_run, name), "rb").read()
        check(same, "%s: the run folder's export through the pipeline is the same file" % name)
    check(sorted(os.listdir(from_log)) == sorted(os.listdir(from_run)),
          "the run folder's export has the log's %d files" % len(os.listdir(from_log)))
    print("PASS")


if __name__ == "__main__":
    main()
