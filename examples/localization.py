"""A robot's localization feeding trajroid (pose.source: lcm) from Python, with no lcm module.

Publishes pose_input_t at --rate Hz, stamped with the host's UTC clock: here the pose of a
robot parked at --x/--y (global frame, m; or --lat/--lon) facing --yaw-deg (counter-clockwise
from east). Replace current_pose() with your localizer's output. With --trajectory it first
publishes a trajectory_t (id --trajectory-id) through the given waypoints, as a planner would.

    python3 localization.py --x 12.5 --y -3.2 --yaw-deg 90 \
        --trajectory "0,0 40,0" --trajectory-id 7
"""
import argparse
import math
import time

import trajroi_lcm


def current_pose(args):
    """(position, orientation w x y z, valid): where the robot is now."""
    half = math.radians(args.yaw_deg) / 2.0
    position = (args.lat, args.lon, args.height) if args.lat is not None else (args.x, args.y, args.z)
    return position, (math.cos(half), 0.0, 0.0, math.sin(half)), not args.invalid


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--url", default="udpm://239.255.76.67:7667?ttl=0")
    p.add_argument("--channel", default="TRAJROI_POSE_INPUT", help="trajroid's lcm.channels.pose_input")
    p.add_argument("--x", type=float, default=0.0)
    p.add_argument("--y", type=float, default=0.0)
    p.add_argument("--z", type=float, default=0.0)
    p.add_argument("--lat", type=float, help="latitude, deg (with --lon, --height: a WGS-84 position)")
    p.add_argument("--lon", type=float)
    p.add_argument("--height", type=float, default=0.0)
    p.add_argument("--yaw-deg", type=float, default=0.0)
    p.add_argument("--rate", type=float, default=20.0, help="poses per second")
    p.add_argument("--seconds", type=float, default=0.0, help="stop after this long (0: never)")
    p.add_argument("--invalid", action="store_true", help="mark the poses invalid (a localizer that is lost)")
    p.add_argument("--trajectory", help="waypoints 'x,y x,y …' (or 'lat,lon …' with --lat) to publish first")
    p.add_argument("--trajectory-id", type=int, default=1)
    p.add_argument("--trajectory-channel", default="TRAJROI_TRAJECTORY")
    args = p.parse_args()

    out = trajroi_lcm.Publisher(args.url)
    if args.trajectory:
        waypoints = [tuple(float(v) for v in w.split(",")) for w in args.trajectory.split()]
        out.publish(args.trajectory_channel,
                    trajroi_lcm.trajectory(args.trajectory_id, waypoints, lat_lon=args.lat is not None))
    start = time.monotonic()
    sent = 0
    while args.seconds <= 0.0 or time.monotonic() - start < args.seconds:
        position, orientation, valid = current_pose(args)
        out.publish(args.channel, trajroi_lcm.pose_input(time.time_ns(), position, orientation,
                                                         lat_lon=args.lat is not None, valid=valid))
        sent += 1
        time.sleep(max(0.0, start + sent / args.rate - time.monotonic()))
    print("localization.py: %d poses published on %s" % (sent, args.channel), flush=True)


if __name__ == "__main__":
    main()
