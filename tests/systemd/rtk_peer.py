"""The peers of the service test's RTK case, written from the protocol documents rather than
from trajroi's code (RTCM 10403 framing and CRC-24Q, the u-blox UBX frame and checksum):

  rtk_peer.py rover LOG LINK RECORD SECONDS
      a u-blox receiver on a pseudo-terminal (LINK: a symlink to it): plays LOG one navigation
      epoch (up to and with each NAV-PVT) a second, over again at its end, acknowledges every
      CFG message written to it, and keeps every byte written to it in RECORD; ends after
      SECONDS or on SIGTERM.
  rtk_peer.py base LOG HOST:PORT
      a base station: connects to HOST:PORT (str2str's input) and sends LOG in pieces.
  rtk_peer.py check RECORD LOG
      exit 0 when RECORD is exactly LOG's valid RTCM3 frames in order, besides CFG-VALSET
      messages; says what it found either way.
"""
import os
import pty
import select
import signal
import socket
import sys
import time
import tty


def crc24q(data):
    crc = 0
    for byte in data:
        crc ^= byte << 16
        for _ in range(8):
            crc <<= 1
            if crc & 0x1000000:
                crc ^= 0x1864CFB
    return crc & 0xFFFFFF


def rtcm3_frames(data):
    """Valid RTCM3 frames of `data` (a frame whose CRC fails is skipped a byte at a time)."""
    frames, at = [], 0
    while at + 6 <= len(data):
        if data[at] != 0xD3 or data[at + 1] & 0xFC:
            at += 1
            continue
        end = at + 3 + (((data[at + 1] & 0x03) << 8) | data[at + 2]) + 3
        if end <= len(data) and crc24q(data[at:end - 3]) == int.from_bytes(data[end - 3:end], "big"):
            frames.append(bytes(data[at:end]))
            at = end
        else:
            at += 1
    return frames


def ubx_checksum(body):
    a = b = 0
    for byte in body:
        a = (a + byte) & 0xFF
        b = (b + a) & 0xFF
    return bytes((a, b))


def ubx_frame_at(data, at):
    """(class, id, end) of a UBX frame with a good checksum at `at`, or None."""
    if data[at:at + 2] != b"\xb5\x62" or at + 8 > len(data):
        return None
    end = at + 8 + int.from_bytes(data[at + 4:at + 6], "little")
    if end > len(data) or ubx_checksum(data[at + 2:end - 2]) != data[end - 2:end]:
        return None
    return data[at + 2], data[at + 3], end


def epochs(log):
    """The log cut after each NAV-PVT (class 0x01, id 0x07)."""
    out, start, at = [], 0, 0
    while True:
        at = log.find(b"\xb5\x62\x01\x07", at)
        if at < 0 or at + 6 > len(log):
            return out
        end = min(len(log), at + 8 + int.from_bytes(log[at + 4:at + 6], "little"))
        out.append(log[start:end])
        start = at = end


def send(fd, data):
    try:
        os.write(fd, data)
    except BlockingIOError:
        pass


def rover(log_path, link, record_path, seconds):
    with open(log_path, "rb") as f:
        cuts = epochs(f.read())
    master, slave = pty.openpty()
    tty.setraw(master)
    # Until trajroid reads, what the receiver sends fills the terminal's buffer: dropped then,
    # as a real receiver's output is when nobody reads it.
    os.set_blocking(master, False)
    os.chmod(os.ttyname(slave), 0o660)
    if os.path.lexists(link):
        os.unlink(link)
    os.symlink(os.ttyname(slave), link)
    running = [True]
    signal.signal(signal.SIGTERM, lambda *_: running.__setitem__(0, False))
    written = bytearray()
    acked = 0
    next_epoch, epoch, deadline = time.monotonic(), 0, time.monotonic() + seconds
    with open(record_path, "wb") as record:
        while running[0] and time.monotonic() < deadline:
            if time.monotonic() >= next_epoch:
                send(master, cuts[epoch % len(cuts)])
                epoch += 1
                next_epoch += 1.0
            if not select.select([master], [], [], 0.01)[0]:
                continue
            try:
                got = os.read(master, 4096)
            except (BlockingIOError, OSError):
                time.sleep(0.01)
                continue
            record.write(got)
            record.flush()
            written += got
            # Acknowledge each whole CFG message not acknowledged yet.
            at = acked
            while at < len(written):
                frame = ubx_frame_at(written, at)
                if frame is None:
                    at += 1
                    continue
                cls, mid, end = frame
                if cls == 0x06:
                    body = bytes((0x05, 0x01, 0x02, 0x00, cls, mid))
                    send(master, b"\xb5\x62" + body + ubx_checksum(body))
                at = acked = end
    os.unlink(link)


def base(log_path, address):
    host, port = address.rsplit(":", 1)
    with open(log_path, "rb") as f:
        data = f.read()
    with socket.create_connection((host, int(port)), timeout=5) as s:
        for at in range(0, len(data), 700):
            s.sendall(data[at:at + 700])
            time.sleep(0.02)
        time.sleep(1)


def check(record_path, log_path):
    with open(record_path, "rb") as f:
        written = f.read()
    with open(log_path, "rb") as f:
        expected = rtcm3_frames(f.read())
    frames, others, stray, at = [], [], 0, 0
    while at < len(written):
        ubx = ubx_frame_at(written, at)
        if ubx is not None:
            others.append((ubx[0], ubx[1]))
            at = ubx[2]
            continue
        found = rtcm3_frames(written[at:at + 1029])
        if found and written.startswith(found[0], at):
            frames.append(found[0])
            at += len(found[0])
            continue
        stray += 1
        at += 1
    not_valset = [m for m in others if m != (0x06, 0x8A)]
    print("receiver read %d bytes: %d RTCM3 frames (the base sent %d valid ones), %d UBX messages "
          "(%d not CFG-VALSET), %d bytes outside any frame" %
          (len(written), len(frames), len(expected), len(others), len(not_valset), stray))
    same = frames == expected
    if not same:
        first = next((i for i, (a, b) in enumerate(zip(frames, expected)) if a != b), min(len(frames), len(expected)))
        print("the frames differ from the base's from frame %d on" % first)
    return 0 if same and not not_valset and stray == 0 and others else 1


if __name__ == "__main__":
    command = sys.argv[1]
    if command == "rover":
        rover(sys.argv[2], sys.argv[3], sys.argv[4], float(sys.argv[5]))
    elif command == "base":
        base(sys.argv[2], sys.argv[3])
    elif command == "check":
        sys.exit(check(sys.argv[2], sys.argv[3]))
    else:
        sys.exit("unknown command %s" % command)
