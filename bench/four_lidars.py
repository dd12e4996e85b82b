"""Makes a four-LiDAR run folder from a one-LiDAR one (bench/daemon_figures.sh):
  four_lidars.py RUN OUT
The run's VLP-16 datagrams sent by four sensors at 192.168.1.201 … 204 on the same ports, the
second to fourth 25, 50 and 75 ms after the first (sensors are not in step), each mounted on its
own side of the robot; its GNSS, IMU and trajectory as they are. The configuration is the run's
with lidars: (four entries, told apart by address) in place of lidar:."""

import os
import re
import shutil
import struct
import sys

SENSORS = [("front", "192.168.1.201", "{xyz: [0.6, 0, 0.8]}"),
           ("rear", "192.168.1.202", "{xyz: [-0.6, 0, 0.8], yaw_deg: 180}"),
           ("left", "192.168.1.203", "{xyz: [0, 0.4, 0.8], yaw_deg: 90}"),
           ("right", "192.168.1.204", "{xyz: [0, -0.4, 0.8], yaw_deg: -90}")]
STAGGER_NS = 25_000_000


def records(path):
    data = open(path, "rb").read()
    magic = struct.unpack("<I", data[:4])[0]
    if magic not in (0xA1B2C3D4, 0xA1B23C4D):
        sys.exit("%s: not a little-endian pcap" % path)
    scale = 1000 if magic == 0xA1B2C3D4 else 1
    at = 24
    while at + 16 <= len(data):
        sec, frac, length, _ = struct.unpack("<IIII", data[at:at + 16])
        yield sec * 1_000_000_000 + frac * scale, data[at + 16:at + 16 + length]
        at += 16 + length


def from_address(frame, address):
    """The Ethernet + IPv4 frame with another source address (its header checksum made again)."""
    f = bytearray(frame)
    f[26:30] = bytes(int(b) for b in address.split("."))
    f[24:26] = b"\0\0"
    total = sum(struct.unpack(">10H", bytes(f[14:34])))
    while total > 0xFFFF:
        total = (total & 0xFFFF) + (total >> 16)
    f[24:26] = struct.pack(">H", ~total & 0xFFFF)
    return bytes(f)


def main():
    run, out = sys.argv[1:3]
    os.makedirs(out, exist_ok=True)
    for name in os.listdir(run):
        if name not in ("lidar.pcap", "trajroid.yaml") and os.path.isfile(os.path.join(run, name)):
            shutil.copy(os.path.join(run, name), out)
    original = list(records(os.path.join(run, "lidar.pcap")))
    merged = []
    for k, (_, address, _) in enumerate(SENSORS):
        merged += [(t + k * STAGGER_NS, k, from_address(f, address)) for t, f in original]
    merged.sort(key=lambda r: (r[0], r[1]))
    with open(os.path.join(out, "lidar.pcap"), "wb") as f:
        f.write(struct.pack("<IHHiIII", 0xA1B23C4D, 2, 4, 0, 0, 65535, 1))
        for t, _, frame in merged:
            f.write(struct.pack("<IIII", t // 1_000_000_000, t % 1_000_000_000, len(frame), len(frame)))
            f.write(frame)
    config = open(os.path.join(run, "trajroid.yaml")).read()
    lidar = re.search(r"^lidar:\n((?:  .*\n)+)", config, re.M)
    keys = [line for line in lidar.group(1).splitlines() if not line.startswith("  mounting:")]
    entries = ""
    for name, address, mounting in SENSORS:
        entries += "  - name: %s\n    sensor_address: %s\n    mounting: %s\n" % (name, address, mounting)
        entries += "".join("  " + line + "\n" for line in keys)
    config = config[:lidar.start()] + "lidars:\n" + entries + config[lidar.end():]
    with open(os.path.join(out, "trajroid.yaml"), "w") as f:
        f.write(config)


if __name__ == "__main__":
    main()
