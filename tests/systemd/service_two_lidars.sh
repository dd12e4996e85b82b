# shellcheck shell=bash disable=SC2154  # data_dir, here, work, trajroi: set by service_test.sh
# The two_lidars case of service_test.sh (sourced by it, with its helpers): two VLP-16s on one
# port, told apart by their addresses (10.0.0.101: the MRPT capture, strongest return;
# 10.0.0.102: nebula's, dual return), each a real capture played over for a few seconds at its
# recorded pace, merged by the unit as installed. What systemd shows of it: the allow-list
# admits both sensors; STATUS= says the merged rate (one cloud per sweep period) beside the
# sensors' while both send; when the rear stops while the front goes on, the journal and
# STATUS= name it silent within a second and the front's sweeps are still published; the
# sweeps the merge held for the rear meanwhile are late by that wait, and said so. The rear then
# sends another model's packets (a real HDL-32E capture): they are dropped, counted and named
# with the rear, as its model was.
pcaps=$data_dir/velodyne/vlp16
front_capture=$pcaps/mrpt_sample_velodyne_vlp16_gps.pcap
rear_capture=$pcaps/nebula_vlp16_dual_1673400471.DERIVED.pcap
other_model=$data_dir/velodyne/other_models/mrpt_sample_velodyne_hdl32e.pcap
for f in "$front_capture" "$rear_capture" "$other_model"; do
  [ -f "$f" ] || skip_or_fail "$f is missing (TRAJROI_DATA_DIR)"
done
# The front runs 9.3 s (24 plays of 0.39 s), the rear 3.2 s (8 plays of 0.40 s), then the
# HDL-32E's packets from the rear's address 1.1 s (4 plays of 0.28 s).
"${PYTHON:-python3}" "$here/pcap_plays.py" "$front_capture" 24 "$work/front.pcap"
"${PYTHON:-python3}" "$here/pcap_plays.py" "$rear_capture" 8 "$work/rear.pcap"
"${PYTHON:-python3}" "$here/pcap_plays.py" "$other_model" 4 "$work/rear_hdl32e.pcap"
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
    cut_azimuth_deg: 180
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
install_unit "$work/trajroid.yaml"
nsd systemctl start trajroid.service || fail "start"
print_allow_lists
for a in 10.0.0.101 10.0.0.102; do
  admits "$a" || fail "the LiDAR at $a is not admitted: $(show IPAddressAllow)"
done
for name in "front at 10.0.0.101" "rear at 10.0.0.102"; do
  journal_has "the LiDAR $name (lidars: sensor_address)" || fail "the allow-list step does not name the LiDAR $name"
done

feed() {  # NAME ADDRESS
  nsd "$trajroi" feed --pcap "$work/$1.pcap" --from "$2" >"$work/feed_$1.log" 2>&1 &
  pids+=($!)
}
feed front 10.0.0.101
feed rear 10.0.0.102
rear_feed=${pids[1]}
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
# Each sensor's model is named with it.
for named in "front (10.0.0.101 → UDP 2368): VLP-16 packets (product id 0x22)" \
  "rear (10.0.0.102 → UDP 2368): VLP-16 packets (product id 0x22)"; do
  journal_has "lidar: $named" || fail "the model is not named with its sensor: lidar: $named"
done
# The rear's packets change model mid-run: dropped, counted and named with the rear.
feed rear_hdl32e 10.0.0.102
wait "${pids[2]}" || fail "the rear's HDL-32E feed: $(tail -3 "$work/feed_rear_hdl32e.log")"
rejected="lidar: rear (10.0.0.102 → UDP 2368): [0-9]* packets rejected in the last second: the sensor's packets \
changed model mid-run, from VLP-16 to product id 0x21 (HDL-32E)"
wait_for 3 journal_has "$rejected" || fail "the rear's packets of another model are not named with it"
nsd journalctl -u trajroid.service --no-pager -o cat | grep -m1 "$rejected"
wait "${pids[0]}" || fail "the front's feed: $(tail -3 "$work/feed_front.log")"
pids=()
sleep 1
nsd systemctl stop trajroid.service
[ "$(show Result)" = success ] || fail "result $(show Result) at stop"
journal=$(nsd journalctl -u trajroid.service --no-pager -o cat)
summary=$(grep "^summary:" <<<"$journal")
echo "$summary"
# The rear cuts its sweeps at 180°, half a turn from the front's: its closing packets are
# handed on at once too (not held for company, up to 20 ms), so while both send, most merged
# clouds go out within a millisecond or two of their last packet: each second's p50 (the
# status lines after the first, until the rear falls silent).
both_p50=$(awk -v silent="lidar: $silent" 'index($0, silent) { exit }
  /^status: / && match($0, /latency p50 [0-9.]+/) { if (++n > 1) printf "%s ", substr($0, RSTART + 12, RLENGTH - 12) }' <<<"$journal")
echo "each second's latency p50 while both sent: $both_p50 ms"
[ -n "$both_p50" ] || fail "no status line while both sent"
for p in $both_p50; do
  awk -v p="$p" 'BEGIN { exit !(p < 2.0) }' || fail "latency p50 $p ms while both sent: the rear's closing packets wait"
done
[[ "$summary" == *"merged sweeps published "* ]] || fail "the summary does not count the merged sweeps"
decode_errors=$(sed -n 's/.*decode errors \([0-9]*\).*/\1/p' <<<"$summary")
[ "${decode_errors:-0}" -ge 500 ] || fail "the summary does not count the rear's rejected packets (the capture's 500 or more)"
# The minute's slowest sweep is one the merge held for the rear before it was named silent
# (up to lidar_merge.max_wait_s): its time is said to be that wait, not the processing thread's.
slowest=$(grep "^minute:" <<<"$journal" | tail -1 | sed -n 's/.*| slowest: //p')
echo "the minute's slowest: $slowest"
[[ "$slowest" == *"waiting for the other LiDARs' sweeps "* ]] ||
  fail "the slowest sweep's time is not put down to the merge's wait: '$slowest'"
