# shellcheck shell=bash disable=SC2154  # data_dir, here, work, trajroi: set by service_test.sh
# The two_lidars case of service_test.sh (sourced by it, with its helpers): two VLP-16s on one
# port, told apart by their addresses (10.0.0.101: the MRPT capture, strongest return;
# 10.0.0.102: nebula's, dual return), each a real capture played over for a few seconds at its
# recorded pace, merged by the unit as installed. What systemd shows of it: the allow-list
# admits both sensors; STATUS= says the merged rate (one cloud per sweep period) beside the
# sensors' while both send; when the rear stops while the front goes on, the journal and
# STATUS= name it silent within a second and the front's sweeps are still published; the
# sweeps the merge held for the rear meanwhile are late by that wait, and said so.
pcaps=$data_dir/velodyne/vlp16
front_capture=$pcaps/mrpt_sample_velodyne_vlp16_gps.pcap
rear_capture=$pcaps/nebula_vlp16_dual_1673400471.DERIVED.pcap
for f in "$front_capture" "$rear_capture"; do
  [ -f "$f" ] || skip_or_fail "$f is missing (TRAJROI_DATA_DIR)"
done
# The front runs 6.2 s (16 plays of 0.39 s), the rear 3.2 s (8 plays of 0.40 s).
"${PYTHON:-python3}" "$here/pcap_plays.py" "$front_capture" 16 "$work/front.pcap"
"${PYTHON:-python3}" "$here/pcap_plays.py" "$rear_capture" 8 "$work/rear.pcap"
printf 'lat,lon\n50.13480,14.42995\n50.13540,14.42995\n' >"$work/trajectory.csv"
cat >"$work/trajroid.yaml" <<YAML
global_frame:
  origin: {lat_deg: 50.13505, lon_deg: 14.42990, height_m: 348.0}
trajectory:
  file: trajectory.csv
lidars:
  - name: front
    sensor_address: 10.0.0.101
    mounting: {xyz: [0.4, 0.1, 0.8], yaw_deg: 10}
    min_range_m: 0.5
  - name: rear
    sensor_address: 10.0.0.102
    mounting: {xyz: [-0.4, -0.1, 0.7], yaw_deg: 190}
    min_range_m: 0.5
lidar_merge: {max_wait_s: 0.15, silent_s: 0.5}
pose:
  source: fixed
  mode: per_sweep
  fixed: {xyz: [3.3, 2.0, 0.5], yaw_deg: 60}
roi:
  circle_diameter_m: 3
  look_ahead_m: 10
YAML
chmod 644 "$work"/*
export NSD_ADDRESSES="10.0.0.101 10.0.0.102"
nsd_boot
feeds=()
nsd_on_exit() {
  local p
  for p in "${feeds[@]}"; do kill "$p" 2>/dev/null || true; done
  true
}
install_unit "$work/trajroid.yaml"
nsd systemctl start trajroid.service || fail "start"
echo "allow-lists set at start:"
nsd journalctl -u trajroid.service --no-pager -o cat | grep "trajroid.service: allowing" | sed 's/^/  /'
allowed=" $(show IPAddressAllow) "
echo "  IPAddressAllow=$allowed"
for a in 10.0.0.101 10.0.0.102; do
  [[ "$allowed" == *" $a/32 "* || "$allowed" == *" $a "* ]] || fail "the LiDAR at $a is not admitted: $allowed"
done
for name in "front at 10.0.0.101" "rear at 10.0.0.102"; do
  journal_has "the LiDAR $name (lidars: sensor_address)" || fail "the allow-list step does not name the LiDAR $name"
done

feed() {  # NAME ADDRESS
  nsd "$trajroi" feed --pcap "$work/$1.pcap" --from "$2" >"$work/feed_$1.log" 2>&1 &
  feeds+=($!)
}
feed front 10.0.0.101
feed rear 10.0.0.102
rear_feed=${feeds[1]}
# While both send: the merged clouds' rate, and the sensors' (each about 10 sweeps a second).
merged_rate='publishing \([0-9.]*\) merged sweeps/s of 2 LiDARs (\([0-9.]*\) sensor sweeps/s)'
both_rates() {
  local status
  status=$(show StatusText)
  read -r merged sensors < <(sed -n "s|.*$merged_rate.*|\1 \2|p" <<<"$status")
  [ -n "${merged:-}" ] && awk -v m="$merged" -v s="$sensors" 'BEGIN { exit !(m >= 8 && m <= 12 && s >= 18 && s <= 22) }'
}
merged="" sensors=""
wait_for 3 both_rates || fail "STATUS= does not say about 10 merged of 20 sensor sweeps/s while both send: '$(show StatusText)'"
echo "both sending, STATUS=$(show StatusText)"
# The rear stops; the front goes on for 3 s more.
wait "$rear_feed" || fail "the rear's feed: $(tail -3 "$work/feed_rear.log")"
rear_ended=$(date +%s.%N)
silent="rear (10.0.0.102 → UDP 2368) silent"
wait_for 3 journal_has "lidar: $silent" || fail "the rear is not named silent in the journal"
named_after=$(awk -v a="$rear_ended" -v b="$(date +%s.%N)" 'BEGIN { printf "%.1f", b - a }')
stated() { [[ "$(show StatusText)" == *"LiDAR rear (10.0.0.102 → UDP 2368): silent"* ]]; }
wait_for 2 stated || fail "STATUS= does not name the silent rear: '$(show StatusText)'"
echo "rear stopped: named silent in the journal within ${named_after} s (polled); STATUS=$(show StatusText)"
# The front's sweeps still go out, alone: the published count grows in the status lines after
# the rear was named.
published_after_silent() {
  nsd journalctl -u trajroid.service --no-pager -o cat | awk -v silent="lidar: $silent" '
    index($0, silent) { named = 1; next }
    named && /^status:/ && match($0, /published [0-9]+/) { n[++k] = substr($0, RSTART + 10, RLENGTH - 10) }
    END { exit !(k >= 2 && n[k] > n[1]) }'
}
wait_for 3 published_after_silent || fail "the front's sweeps are not published after the rear fell silent"
wait "${feeds[0]}" || fail "the front's feed: $(tail -3 "$work/feed_front.log")"
feeds=()
sleep 1
nsd systemctl stop trajroid.service
[ "$(show Result)" = success ] || fail "result $(show Result) at stop"
journal=$(nsd journalctl -u trajroid.service --no-pager -o cat)
summary=$(grep "^summary:" <<<"$journal")
echo "$summary"
[[ "$summary" == *"merged sweeps published "* ]] || fail "the summary does not count the merged sweeps"
# The minute's slowest sweep is one the merge held for the rear before it was named silent
# (up to lidar_merge.max_wait_s): its time is said to be that wait, not the processing thread's.
slowest=$(grep "^minute:" <<<"$journal" | tail -1 | sed -n 's/.*| slowest: //p')
echo "the minute's slowest: $slowest"
[[ "$slowest" == *"waiting for the other LiDARs' sweeps "* ]] ||
  fail "the slowest sweep's time is not put down to the merge's wait: '$slowest'"
