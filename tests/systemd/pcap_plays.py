#!/usr/bin/env python3
"""A VLP-16 capture played PLAYS times over as one sensor running that much longer.

    pcap_plays.py IN PLAYS OUT

Each play's record times and the VLP-16's own clock (top-of-hour µs in every data packet) move
on by the capture's length: a sensor never repeats its clock, and the same bytes again would be
late packets to a decoder. Position packets are kept in the first play only. A classic pcap,
little-endian, µs or ns time stamps, Ethernet + IPv4 + UDP (the MRPT and nebula captures).
"""
import struct
import sys

PAYLOAD = 42  # Ethernet 14 + IPv4 20 + UDP 8
DATA_BYTES = 1206
TOH = PAYLOAD + 1200  # the data packet's µs past the hour
HOUR_US = 3_600_000_000


def main() -> int:
    src, plays, dst = sys.argv[1], int(sys.argv[2]), sys.argv[3]
    data = open(src, "rb").read()
    magic = struct.unpack_from("<I", data, 0)[0]
    if magic not in (0xA1B2C3D4, 0xA1B23C4D):
        sys.exit(f"{src}: not a little-endian classic pcap (magic {magic:#x})")
    per_second = 1_000_000 if magic == 0xA1B2C3D4 else 1_000_000_000
    records = []
    at = 24
    while at + 16 <= len(data):
        length = struct.unpack_from("<I", data, at + 8)[0]
        records.append(data[at : at + 16 + length])
        at += 16 + length

    def is_data(r: bytes) -> bool:
        return struct.unpack_from("<I", r, 8)[0] == PAYLOAD + DATA_BYTES

    clocks = [struct.unpack_from("<I", r, 16 + TOH)[0] for r in records if is_data(r)]
    if not clocks:
        sys.exit(f"{src}: no VLP-16 data packets")
    steps = sorted(b - a for a, b in zip(clocks, clocks[1:]))
    period_us = steps[len(steps) // 2] if steps else 1327
    length_us = clocks[-1] - clocks[0] + period_us  # the next play one packet period after the last
    out = bytearray(data[:24])
    for play in range(plays):
        shift_us = play * length_us
        for r in records:
            if play > 0 and not is_data(r):
                continue
            r = bytearray(r)
            sec, frac = struct.unpack_from("<II", r, 0)
            t = sec * per_second + frac + shift_us * (per_second // 1_000_000)
            struct.pack_into("<II", r, 0, t // per_second, t % per_second)
            if is_data(r):
                toh = (struct.unpack_from("<I", r, 16 + TOH)[0] + shift_us) % HOUR_US
                struct.pack_into("<I", r, 16 + TOH, toh)
            out += r
    open(dst, "wb").write(out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
