#!/usr/bin/env bash
# trajroid under a real systemd (PID 1 of private PID, mount and network namespaces, see
# nsd.sh), with the unit as installed. One case per run:
#   service_test.sh CASE UNIT CONFIG_DIR TRAJROI WORK PYTHONPATH DATA_DIR
# CASE: idle_then_stop | frozen_is_restarted | reload | bad_config | live | rtk | two_lidars
set -euo pipefail
case_name=$1 unit_file=$2 config_dir=$3 trajroi=$4 work=$5 python_path=$6 data_dir=$7
here=$(cd "$(dirname "$0")" && pwd)
# shellcheck source=nsd.sh
source "$here/nsd.sh"

rm -rf "$work"
mkdir -p "$work"
chmod 755 "$work"
export NSD_LOG="$work/boot.log"

fail() {
  echo "FAIL: $*" >&2
  echo "--- journal of trajroid.service ---" >&2
  nsd journalctl -u trajroid.service --no-pager -o short-monotonic 2>/dev/null | tail -60 >&2 || true
  exit 1
}
show() { nsd systemctl show trajroid.service -p "$1" --value; }
# Waits up to $1 seconds for the command after it to succeed.
wait_for() {
  local limit=$1
  shift
  local deadline=$((SECONDS + limit))
  until "$@"; do
    [ $SECONDS -lt $deadline ] || return 1
    sleep 0.2
  done
}
journal_has() { nsd journalctl -u trajroid.service --no-pager -o cat | grep -q -- "$1"; }
is_active() { [ "$(show ActiveState)" = active ]; }

# The unit as installed, reading CONFIG (default: the installed example configuration).
install_unit() {
  local config=${1:-$config_dir/trajroid.yaml}
  sed "s|$config_dir/trajroid.yaml|$config|g" "$unit_file" >"$work/trajroid.service"
  nsd_install_unit "$work/trajroid.service" trajroid.service
  # ProtectHome= hides /root and /home: a build tree there is let through read-only.
  local path
  for path in "$unit_file" "$config" "$work"; do
    case "$path" in
      /root/* | /home/*)
        printf '[Service]\nProtectHome=read-only\n' | nsd_drop_in trajroid.service home
        break
        ;;
    esac
  done
}
restarted() { [ "$(show NRestarts)" -ge 1 ]; }
# The allow-lists the unit's step set at start: its journal lines and IPAddressAllow=.
print_allow_lists() {
  echo "allow-lists set at start:"
  nsd journalctl -u trajroid.service --no-pager -o cat | grep "trajroid.service: allowing" | sed 's/^/  /'
  echo "  IPAddressAllow=$(show IPAddressAllow)"
}
# Whether IPAddressAllow= admits ADDRESS.
admits() {
  local allowed
  allowed=" $(show IPAddressAllow) "
  [[ "$allowed" == *" $1/32 "* || "$allowed" == *" $1 "* ]]
}
# The test's own background processes (PIDs added to `pids`), ended before the namespace ends.
pids=()
nsd_on_exit() {
  local p
  for p in "${pids[@]}"; do kill "$p" 2>/dev/null || true; done
  true
}

case $case_name in
idle_then_stop)
  nsd_boot
  install_unit
  nsd systemctl start trajroid.service || fail "start"
  is_active || fail "not active after start"
  pid=$(show MainPID)
  echo "READY: active, main PID $pid, status '$(show StatusText)'"
  wd_first=$(show WatchdogTimestampMonotonic)
  sleep 30
  restarts=$(show NRestarts)
  status=$(show StatusText)
  wd_last=$(show WatchdogTimestampMonotonic)
  echo "after 30 s without sensor data: NRestarts=$restarts, main PID $(show MainPID), status '$status'"
  [ "$restarts" = 0 ] || fail "restarted $restarts times while idle"
  [ "$(show MainPID)" = "$pid" ] || fail "main PID changed while idle"
  journal_has "Watchdog timeout" && fail "the watchdog fired while idle"
  [[ "$status" == *"waiting for LiDAR data"* ]] || fail "status does not say what is missing: '$status'"
  # The watchdog was fed all along (the loops turn): its last ping came at the end of the 30 s.
  fed_ms=$(((wd_last - wd_first) / 1000))
  echo "watchdog pings spanned ${fed_ms} ms of the 30 s"
  [ "$fed_ms" -ge 28000 ] || fail "the watchdog pings stopped (they spanned ${fed_ms} ms of 30 s)"

  # Warnings reach the journal at warning priority, informational lines do not.
  warnings=$(nsd journalctl -u trajroid.service -p warning --no-pager -o cat)
  grep -q "gnss: no device configured" <<<"$warnings" || fail "the gnss warning is not at warning priority"
  grep -q "trajroid running" <<<"$warnings" && fail "an info line is at warning priority"
  echo "journalctl -p warning: $(grep -c . <<<"$warnings") lines, the configuration's warnings among them"

  start_ns=$(date +%s%N)
  nsd systemctl stop trajroid.service
  stop_ms=$((($(date +%s%N) - start_ns) / 1000000))
  echo "systemctl stop: ${stop_ms} ms, result $(show Result)"
  [ "$stop_ms" -lt 1000 ] || fail "stop took ${stop_ms} ms"
  [ "$(show Result)" = success ] || fail "result $(show Result)"
  journal_has "Killing" && fail "systemd had to kill"
  journal_has "summary:" || fail "no summary in the journal"
  nsd journalctl -u trajroid.service --no-pager -o cat | grep "summary:"
  ;;

frozen_is_restarted)
  nsd_boot
  install_unit
  nsd systemctl start trajroid.service || fail "start"
  pid=$(show MainPID)
  nsd kill -STOP "$pid"
  echo "main PID $pid stopped (SIGSTOP)"
  wait_for 15 journal_has "Watchdog timeout" || fail "the watchdog did not fire on a frozen process"
  wait_for 10 restarted || fail "not restarted"
  wait_for 10 is_active || fail "not active again after the restart"
  [ "$(show MainPID)" != "$pid" ] || fail "same main PID after the restart"
  echo "restarted by the watchdog: NRestarts=$(show NRestarts), new main PID $(show MainPID)"
  nsd journalctl -u trajroid.service --no-pager -o cat | grep "Watchdog timeout" || true
  ;;

reload)
  cp "$config_dir/trajroid.yaml" "$work/trajroid.yaml"
  printf 'x,y\n0,0\n10,0\n20,5\n' >"$work/trajectory.csv"
  sed -i "s|^\(  file:\).*trajectory.*|\1 trajectory.csv|" "$work/trajroid.yaml"
  chmod 644 "$work"/*
  nsd_boot
  install_unit "$work/trajroid.yaml"
  nsd systemctl start trajroid.service || fail "start"
  pid=$(show MainPID)
  printf 'x,y\n0,0\n5,5\n' >"$work/trajectory.csv"
  nsd systemctl reload trajroid.service
  wait_for 5 journal_has "SIGHUP: trajectory 1 reloaded from $work/trajectory.csv" || fail "no reload (as trajectory 1)"
  printf 'x,y\n0,0\n' >"$work/trajectory.csv"
  nsd systemctl reload trajroid.service
  wait_for 5 journal_has "SIGHUP: trajectory not reloaded" || fail "a bad trajectory was not named"
  nsd journalctl -u trajroid.service -p err --no-pager -o cat | grep -q "not reloaded" ||
    fail "the refused reload is not at error priority"
  [ "$(show MainPID)" = "$pid" ] && is_active || fail "the daemon did not keep running"
  nsd systemctl stop trajroid.service
  [ "$(show Result)" = success ] || fail "result $(show Result) at stop"
  # (That the reloaded trajectory filters the sweeps that follow: the live case.)
  nsd journalctl -u trajroid.service --no-pager -o cat | grep "SIGHUP" || true
  ;;

bad_config)
  printf 'global_frame: {origin: {lat_deg: 50, lon_deg: 14, height_m: 0}}\ntrajectory: {file: missing.csv}\nlidar: {data_port: 80000}\n' >"$work/trajroid.yaml"
  chmod 644 "$work/trajroid.yaml"
  nsd_boot
  install_unit "$work/trajroid.yaml"
  nsd systemctl start trajroid.service && fail "a bad configuration started"
  sleep 5
  echo "state $(show ActiveState), result $(show Result), exit status $(show ExecMainStatus), NRestarts=$(show NRestarts)"
  nsd journalctl -u trajroid.service --no-pager -o cat | grep "configuration error\|status=78" || true
  journal_has "status=78" || fail "the start did not end with exit status 78"
  [ "$(show NRestarts)" = 0 ] || fail "restarted after a configuration error"
  [ "$(show ActiveState)" = failed ] || fail "state $(show ActiveState)"
  nsd journalctl -u trajroid.service -p err --no-pager -o cat | grep -q "configuration error" ||
    fail "the configuration error is not at error priority"
  ;;

live)
  # A VLP-16 at 10.0.0.100 (on the namespace's own loopback), the u-blox and the VN-100 as
  # pseudo-terminals handed to the dialout group: real captures at their recorded pace, read
  # by the DynamicUser through the allow-lists the unit derives from this configuration.
  pcap=$data_dir/velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap
  ubx=$data_dir/ublox/gpsd/ublox-neo-m8p.log
  vn100=$data_dir/vectornav/LoggerWavesInIce_F00379.raw
  for f in "$pcap" "$ubx" "$vn100"; do
    [ -f "$f" ] || skip_or_fail "$f is missing (TRAJROI_DATA_DIR)"
  done
  printf 'lat,lon\n50.13480,14.42995\n50.13540,14.42995\n' >"$work/trajectory.csv"
  cat >"$work/trajroid.yaml" <<YAML
global_frame:
  origin: {lat_deg: 50.13505, lon_deg: 14.42990, height_m: 348.0}
trajectory:
  file: trajectory.csv
lidar:
  sensor_address: 10.0.0.100
  min_range_m: 0.5
  max_range_m: 60
gnss:
  device: $work/gnss
imu:
  device: $work/imu
pose:
  source: gnss_imu
  mode: per_sweep
roi:
  circle_diameter_m: 1.2
  look_ahead_m: 6
YAML
  chmod 644 "$work"/*
  export NSD_ADDRESSES=10.0.0.100
  nsd_boot
  feed_pid=""
  logger_pid=""
  nsd_on_exit() {
    [ -n "$feed_pid" ] && kill "$feed_pid" 2>/dev/null
    [ -n "$logger_pid" ] && kill "$logger_pid" 2>/dev/null
    true
  }
  install_unit "$work/trajroid.yaml"

  hand_to_dialout() {
    local link
    for link in "$@"; do
      chgrp dialout "$(readlink -f "$link")"
      chmod 0660 "$(readlink -f "$link")"
    done
  }
  # The control: without its allow-list step, the unit's fixed list (localhost, 192.168/16)
  # drops the sensor's datagrams. (Pseudo-terminals need no DeviceAllow=: systemd's
  # DevicePolicy=closed always admits char-pts; the step adds the devices' class anyway.)
  printf '[Service]\nExecStartPre=\n' | nsd_drop_in trajroid.service no-allow-step
  nsd systemctl start trajroid.service || fail "start (control)"
  nsd "$trajroi" feed --pcap "$pcap" --from 10.0.0.100 --until 2 >"$work/feed-control.log" 2>&1 ||
    fail "feed (control): $(cat "$work/feed-control.log")"
  control_status=$(show StatusText)
  nsd systemctl stop trajroid.service
  control_final=$(nsd journalctl -u trajroid.service --no-pager -o cat | grep "^status:" | tail -1)
  echo "control, the unit's fixed allow-list: status '$control_status'; $control_final"
  firewall=yes
  if [[ "$control_final" != *"sweeps 0 "* ]]; then
    echo "NOTE: this kernel does not enforce IPAddressDeny= (no cgroup BPF): the control received the sensor"
    firewall=no
  fi
  nsd rm "/run/systemd/system/trajroid.service.d/no-allow-step.conf"
  nsd systemctl daemon-reload

  nsd "$trajroi" feed --pcap "$pcap" --from 10.0.0.100 --lidar-after 4 --until 6 --linger 2 \
    --ubx "$ubx" --gnss-link "$work/gnss" --vn100 "$vn100" --imu-link "$work/imu" >"$work/feed.log" 2>&1 &
  feed_pid=$!
  wait_for 10 test -L "$work/gnss" -a -L "$work/imu" || fail "the feed made no devices: $(cat "$work/feed.log")"
  hand_to_dialout "$work/gnss" "$work/imu"
  nsd timeout -s INT 25 lcm-logger --quiet "$work/out.lcmlog" >"$work/logger.log" 2>&1 &
  logger_pid=$!
  sleep 0.5
  nsd systemctl start trajroid.service || fail "start"
  print_allow_lists
  echo "  DeviceAllow=$(show DeviceAllow | tr '\n' ' ')"
  # A new trajectory before the LiDAR starts (4 s into the feed): every sweep is filtered by it.
  sleep 1
  printf 'lat,lon\n50.13470,14.42990\n50.13550,14.43000\n' >"$work/trajectory.csv"
  nsd systemctl reload trajroid.service
  wait_for 3 journal_has "SIGHUP: trajectory 1 reloaded from" || fail "no reload (as trajectory 1)"
  wait "$feed_pid" || fail "feed: $(tail -5 "$work/feed.log")"
  feed_pid=""
  sleep 1
  nsd systemctl stop trajroid.service
  [ "$(show Result)" = success ] || fail "result $(show Result) at stop"
  kill -INT "$logger_pid" 2>/dev/null || true
  wait "$logger_pid" || true
  logger_pid=""
  nsd journalctl -u trajroid.service --no-pager -o cat | grep "^summary:"
  summary=$(PYTHONPATH="$python_path" "${PYTHON:-python3}" "$here/log_summary.py" "$work/out.lcmlog") ||
    fail "the LCM log does not decode with the Python types"
  echo "$summary" | sed 's/^/  lcm-logger outside the unit: /'
  valid=$(awk '/^points_with_valid_pose/ {print $2}' <<<"$summary")
  read -r heading_min heading_max < <(awk '/^roi_heading_deg/ {print $2, $3}' <<<"$summary")
  [ "$valid" -ge 3 ] || fail "only $valid point clouds with a valid pose reached the subscriber outside"
  # The reload is visible to subscribers: the clouds are filtered against trajectory 1.
  last_id=$(awk '/^last_trajectory_id/ {print $2}' <<<"$summary")
  [ "$last_id" = 1 ] || fail "the last status names trajectory $last_id, not the reloaded one (1)"
  # The trajectory at start runs due north (90°); the reloaded one at 85.4° (89 m north, 7.1 m east).
  awk -v lo="$heading_min" -v hi="$heading_max" 'BEGIN { exit !(lo > 84.9 && hi < 85.9) }' ||
    fail "the ROIs are not placed on the reloaded trajectory (headings $heading_min … $heading_max°, expected 85.4°)"
  grep -q "gnss: .*opened\|gnss: reading" "$work/feed.log" || true
  echo "sensor behind the firewall: $firewall"
  ;;

rtk)
  # RTK corrections and the chrony feed through the unit's sandbox: RTKLIB's str2str as an
  # NTRIP caster at 10.0.0.50 (admitted by the allow-list step, as a caster named in the
  # configuration), serving the RTCM3 frames of a real ZED-F9T stream; the u-blox a pseudo-
  # terminal playing a real ZED-F9R log (rtk_peer.py); chronyd -Q making the SHM refclock the
  # DynamicUser writes into (perm=0666), which RemoveIPC= must leave in place at stop.
  rover_log=$data_dir/ublox/gpsd/ublox-zed-f9r.log
  base_log=$data_dir/ublox/gpsd/ublox-zed-f9t-rtcm3.log
  for f in "$rover_log" "$base_log"; do
    [ -f "$f" ] || skip_or_fail "$f is missing (TRAJROI_DATA_DIR)"
  done
  for tool in str2str /usr/sbin/chronyd lcm-logger; do
    command -v "$tool" >/dev/null || skip_or_fail "$tool is missing (scripts/install-deps.sh installs rtklib, chrony, liblcm-bin)"
  done
  peer() { nsd "${PYTHON:-python3}" "$here/rtk_peer.py" "$@"; }
  segment_made() { nsd ipcs -m | grep -q 0x4e545032; }
  every_frame_read() { "${PYTHON:-python3}" "$here/rtk_peer.py" check "$work/written.bin" "$base_log" >/dev/null; }
  printf '0,0\n10,0\n' >"$work/trajectory.csv"
  cat >"$work/trajroid.yaml" <<YAML
global_frame:
  origin: {lat_deg: 45.0657, lon_deg: 7.6590, height_m: 300.0}
trajectory:
  file: trajectory.csv
lidar:
  sensor_address: 10.0.0.100
gnss:
  device: $work/gnss
  configure: true
  rate_hz: 1
  corrections: {url: 'ntrip://rover:s3cret@10.0.0.50:2101/F9T', gga_interval_s: 1}
pose:
  source: gnss
  gnss_heading: {initial_heading_deg: 90}
  require_rtk: float
time:
  chrony_shm: 2
YAML
  printf 'refclock SHM 2:perm=0666 refid GNSS poll 0 filter 3\npidfile %s/chronyd.pid\n' "$work" >"$work/chrony.conf"
  chmod 644 "$work"/*
  export NSD_ADDRESSES=10.0.0.50
  nsd_boot
  install_unit "$work/trajroid.yaml"
  nsd /usr/sbin/chronyd -Q -d -t 45 -u root -f "$work/chrony.conf" >"$work/chronyd.log" 2>&1 &
  chronyd_pid=$!
  pids+=("$chronyd_pid")
  nsd str2str -in tcpsvr://:2102 -out "ntripc://rover:s3cret@:2101/F9T" >"$work/str2str.log" 2>&1 &
  pids+=($!)
  peer rover "$rover_log" "$work/gnss" "$work/written.bin" 40 >"$work/rover.log" 2>&1 &
  pids+=($!)
  wait_for 10 test -L "$work/gnss" || fail "no receiver: $(cat "$work/rover.log")"
  nsd chgrp dialout "$(readlink -f "$work/gnss")"
  wait_for 10 segment_made || fail "chronyd made no SHM 2: $(cat "$work/chronyd.log")"
  nsd timeout -s INT 30 lcm-logger --quiet "$work/out.lcmlog" >"$work/logger.log" 2>&1 &
  pids+=($!)
  nsd systemctl start trajroid.service || fail "start"
  print_allow_lists
  admits 10.0.0.50 ||
    fail "the caster's address is not admitted: $(show IPAddressAllow)"
  wait_for 15 journal_has "corrections: connected to ntrip://rover:\*\*\*@10.0.0.50:2101/F9T" ||
    fail "not connected to the caster"
  peer base "$base_log" 10.0.0.50:2102 || fail "the base could not reach str2str's input"
  wait_for 15 every_frame_read ||
    fail "not every frame reached the receiver: $("${PYTHON:-python3}" "$here/rtk_peer.py" check "$work/written.bin" "$base_log")"
  wait_for 10 journal_has "RTK float" || fail "the RTK solution is not named"
  # chronyd -Q ends once it has measured: "System clock wrong by X seconds".
  wait "$chronyd_pid" || fail "chronyd: $(cat "$work/chronyd.log")"
  chrony_offset=$(sed -n 's/.*System clock wrong by \(-\?[0-9.]*\) seconds.*/\1/p' "$work/chronyd.log" | tail -1)
  [ -n "$chrony_offset" ] || fail "chronyd measured nothing: $(cat "$work/chronyd.log")"
  nsd systemctl stop trajroid.service
  [ "$(show Result)" = success ] || fail "result $(show Result) at stop"
  # RemoveIPC= removes the dynamic user's IPC objects: chronyd's segment is not one of them.
  segment_made || fail "the SHM segment went with trajroid's stop (RemoveIPC=)"
  nsd journalctl -u trajroid.service --no-pager -o cat | grep -q s3cret && fail "the password reached the journal"
  summary=$(PYTHONPATH="$python_path" "${PYTHON:-python3}" "$here/log_summary.py" "$work/out.lcmlog") ||
    fail "the LCM log does not decode with the Python types"
  "${PYTHON:-python3}" "$here/rtk_peer.py" check "$work/written.bin" "$base_log"
  echo "$summary" | grep "^last_" | sed 's/^/  status: /'
  trajroid_offset=$(awk '/^last_host_minus_gnss_utc_s/ {print $2}' <<<"$summary")
  echo "chronyd -Q: host clock wrong by $chrony_offset s; trajroid's status: host − GNSS UTC $trajroid_offset s"
  # chronyd says the correction it would make (GNSS − host): the opposite of trajroid's figure.
  awk -v a="$chrony_offset" -v b="$trajroid_offset" 'BEGIN { d = a + b; exit !(d < 0.05 && d > -0.05) }' ||
    fail "chronyd's offset is not trajroid's"
  grep -q "^last_rtk_solution 1" <<<"$summary" || fail "the status does not report RTK float"
  ;;

two_lidars)
  # shellcheck source=service_two_lidars.sh
  source "$here/service_two_lidars.sh"
  ;;

*)
  echo "unknown case $case_name" >&2
  exit 2
  ;;
esac
echo "PASS: $case_name"
