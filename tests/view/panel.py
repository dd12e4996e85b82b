"""The page's panel in words (view/web/view.js), written again from a status_t: the tests compare
what the page shows with what trajroid published."""


def fixed(v, digits):
    return "–" if v is None or v != v else "%.*f" % (digits, v)


def panel_text(s):
    """The pose, corrections and time lines the page writes for status_t `s` (view.js)."""
    nan = lambda v: v != v  # noqa: E731
    pose = ["pose (%s) %s" % (s.pose_source, "valid" if s.pose_valid else "NOT valid: " + s.pose_status)]
    if not nan(s.pose_age_s):
        pose.append("age %s s" % fixed(s.pose_age_s, 2))
    if s.fix_type >= 0:
        pose.append("fix %d" % s.fix_type + ("" if nan(s.h_acc_m) else ", hAcc %s m" % fixed(s.h_acc_m, 2)))
    if s.rtk_solution >= 0:
        pose.append("RTK " + ["none", "float", "fixed"][s.rtk_solution])
    corrections = []
    if s.corrections:
        corrections = ["corrections: " + s.corrections,
                       "age none written" if nan(s.correction_age_s) else "age %s s" % fixed(s.correction_age_s, 1)]
        if not nan(s.corrections_bytes_per_s):
            corrections.append("%s B/s" % fixed(s.corrections_bytes_per_s, 0))
    ms = lambda v: ("+" if v >= 0 else "") + (  # noqa: E731
        fixed(v, 1) + " s" if abs(v) >= 10 else fixed(1000 * v, 1) + " ms")
    time_parts = []
    if not nan(s.host_minus_gnss_utc_s):
        time_parts.append("host − GNSS " + ms(s.host_minus_gnss_utc_s) + (
            "" if nan(s.gnss_time_accuracy_s) else " (tAcc %s ns)" % fixed(1e9 * s.gnss_time_accuracy_s, 0)))
    if not nan(s.host_minus_lidar_utc_s):
        time_parts.append("host − LiDAR " + ms(s.host_minus_lidar_utc_s))
    if s.lidar_pps_status >= 0:
        time_parts.append("LiDAR PPS " + ["absent", "synchronizing", "locked", "error"][s.lidar_pps_status])
    if s.lidar_gprmc_valid >= 0:
        time_parts.append("GPRMC " + ("valid" if s.lidar_gprmc_valid else "invalid"))
    return {"pose": " · ".join(pose), "corrections": " · ".join(corrections),
            "time": "time: " + " · ".join(time_parts) if time_parts else "time: no GNSS or LiDAR time yet"}
