#!/usr/bin/env bash
# The .deb: built by cpack, installed on this machine with dpkg -i, started by a real systemd
# (PID 1 of private namespaces, tests/systemd/nsd.sh) as the installed unit with the installed
# configuration, fed a real VLP-16 capture, stopped, and purged: nothing of it left behind.
# The machine's net.core.rmem_* (set by the package's postinst) are put back at the end.
# With SPY_CHECK_CLASSPATH (tools/spy's check, the build's type jar, lcm.jar): every channel
# of a replay through the installed daemon decodes in lcm-spy's way with the installed jar.
# Usage: deb_test.sh BUILD WORK DATA_DIR [SPY_CHECK_CLASSPATH]
set -euo pipefail
build=$1 work=$2 data_dir=$(cd "$3" 2>/dev/null && pwd || echo "$3") spy_classpath=${4:-}
here=$(cd "$(dirname "$0")" && pwd)
# shellcheck source=../systemd/nsd.sh
source "$here/../systemd/nsd.sh"
nsd_require
command -v dpkg >/dev/null || skip_or_fail "no dpkg: not a Debian machine"
fail() {
  echo "FAIL: $*" >&2
  [ -n "$NSD_PID1" ] && nsd journalctl -u trajroid.service --no-pager -o cat | tail -30 >&2
  exit 1
}
if dpkg-query -W -f='${Status}' trajroi 2>/dev/null | grep -q installed; then
  fail "a trajroi package is already installed on this machine: not touching it"
fi
rm -rf "$work"
mkdir -p "$work"
(cd "$build" && cpack -G DEB -B "$work" >"$work/cpack.txt" 2>&1) || fail "cpack: $(tail -20 "$work/cpack.txt")"
deb=$(ls "$work"/trajroi_*.deb)
echo "built $(basename "$deb") ($(du -k "$deb" | cut -f1) KiB)"

old_default=$(sysctl -n net.core.rmem_default)
old_max=$(sysctl -n net.core.rmem_max)
purge() {
  dpkg --purge trajroi >/dev/null 2>&1 || true
  sysctl -q -w net.core.rmem_max="$old_max" net.core.rmem_default="$old_default" || true
}
nsd_on_exit() { purge; }
trap 'purge' EXIT

dpkg -i "$deb" >"$work/dpkg-i.txt" 2>&1 || fail "dpkg -i: $(cat "$work/dpkg-i.txt")"
dpkg -L trajroi >"$work/files.txt"
echo "dpkg -i: $(wc -l <"$work/files.txt") paths; conffiles: $(dpkg-query -W -f='${Conffiles}' trajroi | awk 'NF {printf "%s ", $1}')"
dpkg-query -W -f='${Conffiles}' trajroi | grep -q "/etc/trajroi/trajroid.yaml" || fail "the configuration is not a conffile"
/usr/bin/trajroid --version | grep -qx "trajroid [0-9.]*" || fail "trajroid --version"
/usr/bin/trajroi --version | grep -qx "trajroi [0-9.]*" || fail "trajroi --version"
[ "$(sysctl -n net.core.rmem_default)" -ge 8388608 ] || fail "the postinst did not apply the sysctl drop-in"
python=/usr/bin/python3
[ -x "$python" ] || python=${PYTHON:-python3}
PYTHONPATH=/usr/lib/python3/dist-packages "$python" -c "import trajroi, trajroi_lcm; trajroi.points_t()" ||
  fail "the installed Python types do not import"

nsd_boot
nsd systemctl daemon-reload
nsd systemctl start trajroid.service || fail "the installed unit does not start"
echo "installed unit: $(nsd systemctl show trajroid.service -p ActiveState --value), status '$(nsd systemctl show trajroid.service -p StatusText --value)'"
pcap=$data_dir/velodyne/vlp16/mrpt_sample_velodyne_vlp16_gps.pcap
if [ -f "$pcap" ]; then
  nsd /usr/bin/trajroi feed --pcap "$pcap" --until 2 >"$work/feed.txt" 2>&1 || fail "feed: $(cat "$work/feed.txt")"
  sleep 1
  status=$(nsd systemctl show trajroid.service -p StatusText --value)
  echo "after a VLP-16 capture: status '$status'"
  # The example configuration takes its pose from GNSS + IMU: LiDAR data without them is
  # said as a missing pose, no longer as missing LiDAR data.
  [[ "$status" != *"waiting for LiDAR data"* ]] || fail "the installed daemon did not receive the capture"
elif [ "${CI:-}" = true ]; then
  fail "$pcap missing"
fi

if [ -n "$spy_classpath" ] && command -v java >/dev/null; then
  # The build's type jar swapped for the installed one.
  classpath=$(tr ':' '\n' <<<"$spy_classpath" | sed 's|.*/trajroi_lcmtypes\.jar$|/usr/share/java/trajroi_lcmtypes.jar|' | paste -sd:)
  /usr/bin/trajroi sim --quiet --scenario "$here/../daemon/corridor.yaml" --out "$work/run" >/dev/null 2>&1
  bash "$(dirname "$0")/../systemd/own_network.sh" /bin/bash -c '
    set -euo pipefail
    url="udpm://239.255.76.67:7667?ttl=0&recv_buf_size=8388608"
    java -cp "$2" SpyDecodeCheck "$url" 12 TRAJROI_POINTS TRAJROI_POSE TRAJROI_ROI TRAJROI_STATUS >"$1/spy.txt" 2>&1 &
    check=$!
    sleep 2
    /usr/bin/trajroid --config "$1/run/trajroid.yaml" --replay "$1/run" --rate 4 2>"$1/replay.log"
    wait "$check"' _ "$work" "$classpath" || fail "a channel does not decode with the installed jar: $(cat "$work/spy.txt")"
  grep -E "decoded|no message" "$work/spy.txt" | sed 's/^/installed jar, lcm-spy decoding: /'
elif [ "${CI:-}" = true ]; then
  fail "no Java or no spy check: the installed jar is not checked"
fi

start_ns=$(date +%s%N)
nsd systemctl stop trajroid.service
echo "stop: $((($(date +%s%N) - start_ns) / 1000000)) ms, result $(nsd systemctl show trajroid.service -p Result --value)"
[ "$(nsd systemctl show trajroid.service -p Result --value)" = success ] || fail "not stopped cleanly"
nsd_end

dpkg --purge trajroi >"$work/dpkg-purge.txt" 2>&1 || fail "dpkg --purge: $(cat "$work/dpkg-purge.txt")"
left=()
while read -r path; do
  [ -f "$path" ] || [ -L "$path" ] && left+=("$path")
done <"$work/files.txt"
[ -e /etc/trajroi ] && left+=(/etc/trajroi)
[ ${#left[@]} -eq 0 ] || fail "left after the purge: ${left[*]}"
dpkg-query -W -f='${Status}' trajroi 2>/dev/null | grep -q "installed" && fail "still installed"
echo "dpkg --purge: every file gone, /etc/trajroi too"
echo "PASS"
