"""trajroi's point clouds in Python: prints each one as it arrives. Uses the `lcm` module when
installed, else trajroi_lcm's receiver (both installed by the package, with the types)."""
import sys

try:
    import lcm
    connect = lcm.LCM
except ImportError:
    import trajroi_lcm
    connect = trajroi_lcm.Subscriber
from trajroi import points_t


def on_points(channel, data):
    m = points_t.decode(data)
    print("sweep %d: %d of %d points kept, pose %s" % (m.sweep_index, m.num_points, m.points_in,
                                                        "valid" if m.pose.valid else "invalid"), flush=True)


bus = connect(sys.argv[1] if len(sys.argv) > 1 else "udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608")
bus.subscribe("TRAJROI_POINTS", on_points)
while True:
    bus.handle()
