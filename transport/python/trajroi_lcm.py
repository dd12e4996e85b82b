"""trajroi's LCM messages from Python without the lcm module (Debian packages none).

The types themselves are lcm-gen's (package ``trajroi``, installed beside this module). This
module adds what a subscriber needs around them:

- ``Subscriber(url)``: receives LCM's UDP multicast (udpm://, small and fragmented messages),
  with ``subscribe(channel, handler)`` and ``handle_timeout(ms)`` as ``lcm.LCM`` has them, so a
  subscriber written for either runs on both;
- ``Publisher(url)``: sends on it, ``publish(channel, message_or_bytes)`` as ``lcm.LCM`` has it
  (a large message, a long trajectory, in fragments as liblcm sends them); with
  ``pose_input(...)`` and ``trajectory(...)``, the two messages trajroid takes in;
- ``read_log(path)``: the events of an ``lcm-logger`` log;
- ``decode(data)``: the message as its trajroi type, found by its fingerprint.

Run as a program, ``python3 -m trajroi_lcm LOG`` prints each channel's message count and type.

A robot's localization feeding trajroid (pose.source: lcm), and a planner replacing its
trajectory::

    import time, trajroi_lcm
    out = trajroi_lcm.Publisher("udpm://239.255.76.67:7667?ttl=0")
    out.publish("TRAJROI_POSE_INPUT", trajroi_lcm.pose_input(
        t_ns=time.time_ns(), position=(12.5, -3.2, 0.0), orientation=(1.0, 0.0, 0.0, 0.0)))
    out.publish("TRAJROI_TRAJECTORY", trajroi_lcm.trajectory(7, [(0.0, 0.0), (40.0, 0.0)]))
"""

import itertools
import socket
import struct
import sys
import urllib.parse

import trajroi

_SHORT_MAGIC = 0x4C433032  # "LC02": a whole message in one datagram
_LONG_MAGIC = 0x4C433033  # "LC03": one fragment of a larger message
_LOG_SYNC = 0xEDA1DA01
_SHORT_MESSAGE_MAX = 65499  # channel + NUL + payload in one LC02 datagram (liblcm's limit)
_FRAGMENT_MAX = 65487  # channel (first fragment) + payload per LC03 datagram

_TYPES = {}
for _name in dir(trajroi):
    _cls = getattr(trajroi, _name)
    if isinstance(_cls, type) and hasattr(_cls, "_get_packed_fingerprint"):
        _TYPES[_cls._get_packed_fingerprint()] = _cls


def decode(data):
    """The message in ``data`` as its trajroi type; ValueError for any other fingerprint."""
    cls = _TYPES.get(bytes(data[:8]))
    if cls is None:
        raise ValueError("not a trajroi message (fingerprint %s)" % bytes(data[:8]).hex())
    return cls.decode(data)


def read_log(path):
    """Yields (channel, timestamp_us, data) for each event of an lcm-logger log."""
    with open(path, "rb") as log:
        while True:
            header = log.read(28)
            if len(header) < 28:
                return
            sync, _number, timestamp, channel_length, data_length = struct.unpack(">IqqII", header)
            if sync != _LOG_SYNC:
                raise ValueError("%s: lost sync at byte %d" % (path, log.tell() - 28))
            channel = log.read(channel_length).decode()
            data = log.read(data_length)
            if len(data) < data_length:
                return  # a log cut short: its last event is incomplete
            yield channel, timestamp, data


class Subscriber:
    """An LCM udpm:// receiver: ``subscribe``, then ``handle`` or ``handle_timeout``."""

    def __init__(self, url="udpm://239.255.76.67:7667", recv_buf_size=None):
        group, port, options = _udpm_address(url)
        if recv_buf_size is None and "recv_buf_size" in options:
            recv_buf_size = int(options["recv_buf_size"][0])
        self._socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        self._socket.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        if recv_buf_size:
            self._take_receive_buffer(recv_buf_size)
        self._socket.bind(("", port))
        membership = struct.pack("4s4s", socket.inet_aton(group), socket.inet_aton("0.0.0.0"))
        self._socket.setsockopt(socket.IPPROTO_IP, socket.IP_ADD_MEMBERSHIP, membership)
        self._handlers = {}
        self._partial = {}  # (sender, sequence) -> [channel, size, buffer, bytes received]

    def fileno(self):
        return self._socket.fileno()

    def _take_receive_buffer(self, size):
        """Asks for ``size`` bytes: past net.core.rmem_max where permitted (SO_RCVBUFFORCE,
        root), else as much as the kernel allows, said on stderr in one line when capped."""
        so_rcvbufforce = getattr(socket, "SO_RCVBUFFORCE", 33)
        try:
            self._socket.setsockopt(socket.SOL_SOCKET, so_rcvbufforce, size)
        except PermissionError:
            self._socket.setsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF, size)
        granted = self._socket.getsockopt(socket.SOL_SOCKET, socket.SO_RCVBUF) // 2
        if granted < size:
            sys.stderr.write(
                "trajroi_lcm: the kernel capped the LCM receive buffer at %d KiB of the %d KiB asked for "
                "(net.core.rmem_max); clouds may be lost when this subscriber falls behind. Run it as root, "
                "or raise the limit with the drop-in trajroi ships: "
                "sysctl -p /usr/lib/sysctl.d/60-trajroi-lcm.conf\n" % (granted // 1024, size // 1024))
        return granted

    def subscribe(self, channel, handler):
        """``handler(channel, data)`` for every message on ``channel`` (exact name)."""
        self._handlers.setdefault(channel, []).append(handler)

    def handle_timeout(self, timeout_ms):
        """Waits up to ``timeout_ms`` for one datagram; 1 when a message was dispatched."""
        self._socket.settimeout(timeout_ms / 1000.0)
        try:
            datagram, sender = self._socket.recvfrom(65536)
        except socket.timeout:
            return 0
        return self._on_datagram(datagram, sender)

    def handle(self):
        while not self.handle_timeout(1000):
            pass

    def _on_datagram(self, datagram, sender):
        if len(datagram) < 8:
            return 0
        magic, sequence = struct.unpack(">II", datagram[:8])
        if magic == _SHORT_MAGIC:
            end = datagram.find(b"\0", 8)
            if end < 0:
                return 0
            return self._dispatch(datagram[8:end].decode(), datagram[end + 1:])
        if magic != _LONG_MAGIC or len(datagram) < 20:
            return 0
        size, offset, number, count = struct.unpack(">IIHH", datagram[8:20])
        payload = datagram[20:]
        key = (sender, sequence)
        if number == 0:
            end = payload.find(b"\0")
            if end < 0:
                return 0
            self._partial[key] = [payload[:end].decode(), size, bytearray(size), 0]
            payload = payload[end + 1:]
        message = self._partial.get(key)
        if message is None or offset + len(payload) > size:
            return 0
        message[2][offset:offset + len(payload)] = payload
        message[3] += len(payload)
        if number != count - 1 and message[3] < size:
            return 0
        del self._partial[key]
        if message[3] != size:
            return 0  # a fragment was lost: the message is dropped, as liblcm does
        # Fragments of older messages from this sender will not complete any more.
        for stale in [k for k in self._partial if k[0] == sender and k[1] < sequence]:
            del self._partial[stale]
        return self._dispatch(message[0], bytes(message[2]))

    def _dispatch(self, channel, data):
        for handler in self._handlers.get(channel, []):
            handler(channel, data)
        return 1


def _udpm_address(url):
    parsed = urllib.parse.urlparse(url)
    if parsed.scheme != "udpm":
        raise ValueError("only udpm:// URLs: %s" % url)
    group, _, port = (parsed.netloc or "239.255.76.67:7667").partition(":")
    return group, int(port or 7667), urllib.parse.parse_qs(parsed.query)


class Publisher:
    """An LCM udpm:// sender: ``publish(channel, message)`` as ``lcm.LCM.publish``.

    The URL's ``ttl`` is honoured (default 0: this host only, as trajroid's default URL)."""

    def __init__(self, url="udpm://239.255.76.67:7667?ttl=0"):
        group, port, options = _udpm_address(url)
        self._destination = (group, port)
        self._socket = socket.socket(socket.AF_INET, socket.SOCK_DGRAM, socket.IPPROTO_UDP)
        ttl = int(options.get("ttl", ["0"])[0])
        self._socket.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_TTL, ttl)
        self._socket.setsockopt(socket.IPPROTO_IP, socket.IP_MULTICAST_LOOP, 1)
        self._sequence = itertools.count()

    def close(self):
        self._socket.close()

    def publish(self, channel, message):
        """Sends ``message`` (a trajroi type, or its encoded bytes) on ``channel``."""
        data = message if isinstance(message, (bytes, bytearray)) else message.encode()
        name = channel.encode() + b"\0"
        if not 1 < len(name) <= 64:
            raise ValueError("LCM channel names are 1 to 63 bytes: %r" % channel)
        sequence = next(self._sequence) & 0xFFFFFFFF
        if len(name) + len(data) <= _SHORT_MESSAGE_MAX:
            self._socket.sendto(struct.pack(">II", _SHORT_MAGIC, sequence) + name + data, self._destination)
            return
        count = (len(name) + len(data) + _FRAGMENT_MAX - 1) // _FRAGMENT_MAX
        offset = 0
        for number in range(count):
            head = name if number == 0 else b""
            piece = data[offset:offset + _FRAGMENT_MAX - len(head)]
            header = struct.pack(">IIIIHH", _LONG_MAGIC, sequence, len(data), offset, number, count)
            self._socket.sendto(header + head + piece, self._destination)
            offset += len(piece)


def pose_input(t_ns, position, orientation, lat_lon=False, monotonic=False, valid=True):
    """A ``pose_input_t``: the robot's pose at ``t_ns`` (UTC ns since 1970, or the host's
    CLOCK_MONOTONIC with ``monotonic``), ``position`` x east, y north, z up in m in trajroid's
    global frame (or latitude deg, longitude deg, height m with ``lat_lon``), ``orientation``
    global_from_robot as a unit quaternion (w, x, y, z); ``valid`` False when the localizer is lost."""
    m = trajroi.pose_input_t()
    m.t_ns = int(t_ns)
    m.clock = trajroi.pose_input_t.STAMP_MONOTONIC if monotonic else trajroi.pose_input_t.STAMP_UTC
    m.frame = trajroi.pose_input_t.LAT_LON if lat_lon else trajroi.pose_input_t.GLOBAL_XY
    m.position = [float(v) for v in position]
    m.orientation = [float(v) for v in orientation]
    m.valid = bool(valid)
    return m


def trajectory(trajectory_id, waypoints, lat_lon=False):
    """A ``trajectory_t`` with id ``trajectory_id`` (> 0) through ``waypoints``: (x, y) in m in the
    global frame, or (latitude, longitude) in degrees with ``lat_lon``."""
    m = trajroi.trajectory_t()
    m.id = int(trajectory_id)
    m.coordinates = trajroi.trajectory_t.LAT_LON if lat_lon else trajroi.trajectory_t.GLOBAL_XY
    m.num_waypoints = len(waypoints)
    m.u = [float(w[0]) for w in waypoints]
    m.v = [float(w[1]) for w in waypoints]
    return m


def _summary(path):
    counts = {}
    for channel, _timestamp, data in read_log(path):
        name = type(decode(data)).__name__
        counts[(channel, name)] = counts.get((channel, name), 0) + 1
    for (channel, name), count in sorted(counts.items()):
        print("%s %s %d" % (channel, name, count))


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python3 -m trajroi_lcm LCM_LOG")
    _summary(sys.argv[1])
