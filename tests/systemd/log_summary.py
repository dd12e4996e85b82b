"""What an lcm-logger log of trajroid holds, read with the installed Python types:
one line per channel "CHANNEL TYPE COUNT", then "points_with_valid_pose N" and
"last_trajectory_id K" (from the last status_t), "last_rtk_solution", "last_host_minus_gnss_utc_s"
and "last_corrections" (the last status_t's) and "roi_heading_deg MIN MAX" (the
trajectory's heading at the ROI centres of every roi_t)."""
import math
import sys

import trajroi_lcm

counts = {}
valid = 0
last_trajectory = -1
last_status = None
headings = []
for channel, _timestamp, data in trajroi_lcm.read_log(sys.argv[1]):
    if channel == "LCM_SELF_TEST":  # liblcm's own, at each client's start
        continue
    message = trajroi_lcm.decode(data)
    name = type(message).__name__
    counts[(channel, name)] = counts.get((channel, name), 0) + 1
    if name == "points_t" and message.pose.valid:
        valid += 1
    if name == "roi_t":
        headings += [math.degrees(t) for t in message.theta_rad]
    if name == "status_t":
        last_trajectory = message.trajectory_id
        last_status = message
for (channel, name), count in sorted(counts.items()):
    print("%s %s %d" % (channel, name, count))
print("points_with_valid_pose %d" % valid)
print("last_trajectory_id %d" % last_trajectory)
if headings:
    print("roi_heading_deg %.2f %.2f" % (min(headings), max(headings)))
if last_status is not None:
    print("last_rtk_solution %d" % last_status.rtk_solution)
    print("last_host_minus_gnss_utc_s %.6f" % last_status.host_minus_gnss_utc_s)
    print("last_corrections %s" % last_status.corrections)
